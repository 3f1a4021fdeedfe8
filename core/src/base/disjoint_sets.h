#pragma once
// Internal (not installed): union-find with path halving over dense indices 0..n-1.
#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace fss::detail {

class DisjointSets {
public:
    explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
    std::size_t find(std::size_t x) {
        while (parent_[x] != x)
            x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    /// Joins the sets of a and b; the smaller index becomes the representative.
    void unite(std::size_t a, std::size_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    }

private:
    std::vector<std::size_t> parent_;
};

} // namespace fss::detail
