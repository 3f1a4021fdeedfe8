#include "fss/widgets/scan_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QKeyEvent>
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
    resolution_->setToolTip(tr("Samples along the longer side of the scan image (Enter scans). Typing "
                               "it holds the resolution as the view changes."));
    resolution_->setObjectName(QStringLiteral("resolution"));
    target_ = doubleSpin(this, 1e-9, 1e12, 1, 0.1, 4);
    target_->setObjectName(QStringLiteral("targetEdgeLength"));
    target_->setToolTip(tr("Wanted edge length of the scanned triangles in world units (Enter scans); the "
                           "resolution follows it as you zoom. Defaults to the input's mean edge length."));
    form->addRow(tr("Target edge"), target_);
    follow_ = new QCheckBox(tr("Keep edge length"), this);
    follow_->setToolTip(tr("Checked: zooming changes the resolution so that the edge length stays. "
                           "Unchecked: the resolution stays and the edge length changes."));
    form->addRow(QString(), follow_);
    form->addRow(tr("Resolution"), resolution_);
    edgeLabel_ = new QLabel(this);
    edgeLabel_->setWordWrap(true);
    form->addRow(tr("Edge length"), edgeLabel_);
    inputLabel_ = new QLabel(tr("(no mesh)"), this);
    inputLabel_->setWordWrap(true);
    inputLabel_->setToolTip(tr("Mean edge length of the input mesh"));
    form->addRow(tr("Input edges"), inputLabel_);
    erode_ = new QSpinBox(this);
    erode_->setRange(0, 8);
    erode_->setValue(1);
    erode_->setToolTip(tr("Samples within this many grid steps of a hole or silhouette are dropped"));
    form->addRow(tr("Erosion"), erode_);
    dilate_ = new QSpinBox(this);
    dilate_->setRange(0, 8);
    dilate_->setValue(1);
    dilate_->setToolTip(tr("Grows the kept region again by this many grid steps after the erosion"));
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
    lattice_ = new QComboBox(this);
    lattice_->setObjectName(QStringLiteral("lattice"));
    // Item data: the Lattice enumerator.
    lattice_->addItem(tr("Adaptive"), int(Lattice::Adaptive));
    lattice_->addItem(tr("Triangular"), int(Lattice::Triangular));
    lattice_->addItem(tr("Square"), int(Lattice::Square));
    lattice_->setToolTip(tr("Where a regular scan puts its samples: Adaptive, a triangular lattice chosen "
                            "per view so that the triangles are equilateral on the surface; Triangular, "
                            "equilateral on the screen; Square, one sample per pixel (the paper's grid)"));
    // The panel's width stays what the spin boxes ask for (the view beside it keeps its size).
    lattice_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    lattice_->setMinimumContentsLength(6);
    form->addRow(tr("Lattice"), lattice_);
    minLatticeAngle_ = doubleSpin(this, 0, 59, ScanOptions{}.minLatticeAngleDeg, 1, 0);
    minLatticeAngle_->setSuffix(QStringLiteral("°"));
    minLatticeAngle_->setToolTip(
        tr("Samples whose lattice triangle would have a smaller angle on the surface "
           "(seen at a slant) are left to another view; 0 = keep them"));
    form->addRow(tr("Min lattice angle"), minLatticeAngle_);
    // "Warp lattice | to the surface": split over the label and the field so that the panel does not widen.
    warp_ = new QCheckBox(tr("to the surface"), this);
    warp_->setObjectName(QStringLiteral("warpToSurface"));
    warp_->setChecked(ScanOptions{}.warpToSurface);
    warp_->setToolTip(tr("Adaptive lattice only: bend the lattice per sample so that its triangles are "
                         "equilateral on the curved surface, not only on the plane at the view's main slant "
                         "(rounder triangles; off = the one lattice chosen for the view)"));
    form->addRow(tr("Warp lattice"), warp_);
    setLattice(ScanOptions{}.lattice);
    warp_->setEnabled(lattice() == Lattice::Adaptive);
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
    connect(resolution_, &QSpinBox::valueChanged, this, [this, changed] {
        if (!applying_) {
            const QSignalBlocker blocker(follow_);
            follow_->setChecked(false); // a typed resolution is held
        }
        changed();
    });
    connect(target_, &QDoubleSpinBox::valueChanged, this, [this] {
        {
            const QSignalBlocker blocker(follow_);
            follow_->setChecked(true);
        }
        applyTarget();
        emit settingsChanged();
    });
    connect(follow_, &QCheckBox::toggled, this, [this] {
        applyTarget();
        emit settingsChanged();
    });
    resolution_->installEventFilter(this);
    target_->installEventFilter(this);
    // Fields never squeezed below their natural height (RemeshWidget scrolls the panel instead).
    for (QAbstractSpinBox* box : findChildren<QAbstractSpinBox*>())
        box->setMinimumHeight(box->sizeHint().height());
    connect(erode_, &QSpinBox::valueChanged, this, changed);
    connect(dilate_, &QSpinBox::valueChanged, this, changed);
    connect(maxEdge_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(maxAngle_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(margin_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(force_, &QCheckBox::toggled, this, changed);
    connect(lattice_, &QComboBox::currentIndexChanged, this, [this, changed] {
        warp_->setEnabled(lattice() == Lattice::Adaptive); // the warp bends the adaptive lattice only
        changed();
    });
    connect(warp_, &QCheckBox::toggled, this, changed);
    connect(minLatticeAngle_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(spacing_, &QDoubleSpinBox::valueChanged, this, changed);
    connect(fineField_, &QCheckBox::toggled, this, changed);
    refreshEdgeLength();
}

ScanPanel::~ScanPanel() = default;

bool ScanPanel::eventFilter(QObject* watched, QEvent* event) {
    if ((watched == resolution_ || watched == target_) && event->type() == QEvent::KeyPress) {
        const int key = static_cast<QKeyEvent*>(event)->key();
        if (key == Qt::Key_Return || key == Qt::Key_Enter) {
            static_cast<QAbstractSpinBox*>(watched)->interpretText(); // the typed value first
            emit scanRequested();
            return true;
        }
    }
    return QWidget::eventFilter(watched, event);
}

double ScanPanel::targetEdgeLength() const {
    return target_->value();
}

void ScanPanel::setTargetEdgeLength(double length) {
    target_->setValue(length);
    if (!follow_->isChecked()) follow_->setChecked(true); // the same value again still makes it follow
}

bool ScanPanel::followsTargetEdgeLength() const {
    return follow_->isChecked();
}

void ScanPanel::setFollowsTargetEdgeLength(bool follow) {
    follow_->setChecked(follow);
}

void ScanPanel::setInputEdgeLength(double meanEdge) {
    inputEdge_ = meanEdge > 0 && std::isfinite(meanEdge) ? meanEdge : 0;
    if (inputEdge_ == 0) {
        inputLabel_->setText(tr("(no mesh)"));
        return;
    }
    inputLabel_->setText(tr("mean %1").arg(inputEdge_, 0, 'g', 3));
    // Four significant digits at the input's scale.
    const int decimals = std::clamp(3 - int(std::floor(std::log10(inputEdge_))), 0, 12);
    {
        const QSignalBlocker blocker(target_);
        target_->setDecimals(decimals);
        target_->setRange(std::pow(10.0, -decimals), inputEdge_ * 1e4);
        target_->setSingleStep(std::pow(10.0, std::floor(std::log10(inputEdge_))) / 2);
    }
    setTargetEdgeLength(inputEdge_);
}

double ScanPanel::footprintAt(int pixels) const {
    if (!viewCamera_) return 0;
    Camera camera = *viewCamera_;
    const QSizeF view(camera.width, camera.height);
    if (view.width() >= view.height()) {
        camera.width = pixels;
        camera.height = std::max(1, int(std::lround(pixels * view.height() / view.width())));
    } else {
        camera.width = std::max(1, int(std::lround(pixels * view.width() / view.height())));
        camera.height = pixels;
    }
    if (camera.viewDepth(at_) <= 0) return 0;
    return camera.pixelFootprint(at_);
}

void ScanPanel::applyTarget() {
    const double target = target_->value();
    if (follow_->isChecked() && target > 0) {
        const double unit = footprintAt(1024) * 1024; // footprint × pixels: about constant
        if (unit > 0) {
            int best = std::clamp(int(std::lround(unit / target)), 16, 4096);
            // The shorter side is rounded: take the neighbour whose footprint is closest to the target.
            for (int r : {best - 1, best + 1})
                if (r >= 16 && r <= 4096 &&
                    std::abs(footprintAt(r) - target) < std::abs(footprintAt(best) - target))
                    best = r;
            applying_ = true;
            resolution_->setValue(best);
            applying_ = false;
        }
    }
    refreshEdgeLength(); // a changed resolution has emitted settingsChanged
}
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
Lattice ScanPanel::lattice() const {
    return Lattice(lattice_->currentData().toInt());
}
void ScanPanel::setLattice(Lattice lattice) {
    lattice_->setCurrentIndex(lattice_->findData(int(lattice)));
}
double ScanPanel::minLatticeAngleDeg() const {
    return minLatticeAngle_->value();
}
void ScanPanel::setMinLatticeAngleDeg(double degrees) {
    minLatticeAngle_->setValue(degrees);
}
bool ScanPanel::warpToSurface() const {
    return warp_->isChecked();
}
void ScanPanel::setWarpToSurface(bool warp) {
    warp_->setChecked(warp);
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
    params.scan.lattice = lattice();
    params.scan.minLatticeAngleDeg = minLatticeAngleDeg();
    params.scan.warpToSurface = warpToSurface();
    return params;
}

void ScanPanel::updateEdgeLength(const std::optional<Camera>& viewCamera, const Eigen::Vector3d& at) {
    viewCamera_ = viewCamera;
    at_ = at;
    applyTarget(); // following the target: the resolution for the new view
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

#include "fss/widgets/moc_scan_panel.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
