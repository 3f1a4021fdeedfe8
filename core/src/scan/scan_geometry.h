#pragma once
// Geometry shared by the scan's sampling (scan.cpp) and the lattice warp (warp_lattice.cpp).
#include "fss/camera_projector.h"
#include "fss/error.h"
#include "fss/mesh.h"
#include "fss/scan.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <string>

namespace fss::detail {

inline constexpr double kDegToRad = std::numbers::pi / 180.0;

inline Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

struct FaceGeometry {
    Eigen::Vector3d a;
    Eigen::Vector3d normal; // unit, or zero for a degenerate face
};

inline FaceGeometry faceGeometry(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    const Eigen::Vector3d a = toEigen(mesh.point(mesh.source(h))), b = toEigen(mesh.point(mesh.target(h))),
                          c = toEigen(mesh.point(mesh.target(mesh.next(h))));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    return {a, len > 0 && std::isfinite(len) ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero()};
}

inline void checkBuffers(const FrameBuffers& referenceBuffers) {
    const Camera& camera = referenceBuffers.camera;
    camera.validate();
    const int w = camera.width, h = camera.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    if (referenceBuffers.depth.size() != n || referenceBuffers.faceId.size() != n)
        throw InvalidInputError("The scan buffers hold " + std::to_string(referenceBuffers.depth.size()) +
                                " depth and " + std::to_string(referenceBuffers.faceId.size()) +
                                " face-id values instead of " + std::to_string(n) + " for a " +
                                std::to_string(w) + "x" + std::to_string(h) + " camera.");
}

// The inverse of the screen Jacobian of the plane through \p point with normal \p normal, in an orthonormal
// basis of the plane: screen vector w ↦ tangent coordinates of the plane vector that projects onto w
// (the projection linearised at the point, a step of one pixel footprint). False when seen edge-on.
inline bool planeFromScreen(const CameraProjector& camera, const Eigen::Vector3d& point,
                            const Eigen::Vector3d& normal, Eigen::Matrix2d& inverse) {
    const Eigen::Vector3d t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
    const double eps = camera.pixelFootprint(point);
    if (!(eps > 0) || !std::isfinite(eps)) return false;
    const Eigen::Vector2d p0 = camera.project(point).head<2>();
    Eigen::Matrix2d j;
    j.col(0) = (camera.project(point + eps * t1).head<2>() - p0) / eps;
    j.col(1) = (camera.project(point + eps * t2).head<2>() - p0) / eps;
    const double det = j.determinant();
    if (!(std::abs(det) > 1e-9 * j.squaredNorm()) || !std::isfinite(det)) return false;
    inverse = j.inverse();
    return true;
}

} // namespace fss::detail
