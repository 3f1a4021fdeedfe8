#pragma once
// Internal to the crease recovery (crease_snap.h): the creases of the reference as segments in a uniform
// grid.
#include "mesh/features.h"
#include "mesh/triangle_geometry.h"

#include "fss/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace fss::detail::creases {

using Vec = Eigen::Vector3d;

/// Closest points of segments [p1, q1] and [p2, q2] (Ericson, Real-Time Collision Detection, 5.1.9): the
/// parameters s (on the first) and t (on the second).
inline void closestSegmentParameters(const Vec& p1, const Vec& q1, const Vec& p2, const Vec& q2, double& s,
                                     double& t) {
    const Vec d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    constexpr double eps = 1e-300;
    if (a <= eps && e <= eps) {
        s = t = 0;
        return;
    }
    if (a <= eps) {
        s = 0;
        t = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = d1.dot(r);
    if (e <= eps) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = d1.dot(d2), denom = a * e - b * b;
    s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

/// The crease edges of the reference as segments, in a uniform grid of cells of one edge length: the
/// segments within one cell of a point are found in the point's cell.
class CreaseIndex {
public:
    CreaseIndex(const Mesh& reference, double creaseAngleDeg, double cell) : cell_(cell) {
        const std::vector<char> sharp = sharpEdges(reference, creaseAngleDeg);
        for (EdgeIndex e : reference.edges()) {
            if (!sharp[e.idx()]) continue;
            const HalfedgeIndex h = reference.halfedge(e);
            const Vec a = pos(reference, reference.source(h)), b = pos(reference, reference.target(h));
            const int id = int(segments_.size());
            segments_.push_back({a, b});
            const Vec lo = a.cwiseMin(b).array() - cell, hi = a.cwiseMax(b).array() + cell;
            const Key k0 = keyOf(lo), k1 = keyOf(hi);
            for (std::int64_t x = k0.x; x <= k1.x; ++x)
                for (std::int64_t y = k0.y; y <= k1.y; ++y)
                    for (std::int64_t z = k0.z; z <= k1.z; ++z)
                        cells_[hash({x, y, z})].push_back(id);
        }
        for (VertexIndex v : creaseCorners(reference, sharp))
            corners_.push_back(pos(reference, v));
    }
    /// The corners of the creases: reference vertices where a crease ends or branches (one crease edge,
    /// or three and more).
    const std::vector<Vec>& corners() const { return corners_; }
    std::size_t size() const { return segments_.size(); }
    /// The crease segments that may lie within one cell of \p p (and possibly a few more).
    const std::vector<int>& near(const Vec& p) const {
        const auto it = cells_.find(hash(keyOf(p)));
        return it == cells_.end() ? empty_ : it->second;
    }
    const Vec& a(int s) const { return segments_[std::size_t(s)].a; }
    const Vec& b(int s) const { return segments_[std::size_t(s)].b; }
    /// The closest crease point to \p p among the segments near it; false when there is none.
    bool closest(const Vec& p, Vec& out, double& distance) const {
        distance = std::numeric_limits<double>::infinity();
        for (int s : near(p)) {
            const Vec d = b(s) - a(s);
            const double len2 = d.squaredNorm();
            const double t = len2 > 0 ? std::clamp((p - a(s)).dot(d) / len2, 0.0, 1.0) : 0.0;
            const Vec q = a(s) + t * d;
            const double dist = (p - q).norm();
            if (dist < distance) distance = dist, out = q;
        }
        return std::isfinite(distance);
    }

private:
    struct Segment {
        Vec a, b;
    };
    struct Key {
        std::int64_t x, y, z;
    };
    Key keyOf(const Vec& p) const {
        return {std::int64_t(std::floor(p.x() / cell_)), std::int64_t(std::floor(p.y() / cell_)),
                std::int64_t(std::floor(p.z() / cell_))};
    }
    static std::uint64_t hash(const Key& k) {
        return std::uint64_t(k.x) * 73856093ULL ^ std::uint64_t(k.y) * 19349663ULL ^
               std::uint64_t(k.z) * 83492791ULL;
    }
    double cell_;
    std::vector<Segment> segments_;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
    std::vector<int> empty_;
    std::vector<Vec> corners_;
};

} // namespace fss::detail::creases
