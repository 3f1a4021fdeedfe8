#pragma once
// Internal (not installed): the per-face geometry auto v1's stages share (auto_remesh.cpp, auto_views.cpp).
// In its own namespace: scan/scan_geometry.h has another detail::faceGeometry with the same parameters, and
// two inline functions of one name and signature are one function to the linker (the split of session 18
// first called the scan's, whose FaceGeometry has no area, and changed auto v1's results).
#include "mesh/triangle_geometry.h"

#include "fss/mesh.h"

#include <Eigen/Core>

namespace fss::detail::autoview {

struct FaceGeometry {
    Eigen::Vector3d normal{0, 0, 0}; ///< unit (zero for a degenerate face)
    Eigen::Vector3d centroid{0, 0, 0};
    double area = 0;
};

inline FaceGeometry faceGeometry(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    const Eigen::Vector3d a = toEigen(mesh.point(mesh.source(h)));
    const Eigen::Vector3d b = toEigen(mesh.point(mesh.target(h)));
    const Eigen::Vector3d c = toEigen(mesh.point(mesh.target(mesh.next(h))));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    FaceGeometry g;
    const double len = n.norm();
    g.area = 0.5 * len;
    if (len > 0) g.normal = n / len;
    g.centroid = (a + b + c) / 3.0;
    return g;
}

} // namespace fss::detail::autoview
