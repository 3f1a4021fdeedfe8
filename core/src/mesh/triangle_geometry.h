#pragma once
// Internal (not installed): the small triangle measures the seam relaxation and the crease recovery of
// `fss-remesh auto` share, in double precision on Eigen vectors.
#include "fss/mesh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

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

/// Smallest corner angle of triangle (a, b, c), radians (0 for a degenerate one): the minimum of the three
/// corners' atan2(|u × v|, u · v), usually through one atan2 only (the stitch and the band remesh spend much
/// of their time here).
inline double minAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    // Corner i is atan2(y_i, x_i) with y_i = |u × v| ≥ 0, so it lies in [0, π] and the sign of
    // y_i x_j − x_i y_j is the sign of sin(angle i − angle j). When that sign puts one angle below both
    // others by more than 1e-9 rad (far above atan2's error of an ulp and the product's rounding), only
    // that one goes through atan2: the result is the same double as the minimum of the three atan2 values,
    // which is taken otherwise.
    const Eigen::Vector3d e[3] = {b - a, c - b, a - c};
    // (x > 0 exactly when sqrt(x) > 0: Eigen's norm() is the square root of squaredNorm().) Each edge's
    // length once: corner i is between u = −e[i + 2] and v = e[i], and (−w)² = w² exactly.
    for (int i = 0; i < 3; ++i)
        if (!(e[i].squaredNorm() > 0)) return 0;
    double y[3], x[3];
    for (int i = 0; i < 3; ++i) {
        // With u = −w: u × v = −(w × v) and u · v = −(w · v) exactly (IEEE negation commutes with every
        // rounded product and sum), so the same doubles come without negating w.
        const Eigen::Vector3d& w = e[(i + 2) % 3];
        y[i] = w.cross(e[i]).norm();
        x[i] = -w.dot(e[i]);
    }
    auto clearlyBelow = [&](int i, int j) {
        const double d = y[i] * x[j] - x[i] * y[j];
        return d < 0 && d * d > 1e-18 * (x[i] * x[i] + y[i] * y[i]) * (x[j] * x[j] + y[j] * y[j]);
    };
    for (int k = 0; k < 3; ++k)
        if (clearlyBelow(k, (k + 1) % 3) && clearlyBelow(k, (k + 2) % 3)) return std::atan2(y[k], x[k]);
    double best = std::atan2(y[0], x[0]);
    for (int i = 1; i < 3; ++i)
        best = std::min(best, std::atan2(y[i], x[i]));
    return best;
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

/// An angle bound for angleAtMost (its cosine and sine computed once).
struct AngleLimit {
    explicit AngleLimit(double radians) : limit(radians), cos(std::cos(radians)), sin(std::sin(radians)) {}
    double limit, cos, sin;
};

/// Whether angleBetween(u, v) <= \p bound.limit (0 < limit < π): the same answer for every input, mostly
/// without atan2. With y = |u × v| and x = u · v the angle is atan2(y, x) in [0, π], and y cos(limit) −
/// x sin(limit) = |(x, y)| sin(angle − limit) has the sign of angle − limit; where the two differ by more
/// than 1e-9 rad (far above the rounding of either side) that sign decides, else atan2 does.
inline bool angleAtMost(const Eigen::Vector3d& u, const Eigen::Vector3d& v, const AngleLimit& bound) {
    const double y = u.cross(v).norm(), x = u.dot(v);
    const double d = y * bound.cos - x * bound.sin;
    if (d * d > 1e-18 * (x * x + y * y)) return d < 0;
    return std::atan2(y, x) <= bound.limit;
}

/// The two smallest angles a flip test of an edge reads (before and after the flip), remembered per
/// halfedge together with the four corner positions they came from. The flip passes test every edge near
/// the seam again and again while most corners stay where they were; a test whose four corners are exactly
/// where they were gets the doubles computed then (minAngle is a pure function of the positions), without
/// the four minAngle calls. Positions are compared exactly, so a stale entry is never used.
class FlipAngleMemo {
public:
    /// (before, after) of the quad (a, b, c, d) tested through halfedge \p h: computed by \p compute (a
    /// callable returning that pair) unless the entry for \p h holds these four positions.
    template <class Compute>
    std::pair<double, double> get(std::size_t h, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, const Eigen::Vector3d& d, Compute&& compute) {
        if (entries_.size() <= h) entries_.resize(h + 1);
        Entry& e = entries_[h];
        if (e.known && e.p[0] == a && e.p[1] == b && e.p[2] == c && e.p[3] == d) return e.angles;
        e.p = {a, b, c, d};
        e.angles = compute();
        e.known = true;
        return e.angles;
    }

private:
    struct Entry {
        std::array<Eigen::Vector3d, 4> p;
        std::pair<double, double> angles{0, 0};
        bool known = false;
    };
    std::vector<Entry> entries_;
};

} // namespace fss::detail
