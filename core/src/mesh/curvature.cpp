// Principal curvatures by jet fitting (CGAL Monge_via_jet_fitting) on adaptive k-rings.
// The only CGAL-heavy translation unit of the fishbone pipeline.
#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED
#endif

#include "fss/curvature.h"

#include "fss/error.h"

#include "base/option_check.h"

#include "mesh/triangle_geometry.h"

#include <CGAL/Monge_via_jet_fitting.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace fss {
namespace {

using detail::toEigen;

using MongeFitting = CGAL::Monge_via_jet_fitting<Kernel>;

template <class V> Eigen::Vector3d vecToEigen(const V& v) {
    return {CGAL::to_double(v[0]), CGAL::to_double(v[1]), CGAL::to_double(v[2])};
}

std::size_t jetUnknowns(int degree) {
    return std::size_t((degree + 1) * (degree + 2) / 2);
}

// Area-weighted vertex normal (sum of the incident faces' cross products); zero when degenerate.
Eigen::Vector3d vertexNormal(const Mesh& mesh, VertexIndex v) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
        if (mesh.is_border(h)) continue;
        const Eigen::Vector3d a = toEigen(mesh.point(mesh.source(h)));
        const Eigen::Vector3d b = toEigen(mesh.point(mesh.target(h)));
        const Eigen::Vector3d c = toEigen(mesh.point(mesh.target(mesh.next(h))));
        n += (b - a).cross(c - a);
    }
    const double len = n.norm();
    return len > 0 && std::isfinite(len) ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

// Collects the k-ring of v, ring by ring, until it holds at least minPoints vertices or maxRings rings.
// `stamp` / `stampValue` mark visited vertices without clearing an array per vertex (linear total cost).
void growNeighbourhood(const Mesh& mesh, VertexIndex v, const CurvatureOptions& options,
                       std::vector<std::uint32_t>& stamp, std::uint32_t stampValue,
                       std::vector<VertexIndex>& ring) {
    ring.clear();
    ring.push_back(v);
    stamp[v.idx()] = stampValue;
    std::size_t ringBegin = 0;
    for (int k = 0; k < options.maxRings && ring.size() < std::size_t(options.minPoints); ++k) {
        const std::size_t ringEnd = ring.size();
        for (std::size_t i = ringBegin; i < ringEnd; ++i) {
            const HalfedgeIndex h0 = mesh.halfedge(ring[i]);
            if (h0 == Mesh::null_halfedge()) continue;
            for (VertexIndex w : CGAL::vertices_around_target(h0, mesh)) {
                if (stamp[w.idx()] == stampValue) continue;
                stamp[w.idx()] = stampValue;
                ring.push_back(w);
            }
        }
        if (ring.size() == ringEnd) break; // the connected component is exhausted
        ringBegin = ringEnd;
    }
}

bool finite(const Eigen::Vector3d& v) {
    return v.allFinite();
}

} // namespace

void CurvatureOptions::validate() const {
    const detail::OptionCheck check("CurvatureOptions");
    if (jetDegree != 2 && jetDegree != 3)
        check.fail("jetDegree", "must be 2 or 3, not " + std::to_string(jetDegree));
    check.intAtLeast("minPoints", minPoints, 6);
    check.intAtLeast("maxRings", maxRings, 1);
    check.positive("anisotropyEpsilon", anisotropyEpsilon);
}

CurvatureField estimateCurvature(const Mesh& mesh, const CurvatureOptions& options,
                                 const Progress& progress) {
    options.validate();

    const std::size_t slots = mesh.number_of_vertices() + mesh.number_of_removed_vertices();
    CurvatureField field;
    field.k1.assign(slots, 0.0);
    field.k2.assign(slots, 0.0);
    field.d1.assign(slots, Eigen::Vector3d::Zero());
    field.d2.assign(slots, Eigen::Vector3d::Zero());
    field.normal.assign(slots, Eigen::Vector3d::Zero());
    field.anisotropy.assign(slots, 0.0);
    field.defined.assign(slots, 0);

    Eigen::AlignedBox3d box;
    for (VertexIndex v : mesh.vertices()) {
        const Eigen::Vector3d p = toEigen(mesh.point(v));
        if (!finite(p))
            throw InvalidInputError("Vertex " + std::to_string(v.idx()) +
                                    " has a non-finite coordinate; curvature cannot be estimated.");
        box.extend(p);
    }
    if (mesh.is_empty()) return field;
    const double diagonal = box.diagonal().norm();
    const double epsilon = options.anisotropyEpsilon / (diagonal > 0 ? diagonal : 1.0);

    std::vector<std::uint32_t> stamp(slots, 0);
    std::uint32_t stampValue = 0;
    std::vector<VertexIndex> ring;
    std::vector<Point3> points;
    MongeFitting fitting;

    const std::size_t total = mesh.number_of_vertices();
    std::size_t done = 0;
    progress.report(0.0, "curvature");
    for (VertexIndex v : mesh.vertices()) {
        if ((++done & 4095u) == 0) progress.report(double(done) / double(total), "curvature");
        const std::size_t i = v.idx();
        const Eigen::Vector3d n = vertexNormal(mesh, v);
        field.normal[i] = n;
        if (n.isZero()) continue; // isolated or all-degenerate faces: no tangent plane

        growNeighbourhood(mesh, v, options, stamp, ++stampValue, ring);
        int degree = options.jetDegree;
        if (ring.size() < jetUnknowns(degree)) degree = 2;
        if (ring.size() < jetUnknowns(degree)) continue;

        points.clear();
        for (VertexIndex w : ring)
            points.push_back(mesh.point(w));
        // The fitted quadric and the vertex normal must agree on orientation; CGAL's fit picks the
        // normal from PCA. Complying with the *inward* normal makes convex curvature positive.
        MongeFitting::Monge_form monge = fitting(points.begin(), points.end(), std::size_t(degree), 2);
        monge.comply_wrt_given_normal(Vector3(-n.x(), -n.y(), -n.z()));

        const double k1 = monge.principal_curvatures(0);
        const double k2 = monge.principal_curvatures(1);
        Eigen::Vector3d d1 = vecToEigen(monge.maximal_principal_direction());
        Eigen::Vector3d d2 = vecToEigen(monge.minimal_principal_direction());
        if (!std::isfinite(k1) || !std::isfinite(k2) || !finite(d1) || !finite(d2) || d1.norm() < 0.5 ||
            d2.norm() < 0.5 || !std::isfinite(fitting.condition_number()))
            continue;
        d1.normalize();
        d2.normalize();
        field.k1[i] = k1;
        field.k2[i] = k2;
        field.d1[i] = d1;
        field.d2[i] = d2;
        field.anisotropy[i] = std::abs(k1 - k2) / (std::abs(k1) + std::abs(k2) + epsilon);
        field.defined[i] = 1;
    }
    progress.report(1.0, "curvature");
    return field;
}

} // namespace fss
