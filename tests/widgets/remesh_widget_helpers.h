#pragma once
// The helpers the RemeshWidget tests share (remesh_widget_test.cpp, remesh_widget_accept_test.cpp): synthetic
// mouse events, a shown widget, the invariants of DESIGN.md §5 checked with CGAL, and independent counts for
// the QualityPanel's histograms.
#include "pixel_stats.h"
#include "test_data.h"

#include <fss/camera.h>
#include <fss/mask.h>
#include <fss/mesh_io.h>
#include <fss/metrics.h>
#include <fss/shapes.h>
#include <fss/widgets/figures_measurer.h>
#include <fss/widgets/fishbone_tool.h>
#include <fss/widgets/lasso_tool.h>
#include <fss/widgets/quality_panel.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/scan_tool.h>
#include <fss/widgets/screen_mapping.h>
#include <fss/widgets/tool.h>
#include <fss/widgets/vtk_view.h>

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/boost/graph/helpers.h>

#include <QAbstractSpinBox>
#include <QApplication>
#include <QElapsedTimer>
#include <QImage>
#include <QLineF>
#include <QMouseEvent>
#include <QPainter>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTest>
#include <QTimer>
#include <QToolBar>
#include <QUndoStack>
#include <QUndoView>

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <stop_token>
#include <thread>
#include <utility>

namespace remesh_widget_test_helpers {

namespace PMP = CGAL::Polygon_mesh_processing;
using fss::widgets::FishboneTool;
using fss::widgets::RemeshWidget;

inline void sendMouse(QWidget* w, QEvent::Type type, QPointF pos, Qt::MouseButton button,
                      Qt::MouseButtons buttons, Qt::KeyboardModifiers modifiers = Qt::NoModifier) {
    QMouseEvent event(type, pos, w->mapToGlobal(pos), button, buttons, modifiers);
    QApplication::sendEvent(w, &event);
}

inline void click(QWidget* w, QPointF pos, Qt::KeyboardModifiers modifiers = Qt::NoModifier) {
    sendMouse(w, QEvent::MouseButtonPress, pos, Qt::LeftButton, Qt::LeftButton, modifiers);
    sendMouse(w, QEvent::MouseButtonRelease, pos, Qt::LeftButton, Qt::NoButton, modifiers);
}

inline void sendWheel(QWidget* w, QPointF pos, int angle) {
    QWheelEvent event(pos, w->mapToGlobal(pos), QPoint(), QPoint(0, angle), Qt::NoButton, Qt::NoModifier,
                      Qt::NoScrollPhase, false);
    QApplication::sendEvent(w, &event);
}

// A lasso drawn with the mouse: a circle of \p radius DIP around \p centre in \p steps moves.
inline QPolygonF drawLasso(QWidget* view, QPointF centre, double radius, int steps = 48) {
    QPolygonF drawn;
    const QPointF start = centre + QPointF(radius, 0);
    sendMouse(view, QEvent::MouseButtonPress, start, Qt::LeftButton, Qt::LeftButton);
    drawn << start;
    for (int i = 1; i <= steps; ++i) {
        const double a = 2 * std::numbers::pi * i / steps;
        const QPointF p = centre + QPointF(radius * std::cos(a), radius * std::sin(a));
        sendMouse(view, QEvent::MouseMove, p, Qt::NoButton, Qt::LeftButton);
        drawn << p;
    }
    sendMouse(view, QEvent::MouseButtonRelease, drawn.back(), Qt::LeftButton, Qt::NoButton);
    return drawn;
}

inline std::unique_ptr<RemeshWidget> shownWidget(const fss::Mesh& mesh, QSize size = {1000, 700}) {
    auto w = std::make_unique<RemeshWidget>();
    w->resize(size);
    w->show();
    if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
    if (!w->setMesh(mesh)) return nullptr;
    QTest::qWait(20);
    return w;
}

// Independent whole-mesh figures: the share of interior vertices of valence 6 (halfedges pointing at each
// vertex) and the smallest corner angle (law of cosines), for the accept summary.
inline std::pair<double, double> valence6AndMinAngle(const fss::Mesh& m) {
    std::map<fss::VertexIndex, int> in;
    std::set<fss::VertexIndex> onBorder;
    for (fss::HalfedgeIndex h : m.halfedges()) {
        ++in[m.target(h)];
        if (m.is_border(h)) onBorder.insert(m.target(h));
    }
    std::size_t interior = 0, six = 0;
    for (const auto& [v, count] : in)
        if (!onBorder.count(v)) {
            ++interior;
            six += count == 6 ? 1 : 0;
        }
    double smallest = 180;
    for (fss::FaceIndex f : m.faces()) {
        std::vector<fss::Point3> p;
        for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
            p.push_back(m.point(v));
        for (int i = 0; i < 3; ++i) {
            const double a = std::sqrt(CGAL::squared_distance(p[(i + 1) % 3], p[(i + 2) % 3]));
            const double b = std::sqrt(CGAL::squared_distance(p[i], p[(i + 1) % 3]));
            const double c = std::sqrt(CGAL::squared_distance(p[i], p[(i + 2) % 3]));
            smallest =
                std::min(smallest, std::acos(std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0)) *
                                       180 / std::numbers::pi);
        }
    }
    return {interior ? double(six) / double(interior) : 0.0, smallest};
}

// CPU time of the whole process (every thread), seconds.
inline double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

inline bool waitIdle(RemeshWidget& w, int timeoutMs = 120000) {
    QElapsedTimer t;
    t.start();
    while (w.isBusy() && t.elapsed() < timeoutMs)
        QTest::qWait(5);
    return !w.isBusy();
}

inline Eigen::Vector3d vec(const fss::Point3& p) {
    return {p.x(), p.y(), p.z()};
}

using Triangle = std::array<std::array<double, 3>, 3>;

// The face's corner positions, rotated so that the smallest corner comes first (orientation kept).
inline Triangle triangle(const fss::Mesh& m, fss::FaceIndex f) {
    Triangle t;
    int i = 0;
    for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m)) {
        const fss::Point3& p = m.point(v);
        t[std::size_t(i++)] = {p.x(), p.y(), p.z()};
    }
    const auto first = std::min_element(t.begin(), t.end()) - t.begin();
    std::rotate(t.begin(), t.begin() + first, t.end());
    return t;
}

inline double longestEdge(const fss::Mesh& m) {
    double l = 0;
    for (fss::EdgeIndex e : m.edges())
        l = std::max(l,
                     (vec(m.point(m.source(m.halfedge(e)))) - vec(m.point(m.target(m.halfedge(e))))).norm());
    return l;
}

inline std::size_t borderEdges(const fss::Mesh& m) {
    std::size_t n = 0;
    for (fss::EdgeIndex e : m.edges())
        n += m.is_border(e) ? 1 : 0;
    return n;
}

// DESIGN.md §5 on \p after, the result of stitching \p patch into \p before.
// Returns the number of faces far from the patch that were checked to be untouched.
inline std::size_t checkInvariants(const fss::Mesh& before, const fss::Mesh& after, const fss::Mesh& patch) {
    [&] {
        QVERIFY(CGAL::is_valid_polygon_mesh(after));
        QVERIFY(CGAL::is_triangle_mesh(after));
        QCOMPARE(borderEdges(after), borderEdges(before)); // no new holes; closed stays closed
        if (CGAL::is_closed(before)) {
            QVERIFY(CGAL::is_closed(after));
            QCOMPARE(PMP::is_outward_oriented(after),
                     PMP::is_outward_oriented(before)); // consistent orientation
        }
        for (fss::VertexIndex v : after.vertices())
            QVERIFY2(!after.is_isolated(v), "isolated vertex");
        for (fss::FaceIndex f : after.faces())
            QVERIFY2(!PMP::is_degenerate_triangle_face(f, after), "degenerate face");
        QVERIFY2(!PMP::does_self_intersect(after), "self-intersection");
        fss::Mesh a = after, b = before;
        QCOMPARE(PMP::connected_components(a, a.add_property_map<fss::FaceIndex, std::size_t>("f:cc").first),
                 PMP::connected_components(b, b.add_property_map<fss::FaceIndex, std::size_t>("f:cc").first));
    }();
    // Faces away from the patch (farther than 4 of the mesh's longest edges from its bounding box) are
    // untouched: the same corners in the same order.
    Eigen::AlignedBox3d box;
    for (fss::VertexIndex v : patch.vertices())
        box.extend(vec(patch.point(v)));
    const double margin = 4 * std::max(longestEdge(before), longestEdge(patch));
    box.min().array() -= margin;
    box.max().array() += margin;
    std::set<Triangle> afterFaces;
    for (fss::FaceIndex f : after.faces())
        afterFaces.insert(triangle(after, f));
    std::size_t far = 0, missing = 0;
    for (fss::FaceIndex f : before.faces()) {
        bool inside = false;
        for (fss::VertexIndex v : CGAL::vertices_around_face(before.halfedge(f), before))
            inside = inside || box.contains(vec(before.point(v)));
        if (inside) continue;
        ++far;
        missing += afterFaces.count(triangle(before, f)) ? 0 : 1;
    }
    if (missing != 0) qWarning("%zu of %zu far faces changed", missing, far);
    return missing == 0 ? far : 0;
}

inline bool identical(const fss::Mesh& a, const fss::Mesh& b) {
    if (a.number_of_vertices() != b.number_of_vertices() || a.number_of_faces() != b.number_of_faces() ||
        a.number_of_removed_faces() != b.number_of_removed_faces())
        return false;
    auto va = a.vertices().begin();
    for (fss::VertexIndex vb : b.vertices()) {
        if (*va != vb || a.point(*va) != b.point(vb)) return false;
        ++va;
    }
    auto fa = a.faces().begin();
    for (fss::FaceIndex fb : b.faces()) {
        if (*fa != fb) return false;
        auto ca = CGAL::vertices_around_face(a.halfedge(*fa), a).begin();
        for (fss::VertexIndex v : CGAL::vertices_around_face(b.halfedge(fb), b))
            if (*ca++ != v) return false;
        ++fa;
    }
    return true;
}

// Independent counts for the QualityPanel: valence by counting the halfedges pointing at each vertex,
// smallest angle by the law of cosines; faces whose smallest angle lies within 1e-6° of a bin boundary
// are counted in `ambiguous` (the panel's atan2 may put them in the neighbouring bin).
struct Counts {
    std::map<int, std::size_t> valence;
    std::vector<std::size_t> angle = std::vector<std::size_t>(12, 0);
    std::size_t ambiguous = 0;
};

inline Counts independentCounts(const fss::Mesh& m) {
    Counts c;
    std::map<fss::VertexIndex, int> in;
    std::set<fss::VertexIndex> onBorder;
    for (fss::HalfedgeIndex h : m.halfedges()) {
        ++in[m.target(h)];
        if (m.is_border(h)) {
            onBorder.insert(m.target(h));
            onBorder.insert(m.source(h));
        }
    }
    for (const auto& [v, count] : in)
        if (!onBorder.count(v)) ++c.valence[count];
    for (fss::FaceIndex f : m.faces()) {
        std::vector<Eigen::Vector3d> p;
        for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
            p.push_back(vec(m.point(v)));
        const double a = (p[1] - p[2]).norm(), b = (p[0] - p[2]).norm(), cc = (p[0] - p[1]).norm();
        auto corner = [](double opposite, double s1, double s2) {
            return std::acos(
                       std::clamp((s1 * s1 + s2 * s2 - opposite * opposite) / (2 * s1 * s2), -1.0, 1.0)) *
                   180 / std::numbers::pi;
        };
        const double smallest = std::min({corner(a, b, cc), corner(b, a, cc), corner(cc, a, b)});
        const double bin = smallest / 5.0;
        if (std::abs(bin - std::round(bin)) < 1e-6 / 5.0 && smallest > 1e-6 && smallest < 60 - 1e-6)
            ++c.ambiguous;
        ++c.angle[std::size_t(std::clamp(int(bin), 0, 11))];
    }
    return c;
}

inline void compareQuality(const fss::widgets::QualityPanel& panel, const fss::Mesh& mesh) {
    const Counts c = independentCounts(mesh);
    QVERIFY(panel.valenceHistogram() == c.valence);
    QCOMPARE(panel.faceCount(), mesh.number_of_faces());
    std::size_t differ = 0;
    for (int i = 0; i < 12; ++i)
        differ += std::size_t(
            std::abs(long(panel.minAngleHistogram()[std::size_t(i)]) - long(c.angle[std::size_t(i)])));
    QVERIFY2(differ <= 2 * c.ambiguous,
             qPrintable(QString("%1 differences, %2 ambiguous").arg(differ).arg(c.ambiguous)));
}

} // namespace remesh_widget_test_helpers
