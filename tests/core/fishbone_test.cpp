// Fishbone grid: the paper's rib representation and blending rule reproduced exactly, hand-drawn splines,
// grid assembly, key-rib mode, and the whole chain (curvature → direction field → backbone → ribs) on a
// cylinder seen from the side, where ribs must follow the circles and the backbone the axis.
#include "fss/curvature.h"
#include "fss/direction_field.h"
#include "fss/error.h"
#include "fss/fishbone.h"
#include "fss/shapes.h"

#include "brute_force_raster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

using fss::Backbone;
using fss::FishboneGrid;
using fss::FishboneOptions;
using fss::KeyRib;
using fss::Polyline2;
using fss::Rib;
using fss::RibShape;

namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Vector2d rot(const Eigen::Vector2d& v, double a) {
    return {std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y()};
}

// Rib half from p0 with first edge direction u, n edges of length h, constant turning angle a.
Polyline2 arcRib(const Eigen::Vector2d& p0, const Eigen::Vector2d& u, double h, double a, int n) {
    Polyline2 r{p0};
    for (int i = 0; i < n; ++i)
        r.push_back(r.back() + h * rot(u.normalized(), a * i));
    return r;
}

// A smooth random curve resampled at spacing h.
Polyline2 randomRib(unsigned seed, double h, const Eigen::Vector2d& p0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.02, 0.02);
    Polyline2 dense{p0};
    double heading = 0.3, turn = 0;
    for (int i = 0; i < 2000; ++i) {
        turn = std::clamp(turn + u(rng), -0.05, 0.05);
        heading += turn;
        dense.push_back(dense.back() + 0.1 * Eigen::Vector2d(std::cos(heading), std::sin(heading)));
    }
    return fss::resampleAtSpacing(dense, h);
}

double maxDistance(const Polyline2& a, const Polyline2& b) {
    EXPECT_EQ(a.size(), b.size());
    double d = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        d = std::max(d, (a[i] - b[i]).norm());
    return d;
}

Backbone straightBackbone(const Eigen::Vector2d& from, const Eigen::Vector2d& dir, double h, int n) {
    Backbone b;
    for (int i = 0; i < n; ++i)
        b.samples.push_back(from + i * h * dir.normalized());
    return b;
}

} // namespace

// ---- The paper's rib formula ----------------------------------------------------------------------------

TEST(Fishbone, RibShapeRoundTripIsExact) {
    const double h = 3.0;
    const Polyline2 rib = randomRib(1, h, {10, 20});
    ASSERT_GT(rib.size(), 30u);
    const RibShape s = fss::ribShape(rib);
    EXPECT_EQ(s.edgeCount(), rib.size() - 1);
    EXPECT_LT(maxDistance(fss::ribFromShape(rib[0], s, h), rib), 1e-9);
    // The formula written out: p_k = p0 + G0 + h Σ_{i=1}^{k−1} R(θ0)(cos Σ_{j≤i}γj, sin Σ_{j≤i}γj).
    const double theta0 = std::atan2(s.firstEdge.y(), s.firstEdge.x());
    for (std::size_t k = 2; k < rib.size(); ++k) {
        Eigen::Vector2d p = rib[0] + s.firstEdge;
        double sum = 0;
        for (std::size_t i = 1; i <= k - 1; ++i) {
            sum += s.turningAngles[i - 1];
            p += h * Eigen::Vector2d(std::cos(theta0 + sum), std::sin(theta0 + sum));
        }
        EXPECT_LT((p - rib[k]).norm(), 1e-9);
    }
    // Degenerate halves.
    EXPECT_EQ(fss::ribShape(Polyline2{{1, 1}}).edgeCount(), 0u);
    EXPECT_EQ(fss::ribFromShape({1, 1}, RibShape{}, h).size(), 1u);
}

TEST(Fishbone, BlendingARibWithItselfGivesItself) {
    const double h = 2.0;
    const Polyline2 rib = randomRib(2, h, {0, 0});
    const RibShape s = fss::ribShape(rib);
    for (double t : {0.0, 0.25, 0.5, 0.9, 1.0}) {
        const RibShape g = fss::blendRibShapes(s, s, t, h);
        EXPECT_LT(maxDistance(fss::ribFromShape(rib[0], g, h), rib), 1e-9) << "t = " << t;
    }
}

TEST(Fishbone, BlendingAtZeroAndOneGivesTheKeyRibsExactly) {
    const double h = 2.5;
    const Polyline2 a = randomRib(3, h, {0, 0}), b = randomRib(4, h, {0, 0});
    const RibShape sa = fss::ribShape(a), sb = fss::ribShape(b);
    const std::size_t n = std::min(sa.turningAngles.size(), sb.turningAngles.size());
    const RibShape g0 = fss::blendRibShapes(sa, sb, 0.0, h), g1 = fss::blendRibShapes(sa, sb, 1.0, h);
    EXPECT_EQ(g0.firstEdge, sa.firstEdge);
    EXPECT_EQ(g1.firstEdge, sb.firstEdge);
    ASSERT_EQ(g0.turningAngles.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(g0.turningAngles[i], sa.turningAngles[i]);
        EXPECT_EQ(g1.turningAngles[i], sb.turningAngles[i]);
    }
    // Placed at another backbone sample, the blended rib is the key-rib translated.
    const Eigen::Vector2d p0(7, -3);
    const Polyline2 moved = fss::ribFromShape(p0, g0, h);
    for (std::size_t k = 0; k < moved.size(); ++k)
        EXPECT_LT((moved[k] - (a[k] + p0)).norm(), 1e-9);
}

TEST(Fishbone, StraightAndCircularRibsBlendToTheExpectedArc) {
    // Key-rib A straight (αi = 0), key-rib B inscribed in a circle of radius R with chord h (constant
    // turning β = 2 asin(h / 2R)), first edges at an angle φ. Blend at t: G0 = h·normalise((1−t)E0 + tF0),
    // at t = ½ the bisector (angle φ/2); γi = t·β constant, so the blend is again a circular arc with chord
    // h and radius R_t = h / (2 sin(tβ/2)).
    const double h = 2.0, R = 30.0, phi = 0.4;
    const double beta = 2 * std::asin(h / (2 * R));
    const Eigen::Vector2d u(1, 0);
    const Polyline2 straight = arcRib({0, 0}, u, h, 0.0, 25),
                    circle = arcRib({0, 0}, rot(u, phi), h, beta, 25);
    const RibShape sa = fss::ribShape(straight), sb = fss::ribShape(circle);
    for (double t : {0.25, 0.5, 0.75}) {
        const RibShape g = fss::blendRibShapes(sa, sb, t, h);
        const Eigen::Vector2d avg = (1 - t) * h * u + t * h * rot(u, phi);
        const double g0Angle = std::atan2(avg.y(), avg.x());
        EXPECT_NEAR(std::atan2(g.firstEdge.y(), g.firstEdge.x()), g0Angle, 1e-12);
        EXPECT_NEAR(g.firstEdge.norm(), h, 1e-12);
        for (double gamma : g.turningAngles)
            EXPECT_NEAR(gamma, t * beta, 1e-12);
        const Eigen::Vector2d p0(5, 5);
        const Polyline2 blended = fss::ribFromShape(p0, g, h);
        EXPECT_LT(maxDistance(blended, arcRib(p0, rot(u, g0Angle), h, t * beta, 25)), 1e-9);
        // All vertices on one circle of radius R_t: centre = p0 + R_t·(unit normal of the first chord,
        // turned back by half the turning angle).
        const double Rt = h / (2 * std::sin(t * beta / 2));
        const Eigen::Vector2d towardsCentre =
            rot(Eigen::Vector2d(std::cos(g0Angle), std::sin(g0Angle)), kPi / 2 - t * beta / 2);
        const Eigen::Vector2d centre = p0 + Rt * towardsCentre;
        for (const Eigen::Vector2d& p : blended)
            EXPECT_NEAR((p - centre).norm(), Rt, 1e-9);
    }
    // t = ½ with equal first edges: turning exactly β/2.
    const RibShape half = fss::blendRibShapes(sa, fss::ribShape(arcRib({0, 0}, u, h, beta, 25)), 0.5, h);
    for (double gamma : half.turningAngles)
        EXPECT_NEAR(gamma, beta / 2, 1e-12);
}

TEST(Fishbone, UnequalKeyRibsBlendUpToTheShorter) {
    const double h = 1.0;
    const RibShape a = fss::ribShape(arcRib({0, 0}, {1, 0}, h, 0.01, 30));
    const RibShape b = fss::ribShape(arcRib({0, 0}, {1, 0.1}, h, -0.02, 12));
    EXPECT_EQ(fss::blendRibShapes(a, b, 0.3, h).edgeCount(), 12u);
    EXPECT_EQ(fss::blendRibShapes(b, a, 0.3, h).edgeCount(), 12u);
    EXPECT_EQ(fss::blendRibShapes(a, RibShape{}, 0.3, h).edgeCount(), 0u);
    EXPECT_THROW(fss::blendRibShapes(a, b, 1.5, h), fss::InvalidInputError);
    // Opposite first edges cannot be averaged.
    const RibShape c = fss::ribShape(arcRib({0, 0}, {-1, 0}, h, 0.0, 5));
    const RibShape d = fss::ribShape(arcRib({0, 0}, {1, 0}, h, 0.0, 5));
    EXPECT_THROW(fss::blendRibShapes(c, d, 0.5, h), fss::InvalidInputError);
}

// ---- Hand-drawn curves ----------------------------------------------------------------------------------

TEST(Fishbone, CatmullRomSplinePassesThroughItsPoints) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> c(0, 200);
    Polyline2 pts;
    for (int i = 0; i < 12; ++i)
        pts.push_back({c(rng), c(rng)});
    pts.push_back(pts.back()); // a duplicate is merged
    const Polyline2 s = fss::catmullRomSpline(pts, 0.5);
    for (std::size_t i = 0; i < pts.size(); ++i)
        EXPECT_TRUE(std::find(s.begin(), s.end(), pts[i]) != s.end()) << "point " << i;
    EXPECT_EQ(s.front(), pts.front());
    EXPECT_EQ(s.back(), pts.back());
    for (std::size_t i = 1; i < s.size(); ++i)
        EXPECT_LE((s[i] - s[i - 1]).norm(), 0.5 + 1e-12);

    // Through 16 points of a circle of radius 50 it stays close to the circle.
    Polyline2 circle;
    for (int i = 0; i <= 16; ++i)
        circle.push_back(50.0 * Eigen::Vector2d(std::cos(i * kPi / 16), std::sin(i * kPi / 16)));
    double worst = 0;
    const Polyline2 arc = fss::catmullRomSpline(circle);
    for (std::size_t i = arc.size() / 8; i < arc.size() * 7 / 8; ++i)
        worst = std::max(worst, std::abs(arc[i].norm() - 50.0));
    std::printf("[ spline ] 16 points on a circle of radius 50: worst radial deviation %.3f px (inner 3/4)\n",
                worst);
    EXPECT_LT(worst, 0.1);

    EXPECT_THROW(fss::catmullRomSpline(pts, 0.0), fss::InvalidInputError);
    EXPECT_THROW(fss::catmullRomSpline(Polyline2{{0, 0}, {std::nan(""), 1}}), fss::InvalidInputError);
    EXPECT_EQ(fss::catmullRomSpline(Polyline2{{1, 1}, {1, 1}}).size(), 1u);
}

TEST(Fishbone, DrawnBackboneAndKeyRib) {
    FishboneOptions o;
    o.spacing = 5;
    const Backbone b = fss::drawnBackbone(Polyline2{{100, 20}, {104, 100}, {100, 180}}, o);
    EXPECT_EQ(b.samples.front(), Eigen::Vector2d(100, 20));
    for (std::size_t i = 1; i < b.samples.size(); ++i)
        EXPECT_NEAR((b.samples[i] - b.samples[i - 1]).norm(), 5.0, 1e-9);
    EXPECT_GT(b.samples.size(), 30u);
    // Backbone runs down the screen: t ≈ (0, 1), n = (−t.y, t.x) ≈ (−1, 0): the positive side is the left.
    const std::size_t mid = b.nearestSample({104, 100});
    EXPECT_LT(b.normal(mid).x(), -0.99);

    const KeyRib k =
        fss::drawnKeyRib(b, Polyline2{{160, 95}, {130, 98}, {104, 101}, {70, 100}, {40, 104}}, o);
    EXPECT_EQ(k.row, b.nearestSample({104, 101}));
    ASSERT_GT(k.rib.positive.size(), 5u);
    ASSERT_GT(k.rib.negative.size(), 5u);
    EXPECT_EQ(k.rib.positive.front(), b.samples[k.row]);
    EXPECT_EQ(k.rib.negative.front(), b.samples[k.row]);
    EXPECT_LT(k.rib.positive.back().x(), 60.0);  // left
    EXPECT_GT(k.rib.negative.back().x(), 140.0); // right
    for (const Polyline2* half : {&k.rib.positive, &k.rib.negative})
        for (std::size_t i = 1; i < half->size(); ++i)
            EXPECT_NEAR(((*half)[i] - (*half)[i - 1]).norm(), 5.0, 1e-9);

    EXPECT_THROW(fss::drawnKeyRib(b, Polyline2{{10, 10}, {20, 10}}, o), fss::InvalidInputError);
    EXPECT_THROW(fss::drawnBackbone(Polyline2{{1, 1}}, o), fss::InvalidInputError);
}

// ---- Grids ----------------------------------------------------------------------------------------------

TEST(Fishbone, KeyRibGridBlendsBetweenKeyRibs) {
    // Vertical backbone; key-rib at row 5 straight, at row 25 circular (both sides); blended rows between.
    const double h = 2.0, R = 25.0, beta = 2 * std::asin(h / (2 * R));
    const Backbone b = straightBackbone({100, 10}, {0, 1}, h, 40);
    const Eigen::Vector2d n = b.normal(0); // (−1, 0)
    KeyRib k5{5, Rib{arcRib(b.samples[5], n, h, 0.0, 10), arcRib(b.samples[5], -n, h, 0.0, 10)}};
    KeyRib k25{25, Rib{arcRib(b.samples[25], n, h, beta, 10), arcRib(b.samples[25], -n, h, -beta, 8)}};
    FishboneOptions o;
    o.spacing = h;
    const FishboneGrid g = fss::keyRibFishbone(b, {k25, k5}, o);
    EXPECT_EQ(g.rows, 40);
    EXPECT_EQ(g.cols, 21);
    EXPECT_EQ(g.backboneColumn, 10);
    // Key rows reproduce their key-ribs exactly.
    for (int c = 0; c <= 10; ++c) {
        EXPECT_EQ(g.at(5, 10 + c), k5.rib.positive[std::size_t(c)]);
        EXPECT_EQ(g.at(25, 10 + c), k25.rib.positive[std::size_t(c)]);
    }
    for (int c = 0; c <= 8; ++c)
        EXPECT_EQ(g.at(25, 10 - c), k25.rib.negative[std::size_t(c)]);
    EXPECT_FALSE(g.isPresent(25, 1)); // the shorter negative half of row 25
    // Row 15 is half way: turning β/2, starting on its own backbone sample.
    const Polyline2 expect = arcRib(b.samples[15], n, h, beta / 2, 10);
    for (int c = 0; c <= 10; ++c)
        EXPECT_LT((g.at(15, 10 + c) - expect[std::size_t(c)]).norm(), 1e-9);
    // Blended negative halves stop at the shorter key-rib's length (8) between the key-ribs.
    EXPECT_TRUE(g.isPresent(15, 2));
    EXPECT_FALSE(g.isPresent(15, 1));
    // Beyond the key-ribs: copies of the nearest key-rib, translated to their backbone sample.
    for (int c = 0; c <= 10; ++c) {
        EXPECT_LT((g.at(0, 10 + c) - (k5.rib.positive[std::size_t(c)] - b.samples[5] + b.samples[0])).norm(),
                  1e-9);
        EXPECT_LT(
            (g.at(39, 10 + c) - (k25.rib.positive[std::size_t(c)] - b.samples[25] + b.samples[39])).norm(),
            1e-9);
    }
    // Without extension only the rows from the first to the last key-rib.
    o.extendBeyondKeyRibs = false;
    const FishboneGrid inner = fss::keyRibFishbone(b, {k5, k25}, o);
    EXPECT_EQ(inner.rows, 21);
    EXPECT_EQ(inner.at(0, inner.backboneColumn), b.samples[5]);
    // Image clipping marks outside entries absent.
    const FishboneGrid clipped = fss::keyRibFishbone(b, {k5, k25}, FishboneOptions{.spacing = h}, 110, 200);
    EXPECT_TRUE(clipped.isPresent(5, 10 - 5));  // x = 110
    EXPECT_FALSE(clipped.isPresent(5, 10 - 6)); // x = 112
    EXPECT_THROW(fss::keyRibFishbone(b, {}, o), fss::InvalidInputError);
    EXPECT_THROW(fss::keyRibFishbone(b, {KeyRib{40, {}}}, o), fss::InvalidInputError);
}

// Key-ribs between backbone samples (KeyRib::position, FishboneOptions::continuousKeyRibs): the row of sample
// r between key-ribs at positions a < b is their blend with t = (r − a)/(b − a), and a key-rib moved along
// the backbone by a quarter of h moves the grid by a fraction of that (no row jumps to another key-rib).
TEST(Fishbone, KeyRibsBetweenSamplesBlendByTheirPositions) {
    const double h = 2.0, R = 25.0, beta = 2 * std::asin(h / (2 * R));
    const Backbone b = straightBackbone({100, 10}, {0, 1}, h, 40);
    const Eigen::Vector2d n = b.normal(0);
    FishboneOptions o;
    o.spacing = h;
    auto grid = [&](double pa, double pb) {
        auto at = [&](double pos) { return Eigen::Vector2d(b.samples[0] + pos * h * Eigen::Vector2d(0, 1)); };
        KeyRib a{std::size_t(std::lround(pa)),
                 Rib{arcRib(at(pa), n, h, 0.0, 10), arcRib(at(pa), -n, h, 0.0, 10)}, pa};
        KeyRib c{std::size_t(std::lround(pb)),
                 Rib{arcRib(at(pb), n, h, beta, 10), arcRib(at(pb), -n, h, -beta, 10)}, pb};
        return fss::keyRibFishbone(b, {c, a}, o);
    };
    const FishboneGrid g = grid(5.3, 24.6);
    ASSERT_EQ(g.rows, 40);
    for (int r = 0; r < 40; ++r) {
        const double t = std::clamp((r - 5.3) / (24.6 - 5.3), 0.0, 1.0);
        const Polyline2 expect = arcRib(b.samples[std::size_t(r)], n, h, t * beta, 10);
        for (int c = 0; c <= 10; ++c)
            ASSERT_LT((g.at(r, g.backboneColumn + c) - expect[std::size_t(c)]).norm(), 1e-9) << r << " " << c;
    }
    // Moved by h/4 along the backbone: every vertex moves by less than 0.1 h (about 0.09 px by the formula:
    // row 24's t changes by 0.0124, its tenth vertex by 45·h·0.0124·β).
    const FishboneGrid moved = grid(5.3, 24.85);
    double most = 0;
    for (std::size_t i = 0; i < g.screen.size(); ++i)
        if (g.present[i] && moved.present[i]) most = std::max(most, (g.screen[i] - moved.screen[i]).norm());
    EXPECT_LT(most, 0.1 * h);
    EXPECT_GT(most, 0.0);
    // A key-rib beyond the backbone's last sample is refused.
    EXPECT_THROW(grid(5.3, 39.5), fss::InvalidInputError);
}

// A traced key-rib whose point lies where the rib field is undefined (fandisk's flat faces: no principal
// direction, tests/cli/fishbone_scan_test.cpp's drawn case): the half towards a defined region within 8h
// runs straight to it and is traced on from there; the half into the undefined region stays empty. The
// field: horizontal for x ≥ 20 only; the backbone vertical at x = 17.5, the key-rib's point at y = 20.3
// (between samples). Before session 18 both halves came back empty.
TEST(Fishbone, TracedKeyRibStartsStraightWhereTheFieldIsUndefined) {
    const int W = 60, H = 40;
    fss::DirectionField across(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 20; x < W; ++x)
            across.setPixel(x, y, {1, 0}, 1.0);
    const double h = 2.0;
    const Backbone b = straightBackbone({17.5, 4}, {0, 1}, h, 16);
    FishboneOptions o;
    o.spacing = h;
    const KeyRib k = fss::tracedKeyRib(across, b, {18.0, 20.3}, o);
    EXPECT_NEAR(k.position, 8.15, 1e-9);
    EXPECT_EQ(k.row, 8u);
    const bool positiveRight = b.normal(8).x() > 0;
    const Polyline2& right = positiveRight ? k.rib.positive : k.rib.negative;
    const Polyline2& left = positiveRight ? k.rib.negative : k.rib.positive;
    EXPECT_EQ(left.size(), 1u); // into the undefined region: nothing to trace
    // To the image's right border (42.5 px from the start) at spacing h: 22 vertices, all on y = 20.3.
    ASSERT_EQ(right.size(), 22u);
    for (std::size_t i = 0; i < right.size(); ++i) {
        EXPECT_NEAR(right[i].x(), 17.5 + h * double(i), 1e-6) << i;
        EXPECT_NEAR(right[i].y(), 20.3, 1e-6) << i;
    }
    // Defined only beyond 8h (x ≥ 34): no straight start that long.
    fss::DirectionField far(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 34; x < W; ++x)
            far.setPixel(x, y, {1, 0}, 1.0);
    const KeyRib none = fss::tracedKeyRib(far, b, {18.0, 20.3}, o);
    EXPECT_EQ(none.rib.positive.size() + none.rib.negative.size(), 2u);
}

TEST(Fishbone, AutomaticGridOnSyntheticFields) {
    // Backbone field vertical, rib field horizontal (random signs): a square grid of spacing h.
    const int W = 120, H = 100;
    fss::DirectionField down(W, H), across(W, H);
    std::mt19937 rng(4);
    std::bernoulli_distribution flip(0.5);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            down.setPixel(x, y, {0, flip(rng) ? 1.0 : -1.0});
            across.setPixel(x, y, {flip(rng) ? 1.0 : -1.0, 0});
        }
    FishboneOptions o;
    o.spacing = 4;
    const Eigen::Vector2d seed(50.25, 49.5);
    const FishboneGrid g = fss::automaticFishbone(down, across, seed, o);
    // Rows: 49.5/4 → 12 samples up, (100 − 49.5)/4 → 12 down; cols: 50.25/4 → 12 left, 69.75/4 → 17 right.
    EXPECT_EQ(g.rows, 25);
    EXPECT_EQ(g.cols, 30);
    int seedRow = -1;
    for (int r = 0; r < g.rows; ++r) {
        const Eigen::Vector2d bb = g.at(r, g.backboneColumn);
        EXPECT_NEAR(bb.x(), seed.x(), 1e-9);
        if ((bb - seed).norm() < 1e-12) seedRow = r;
        for (int c = 0; c < g.cols; ++c) {
            ASSERT_TRUE(g.isPresent(r, c));
            EXPECT_NEAR(g.at(r, c).y(), bb.y(), 1e-9);
            EXPECT_NEAR(std::abs(g.at(r, c).x() - bb.x()), 4.0 * std::abs(c - g.backboneColumn), 1e-9);
        }
    }
    EXPECT_GE(seedRow, 0);
    // Positive side = (−t.y, t.x): columns increase to the right when the backbone runs up the screen.
    const double tY = g.at(1, g.backboneColumn).y() - g.at(0, g.backboneColumn).y();
    EXPECT_EQ(g.at(0, g.cols - 1).x() > seed.x(), tY < 0);
    EXPECT_EQ(g.presentCount(), std::size_t(g.rows * g.cols));
    EXPECT_THROW(fss::automaticFishbone(down, fss::DirectionField(3, 3), seed, o), fss::InvalidInputError);
}

// ---- The whole chain on a cylinder ----------------------------------------------------------------------

namespace {

struct CylinderScene {
    fss::Mesh mesh = fss::shapes::cylinder(128, 40, 1.0, 2.0, /*capped=*/true);
    fss::Camera camera;
    fss::DirectionField minField, maxField;

    explicit CylinderScene(bool parallel) {
        camera.eye = {5, 0.4, 1.3};
        camera.focal = {0, 0, 1};
        camera.up = {0, 0, 1};
        camera.parallel = parallel;
        camera.parallelScale = 1.3;
        camera.width = camera.height = 200;
        camera.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 2)));
        const fss::CurvatureField curv = fss::estimateCurvature(mesh);
        const fss::FrameBuffers fb = fss::test::bruteForceRaster(mesh, camera);
        minField = fss::computeDirectionField(mesh, curv, fb, {fss::PrincipalDirection::Min});
        maxField = fss::computeDirectionField(mesh, curv, fb, {fss::PrincipalDirection::Max});
    }

    // The point of the (analytic) cylinder side under a screen position.
    std::optional<Eigen::Vector3d> surfacePoint(const Eigen::Vector2d& s) const {
        const fss::Ray ray = camera.ray(s.x(), s.y());
        const Eigen::Vector2d o = ray.origin.head<2>(), d = ray.direction.head<2>();
        const double A = d.squaredNorm(), B = o.dot(d), C = o.squaredNorm() - 1, disc = B * B - A * C;
        if (disc < 0) return std::nullopt;
        const Eigen::Vector3d p = ray.origin + ((-B - std::sqrt(disc)) / A) * ray.direction;
        if (p.z() < 0 || p.z() > 2) return std::nullopt;
        return p;
    }
};

// Ribs are meant to lie on circles z = const: the spread of z along each row (side part only, away from
// the caps' rims, whose crease enters the jet fits of the 3 nearest rings, and the silhouettes), and the
// spread of the angle around the axis along the backbone.
struct Deviation {
    double ribZSpread = 0, backbonePhiSpread = 0;
    int rows = 0, samples = 0;
};

Deviation cylinderDeviation(const CylinderScene& s, const FishboneGrid& g) {
    Deviation d;
    double phiMin = 1e9, phiMax = -1e9;
    for (int r = 0; r < g.rows; ++r) {
        double zMin = 1e9, zMax = -1e9;
        int n = 0;
        for (int c = 0; c < g.cols; ++c) {
            if (!g.isPresent(r, c)) continue;
            const std::optional<Eigen::Vector3d> p = s.surfacePoint(g.at(r, c));
            if (!p || p->z() < 0.3 || p->z() > 1.7) continue;
            // Near the silhouettes the analytic surface and the mesh's polygon part ways along the nearly
            // tangent viewing ray, so the analytic check means nothing there (the rib itself is fine).
            const Eigen::Vector3d toEye = s.camera.parallel
                                              ? Eigen::Vector3d(-s.camera.viewDirection())
                                              : Eigen::Vector3d((s.camera.eye - *p).normalized());
            if (Eigen::Vector3d(p->x(), p->y(), 0).dot(toEye) < 0.2) continue;
            zMin = std::min(zMin, p->z());
            zMax = std::max(zMax, p->z());
            ++n;
            if (c == g.backboneColumn) {
                const double phi = std::atan2(p->y(), p->x());
                phiMin = std::min(phiMin, phi);
                phiMax = std::max(phiMax, phi);
            }
        }
        if (n < 5) continue;
        ++d.rows;
        d.samples += n;
        d.ribZSpread = std::max(d.ribZSpread, zMax - zMin);
    }
    d.backbonePhiSpread = phiMax - phiMin;
    return d;
}

} // namespace

TEST(Fishbone, CylinderSideViewRibsFollowTheCircles) {
    for (bool parallel : {false, true}) {
        const CylinderScene s(parallel);
        FishboneOptions o;
        o.spacing = 4;
        // Backbone along the axis (min curvature), ribs around (max curvature).
        const FishboneGrid g = fss::automaticFishbone(s.minField, s.maxField, {100.5, 100.5}, o);
        const Deviation d = cylinderDeviation(s, g);
        const double pixel = s.camera.pixelFootprint({1, 0, 1});
        std::printf("[ cylinder fishbone, %s ] grid %d x %d, %d rows checked (%d samples): rib z spread "
                    "%.2e (%.3f px), backbone angle spread %.2e rad\n",
                    parallel ? "parallel" : "perspective", g.rows, g.cols, d.rows, d.samples, d.ribZSpread,
                    d.ribZSpread / pixel, d.backbonePhiSpread);
        EXPECT_GE(d.rows, 25);
        EXPECT_GE(g.cols, 35); // ribs reach around the visible half of the cylinder
        EXPECT_LT(d.ribZSpread, 0.1 * pixel);
        EXPECT_LT(d.backbonePhiSpread, 0.01);
    }
}

TEST(Fishbone, CylinderSwappedDirectionsAndKeyRibs) {
    const CylinderScene s(/*parallel=*/true);
    FishboneOptions o;
    o.spacing = 4;
    // Swapped: backbone around the cylinder (max), ribs along the axis (min): the backbone keeps z.
    const FishboneGrid swapped = fss::automaticFishbone(s.maxField, s.minField, {100.5, 90.5}, o);
    double zMin = 1e9, zMax = -1e9;
    for (int r = 0; r < swapped.rows; ++r)
        if (const auto p = s.surfacePoint(swapped.at(r, swapped.backboneColumn))) {
            zMin = std::min(zMin, p->z());
            zMax = std::max(zMax, p->z());
        }
    EXPECT_GE(swapped.rows, 35);
    EXPECT_LT(zMax - zMin, 0.01);

    // Key-rib mode: two traced key-ribs; in a parallel view every circle projects to the same curve, so
    // the blended ribs must lie on circles as well.
    const Backbone b = fss::traceBackbone(s.minField, {100.5, 100.5}, o);
    const std::size_t r1 = b.nearestSample({100, 60}), r2 = b.nearestSample({100, 140});
    ASSERT_LT(r1 + 5, r2);
    const FishboneGrid g = fss::keyRibFishbone(
        b, {KeyRib{r1, fss::traceRib(s.maxField, b, r1, o)}, KeyRib{r2, fss::traceRib(s.maxField, b, r2, o)}},
        o, s.camera.width, s.camera.height);
    const Deviation d = cylinderDeviation(s, g);
    const double pixel = s.camera.pixelFootprint({1, 0, 1});
    std::printf("[ cylinder key-ribs ] grid %d x %d, rib z spread %.3f px\n", g.rows, g.cols,
                d.ribZSpread / pixel);
    EXPECT_GE(d.rows, 20);
    EXPECT_LT(d.ribZSpread, 0.1 * pixel);
}

// Rib trimming (issue #20): ribs that converge stop where a neighbour comes closer than minRibGap·h, a rib
// that turns away from the backbone's normal stops at the turn; every half-rib stays a prefix.
TEST(Fishbone, TrimRibsStopsConvergingAndTurningRibs) {
    const double h = 1.0;
    fss::Backbone backbone;
    for (int i = 0; i <= 10; ++i)
        backbone.samples.emplace_back(double(i), 0.0); // along +x: the normal (positive side) is +y
    // Positive halves run from (i, 0) towards the common point (5, 8): they converge. Negative halves run
    // straight down (−y) for 3 edges and then turn 90° along +x (rib 4: 30°, below the bound).
    std::vector<fss::Rib> ribs;
    for (int i = 0; i <= 10; ++i) {
        fss::Rib rib;
        const Eigen::Vector2d p0(double(i), 0.0), d = (Eigen::Vector2d(5, 8) - p0).normalized();
        for (int k = 0; k <= 8; ++k)
            rib.positive.push_back(p0 + k * h * d);
        rib.negative.push_back(p0);
        for (int k = 1; k <= 3; ++k)
            rib.negative.push_back(p0 + Eigen::Vector2d(0, -k * h));
        const double turn = (i == 4 ? 30.0 : 90.0) * std::numbers::pi / 180.0;
        for (int k = 1; k <= 3; ++k)
            rib.negative.push_back(rib.negative[3] +
                                   k * h * Eigen::Vector2d(std::sin(turn), -std::cos(turn)));
        ribs.push_back(rib);
    }
    const fss::FishboneGrid untrimmed = fss::assembleFishboneGrid(backbone, ribs, h, 0, 0);
    auto closestNeighbours = [](const fss::FishboneGrid& g) {
        double d = std::numeric_limits<double>::infinity();
        for (int r = 0; r + 1 < g.rows; ++r)
            for (int c = 0; c < g.cols; ++c)
                if (g.isPresent(r, c) && g.isPresent(r + 1, c))
                    d = std::min(d, (g.at(r, c) - g.at(r + 1, c)).norm());
        return d;
    };
    ASSERT_LT(closestNeighbours(untrimmed), 0.5 * h);
    fss::FishboneOptions options;
    options.spacing = h;
    options.minRibGap = 0.5;
    options.maxRibTurnDeg = 60;
    fss::FishboneGrid g = untrimmed;
    const std::size_t removed = fss::trimRibs(g, backbone, options);
    EXPECT_GT(removed, 0u);
    EXPECT_GE(closestNeighbours(g), options.minRibGap * h);
    EXPECT_EQ(g.presentCount() + removed, untrimmed.presentCount());
    for (int r = 0; r < g.rows; ++r) {
        for (const int side : {1, -1}) { // prefixes: nothing present beyond an absent vertex
            bool ended = false;
            for (int c = g.backboneColumn; c >= 0 && c < g.cols; c += side) {
                if (ended) {
                    EXPECT_FALSE(g.isPresent(r, c)) << r << " " << c;
                }
                ended = ended || !g.isPresent(r, c);
            }
        }
        // The negative halves: 3 edges straight, then the 90° turn stops them (60° bound); rib 4 turns by
        // 30° only and keeps its 6 edges. Column backboneColumn − k is vertex k of the negative half.
        const int kept = r == 4 ? 6 : 3;
        for (int k = 1; k <= 6; ++k)
            EXPECT_EQ(g.isPresent(r, g.backboneColumn - k), k <= kept) << "rib " << r << " vertex " << k;
    }
    // Without bounds nothing changes.
    options.minRibGap = 0;
    options.maxRibTurnDeg = 180;
    fss::FishboneGrid same = untrimmed;
    EXPECT_EQ(fss::trimRibs(same, backbone, options), 0u);
    EXPECT_EQ(same.present, untrimmed.present);
}

// Backbone loops (issue #20, FishboneOptions::closeLoops): a streamline that runs 1.4 times round a circle
// of radius 20 px from its seed (both halves overlapping beyond the seed, as a traced backbone on a closed
// ridge does) becomes a closed backbone of round(2π·20/h) samples on the circle, starting at the seed, the
// closing edge as long as the others; a streamline that curls into a loop away from its seed (a "6") is cut
// before it comes back near itself; a straight one is only resampled.
TEST(Fishbone, BackboneLoopsCloseOrStop) {
    const double h = 3.0, radius = 20.0;
    const Eigen::Vector2d centre(50, 50);
    auto onCircle = [&](double a) {
        return Eigen::Vector2d(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
    };
    fss::Streamline circle;
    for (double a = -0.7 * 2 * kPi; a <= 0.7 * 2 * kPi + 1e-9; a += 0.02)
        circle.points.push_back(onCircle(a));
    circle.seedIndex = std::size_t(std::lround(0.7 * 2 * kPi / 0.02));
    const Backbone closed = fss::backboneFromStreamline(circle, h, true);
    ASSERT_TRUE(closed.closed);
    const std::size_t n = std::size_t(std::lround(2 * kPi * radius / h));
    EXPECT_EQ(closed.samples.size(), n);
    EXPECT_EQ(closed.seedIndex, 0u);
    EXPECT_LT((closed.samples.front() - circle.points[circle.seedIndex]).norm(), 1e-9);
    for (std::size_t i = 0; i < closed.samples.size(); ++i) {
        EXPECT_NEAR((closed.samples[i] - centre).norm(), radius, 0.05);
        const double edge = (closed.samples[(i + 1) % n] - closed.samples[i]).norm();
        EXPECT_NEAR(edge, 2 * radius * std::sin(kPi / double(n)), 0.05) << "edge " << i;
    }
    // Tangents wrap: at the seed the tangent is the circle's (perpendicular to the radius).
    EXPECT_NEAR(closed.tangent(0).dot((closed.samples[0] - centre).normalized()), 0.0, 1e-3);
    // Without closeLoops the same streamline is resampled as before: open, and overlapping itself.
    const Backbone open = fss::backboneFromStreamline(circle, h, false);
    EXPECT_FALSE(open.closed);
    EXPECT_GT(open.samples.size(), n + n / 4);

    // A "6": straight from the seed for 30 px, then once round a circle of radius 10 px and back over the
    // circle's first point. Cut before a sample within h/2 of a kept one three or more samples away.
    fss::Streamline six;
    for (double x = 0; x < 30; x += 0.25)
        six.points.emplace_back(x, 0.0);
    for (double a = 0; a <= 1.5 * 2 * kPi; a += 0.02)
        six.points.emplace_back(30 + 10 * std::sin(a), 10 - 10 * std::cos(a));
    six.seedIndex = 0;
    const Backbone cut = fss::backboneFromStreamline(six, h, true);
    EXPECT_FALSE(cut.closed);
    const Backbone uncut = fss::backboneFromStreamline(six, h, false);
    EXPECT_LT(cut.samples.size(), uncut.samples.size());
    auto closestNonAdjacent = [](const Polyline2& s) {
        double d = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < s.size(); ++i)
            for (std::size_t j = i + 3; j < s.size(); ++j)
                d = std::min(d, (s[i] - s[j]).norm());
        return d;
    };
    EXPECT_LT(closestNonAdjacent(uncut.samples), 0.5 * h);
    EXPECT_GE(closestNonAdjacent(cut.samples), 0.5 * h);
    // The loop is kept up to its last sample before the overlap: more than the straight part and most
    // of the circle's 2π·10/h ≈ 21 samples.
    EXPECT_GT(cut.samples.size(), 10u + 15u);
    // A straight streamline: the same samples with or without the loop test.
    fss::Streamline line;
    for (double x = -20; x <= 20; x += 0.25)
        line.points.emplace_back(x, 3.0);
    line.seedIndex = 80;
    const Backbone a = fss::backboneFromStreamline(line, h, true),
                   b = fss::backboneFromStreamline(line, h, false);
    EXPECT_EQ(a.samples, b.samples);
    EXPECT_EQ(a.seedIndex, b.seedIndex);
    EXPECT_FALSE(a.closed);
}

// FishboneOptions::maxRibAspect (issue #20): ribs that fan out from a curved backbone make quads wider than
// long (1:2 gives triangles of 26.6°): each half-rib stops before its first vertex whose quad with a
// neighbouring rib is longer one way than maxRibAspect times the other (here on the screen). The positive
// halves radiate from (5, −8) through the backbone samples (i, 0): at vertex k the neighbours are about
// h·(8 + k)/8 · 1/√(1 + ((i − 5)/8)²)… apart — checked against the bound directly.
TEST(Fishbone, RibsStopWhereTheirQuadsGetTooLong) {
    const double h = 1.0;
    fss::Backbone backbone;
    for (int i = 0; i <= 10; ++i)
        backbone.samples.emplace_back(double(i), 0.0);
    std::vector<fss::Rib> ribs;
    for (int i = 0; i <= 10; ++i) {
        fss::Rib rib;
        const Eigen::Vector2d p0(double(i), 0.0), d = (p0 - Eigen::Vector2d(5, -8)).normalized();
        for (int k = 0; k <= 12; ++k)
            rib.positive.push_back(p0 + k * h * d);
        rib.negative.push_back(p0);
        ribs.push_back(rib);
    }
    const fss::FishboneGrid untrimmed = fss::assembleFishboneGrid(backbone, ribs, h, 0, 0);
    fss::FishboneOptions options;
    options.spacing = h;
    options.maxRibAspect = 1.7;
    fss::FishboneGrid g = untrimmed;
    const std::size_t removed = fss::trimRibs(g, backbone, options);
    EXPECT_GT(removed, 0u);
    EXPECT_EQ(g.presentCount() + removed, untrimmed.presentCount());
    const int bc = g.backboneColumn;
    int longest = 0;
    for (int r = 0; r < g.rows; ++r) {
        int kept = 0;
        while (g.isPresent(r, bc + kept + 1))
            ++kept;
        // The last rib keeps its tail: its neighbour ended there already, no quad is left to judge.
        if (r + 1 < g.rows) longest = std::max(longest, kept);
        EXPECT_GE(kept, 4) << "rib " << r; // the quads near the backbone are nearly square
        for (int k = 1; k <= kept; ++k)
            for (const int n : {r - 1, r + 1}) {
                if (!g.isPresent(n, bc + k)) continue;
                const double gap = (g.at(n, bc + k) - g.at(r, bc + k)).norm();
                EXPECT_LE(gap, 1.7 * h) << "rib " << r << " vertex " << k;
            }
        // The first vertex beyond the kept ones (if the rib had one) breaks the bound with a neighbour.
        if (kept < 12) {
            double widest = 0;
            for (const int n : {r - 1, r + 1})
                if (untrimmed.isPresent(n, bc + kept + 1))
                    widest = std::max(
                        widest, (untrimmed.at(n, bc + kept + 1) - untrimmed.at(r, bc + kept + 1)).norm());
            EXPECT_GT(widest, 1.7 * h) << "rib " << r;
        }
    }
    EXPECT_LT(longest, 12);
    options.maxRibAspect = 0; // no bound: nothing changes
    fss::FishboneGrid same = untrimmed;
    EXPECT_EQ(fss::trimRibs(same, backbone, options), 0u);
}
