#include "fss/widgets/scan_panel.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QSpinBox>

#include <algorithm>
#include <cmath>

namespace fss::widgets {

namespace {
QDoubleSpinBox* doubleSpin(QWidget* parent, double lo, double hi, double value, double step, int decimals) {
    auto* box = new QDoubleSpinBox(parent);
    box->setRange(lo, hi);
    box->setDecimals(decimals);
    box->setSingleStep(step);
    box->setValue(value);
    return box;
}
} // namespace

ScanPanel::ScanPanel(QWidget* parent) : QWidget(parent) {
    auto* form = new QFormLayout(this);
    resolution_ = new QSpinBox(this);
    resolution_->setRange(16, 4096);
    resolution_->setValue(256);
    resolution_->setSingleStep(32);
    resolution_->setSuffix(tr(" px"));
    resolution_->setToolTip(tr("Samples along the longer side of the scan image"));
    form->addRow(tr("Resolution"), resolution_);
    edgeLabel_ = new QLabel(this);
    edgeLabel_->setWordWrap(true);
    form->addRow(tr("Edge length"), edgeLabel_);
    erode_ = new QSpinBox(this);
    erode_->setRange(0, 8);
    erode_->setValue(1);
    form->addRow(tr("Erosion"), erode_);
    dilate_ = new QSpinBox(this);
    dilate_->setRange(0, 8);
    dilate_->setValue(1);
    form->addRow(tr("Dilation"), dilate_);
    maxEdge_ = doubleSpin(this, 1, 20, 3, 0.5, 1);
    maxEdge_->setToolTip(tr("Triangles with a longer edge (in pixel footprints) span a depth step"));
    form->addRow(tr("Max edge (footprints)"), maxEdge_);
    maxAngle_ = doubleSpin(this, 10, 90, 80, 1, 0);
    maxAngle_->setSuffix(QStringLiteral("°"));
    maxAngle_->setToolTip(tr("Samples and triangles seen at a larger angle are grazing and dropped"));
    form->addRow(tr("Max sampling angle"), maxAngle_);
    margin_ = doubleSpin(this, 0, 0.9, 0.1, 0.05, 2);
    margin_->setToolTip(tr("A sample replaces an existing face only when better by this fraction"));
    form->addRow(tr("Quality margin"), margin_);
    force_ = new QCheckBox(tr("Force replace"), this);
    force_->setToolTip(tr("Replace the mesh under the scan whatever its quality"));
    form->addRow(QString(), force_);
    spacing_ = doubleSpin(this, 0.5, 32, 2, 0.5, 1);
    spacing_->setSuffix(tr(" px"));
    spacing_->setToolTip(tr("Spacing of the fishbone grid in scan pixels"));
    form->addRow(tr("Fishbone spacing"), spacing_);
    fineField_ = new QCheckBox(tr("Fine direction field"), this);
    fineField_->setToolTip(tr("Trace fishbones on every pixel of the scan image: better alignment with "
                              "features, up to spacing² times the render cost (otherwise about one pixel "
                              "per sample, like a regular scan)"));
    form->addRow(QString(), fineField_);

    auto changed = [this] {
        refreshEdgeLength();
        emit settingsChanged();
    };
    connect(resolution_, &QSpinBox::valueChanged, this, changed);
    connect(erode_, &QSpinBox::valueChanged, this, changed);
    connect(dilate_, &QSpinBox::valueChanged, this, changed);
    connect(maxEdge_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(maxAngle_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(margin_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(force_, &QCheckBox::toggled, this, changed);
    connect(spacing_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(fineField_, &QCheckBox::toggled, this, changed);
    refreshEdgeLength();
}

ScanPanel::~ScanPanel() = default;

int ScanPanel::resolution() const {
    return resolution_->value();
}
void ScanPanel::setResolution(int pixels) {
    resolution_->setValue(pixels);
}
int ScanPanel::erodeRadius() const {
    return erode_->value();
}
void ScanPanel::setErodeRadius(int radius) {
    erode_->setValue(radius);
}
int ScanPanel::dilateRadius() const {
    return dilate_->value();
}
void ScanPanel::setDilateRadius(int radius) {
    dilate_->setValue(radius);
}
double ScanPanel::maxEdgeFootprints() const {
    return maxEdge_->value();
}
void ScanPanel::setMaxEdgeFootprints(double footprints) {
    maxEdge_->setValue(footprints);
}
double ScanPanel::maxSamplingAngleDeg() const {
    return maxAngle_->value();
}
void ScanPanel::setMaxSamplingAngleDeg(double degrees) {
    maxAngle_->setValue(degrees);
}
double ScanPanel::qualityMargin() const {
    return margin_->value();
}
void ScanPanel::setQualityMargin(double margin) {
    margin_->setValue(margin);
}
bool ScanPanel::forceReplace() const {
    return force_->isChecked();
}
void ScanPanel::setForceReplace(bool force) {
    force_->setChecked(force);
}
double ScanPanel::fishboneSpacing() const {
    return spacing_->value();
}
void ScanPanel::setFishboneSpacing(double pixels) {
    spacing_->setValue(pixels);
}
bool ScanPanel::fishboneFineField() const {
    return fineField_->isChecked();
}
void ScanPanel::setFishboneFineField(bool fine) {
    fineField_->setChecked(fine);
}

QSize ScanPanel::scanSize(QSizeF viewSize) const {
    const int r = resolution();
    if (viewSize.isEmpty()) return {r, r};
    if (viewSize.width() >= viewSize.height())
        return {r, std::max(1, int(std::lround(r * viewSize.height() / viewSize.width())))};
    return {std::max(1, int(std::lround(r * viewSize.width() / viewSize.height()))), r};
}

Camera ScanPanel::scanCamera(const Camera& viewCamera) const {
    Camera camera = viewCamera;
    const QSize size = scanSize(QSizeF(viewCamera.width, viewCamera.height));
    camera.width = size.width();
    camera.height = size.height();
    return camera;
}

ScanParams ScanPanel::scanParams(const Camera& viewCamera) const {
    ScanParams params;
    params.camera = scanCamera(viewCamera);
    params.erodeRadius = erodeRadius();
    params.dilateRadius = dilateRadius();
    params.triangulate.maxEdgeFootprints = maxEdgeFootprints();
    params.triangulate.maxSamplingAngleDeg = maxSamplingAngleDeg();
    params.quality.margin = qualityMargin();
    params.quality.forceReplace = forceReplace();
    return params;
}

void ScanPanel::updateEdgeLength(const std::optional<Camera>& viewCamera, const Eigen::Vector3d& at) {
    viewCamera_ = viewCamera;
    at_ = at;
    refreshEdgeLength();
}

QString ScanPanel::edgeLengthText() const {
    return edgeLabel_->text();
}

void ScanPanel::refreshEdgeLength() {
    edgeLength_ = 0;
    if (!viewCamera_) {
        edgeLabel_->setText(tr("(no mesh)"));
        return;
    }
    const Camera camera = scanCamera(*viewCamera_);
    if (camera.viewDepth(at_) <= 0) {
        edgeLabel_->setText(tr("(the mesh is behind the camera)"));
        return;
    }
    edgeLength_ = camera.pixelFootprint(at_);
    edgeLabel_->setText(tr("%1 (fishbone %2) at the mesh centre")
                            .arg(edgeLength_, 0, 'g', 3)
                            .arg(edgeLength_ * fishboneSpacing(), 0, 'g', 3));
}

} // namespace fss::widgets
