#pragma once
// The helpers the stitch tests share (stitch_test.cpp, stitch_chained_test.cpp): patches built as a scan
// would on analytic surfaces (the nearest hit of a view ray) and the invariants of DESIGN.md §5.
#include "fss/error.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"
#include "fss/stitch.h"

#include "test_data.h"

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh/IO/OFF.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <set>
#include <string_view>
#include <unordered_map>

namespace PMP = CGAL::Polygon_mesh_processing;
using fss::Camera;
using fss::FaceIndex;
using fss::Mesh;
using fss::Point3;
using fss::VertexIndex;
using Vec3 = Eigen::Vector3d;

namespace stitch_test_helpers {

constexpr double kDeg = std::numbers::pi / 180.0;

inline Vec3 vec(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

// ---- analytic surfaces: the nearest hit of a view ray
using Surface = std::function<std::optional<Vec3>(const fss::Ray&)>;

inline Surface planeZ0() {
    return [](const fss::Ray& r) -> std::optional<Vec3> {
        if (std::abs(r.direction.z()) < 1e-12) return std::nullopt;
        const double t = -r.origin.z() / r.direction.z();
        if (t <= 0) return std::nullopt;
        Vec3 p = r.origin + t * r.direction;
        p.z() = 0.0; // exactly on the plane
        return p;
    };
}

inline Surface sphere(double radius) {
    return [radius](const fss::Ray& r) -> std::optional<Vec3> {
        const double b = r.origin.dot(r.direction), c = r.origin.squaredNorm() - radius * radius;
        const double disc = b * b - c;
        if (disc < 0) return std::nullopt;
        const double t = -b - std::sqrt(disc);
        if (t <= 0) return std::nullopt;
        const Vec3 p = r.origin + t * r.direction;
        return p * (radius / p.norm());
    };
}

// A scan patch: samples at the centres of the pixels (x, y) for which `mask` holds, on `surface`;
// quads of four samples become two triangles (same diagonal everywhere), facing the camera; triangles
// seen more obliquely than maxAngleDeg are dropped (as the scan's sampling-angle test does).
inline Mesh makePatch(const Camera& cam, const std::function<bool(int, int)>& mask, const Surface& surface,
                      std::int32_t scanId = 1, double maxAngleDeg = 75.0) {
    const int W = cam.width, H = cam.height;
    std::vector<std::optional<Vec3>> pts(std::size_t(W) * std::size_t(H));
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (mask(x, y))
                pts[std::size_t(y) * std::size_t(W) + std::size_t(x)] = surface(cam.ray(x + 0.5, y + 0.5));
    Mesh m;
    std::vector<VertexIndex> vid(pts.size());
    auto vertex = [&](int x, int y) {
        const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
        if (vid[i] == VertexIndex()) vid[i] = m.add_vertex(Point3(pts[i]->x(), pts[i]->y(), pts[i]->z()));
        return vid[i];
    };
    auto quality = m.add_property_map<FaceIndex, float>(fss::props::faceQuality, 0.f).first;
    auto sid = m.add_property_map<FaceIndex, std::int32_t>(fss::props::faceScanId, -1).first;
    auto addTri = [&](int x0, int y0, int x1, int y1, int x2, int y2) {
        const auto& a = pts[std::size_t(y0) * std::size_t(W) + std::size_t(x0)];
        const auto& b = pts[std::size_t(y1) * std::size_t(W) + std::size_t(x1)];
        const auto& c = pts[std::size_t(y2) * std::size_t(W) + std::size_t(x2)];
        if (!a || !b || !c) return;
        const Vec3 n = (*b - *a).cross(*c - *a).normalized();
        const Vec3 toEye = (cam.eye - (*a + *b + *c) / 3.0).normalized();
        const double cosA = n.dot(toEye);
        if (cosA < std::cos(maxAngleDeg * kDeg)) return;
        // Across a depth discontinuity (an occluding contour) the triangle is long: the scan drops it.
        const double longest = std::max({(*b - *a).norm(), (*c - *b).norm(), (*a - *c).norm()});
        if (longest > 8.0 * cam.pixelFootprint((*a + *b + *c) / 3.0)) return;
        const FaceIndex f = m.add_face(vertex(x0, y0), vertex(x1, y1), vertex(x2, y2));
        ASSERT_NE(f, Mesh::null_face());
        quality[f] = float(1.0 - cosA);
        sid[f] = scanId;
    };
    for (int y = 0; y + 1 < H; ++y)
        for (int x = 0; x + 1 < W; ++x) {
            addTri(x, y, x, y + 1, x + 1, y);
            addTri(x + 1, y, x, y + 1, x + 1, y + 1);
        }
    return m;
}

// The pixels (x, y) of a W x H image whose centres lie in the screen triangle s (closed edge functions in
// double; a triangle of zero area covers none), with the depth interpolated affinely there: visit(x, y, z).
template <class Visit> void forEachCoveredPixel(const Vec3 (&s)[3], int W, int H, Visit&& visit) {
    const double area =
        (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[1].y() - s[0].y()) * (s[2].x() - s[0].x());
    if (!(area != 0)) return;
    const int x0 = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}) - 0.5)));
    const int x1 = std::min(W - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}) - 0.5)));
    const int y1 = std::min(H - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            double b[3];
            for (int i = 0; i < 3; ++i) {
                const Vec3 &p = s[(i + 1) % 3], &q = s[(i + 2) % 3];
                b[i] = ((q.x() - p.x()) * (py - p.y()) - (q.y() - p.y()) * (px - p.x())) / area;
            }
            if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
            visit(x, y, b[0] * s[0].z() + b[1] * s[1].z() + b[2] * s[2].z());
        }
}

// ---- invariants
inline std::size_t boundaryLoops(const Mesh& m) {
    std::set<std::uint32_t> seen;
    std::size_t loops = 0;
    for (auto h : m.halfedges()) {
        if (!m.is_border(h) || seen.count(std::uint32_t(h))) continue;
        ++loops;
        auto g = h;
        do {
            seen.insert(std::uint32_t(g));
            g = m.next(g);
        } while (g != h);
    }
    return loops;
}

inline std::size_t nonManifoldVertices(const Mesh& m) {
    std::unordered_map<std::uint32_t, int> incoming;
    for (auto h : m.halfedges())
        ++incoming[std::uint32_t(m.target(h))];
    std::size_t bad = 0;
    for (auto v : m.vertices()) {
        if (m.halfedge(v) == Mesh::null_halfedge()) {
            ++bad; // isolated
            continue;
        }
        int n = 0, borders = 0;
        for (auto h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
            ++n;
            borders += m.is_border(h);
        }
        if (n != incoming[std::uint32_t(v)] || borders > 1) ++bad;
    }
    return bad;
}

inline std::size_t degenerateFaces(const Mesh& m) {
    std::size_t n = 0;
    for (auto f : m.faces()) {
        auto h = m.halfedge(f);
        if (CGAL::collinear(m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h))))) ++n;
    }
    return n;
}

// All faces of a patch scanned by `cam` face it: counter-clockwise after projection (y flipped).
inline std::size_t facesNotFacing(const Mesh& m, const Camera& cam, const std::set<std::uint32_t>& only) {
    std::size_t n = 0;
    for (auto f : m.faces()) {
        if (!only.empty() && !only.count(std::uint32_t(f))) continue;
        auto h = m.halfedge(f);
        const Vec3 a = cam.project(vec(m.point(m.source(h)))), b = cam.project(vec(m.point(m.target(h)))),
                   c = cam.project(vec(m.point(m.target(m.next(h)))));
        const double o = (b.x() - a.x()) * (-(c.y() - a.y())) - (-(b.y() - a.y())) * (c.x() - a.x());
        if (!(o > 0)) ++n;
    }
    return n;
}

struct Invariants {
    bool closed;
    std::size_t loops;
};

inline void expectValid(const Mesh& m, const Invariants& inv, bool checkSelfIntersections = true) {
    ASSERT_TRUE(m.is_valid(false));
    ASSERT_TRUE(CGAL::is_triangle_mesh(m));
    EXPECT_EQ(CGAL::is_closed(m), inv.closed);
    EXPECT_EQ(boundaryLoops(m), inv.loops);
    EXPECT_EQ(nonManifoldVertices(m), 0u);
    EXPECT_EQ(degenerateFaces(m), 0u);
    if (checkSelfIntersections) {
        EXPECT_FALSE(PMP::does_self_intersect(m));
    }
}

using FaceKey = std::array<std::array<double, 3>, 3>;
inline FaceKey faceKey(const Mesh& m, FaceIndex f) {
    FaceKey k;
    int i = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
        const auto& p = m.point(v);
        k[std::size_t(i++)] = {p.x(), p.y(), p.z()};
    }
    std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end()); // same cyclic order
    return k;
}

inline std::string reportText(const fss::StitchReport& r) {
    std::ostringstream os;
    os << "stitched " << r.componentsStitched << " (" << r.piecesStitched << " pieces) skipped "
       << r.componentsSkipped << " removed " << r.facesRemoved << " added " << r.facesAdded << " seam edges "
       << r.seamEdges << " seam faces " << r.seamFaces << " min angle " << r.seamMinAngleDeg << " frac>=25 "
       << r.seamFracMinAngleAbove25 << " collapses " << r.collapses << " flips " << r.flips << " trimmed "
       << r.patchFacesTrimmed << " time " << r.seconds;
    for (const auto& s : r.skipped)
        os << "\n  " << s;
    return os.str();
}

// A camera looking straight down at the z = 0 plane, its image rotated by `rollDeg`.
inline Camera downCamera(double cx, double cy, double height, double rollDeg, int res) {
    Camera c;
    c.eye = {cx, cy, height};
    c.focal = {cx, cy, 0};
    c.up = {std::sin(rollDeg * kDeg), std::cos(rollDeg * kDeg), 0};
    c.viewAngleDeg = 40;
    c.width = c.height = res;
    c.nearPlane = 0.1;
    c.farPlane = 100;
    return c;
}

// A camera at `distance` from the origin looking at it from direction `from`.
inline Camera orbitCamera(const Vec3& from, double distance, int res, double angleDeg = 30.0) {
    Camera c;
    c.eye = from.normalized() * distance;
    c.focal = {0, 0, 0};
    const Vec3 f = -from.normalized();
    c.up = std::abs(f.z()) < 0.9 ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    c.viewAngleDeg = angleDeg;
    c.width = c.height = res;
    c.nearPlane = 0.1;
    c.farPlane = 100;
    return c;
}

// The smallest angle of face f (degrees).
inline double faceMinAngleDeg(const Mesh& m, FaceIndex f) {
    std::array<Vec3, 3> p;
    int k = 0;
    for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
        p[std::size_t(k++)] = vec(m.point(v));
    double best = 180;
    for (std::size_t i = 0; i < 3; ++i) {
        const Vec3 u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
        best = std::min(best, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / std::numbers::pi);
    }
    return best;
}

inline std::function<bool(int, int)> disk(double cx, double cy, double r) {
    return [=](int x, int y) {
        return (x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) <= r * r;
    };
}

// Largest distance of a point of a face of a sphere mesh (whose vertices lie on the sphere) from the
// sphere: the discretisation error. (Stitching puts vertices on mesh edges and inside faces' planes.)
inline double sphereSag(const Mesh& m, double radius) {
    double sag = 0;
    for (auto f : m.faces()) {
        auto h = m.halfedge(f);
        const Vec3 a = vec(m.point(m.source(h))), b = vec(m.point(m.target(h))),
                   c = vec(m.point(m.target(m.next(h))));
        const Vec3 n = (b - a).cross(c - a).normalized();
        sag = std::max(sag, radius - std::abs(n.dot(a)));
    }
    return sag;
}

inline void expectOnSphere(const Mesh& m, double radius, double tolerance) {
    double worst = 0;
    for (auto v : m.vertices())
        worst = std::max(worst, std::abs(vec(m.point(v)).norm() - radius));
    EXPECT_LE(worst, tolerance);
}

// Everything of a Surface_mesh that a caller could observe, including garbage and free slots.
inline void expectBitIdentical(const Mesh& a, const Mesh& b) {
    ASSERT_EQ(a.num_vertices(), b.num_vertices());
    ASSERT_EQ(a.num_halfedges(), b.num_halfedges());
    ASSERT_EQ(a.num_faces(), b.num_faces());
    ASSERT_EQ(a.number_of_removed_vertices(), b.number_of_removed_vertices());
    ASSERT_EQ(a.number_of_removed_faces(), b.number_of_removed_faces());
    ASSERT_EQ(a.number_of_removed_edges(), b.number_of_removed_edges());
    ASSERT_EQ(a.properties<VertexIndex>(), b.properties<VertexIndex>());
    ASSERT_EQ(a.properties<FaceIndex>(), b.properties<FaceIndex>());
    ASSERT_EQ(a.properties<fss::HalfedgeIndex>(), b.properties<fss::HalfedgeIndex>());
    ASSERT_EQ(a.properties<fss::EdgeIndex>(), b.properties<fss::EdgeIndex>());
    for (std::size_t i = 0; i < a.num_vertices(); ++i) {
        const VertexIndex v(static_cast<Mesh::size_type>(i));
        ASSERT_EQ(a.is_removed(v), b.is_removed(v));
        ASSERT_EQ(a.point(v), b.point(v));
        ASSERT_EQ(a.halfedge(v), b.halfedge(v));
    }
    for (std::size_t i = 0; i < a.num_halfedges(); ++i) {
        const fss::HalfedgeIndex h(static_cast<Mesh::size_type>(i));
        ASSERT_EQ(a.next(h), b.next(h));
        ASSERT_EQ(a.target(h), b.target(h));
        ASSERT_EQ(a.face(h), b.face(h));
    }
    auto qa = a.property_map<FaceIndex, float>(fss::props::faceQuality);
    auto qb = b.property_map<FaceIndex, float>(fss::props::faceQuality);
    for (std::size_t i = 0; i < a.num_faces(); ++i) {
        const FaceIndex f(static_cast<Mesh::size_type>(i));
        ASSERT_EQ(a.is_removed(f), b.is_removed(f));
        ASSERT_EQ(a.halfedge(f), b.halfedge(f));
        if (qa.second) {
            ASSERT_EQ(qa.first[f], qb.first[f]);
        }
    }
}

inline double sumArea(const Mesh& m) {
    return PMP::area(m);
}

} // namespace stitch_test_helpers
