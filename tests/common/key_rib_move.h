#pragma once
// Issue #20's "a key-rib moved by 1 px moves no sample by more than 2 px", shared by the creased-ring test
// (fishbone_scan_test.cpp) and the fandisk test (fishbone_fandisk_test.cpp): the key-rib fishbone with its
// second key-rib moved by 1 px in eight directions and once across the midpoint of two backbone samples,
// against the fishbone before the move; the largest screen move of a rib vertex present in both grids.
#include "fss/fishbone_scan.h"
#include "fss/mesh_renderer.h"

#include <Eigen/Core>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>

namespace fss::test {

/// The largest screen distance between the rib vertices present in both \p a and \p b at the same row and
/// the same offset from the backbone column; \p common counts them.
inline double largestCommonMove(const FishboneGrid& a, const FishboneGrid& b, std::size_t& common) {
    double most = 0;
    common = 0;
    for (int row = 0; row < std::min(a.rows, b.rows); ++row)
        for (int dc = -std::min(a.backboneColumn, b.backboneColumn);
             a.backboneColumn + dc < a.cols && b.backboneColumn + dc < b.cols; ++dc) {
            if (!a.isPresent(row, a.backboneColumn + dc) || !b.isPresent(row, b.backboneColumn + dc))
                continue;
            ++common;
            most =
                std::max(most, (a.at(row, a.backboneColumn + dc) - b.at(row, b.backboneColumn + dc)).norm());
        }
    return most;
}

/// \p fb with two key-ribs (traced, at a quarter and three quarters of \p traced's backbone) and the second
/// moved as the file comment says, each scanned; returns the largest move over the nine cases (printed
/// under \p what) and expects at least \p minCommon common rib vertices in each.
inline double largestKeyRibMove(const char* what, const Mesh& mesh, MeshRenderer& renderer,
                                const ScanParams& params, FishboneParams fb, const FishboneScanResult& traced,
                                FishboneCache& cache, std::size_t minCommon) {
    const FishboneGrid& g0 = traced.fishbone;
    const int bc = g0.backboneColumn, r2 = 3 * g0.rows / 4;
    fb.keyRibs = {g0.at(g0.rows / 4, bc), g0.at(r2, bc)};
    fb.tracing.continuousKeyRibs = true; // the 2 px criterion holds with continuous key-ribs only
    // The second point 1 px before the midpoint of two backbone samples, then moved by 1 px along the
    // backbone across that midpoint (the worst case where key-ribs start at the nearest sample,
    // FishboneOptions::continuousKeyRibs off), and 1 px in eight directions from the sample itself.
    const Eigen::Vector2d along = (g0.at(r2 + 1, bc) - g0.at(r2, bc)).normalized();
    const Eigen::Vector2d beforeMid = 0.5 * (g0.at(r2, bc) + g0.at(r2 + 1, bc)) - 0.5 * along;
    double worst = 0;
    for (int k = 0; k < 9; ++k) {
        FishboneParams from = fb, moved = fb;
        const double t = k * std::numbers::pi / 4;
        if (k == 8) {
            from.keyRibs[1] = beforeMid;
            moved.keyRibs[1] = beforeMid + along;
        } else {
            moved.keyRibs[1] += Eigen::Vector2d(std::cos(t), std::sin(t));
        }
        const FishboneScanResult base =
            scanFishbonePatch(mesh, renderer, mesh, renderer, params, from, cache);
        const FishboneScanResult r = scanFishbonePatch(mesh, renderer, mesh, renderer, params, moved, cache);
        std::size_t common = 0;
        const double most = largestCommonMove(base.fishbone, r.fishbone, common);
        std::printf("%s: key-rib moved by 1 px %s%3d°: %zu common rib vertices, largest move %.2f px\n", what,
                    k == 8 ? "across a midpoint, " : "towards ", k == 8 ? 0 : 45 * k, common, most);
        EXPECT_GT(common, minCommon);
        worst = std::max(worst, most);
    }
    std::printf("%s: key-rib moved by 1 px: largest sample move %.2f px (issue #20 asks <= 2)\n", what,
                worst);
    return worst;
}

} // namespace fss::test
