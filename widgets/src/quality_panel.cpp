#include "fss/widgets/quality_panel.h"

#include <QPaintEvent>
#include <QPainter>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fss::widgets {

namespace {

// Smallest corner angle of triangle (a, b, c) in degrees (atan2 of |cross| and dot: stable for slivers).
double smallestAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    auto angle = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
        return std::atan2(u.cross(v).norm(), u.dot(v));
    };
    const double A = angle(b - a, c - a), B = angle(a - b, c - b), C = angle(a - c, b - c);
    return std::min({A, B, C}) * 180.0 / std::numbers::pi;
}

Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

// Draws one bar chart into \p area: bars with their labels below and the largest count above.
void drawBars(QPainter& painter, const QRectF& area, const QString& title, const std::vector<double>& values,
              const std::vector<QString>& labels, const std::vector<QColor>& colors) {
    const QFontMetricsF fm(painter.font());
    const double lineH = fm.height();
    painter.setPen(QPalette().color(QPalette::WindowText));
    painter.drawText(QRectF(area.left(), area.top(), area.width(), lineH), Qt::AlignLeft, title);
    const QRectF plot(area.left(), area.top() + lineH + 2, area.width(), area.height() - 2 * lineH - 4);
    if (values.empty() || plot.height() <= 4) return;
    const double maxValue = std::max(1.0, *std::max_element(values.begin(), values.end()));
    const double barW = plot.width() / double(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
        const double h = plot.height() * values[i] / maxValue;
        const QRectF bar(plot.left() + i * barW + 1, plot.bottom() - h, std::max(1.0, barW - 2), h);
        painter.fillRect(bar, colors[i]);
        painter.drawText(QRectF(plot.left() + i * barW, plot.bottom() + 1, barW, lineH), Qt::AlignHCenter,
                         labels[i]);
    }
    painter.drawLine(plot.bottomLeft(), plot.bottomRight());
}

} // namespace

QualityPanel::QualityPanel(QWidget* parent) : QWidget(parent), minAngle_(kAngleBins, 0) {
    setSizePolicy(QSizePolicy::Preferred, QSizePolicy::Expanding);
}

QualityPanel::~QualityPanel() = default;

void QualityPanel::setMesh(const Mesh& mesh) {
    valence_.clear();
    minAngle_.assign(kAngleBins, 0);
    faces_ = 0;
    for (VertexIndex v : mesh.vertices()) {
        if (mesh.is_isolated(v) || mesh.is_border(v, true)) continue; // true: checks every incident halfedge
        ++valence_[int(mesh.degree(v))];
    }
    for (FaceIndex f : mesh.faces()) {
        const HalfedgeIndex h = mesh.halfedge(f);
        const double angle =
            smallestAngleDeg(toEigen(mesh.point(mesh.source(h))), toEigen(mesh.point(mesh.target(h))),
                             toEigen(mesh.point(mesh.target(mesh.next(h)))));
        const int bin = std::isfinite(angle) ? std::clamp(int(angle / kAngleBinDeg), 0, kAngleBins - 1) : 0;
        ++minAngle_[std::size_t(bin)];
        ++faces_;
    }
    ++updates_;
    update();
    emit updated();
}

void QualityPanel::clear() {
    valence_.clear();
    minAngle_.assign(kAngleBins, 0);
    faces_ = 0;
    update();
    emit updated();
}

QSize QualityPanel::sizeHint() const {
    return {260, 260};
}
QSize QualityPanel::minimumSizeHint() const {
    return {160, 160};
}

void QualityPanel::paintEvent(QPaintEvent*) {
    QPainter painter(this);
    painter.fillRect(rect(), palette().color(QPalette::Base));
    const QRectF all = QRectF(rect()).adjusted(6, 4, -6, -4);
    const QRectF top(all.left(), all.top(), all.width(), all.height() / 2 - 4);
    const QRectF bottom(all.left(), all.top() + all.height() / 2 + 4, all.width(), all.height() / 2 - 4);

    // Valence 3 … 9, with everything below or above folded into the ends.
    std::vector<double> values(7, 0.0);
    std::size_t interior = 0;
    for (const auto& [valence, count] : valence_) {
        values[std::size_t(std::clamp(valence, 3, 9) - 3)] += double(count);
        interior += count;
    }
    std::vector<QString> labels{QStringLiteral("≤3"), QStringLiteral("4"), QStringLiteral("5"),
                                QStringLiteral("6"),  QStringLiteral("7"), QStringLiteral("8"),
                                QStringLiteral("≥9")};
    std::vector<QColor> colors(7, QColor(230, 120, 60));
    colors[3] = QColor(70, 170, 70);
    colors[2] = colors[4] = QColor(230, 200, 60);
    const double regular =
        interior ? 100.0 * double(valence_.count(6) ? valence_.at(6) : 0) / double(interior) : 0;
    drawBars(painter, top, tr("Valence: %1 % of %2 regular").arg(regular, 0, 'f', 1).arg(interior), values,
             labels, colors);

    std::vector<double> angles(minAngle_.begin(), minAngle_.end());
    std::vector<QString> angleLabels;
    std::vector<QColor> angleColors;
    for (int i = 0; i < kAngleBins; ++i) {
        angleLabels.push_back(i % 2 == 0 ? QString::number(int(i * kAngleBinDeg)) : QString());
        // red at 0°, yellow at 30°, green at 60° (as VtkView's MinAngle colour map)
        const double t = (i + 0.5) / kAngleBins;
        angleColors.push_back(t < 0.5 ? QColor::fromRgbF(0.9f, float(0.2 + 1.4 * t), 0.2f)
                                      : QColor::fromRgbF(float(0.9 - 1.4 * (t - 0.5)), 0.85f, 0.25f));
    }
    drawBars(painter, bottom, tr("Smallest angle (°) of %1 faces").arg(faces_), angles, angleLabels,
             angleColors);
}

} // namespace fss::widgets

#include "fss/widgets/moc_quality_panel.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
