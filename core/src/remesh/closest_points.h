#pragma once
// Internal (not installed): closest reference points memoized by their query point, for the crease recovery
// (crease_snap.h), whose sweeps ask the reference's AABB tree for the closest point of face centroids and
// sample points, most of them again over sweeps and rounds where nothing moved there: each exact query point
// is answered once (measured on fandisk: 284k queries of 78k points). The seam relaxation does not use it:
// its smoothing moves the vertices at every sweep, so its queries repeat too rarely to pay for the table (83k
// queries of 76k points, slower with the table). A batch of points known in advance (every face's centroid at
// the start of a crease sweep) is answered in parallel (TBB); the answers are those of
// RayCaster::closestPoint whatever the thread count, as each depends on its query point only.
#include "fss/raycast.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace fss::detail {

class ClosestPoints {
public:
    explicit ClosestPoints(const RayCaster& caster) : caster_(caster) {}

    /// RayCaster::closestPoint(p), computed at most once per exact point.
    SurfacePoint operator()(const Eigen::Vector3d& p) const {
        const Key k = key(p);
        if (const auto it = memo_.find(k); it != memo_.end()) return it->second;
        const SurfacePoint sp = caster_.closestPoint(p);
        if (memo_.size() >= kMaxAnswers) memo_.clear();
        memo_.emplace(k, sp);
        return sp;
    }

    /// Answers the points of \p points not answered yet, in parallel.
    void prefetch(const std::vector<Eigen::Vector3d>& points) const {
        std::vector<Eigen::Vector3d> missing;
        missing.reserve(points.size());
        for (const Eigen::Vector3d& p : points)
            if (!memo_.contains(key(p))) missing.push_back(p);
        std::vector<SurfacePoint> answers(missing.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, missing.size(), 256),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t i = r.begin(); i != r.end(); ++i)
                                  answers[i] = caster_.closestPoint(missing[i]);
                          });
        for (std::size_t i = 0; i < missing.size(); ++i)
            memo_.emplace(key(missing[i]), answers[i]);
    }

    /// Forgets every answer (bounds the memory between sweeps).
    void clear() const { memo_.clear(); }

private:
    struct Key {
        std::uint64_t x, y, z;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        // splitmix64's finaliser on each coordinate's bits, chained: nearby points (equal high bits) spread.
        static std::uint64_t mix(std::uint64_t z) {
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
            return z ^ (z >> 31);
        }
        std::size_t operator()(const Key& k) const {
            return std::size_t(mix(k.x ^ mix(k.y ^ mix(k.z + 0x9e3779b97f4a7c15ull))));
        }
    };
    static Key key(const Eigen::Vector3d& p) {
        return {std::bit_cast<std::uint64_t>(p.x()), std::bit_cast<std::uint64_t>(p.y()),
                std::bit_cast<std::uint64_t>(p.z())};
    }
    static constexpr std::size_t kMaxAnswers = std::size_t(1) << 21; // about 150 MB
    const RayCaster& caster_;
    mutable std::unordered_map<Key, SurfacePoint, KeyHash> memo_;
};

} // namespace fss::detail
