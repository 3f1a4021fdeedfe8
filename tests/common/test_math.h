#pragma once
// Small numeric helpers shared by the GoogleTest programs (one copy each: the tests compiled together in a
// unity build must not define them twice).
#include "fss/mesh.h"
#include "fss/metrics.h"

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <numbers>
#include <vector>

namespace fss::test {

inline constexpr double kPi = std::numbers::pi;
/// Degrees per radian.
inline constexpr double kDeg = 180.0 / std::numbers::pi;

/// The median of \p v (the upper one for an even count); \p v must not be empty.
inline double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

/// The position of vertex \p v of \p m as an Eigen vector.
inline Eigen::Vector3d position(const Mesh& m, VertexIndex v) {
    const auto& p = m.point(v);
    return {p.x(), p.y(), p.z()};
}

/// computeMetrics of \p mesh with the distances to \p reference.
inline Metrics metricsAgainst(const Mesh& mesh, const Mesh& reference) {
    MetricsOptions mo;
    mo.reference = &reference;
    return computeMetrics(mesh, mo);
}

} // namespace fss::test
