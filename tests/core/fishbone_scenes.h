#pragma once
// The scenes of the fishbone scan tests (fishbone_scan_test.cpp, fishbone_trim_test.cpp,
// fishbone_sliver_table_test.cpp): the creased ring and its crease scene, the lens torus, and the patch
// figures they share.
#include "fss/fishbone_scan.h"
#include "fss/mesh.h"

#include <CGAL/boost/graph/helpers.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace fishbone_scenes {

using Eigen::Vector2d;
using Eigen::Vector3d;
using fss::Mesh;

inline Eigen::AlignedBox3d bbox(const Mesh& m) {
    Eigen::AlignedBox3d b;
    for (auto v : m.vertices())
        b.extend(Vector3d(m.point(v).x(), m.point(v).y(), m.point(v).z()));
    return b;
}

inline Vector3d pt(const Mesh& m, fss::VertexIndex v) {
    return {m.point(v).x(), m.point(v).y(), m.point(v).z()};
}

// ---- The creased ring -----------------------------------------------------------------------------------
// A surface of revolution around z whose cross-section is two circular arcs (radius rho, centres at
// s = kCentre, z = ∓d) meeting in a sharp ridge at z = 0: s(z) = kCentre + sqrt(rho² − (|z| + d)²). The
// ridge is the circle s = kRidge, z = 0 with a dihedral turn of 2·asin(d/rho) = 60°; the meridian
// curvature 1/rho exceeds the parallel one everywhere, so the ridge follows the min-curvature direction.
inline constexpr double kCentre = 2.0, kRho = 1.0, kD = 0.5, kHalfHeight = 0.4;
inline const double kRidge = kCentre + std::sqrt(kRho * kRho - kD * kD);

inline Mesh creasedRing(int nu, int nzHalf, bool alternateDiagonals = true) {
    Mesh m;
    const int nz = 2 * nzHalf + 1; // row nzHalf is the ridge
    std::vector<fss::VertexIndex> v(std::size_t(nu) * nz);
    for (int j = 0; j < nz; ++j) {
        const double z = kHalfHeight * (j - nzHalf) / nzHalf;
        const double s = kCentre + std::sqrt(kRho * kRho - (std::abs(z) + kD) * (std::abs(z) + kD));
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * std::numbers::pi * i / nu;
            v[std::size_t(j) * nu + i] = m.add_vertex(fss::Point3(s * std::cos(phi), s * std::sin(phi), z));
        }
    }
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i < nu; ++i) {
            const auto a = v[std::size_t(j) * nu + i], b = v[std::size_t(j) * nu + (i + 1) % nu];
            const auto c = v[std::size_t(j + 1) * nu + (i + 1) % nu], d = v[std::size_t(j + 1) * nu + i];
            // Alternating diagonals: the triangulation is mirror-symmetric about every meridian plane of
            // an even index, so the fitted principal directions on the ridge are not tilted one way. With
            // one diagonal direction throughout, the jet fits across the sharp ridge tilt the directions
            // by about a degree and a plain streamline drifts off the ridge (see the second aliasing test).
            if (!alternateDiagonals || (i + j) % 2 == 0) {
                m.add_face(a, b, c);
                m.add_face(a, c, d);
            } else {
                m.add_face(a, b, d);
                m.add_face(b, c, d);
            }
        }
    return m;
}

// Distance of a point to the ridge circle.
inline double distanceToRidge(const Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - kRidge, p.z());
}

inline Vector3d faceNormal(const Mesh& m, fss::FaceIndex f) {
    std::array<Vector3d, 3> p;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
        p[std::size_t(k++)] = pt(m, v);
    return (p[1] - p[0]).cross(p[2] - p[0]).normalized();
}

// ---- The crease scene -----------------------------------------------------------------------------------

struct CreaseScene {
    Mesh ring;
    fss::Camera camera;
    fss::Lasso lasso;
    Eigen::AlignedBox2d inner;

    explicit CreaseScene(bool alternateDiagonals = true) : ring(creasedRing(720, 40, alternateDiagonals)) {
        // Looking at the front of the ridge from 30° above: the ridge circle projects to a curved arc.
        const Vector3d focal(kRidge, 0, 0);
        const double elevation = 30 * std::numbers::pi / 180;
        camera.focal = focal;
        camera.eye = focal + 4.0 * Vector3d(std::cos(elevation), 0, std::sin(elevation));
        camera.up = {0, 0, 1};
        camera.viewAngleDeg = 30;
        camera.width = camera.height = 160;
        camera.fitClippingRange(bbox(ring));
        // The lasso: the middle of the image (the ridge arc and both flanks).
        const double lo = 0.15 * camera.width, hi = 0.85 * camera.width;
        lasso.points = {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
        inner = Eigen::AlignedBox2d(Vector2d(lo + 4, lo + 4), Vector2d(hi - 4, hi - 4));
    }

    Vector2d ridgeSeed() const {
        const Vector3d s = camera.project(Vector3d(kRidge, 0, 0));
        return {s.x(), s.y()};
    }
};

struct AngleFigures {
    std::size_t faces = 0;
    double minDeg = 90, meanDeg = 0, below30 = 0, below10 = 0;
};

inline AngleFigures angleFigures(const Mesh& m) {
    AngleFigures a;
    for (auto f : m.faces()) {
        std::array<Vector3d, 3> p;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            p[std::size_t(k++)] = pt(m, v);
        double smallest = 180;
        for (int i = 0; i < 3; ++i) {
            const Vector3d u = (p[std::size_t((i + 1) % 3)] - p[std::size_t(i)]).normalized();
            const Vector3d w = (p[std::size_t((i + 2) % 3)] - p[std::size_t(i)]).normalized();
            smallest =
                std::min(smallest, std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180 / std::numbers::pi);
        }
        ++a.faces;
        a.minDeg = std::min(a.minDeg, smallest);
        a.meanDeg += smallest;
        a.below30 += smallest < 30 ? 1 : 0;
        a.below10 += smallest < 10 ? 1 : 0;
    }
    if (a.faces) {
        a.meanDeg /= double(a.faces);
        a.below30 /= double(a.faces);
        a.below10 /= double(a.faces);
    }
    return a;
}

// The crease scene's ring from 75° above its centre: the ridge is a closed curve on the screen (as in
// RibTrimmingFiguresOnTheCreasedRing), but on the silhouette all round, and edge-on where the view grazes the
// band (near (-0.27, ±2.85, 0), measured in session 21): the crease backbone walks 53 samples each way from
// the near side and stops there, so its grid cannot close.
inline fss::Camera topCamera(const CreaseScene& scene) {
    fss::Camera top = scene.camera;
    const double up = 75 * std::numbers::pi / 180;
    top.focal = Vector3d(0, 0, 0);
    top.eye = 9.0 * Vector3d(std::cos(up), 0, std::sin(up));
    top.up = {0, 1, 0};
    top.viewAngleDeg = 45;
    top.fitClippingRange(bbox(scene.ring));
    return top;
}

// A torus-like ring with two sharp circular ridges, on top and at the bottom of its tube: the surface of
// revolution of a lens standing upright (two circular arcs of radius rho, centres at s = R ∓ d, z = 0,
// meeting at s = R, z = ±√(rho² − d²), each ridge with a dihedral turn of 2·asin(d/rho) = 60°). Closed. Its
// meridian curvature 1/rho exceeds the parallel one, so the ridges follow the min-curvature direction, and
// the top ridge is a closed curve in full view from above.
inline constexpr double kLensR = 2.0, kLensRho = 0.6, kLensD = 0.3;
inline const double kLensHalf = std::sqrt(kLensRho * kLensRho - kLensD * kLensD);

inline Mesh lensTorus(int nu, int m) {
    Mesh mesh;
    const double a0 = std::acos(kLensD / kLensRho);
    std::vector<Vector2d> section; // (s, z): the outer arc bottom → top, then the inner arc top → bottom
    for (int k = 0; k < m; ++k) {
        const double a = -a0 + 2 * a0 * k / m;
        section.emplace_back(kLensR - kLensD + kLensRho * std::cos(a), kLensRho * std::sin(a));
    }
    for (int k = 0; k < m; ++k) {
        const double a = a0 - 2 * a0 * k / m;
        section.emplace_back(kLensR + kLensD - kLensRho * std::cos(a), kLensRho * std::sin(a));
    }
    const int nv = int(section.size());
    std::vector<fss::VertexIndex> v(std::size_t(nu) * std::size_t(nv));
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * std::numbers::pi * i / nu;
            v[std::size_t(j) * nu + i] = mesh.add_vertex(
                fss::Point3(section[std::size_t(j)].x() * std::cos(phi),
                            section[std::size_t(j)].x() * std::sin(phi), section[std::size_t(j)].y()));
        }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const int j1 = (j + 1) % nv, i1 = (i + 1) % nu;
            const auto a = v[std::size_t(j) * nu + i], b = v[std::size_t(j) * nu + i1];
            const auto c = v[std::size_t(j1) * nu + i1], d = v[std::size_t(j1) * nu + i];
            if ((i + j) % 2 == 0) { // alternating diagonals, as creasedRing
                mesh.add_face(a, b, c);
                mesh.add_face(a, c, d);
            } else {
                mesh.add_face(a, b, d);
                mesh.add_face(b, c, d);
            }
        }
    return mesh;
}

inline double distanceToLensRidges(const Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - kLensR, std::abs(p.z()) - kLensHalf);
}

inline fss::Camera lookAt(const Mesh& mesh, const Vector3d& focal, const Vector3d& eye, const Vector3d& up,
                          double angle, int size) {
    fss::Camera c;
    c.focal = focal;
    c.eye = eye;
    c.up = up;
    c.viewAngleDeg = angle;
    c.width = c.height = size;
    c.fitClippingRange(bbox(mesh));
    return c;
}

// Border cycles of a mesh.
inline int borderCycles(const Mesh& m) {
    std::vector<char> seen(m.number_of_halfedges(), 0);
    int cycles = 0;
    for (auto h : m.halfedges()) {
        if (!m.is_border(h) || seen[h.idx()]) continue;
        ++cycles;
        for (auto g = h; !seen[g.idx()]; g = m.next(g))
            seen[g.idx()] = 1;
    }
    return cycles;
}

// Border edges of the patch along rib rows \p a or \p b (both end vertices on that row).
inline int borderEdgesAlongRows(const fss::Patch& patch, int a, int b) {
    const Mesh& m = patch.mesh;
    const auto index = m.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    int n = 0;
    for (auto e : m.edges()) {
        if (!m.is_border(e)) continue;
        const fss::GridIndex s = index[m.vertex(e, 0)], t = index[m.vertex(e, 1)];
        n += s.row == t.row && (s.row == a || s.row == b);
    }
    return n;
}

} // namespace fishbone_scenes
