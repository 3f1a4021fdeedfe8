// Where the worst face a stitch created lies (stitch_property_test.cpp; printed with
// FSS_STITCH_PROPERTY_DIAG=1 for every stitch whose created faces go below issue 19's 20 deg bound). The
// classes name what holds the face's corners, in this order of precedence:
//  - border:     a corner on the mesh's border;
//  - held-rim:   a corner is a vertex of the mesh before, not moved, that a face the stitch kept touches
//                (the band never moves those);
//  - held-old:   a corner is an unmoved vertex of the mesh before whose faces all changed;
//  - crease-end: a corner ends a crease (one crease edge) or joins three or more (a crease corner);
//  - crease:     a corner on a crease (two crease edges);
//  - patch:      a corner is one of the patch's samples, not moved;
//  - free:       none of these.
// A crease edge here: its two faces' normals differ by more than 30 deg (the band's own test).
#pragma once

#include "fss/camera.h"
#include "fss/mesh.h"

#include <CGAL/Polygon_mesh_processing/compute_normal.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <set>
#include <string>
#include <unordered_set>

namespace fss::test {

inline bool stitchPropertyDiag() {
    static const bool on = [] {
        const char* e = std::getenv("FSS_STITCH_PROPERTY_DIAG");
        return e && std::string(e) == "1";
    }();
    return on;
}

inline int creaseDegree(const Mesh& m, VertexIndex v) {
    int n = 0;
    for (auto h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
        if (m.is_border(h) || m.is_border(m.opposite(h))) continue;
        const auto a = CGAL::Polygon_mesh_processing::compute_face_normal(m.face(h), m);
        const auto b = CGAL::Polygon_mesh_processing::compute_face_normal(m.face(m.opposite(h)), m);
        n += a * b < std::cos(30.0 * std::numbers::pi / 180.0);
    }
    return n;
}

/// The class of created face `f` (see the file comment), with flags: "forced" (every corner an unmoved vertex
/// of the mesh before: only a flip or a freed corner changes it), "occl" (a corner's star has a face turned
/// away from the scan camera: an occlusion contour), "near-border" (a corner's neighbour on the border).
/// `kinds` gets each corner's kind, angle, valence and crease degree.
inline std::string classifyCreatedFace(const Mesh& before, const Mesh& current, FaceIndex f,
                                       const std::unordered_set<std::uint32_t>& changed,
                                       const std::set<std::array<double, 3>>& patchPoints, const Camera* cam,
                                       std::string* kinds, bool* capOut = nullptr) {
    std::array<VertexIndex, 3> c;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(current.halfedge(f), current))
        c[std::size_t(k++)] = v;
    std::string cls = "free";
    int rank = 7, olds = 0;
    bool occl = false, nearBorder = false;
    double maxAngle = 0, minAngleSeen = 180;
    std::string minKind;
    for (std::size_t i = 0; i < 3; ++i) {
        const VertexIndex v = c[i];
        const auto &p = current.point(v), &q = current.point(c[(i + 1) % 3]),
                   &r = current.point(c[(i + 2) % 3]);
        const auto u = q - p, w = r - p;
        const double a = std::atan2(std::sqrt(CGAL::cross_product(u, w).squared_length()), u * w) * 180.0 /
                         std::numbers::pi;
        maxAngle = std::max(maxAngle, a);
        const bool old =
            std::size_t(v) < before.num_vertices() && !before.is_removed(v) && before.point(v) == p;
        olds += old;
        bool kept = false;
        for (auto g : CGAL::faces_around_target(current.halfedge(v), current)) {
            kept = kept || (g != Mesh::null_face() && !changed.count(std::uint32_t(g)));
            if (g != Mesh::null_face() && cam) {
                const auto n = CGAL::Polygon_mesh_processing::compute_face_normal(g, current);
                const Eigen::Vector3d pe(p.x(), p.y(), p.z());
                const Eigen::Vector3d toViewer =
                    cam->parallel ? Eigen::Vector3d(-cam->viewDirection()) : Eigen::Vector3d(cam->eye - pe);
                occl = occl || (n.x() * toViewer.x() + n.y() * toViewer.y() + n.z() * toViewer.z() <= 0);
            }
        }
        for (auto x : CGAL::vertices_around_target(current.halfedge(v), current))
            nearBorder = nearBorder || current.is_border(x);
        const int cd = creaseDegree(current, v);
        const bool patch = patchPoints.count({p.x(), p.y(), p.z()}) > 0;
        std::string kind = current.is_border(v) ? "border"
                           : old && kept        ? "held-rim"
                           : old                ? "held-old"
                           : cd == 1 || cd >= 3 ? "crease-end"
                           : cd == 2            ? "crease"
                           : patch              ? "patch"
                                                : "free";
        const int r0 = kind == "border"       ? 0
                       : kind == "held-rim"   ? 1
                       : kind == "held-old"   ? 2
                       : kind == "crease-end" ? 3
                       : kind == "crease"     ? 4
                       : kind == "patch"      ? 5
                                              : 6;
        if (r0 < rank) rank = r0, cls = kind;
        if (a < minAngleSeen) {
            minAngleSeen = a, minKind = kind;
            if (kind == "held-rim") {
                // The wedge of created faces at this held corner: below the bound, the small angle is forced
                // by the kept faces around it (only freeing the corner helps); else too many faces share it.
                double wedge = 0;
                int nw = 0;
                for (auto h : CGAL::halfedges_around_target(current.halfedge(v), current)) {
                    const auto g = current.face(h);
                    if (g == Mesh::null_face() || !changed.count(std::uint32_t(g))) continue;
                    const auto x = current.point(current.source(h)) - p,
                               y = current.point(current.target(current.next(h))) - p;
                    wedge += std::atan2(std::sqrt(CGAL::cross_product(x, y).squared_length()), x * y) *
                             180.0 / std::numbers::pi;
                    ++nw;
                }
                minKind += wedge < 20        ? "[wedge<20]"
                           : wedge < 30      ? "[wedge<30]"
                           : wedge / nw < 30 ? "[crowded]"
                                             : "[room]";
            }
        }
        if (kinds) {
            char buf[96];
            std::snprintf(buf, sizeof buf, " %s(%.1f deg, valence %zu, crease %d)", kind.c_str(), a,
                          std::size_t(current.degree(v)), cd);
            *kinds += buf;
        }
    }
    if (std::getenv("FSS_STITCH_PROPERTY_DIAG_AT")) cls += "@" + minKind;
    // An edge of f shared with a face the stitch kept: the rim to kept faces.
    for (auto h : CGAL::halfedges_around_face(current.halfedge(f), current)) {
        const auto g = current.face(current.opposite(h));
        if (g != Mesh::null_face() && !changed.count(std::uint32_t(g))) {
            if (std::getenv("FSS_STITCH_PROPERTY_DIAG_AT")) cls += "+rim-edge";
            break;
        }
    }
    if (olds == 3) cls += "+forced";
    if (occl) cls += "+occl";
    if (nearBorder && rank != 0) cls += "+near-border";
    if (capOut) *capOut = maxAngle > 120;
    return cls;
}

/// Prints one line for the worst created face `f` of a stitch (see the file comment). `changed`: the faces
/// of `current` the stitch made; `patchPoints`: the patch's sample positions.
inline void printWorstCreatedFace(const char* mesh, int scanId, double angleDeg, const Mesh& before,
                                  const Mesh& current, FaceIndex f,
                                  const std::unordered_set<std::uint32_t>& changed,
                                  const std::set<std::array<double, 3>>& patchPoints,
                                  const Camera* cam = nullptr) {
    std::string kinds;
    bool cap = false;
    const std::string cls = classifyCreatedFace(before, current, f, changed, patchPoints, cam, &kinds, &cap);
    std::fprintf(stderr, "diag %s stitch %d: created min %.2f deg, class %s%s; corners%s\n", mesh, scanId,
                 angleDeg, cls.c_str(), cap ? " (cap)" : " (needle)", kinds.c_str());
}

} // namespace fss::test
