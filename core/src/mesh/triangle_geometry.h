#pragma once
// Internal (not installed): the small triangle measures the seam relaxation and the crease recovery of
// `fss-remesh auto` share, in double precision on Eigen vectors.
#include "fss/mesh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <boost/container/small_vector.hpp>

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
/// The three corners' terms of minAngle: corner i of (a, b, c) is atan2(y[i], x[i]); false for a degenerate
/// triangle (an edge of length zero, minAngle 0).
[[gnu::always_inline]] inline bool cornerTerms(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                               const Eigen::Vector3d& c, double (&y)[3], double (&x)[3]) {
    const Eigen::Vector3d e[3] = {b - a, c - b, a - c};
    // (x > 0 exactly when sqrt(x) > 0: Eigen's norm() is the square root of squaredNorm().) Each edge's
    // length once: corner i is between u = −e[i + 2] and v = e[i], and (−w)² = w² exactly.
    for (int i = 0; i < 3; ++i)
        if (!(e[i].squaredNorm() > 0)) return false;
    for (int i = 0; i < 3; ++i) {
        // With u = −w: u × v = −(w × v) and u · v = −(w · v) exactly (IEEE negation commutes with every
        // rounded product and sum), so the same doubles come without negating w.
        const Eigen::Vector3d& w = e[(i + 2) % 3];
        y[i] = w.cross(e[i]).norm();
        x[i] = -w.dot(e[i]);
    }
    return true;
}

/// Whether corner (yi, xi) is below corner (yj, xj) by more than 1e-9 rad: both angles are atan2(y, x) with
/// y ≥ 0, so in [0, π], and y_i x_j − x_i y_j has the sign of sin(angle i − angle j); the margin lies far
/// above atan2's error of an ulp and the product's rounding, so atan2 orders them the same way.
inline bool clearlyBelow(double yi, double xi, double yj, double xj) {
    const double d = yi * xj - xi * yj;
    return d < 0 && d * d > 1e-18 * (xi * xi + yi * yi) * (xj * xj + yj * yj);
}

inline double minAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    // When one corner lies below both others by more than 1e-9 rad only that one goes through atan2: the
    // result is the same double as the minimum of the three atan2 values, which is taken otherwise.
    double y[3], x[3];
    if (!cornerTerms(a, b, c, y, x)) return 0;
    for (int k = 0; k < 3; ++k)
        if (clearlyBelow(y[k], x[k], y[(k + 1) % 3], x[(k + 1) % 3]) &&
            clearlyBelow(y[k], x[k], y[(k + 2) % 3], x[(k + 2) % 3]))
            return std::atan2(y[k], x[k]);
    double best = std::atan2(y[0], x[0]);
    for (int i = 1; i < 3; ++i)
        best = std::min(best, std::atan2(y[i], x[i]));
    return best;
}

/// The smallest of minAngle over several triangles (π for none): the same double as the minimum of
/// minAngle(a, b, c) over the triangles added, each minAngle being the smallest of its corners' atan2. Only
/// the corners not clearly above (clearlyBelow) the smallest one go through atan2, usually that one alone,
/// where a star's minimum face by face takes one atan2 per face or more.
class MinAngleOfMany {
public:
    void add(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
        if (zero_) return;
        double y[3], x[3];
        if (!cornerTerms(a, b, c, y, x)) {
            zero_ = true;
            return;
        }
        for (int i = 0; i < 3; ++i) {
            if (corners_.empty() || y[i] * corners_[best_].second - x[i] * corners_[best_].first < 0)
                best_ = corners_.size();
            corners_.push_back({y[i], x[i]});
        }
    }
    double value() const {
        if (zero_) return 0;
        if (corners_.empty()) return 3.14159265358979323846;
        const auto [yk, xk] = corners_[best_];
        double m = std::atan2(yk, xk);
        for (std::size_t j = 0; j < corners_.size(); ++j)
            if (j != best_ && !clearlyBelow(yk, xk, corners_[j].first, corners_[j].second))
                m = std::min(m, std::atan2(corners_[j].first, corners_[j].second));
        return m;
    }

private:
    boost::container::small_vector<std::pair<double, double>, 36> corners_; // 12 faces inline
    std::size_t best_ = 0;
    bool zero_ = false;
};

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

/// Whether angleBetween(u, v) > \p bound.limit: the same answer for every input (NaN included), mostly
/// without atan2, by the sign test of angleAtMost.
inline bool angleAbove(const Eigen::Vector3d& u, const Eigen::Vector3d& v, const AngleLimit& bound) {
    const double y = u.cross(v).norm(), x = u.dot(v);
    const double d = y * bound.cos - x * bound.sin;
    if (d * d > 1e-18 * (x * x + y * y)) return d > 0;
    return std::atan2(y, x) > bound.limit;
}

/// Whether minAngle(a, b, c) < \p bound.limit: the same answer for every input, mostly without atan2. As in
/// angleAtMost, y cos(limit) − x sin(limit) has the sign of corner − limit; a corner clearly below the limit
/// answers yes, all three clearly above it no, else minAngle decides.
inline bool minAngleBelow(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const AngleLimit& bound) {
    double y[3], x[3];
    if (!cornerTerms(a, b, c, y, x)) return 0 < bound.limit;
    bool allAbove = true;
    for (int i = 0; i < 3; ++i) {
        const double d = y[i] * bound.cos - x[i] * bound.sin;
        if (d * d > 1e-18 * (x[i] * x[i] + y[i] * y[i])) {
            if (d < 0) return true;
        } else {
            allAbove = false;
        }
    }
    return allAbove ? false : minAngle(a, b, c) < bound.limit;
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
