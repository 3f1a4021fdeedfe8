// The fishbone grid clipped at the lasso (FishboneOptions::clipRibsAtLasso, issue 20; fishbone/lasso_clip.h).
#include "fishbone/lasso_clip.h"

#include "fss/mask.h"
#include "fss/sample_grid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

// A straight backbone along y at x = 50 with horizontal ribs every pixel, 41 columns, rows y = 10 … 89.
fss::FishboneGrid straightGrid() {
    fss::FishboneGrid g;
    g.rows = 80;
    g.cols = 41;
    g.backboneColumn = 20;
    g.spacing = 1;
    g.screen.resize(std::size_t(g.rows) * std::size_t(g.cols));
    g.present.assign(g.screen.size(), 1);
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c)
            g.screen[g.index(r, c)] = Eigen::Vector2d(50 + (c - 20), 10 + r);
    return g;
}

} // namespace

// A lasso whose right side is slanted (x = 58 + 0.1·(y − 10)) crosses the ribs' positive halves between
// samples: every such half ends on the lasso (within 1e-3 px, inside it) with a last edge of ½–1½ h, and
// the negative halves (the left side at x = 35, through samples) keep their samples.
TEST(FishboneLassoClip, HalfRibsEndOnTheLasso) {
    fss::FishboneGrid g = straightGrid();
    const fss::Lasso lasso{{{35, 0}, {58, 10}, {66, 90}, {35, 100}}};
    const std::size_t dropped = fss::detail::clipRibsAtLasso(g, lasso, 0.5);
    EXPECT_GT(dropped, 0u);
    for (int r = 0; r < g.rows; ++r) {
        const double y = 10 + r, xLasso = 58 + 0.1 * (y - 10);
        int last = 20;
        while (g.isPresent(r, last + 1))
            ++last;
        const Eigen::Vector2d end = g.at(r, last);
        EXPECT_NEAR(end.x(), xLasso, 2e-3) << "row " << r;
        EXPECT_TRUE(fss::insideLasso(lasso, end)) << "row " << r;
        const double edge = (end - g.at(r, last - 1)).norm();
        EXPECT_GE(edge, 0.5 - 2e-3) << "row " << r;
        EXPECT_LT(edge, 1.5) << "row " << r;
        for (int c = last + 1; c < g.cols; ++c)
            EXPECT_FALSE(g.isPresent(r, c));
        // The left side: x = 35 is column 5 exactly (on the boundary: inside), nothing moves.
        EXPECT_TRUE(g.isPresent(r, 5));
        EXPECT_FALSE(g.isPresent(r, 4));
        EXPECT_DOUBLE_EQ(g.at(r, 5).x(), 35.0);
    }
}

// peelSliverRibEnds on a planar cast grid (5 ribs of 5 samples, unit squares, backbone column 2): the
// positive end of the middle rib pulled in to 0.2 beyond its inner neighbour makes triangles of 11.3° and
// 6.3° with the ribs beside it, in quads that end those ribs too: at 30° the three ends are peeled in one
// pass, and the next pass finds square ends (45°) and stops; the negative ends and the other samples stay; at
// 5° nothing goes.
TEST(FishboneLassoClip, PeelDropsTheRibEndsOfThinQuads) {
    auto grid = [] {
        fss::SampleGrid g(5, 5);
        for (int r = 0; r < 5; ++r)
            for (int c = 0; c < 5; ++c) {
                fss::Sample& s = g.at(r, c);
                s.point = Eigen::Vector3d(c, r, 0);
                s.hit = s.valid = s.admissible = true;
            }
        g.at(2, 4).point.x() = 3.2;
        return g;
    };
    fss::SampleGrid g = grid();
    EXPECT_EQ(fss::detail::peelSliverRibEnds(g, 2, 30.0, 3), 3u);
    for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 5; ++c)
            EXPECT_EQ(g.at(r, c).valid, !(c == 4 && r >= 1 && r <= 3)) << r << ", " << c;
    fss::SampleGrid loose = grid();
    EXPECT_EQ(fss::detail::peelSliverRibEnds(loose, 2, 5.0, 3), 0u);
}
