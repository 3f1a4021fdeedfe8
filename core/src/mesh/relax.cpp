#include "mesh/relax.h"

#include "fss/raycast.h"

#include "mesh/local_closest_point.h"
#include "mesh/triangle_geometry.h"

#include <CGAL/boost/graph/iterator.h>
#include <boost/container/small_vector.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace fss::detail {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Vector3d unitFaceNormal(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    return unitNormal(pos(m, m.source(h)), pos(m, m.target(h)), pos(m, m.target(m.next(h))));
}

// A crease edge of the reference that \p p lies on: its end points.
struct CreaseLine {
    Eigen::Vector3d a, b;
};

// The sharp edge of face \p f (dihedral angle beyond \p cosCrease) that \p p lies on, within \p tolerance.
std::optional<CreaseLine> creaseUnder(const Mesh& ref, FaceIndex f, const Eigen::Vector3d& p,
                                      double cosCrease, double tolerance) {
    const Eigen::Vector3d n = unitFaceNormal(ref, f);
    for (HalfedgeIndex h : CGAL::halfedges_around_face(ref.halfedge(f), ref)) {
        const FaceIndex g = ref.face(ref.opposite(h));
        if (g == Mesh::null_face()) continue;
        const Eigen::Vector3d m = unitFaceNormal(ref, g);
        if (!(n.squaredNorm() > 0 && m.squaredNorm() > 0) || n.dot(m) >= cosCrease) continue;
        const Eigen::Vector3d a = pos(ref, ref.source(h)), b = pos(ref, ref.target(h));
        const Eigen::Vector3d ab = b - a;
        const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        if ((a + t * ab - p).norm() <= tolerance) return CreaseLine{a, b};
    }
    return std::nullopt;
}

// The smallest angle of the faces around \p v, and whether each is acceptable after a move (normal turned
// by less than the bound from \p before, not degenerate, facing the camera).
struct Ring {
    // By incident face, in circulation order (inline up to 12: two rings per vertex and sweep, no
    // allocation).
    boost::container::small_vector<Eigen::Vector3d, 12> normals;
    double minAngle = 0;
    bool ok = true;
};

Ring ringOf(const Mesh& m, VertexIndex v, const Eigen::Vector3d& at, const Ring* before, double cosTurn,
            const Camera* facing) {
    Ring ring;
    MinAngleOfMany smallest; // the same double as the minimum of minAngle over the faces
    std::size_t k = 0;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
        if (m.is_border(h)) continue;
        const Eigen::Vector3d b = pos(m, m.source(h)), c = pos(m, m.target(m.next(h)));
        const Eigen::Vector3d n = unitNormal(b, at, c); // the face (source, v, next's target) in its order
        smallest.add(b, at, c);
        ring.normals.push_back(n);
        if (!(n.squaredNorm() > 0)) ring.ok = false;
        if (before && k < before->normals.size() && before->normals[k].dot(n) < cosTurn) ring.ok = false;
        if (facing && ring.ok) {
            const Eigen::Vector3d centroid = (b + at + c) / 3.0;
            const Eigen::Vector3d toViewer = facing->parallel ? Eigen::Vector3d(-facing->viewDirection())
                                                              : Eigen::Vector3d(facing->eye - centroid);
            if (!(n.dot(toViewer) > 0)) ring.ok = false;
        }
        ++k;
    }
    ring.minAngle = smallest.value();
    return ring;
}

// Whether moving \p v to \p at is accepted against its ring \p before: every face around acceptable after
// the move (ringOf's tests) and none below before's smallest angle. The same answer as ringOf(…, &before,
// …) with `ok && minAngle >= before.minAngle`, but it stops at the first face that fails, and computes a
// face's smallest angle only once its normal passed (most refused moves fail early).
bool moveAccepted(const Mesh& m, VertexIndex v, const Eigen::Vector3d& at, const Ring& before, double cosTurn,
                  const Camera* facing) {
    std::optional<AngleLimit> floor; // before's smallest angle, once a face reaches that test
    std::size_t k = 0;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
        if (m.is_border(h)) continue;
        const Eigen::Vector3d b = pos(m, m.source(h)), c = pos(m, m.target(m.next(h)));
        const Eigen::Vector3d n = unitNormal(b, at, c);
        if (!(n.squaredNorm() > 0)) return false;
        if (k < before.normals.size() && before.normals[k].dot(n) < cosTurn) return false;
        if (facing) {
            const Eigen::Vector3d centroid = (b + at + c) / 3.0;
            const Eigen::Vector3d toViewer = facing->parallel ? Eigen::Vector3d(-facing->viewDirection())
                                                              : Eigen::Vector3d(facing->eye - centroid);
            if (!(n.dot(toViewer) > 0)) return false;
        }
        if (!floor) floor.emplace(before.minAngle);
        if (minAngleBelow(b, at, c, *floor)) return false;
        ++k;
    }
    return true;
}

} // namespace

RelaxReport relaxOnReference(Mesh& mesh, const Mesh& reference, const std::vector<VertexIndex>& vertices,
                             std::vector<FaceIndex>& hints, const std::vector<double>& footprints,
                             const RelaxOptions& options, const Camera* facing, LocalClosestPoint* shared) {
    RelaxReport report;
    report.vertices = vertices.size();
    if (options.iterations <= 0 || vertices.empty()) return report;
    const double cosCrease = std::cos(options.creaseAngleDeg * kDeg);
    const double cosTurn = std::cos(options.maxNormalTurnDeg * kDeg);
    // Per vertex: its first reference face's normal (moves may not cross a crease away from it) and the
    // crease it lies on, if any.
    std::vector<Eigen::Vector3d> firstNormal(vertices.size());
    std::vector<std::optional<CreaseLine>> crease(vertices.size());
    for (std::size_t k = 0; k < vertices.size(); ++k) {
        firstNormal[k] = unitFaceNormal(reference, hints[k]);
        crease[k] = creaseUnder(reference, hints[k], pos(mesh, vertices[k]), cosCrease, 1e-6 * footprints[k]);
        report.onCrease += crease[k].has_value();
    }
    // The reference does not change here: its rings are collected once (same results as closestPointNear).
    std::optional<LocalClosestPoint> own;
    LocalClosestPoint& search = shared ? *shared : own.emplace(reference, LocalSearchOptions{.rings = 1});
    for (int sweep = 0; sweep < options.iterations; ++sweep) {
        for (std::size_t k = 0; k < vertices.size(); ++k) {
            const VertexIndex v = vertices[k];
            const Eigen::Vector3d p = pos(mesh, v);
            Eigen::Vector3d centroid(0, 0, 0);
            int n = 0;
            for (VertexIndex w : CGAL::vertices_around_target(mesh.halfedge(v), mesh)) {
                centroid += pos(mesh, w);
                ++n;
            }
            if (n < 3) continue;
            const Eigen::Vector3d d = centroid / double(n) - p;
            Eigen::Vector3d target;
            FaceIndex face = hints[k];
            if (crease[k]) { // along the crease edge only, kept within it
                const Eigen::Vector3d ab = crease[k]->b - crease[k]->a;
                const double t =
                    std::clamp((p + options.step * d - crease[k]->a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
                target = crease[k]->a + t * ab;
            } else {
                const Eigen::Vector3d normal = unitFaceNormal(reference, hints[k]);
                const Eigen::Vector3d moved = p + options.step * (d - d.dot(normal) * normal);
                const SurfacePoint onRef = search(moved, hints[k]);
                if (!onRef || onRef.distance > options.maxOffFootprints * footprints[k] ||
                    unitFaceNormal(reference, onRef.face).dot(firstNormal[k]) < cosCrease) {
                    ++report.refused;
                    continue;
                }
                target = onRef.point;
                face = onRef.face;
            }
            if ((target - p).squaredNorm() == 0) continue;
            // (moveAccepted reads before's normals and smallest angle, not its `ok`: no facing test)
            const Ring before = ringOf(mesh, v, p, nullptr, cosTurn, nullptr);
            if (!moveAccepted(mesh, v, target, before, cosTurn, facing)) {
                ++report.refused;
                continue;
            }
            mesh.point(v) = Point3(target.x(), target.y(), target.z());
            hints[k] = face;
            ++report.moves;
        }
    }
    return report;
}

} // namespace fss::detail
