// Stitch v2: refilling the seam strip (strip_refill.h, DESIGN.md §6.2 steps 2–5).
#include "stitch/strip_refill.h"

#include "stitch/gap_triangulation.h"
#include "stitch/lift.h"

#include <CGAL/boost/graph/iterator.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>
#include <unordered_set>

namespace fss::stitch {
namespace {

Eigen::Vector3d refillPoint(const Mesh& m, VertexIndex v) {
    const Point3& p = m.point(v);
    return {p.x(), p.y(), p.z()};
}

Eigen::Vector3d refillNormal(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    const Eigen::Vector3d a = refillPoint(m, m.source(h)), b = refillPoint(m, m.target(h)),
                          c = refillPoint(m, m.target(m.next(h)));
    return (b - a).cross(c - a).normalized();
}

// An affine map of the view that undoes the strip's foreshortening on average: least squares from the view
// positions of the strip's vertices to their coordinates in the plane across the strip's mean normal, scaled
// to keep areas in pixels. An affine map keeps the triangulation's combinatorics (orientation, incidence,
// the constraints), so the fill can be built in these coordinates, where angles are close to the 3D ones,
// and mapped back. Identity where the fit is degenerate or would flip orientation.
Eigen::Matrix2d refillUnforeshorten(const std::vector<Eigen::Vector2d>& uv,
                                    const std::vector<Eigen::Vector3d>& xyz, const Eigen::Vector3d& normal) {
    const Eigen::Matrix2d identity = Eigen::Matrix2d::Identity();
    if (uv.size() < 3 || !(normal.norm() > 0)) return identity;
    const Eigen::Vector3d n = normal.normalized();
    const Eigen::Vector3d e1 =
        (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(n).normalized();
    const Eigen::Vector3d e2 = n.cross(e1);
    Eigen::Vector2d mu = Eigen::Vector2d::Zero();
    Eigen::Vector3d mx = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < uv.size(); ++i) {
        mu += uv[i];
        mx += xyz[i];
    }
    mu /= double(uv.size());
    mx /= double(uv.size());
    Eigen::Matrix2d uu = Eigen::Matrix2d::Zero(), pu = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < uv.size(); ++i) {
        const Eigen::Vector2d a = uv[i] - mu;
        const Eigen::Vector2d b((xyz[i] - mx).dot(e1), (xyz[i] - mx).dot(e2));
        uu += a * a.transpose();
        pu += b * a.transpose();
    }
    if (!(std::abs(uu.determinant()) > 1e-12 * uu.squaredNorm())) return identity;
    Eigen::Matrix2d A = pu * uu.inverse();
    const double det = A.determinant();
    if (!(det > 0) || !A.allFinite()) return identity;
    A /= std::sqrt(det);
    // Guard against wild fits: the map must not stretch any direction by more than 4 (views up to ~75 deg).
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(A);
    if (!(svd.singularValues()(0) < 4.0)) return identity;
    return A;
}

} // namespace

StripRefill refillStrip(const StripRefillInput& in) {
    StripRefill out;
    const Mesh& m = *in.mesh;
    std::unordered_set<std::uint32_t> inStrip;
    for (FaceIndex f : in.strip)
        inStrip.insert(std::uint32_t(f));
    // Reference: the strip's faces as they are.
    LiftReference reference;
    std::unordered_map<std::uint32_t, int> refIndex;
    for (FaceIndex f : in.strip) {
        std::array<int, 3> t{};
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m)) {
            auto [it, fresh] = refIndex.try_emplace(std::uint32_t(v), int(reference.points.size()));
            if (fresh) reference.points.push_back(refillPoint(m, v));
            t[std::size_t(k++)] = it->second;
        }
        reference.triangles.push_back(t);
    }
    // Constraints: the strip's boundary and its creases; kept vertices: theirs and those the caller keeps.
    std::unordered_map<std::uint32_t, int> keptIndex;
    auto keepVertex = [&](VertexIndex v) {
        auto [it, fresh] = keptIndex.try_emplace(std::uint32_t(v), int(out.kept.size()));
        if (fresh) out.kept.push_back(v);
        return it->second;
    };
    GapBoundary gap;
    const double creaseCos = std::cos(in.creaseAngleDeg * std::numbers::pi / 180.0);
    for (FaceIndex f : in.strip)
        for (HalfedgeIndex h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
            const FaceIndex g = m.face(m.opposite(h));
            const bool boundary = g == Mesh::null_face() || !inStrip.count(std::uint32_t(g));
            const bool crease = !boundary && std::uint32_t(f) < std::uint32_t(g) &&
                                refillNormal(m, f).dot(refillNormal(m, g)) < creaseCos;
            if (!boundary && !crease) continue;
            const int a = keepVertex(m.source(h)), b = keepVertex(m.target(h));
            gap.constraints.push_back({a, b});
        }
    for (FaceIndex f : in.strip)
        for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
            if (in.keep && in.keep(v)) keepVertex(v);
    // The fill is built in view coordinates with the strip's mean foreshortening undone (an affine map).
    std::vector<Eigen::Vector2d> refUv;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < in.strip.size(); ++i) {
        const auto& t = reference.triangles[i];
        normal += (reference.points[std::size_t(t[1])] - reference.points[std::size_t(t[0])])
                      .cross(reference.points[std::size_t(t[2])] - reference.points[std::size_t(t[0])]);
    }
    for (const auto& [v, k] : refIndex)
        refUv.push_back(in.uv(VertexIndex(v)));
    std::vector<Eigen::Vector3d> refXyz;
    for (const auto& [v, k] : refIndex)
        refXyz.push_back(reference.points[std::size_t(k)]);
    const Eigen::Matrix2d A = refillUnforeshorten(refUv, refXyz, normal);
    const Eigen::Matrix2d Ainv = A.inverse();
    for (VertexIndex v : out.kept)
        gap.points.push_back(A * in.uv(v));
    const Camera& camera = *in.camera;
    const ReferenceLocator locator(camera, reference);
    gap.inside = [&](const Eigen::Vector2d& p) { return locator.covers(Ainv * p); };
    GapOptions options;
    options.minAngleDeg = in.minAngleDeg;
    options.lloydIterations = in.lloydIterations;
    double maxEdge = in.maxEdge;
    if (!(maxEdge > 0))
        for (const auto& [a, b] : gap.constraints)
            maxEdge = std::max(maxEdge, (gap.points[std::size_t(a)] - gap.points[std::size_t(b)]).norm());
    options.size = [maxEdge](const Eigen::Vector2d&) { return maxEdge; };
    GapTriangulation filled = triangulateGap(gap, options);
    if (!filled.ok) {
        out.reason = filled.reason;
        return out;
    }
    // Lift the new vertices onto the strip's faces (a hair of tolerance for points on their outline).
    const double tolerance = 1e-6 * std::max(1.0, maxEdge);
    for (std::size_t i = filled.boundaryPoints; i < filled.points.size(); ++i) {
        const Eigen::Vector2d uv = Ainv * filled.points[i];
        const auto hit = locator.lift(uv, tolerance);
        if (!hit) {
            out.reason = "a new seam vertex does not lie over the seam strip in the view";
            return out;
        }
        out.fresh.push_back(hit->point);
        out.freshUv.push_back(uv);
    }
    // Parents (for the faces' properties) and the triangles themselves.
    for (const auto& t : filled.triangles) {
        const Eigen::Vector2d c = Ainv *
                                  (filled.points[std::size_t(t[0])] + filled.points[std::size_t(t[1])] +
                                   filled.points[std::size_t(t[2])]) /
                                  3.0;
        const auto hit = locator.lift(c, tolerance);
        if (!hit) {
            out.reason = "a new seam face does not lie over the seam strip in the view";
            return out;
        }
        out.parent.push_back(in.strip[std::size_t(hit->triangle)]);
        out.triangles.push_back(t);
    }
    out.ok = true;
    return out;
}

} // namespace fss::stitch
