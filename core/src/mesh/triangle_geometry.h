#pragma once
// Internal (not installed): the small triangle measures the seam relaxation and the crease recovery of
// `fss-remesh auto` share, in double precision on Eigen vectors.
#include "fss/mesh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace fss::detail {

/// \p p as an Eigen vector.
inline Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

/// The position of vertex \p v of \p m.
inline Eigen::Vector3d pos(const Mesh& m, VertexIndex v) {
    const Point3& p = m.point(v);
    return {p.x(), p.y(), p.z()};
}

/// Smallest corner angle of triangle (a, b, c), radians (0 for a degenerate one).
inline double minAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    auto corner = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
        const Eigen::Vector3d u = q - p, v = r - p;
        return std::atan2(u.cross(v).norm(), u.dot(v));
    };
    return std::min({corner(a, b, c), corner(b, c, a), corner(c, a, b)});
}

/// Unit normal of triangle (a, b, c); zero when degenerate.
inline Eigen::Vector3d unitNormal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c) {
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d(0, 0, 0);
}

/// Angle between the vectors \p u and \p v, radians.
inline double angleBetween(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return std::atan2(u.cross(v).norm(), u.dot(v));
}

} // namespace fss::detail
