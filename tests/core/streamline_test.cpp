// 2D streamlines on synthetic line fields with known integral curves (concentric circles, a straight
// field, a sine field), with random sign flips; every stop criterion; resampling at constant spacing.
#include "fss/direction_field.h"
#include "fss/error.h"
#include "fss/streamline.h"
#include "test_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>
#include <random>

using fss::DirectionField;
using fss::Polyline2;
using fss::StreamlineOptions;
using fss::StreamlineStop;

namespace {

using fss::test::kPi;

// A field whose pixel centres carry dir(centre), each with a random sign (a line field, not a vector field).
DirectionField makeField(int w, int h, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& dir,
                         unsigned seed = 1, double anisotropy = 1.0) {
    DirectionField f(w, h);
    std::mt19937 rng(seed);
    std::bernoulli_distribution flip(0.5);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Eigen::Vector2d d = dir({x + 0.5, y + 0.5});
            f.setPixel(x, y, flip(rng) ? Eigen::Vector2d(-d) : d, anisotropy);
        }
    return f;
}

const Eigen::Vector2d kCentre(256.3, 255.8);
Eigen::Vector2d circleTangent(const Eigen::Vector2d& p) {
    const Eigen::Vector2d r = p - kCentre;
    return {-r.y(), r.x()};
}

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

double distanceToPolyline(const Polyline2& line, const Eigen::Vector2d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Eigen::Vector2d d = line[i + 1] - line[i];
        const double t = std::clamp((p - line[i]).dot(d) / d.squaredNorm(), 0.0, 1.0);
        best = std::min(best, (line[i] + t * d - p).norm());
    }
    return best;
}

} // namespace

// The streamline default (quarter-pixel steps) and the fishbone ribs' tracing (whole-pixel steps, 12° turns:
// FishboneParams::defaultTracing) must both hold 0.1 px over 200 px.
struct StepCase {
    const char* name;
    double step, maxTurnDeg;
};
constexpr StepCase kStepCases[] = {{"default step", 0.25, 10.0}, {"rib step 1 px", 1.0, 12.0}};

TEST(Streamline, ConcentricCirclesStayOnTheirCircle) {
    const DirectionField f = makeField(512, 512, circleTangent);
    for (const StepCase& c : kStepCases)
        for (double radius : {40.0, 100.0, 200.0}) {
            StreamlineOptions o;
            o.step = c.step;
            o.maxTurnDeg = c.maxTurnDeg;
            o.maxLength = 200;
            const Eigen::Vector2d seed = kCentre + Eigen::Vector2d(radius, 0.3);
            const fss::Streamline line = fss::traceStreamline(f, seed, o);
            EXPECT_EQ(line.forwardStop, StreamlineStop::MaxLength);
            EXPECT_EQ(line.backwardStop, StreamlineStop::MaxLength);
            EXPECT_NEAR(fss::polylineLength(line.forward()), 200.0, 1e-9);
            EXPECT_NEAR(fss::polylineLength(line.backward()), 200.0, 1e-9);
            const double r0 = (seed - kCentre).norm();
            double worst = 0;
            for (const Eigen::Vector2d& p : line.points)
                worst = std::max(worst, std::abs((p - kCentre).norm() - r0));
            std::printf("[ circle r=%.0f, %s ] %zu points over 2 x 200 px, worst radial deviation %.2e px\n",
                        radius, c.name, line.points.size(), worst);
            EXPECT_LT(worst, 0.1);
        }
}

TEST(Streamline, ClosedCircleStopsAtTheSeed) {
    const DirectionField f = makeField(512, 512, circleTangent);
    const Eigen::Vector2d seed = kCentre + Eigen::Vector2d(50, 0);
    const fss::Streamline line = fss::traceStreamline(f, seed);
    EXPECT_EQ(line.forwardStop, StreamlineStop::Closed);
    EXPECT_EQ(line.seedIndex, 0u);
    EXPECT_NEAR(fss::polylineLength(line.points), 2 * kPi * 50, 0.5);
}

TEST(Streamline, StraightFieldGivesStraightLine) {
    const Eigen::Vector2d d(std::cos(0.3), std::sin(0.3));
    const DirectionField f = makeField(300, 300, [&](const Eigen::Vector2d&) { return d; });
    const Eigen::Vector2d seed(20.2, 40.7);
    StreamlineOptions o;
    o.maxLength = 200;
    const fss::StreamlineHalf half = fss::traceStreamlineHalf(f, seed, d, o);
    EXPECT_EQ(half.stop, StreamlineStop::MaxLength);
    double worst = 0;
    for (const Eigen::Vector2d& p : half.points)
        worst = std::max(worst, std::abs(cross(p - seed, d)));
    EXPECT_LT(worst, 1e-9);
    EXPECT_NEAR((half.points.back() - seed).norm(), 200.0, 1e-9);
}

TEST(Streamline, SineFieldFollowsItsIntegralCurves) {
    // Integral curves of (1, y'(x)) with y = A sin(x/L) + C; gentle enough for 0.1 px over 200 px.
    const double A = 20, L = 40;
    auto dir = [&](const Eigen::Vector2d& p) { return Eigen::Vector2d(1, A / L * std::cos(p.x() / L)); };
    const DirectionField f = makeField(300, 200, dir, 5);
    const Eigen::Vector2d seed(40.0, 100.0);
    for (const StepCase& c : kStepCases) {
        StreamlineOptions o;
        o.step = c.step;
        o.maxTurnDeg = c.maxTurnDeg;
        o.maxLength = 400; // more than 200 px in x
        const fss::StreamlineHalf half = fss::traceStreamlineHalf(f, seed, {1, 0}, o);
        const double C = seed.y() - A * std::sin(seed.x() / L);
        double worst = 0, xmax = 0;
        for (const Eigen::Vector2d& p : half.points) {
            worst = std::max(worst, std::abs(p.y() - (A * std::sin(p.x() / L) + C)));
            xmax = std::max(xmax, p.x());
        }
        std::printf("[ sine field, %s ] x from %.1f to %.1f, worst deviation %.2e px\n", c.name, seed.x(),
                    xmax, worst);
        EXPECT_GE(xmax - seed.x(), 200.0);
        EXPECT_LT(worst, 0.1);
    }
}

TEST(Streamline, StopsAtBackgroundBorderRegionAnisotropyAndTurns) {
    auto right = [](const Eigen::Vector2d&) { return Eigen::Vector2d(1, 0); };
    StreamlineOptions o;
    // Background: a hole from x = 60 on.
    DirectionField f = makeField(100, 50, right);
    for (int y = 0; y < 50; ++y)
        for (int x = 60; x < 100; ++x)
            f.setPixel(x, y, Eigen::Vector2d::Zero());
    fss::StreamlineHalf h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::Background);
    EXPECT_LE(h.points.back().x(), 60.0);
    EXPECT_GE(h.points.back().x(), 60.0 - 2 * o.minStep);
    // Image border.
    f = makeField(100, 50, right);
    h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::ImageBorder);
    EXPECT_GE(h.points.back().x(), 100.0 - 2 * o.minStep);
    h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {-1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::ImageBorder);
    EXPECT_LE(h.points.back().x(), 2 * o.minStep);
    // Region mask: a disc of radius 20 around the seed.
    StreamlineOptions masked = o;
    masked.insideRegion = [](const Eigen::Vector2d& p) { return (p - Eigen::Vector2d(30, 25)).norm() <= 20; };
    h = fss::traceStreamlineHalf(f, {30, 25}, {1, 0}, masked);
    EXPECT_EQ(h.stop, StreamlineStop::OutsideRegion);
    EXPECT_NEAR(h.points.back().x(), 50.0, 2 * o.minStep);
    // Low anisotropy from pixel column 70 on: the bilinear anisotropy 1 − 0.99·(x − 69.5) falls below
    // 0.05 at x = 69.5 + 0.95/0.99.
    for (int y = 0; y < 50; ++y)
        for (int x = 70; x < 100; ++x)
            f.setPixel(x, y, {1, 0}, 0.01);
    h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::LowAnisotropy);
    EXPECT_LE(h.points.back().x(), 69.5 + 0.95 / 0.99);
    EXPECT_GT(h.points.back().x(), 69.5 + 0.95 / 0.99 - 2 * o.minStep);
    // Sharp turn: the field turns by 90° from x = 50 on (a seam).
    f = makeField(100, 50, [](const Eigen::Vector2d& p) {
        return p.x() < 50 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1);
    });
    h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::SharpTurn);
    EXPECT_NEAR(h.points.back().x(), 50.0, 1.0);
    // A looser turn limit follows the seam around the corner instead.
    StreamlineOptions loose = o;
    loose.maxTurnDeg = 90;
    h = fss::traceStreamlineHalf(f, {10.5, 25.5}, {1, 0}, loose);
    EXPECT_NE(h.stop, StreamlineStop::SharpTurn);
    EXPECT_GT(h.points.back().y(), 40.0);
}

TEST(Streamline, ContinuesStraightThroughIsotropicRegionsWhenAsked) {
    // Field along +x with a band 40 <= x < 60 of noise directions and anisotropy 0.01 (a flat region).
    DirectionField f = makeField(100, 50, [](const Eigen::Vector2d&) { return Eigen::Vector2d(1, 0.02); });
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angle(0, 2 * kPi);
    for (int y = 0; y < 50; ++y)
        for (int x = 40; x < 60; ++x) {
            const double a = angle(rng);
            f.setPixel(x, y, {std::cos(a), std::sin(a)}, 0.01);
        }
    StreamlineOptions o;
    fss::StreamlineHalf h = fss::traceStreamlineHalf(f, {10.5, 20.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::LowAnisotropy);
    EXPECT_LT(h.points.back().x(), 40.5); // bilinear anisotropy 1 → 0.01 between pixel centres 39.5 and 40.5
    o.lowAnisotropy = fss::LowAnisotropyPolicy::ContinueStraight;
    h = fss::traceStreamlineHalf(f, {10.5, 20.5}, {1, 0}, o);
    EXPECT_EQ(h.stop, StreamlineStop::ImageBorder);
    EXPECT_GT(h.points.back().x(), 100.0 - 2 * o.minStep);
    // The field's slope 0.02 everywhere outside the band, straight across it: one straight line (the noise
    // pixels carry the previous direction, so nothing leaks in).
    double worst = 0;
    for (const Eigen::Vector2d& p : h.points)
        worst = std::max(worst, std::abs(p.y() - (20.5 + 0.02 * (p.x() - 10.5))));
    std::printf("[ isotropic band ] crossed straight, worst deviation %.2e px\n", worst);
    EXPECT_LT(worst, 1e-9);
}

TEST(Streamline, BadSeedsAndOptionsThrow) {
    DirectionField f = makeField(50, 50, [](const Eigen::Vector2d&) { return Eigen::Vector2d(1, 0); });
    f.setPixel(5, 5, Eigen::Vector2d::Zero());
    EXPECT_THROW(fss::traceStreamline(f, {5.5, 5.5}), fss::InvalidInputError);
    EXPECT_THROW(fss::traceStreamline(f, {-1, 5.5}), fss::InvalidInputError);
    EXPECT_THROW(fss::traceStreamlineHalf(f, {20, 20}, {0, 0}), fss::InvalidInputError);
    StreamlineOptions o;
    o.step = 0;
    EXPECT_THROW(fss::traceStreamline(f, {20, 20}, o), fss::InvalidInputError);
    o = {};
    o.minStep = 1;
    EXPECT_THROW(fss::traceStreamline(f, {20, 20}, o), fss::InvalidInputError);
    o = {};
    o.maxLength = 0;
    EXPECT_THROW(fss::traceStreamline(f, {20, 20}, o), fss::InvalidInputError);
}

TEST(Streamline, PreferredDirectionChoosesForward) {
    const DirectionField f =
        makeField(100, 100, [](const Eigen::Vector2d&) { return Eigen::Vector2d(1, 0); });
    StreamlineOptions o;
    o.maxLength = 10;
    const fss::Streamline a = fss::traceStreamline(f, {50, 50}, o, {-1, 0.2});
    EXPECT_NEAR(a.points.back().x(), 40.0, 1e-9);
    EXPECT_NEAR(a.points.front().x(), 60.0, 1e-9);
    EXPECT_EQ(a.points[a.seedIndex], Eigen::Vector2d(50, 50));
}

TEST(Streamline, ResamplingKeepsSpacingExactly) {
    // A wiggly polyline with uneven segments, some duplicate points and sharp corners.
    Polyline2 line;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> step(0.0, 3.0), angle(-1.2, 1.2);
    Eigen::Vector2d p(0, 0);
    double heading = 0;
    for (int i = 0; i < 400; ++i) {
        line.push_back(p);
        if (i % 37 == 0) line.push_back(p); // duplicate
        heading += angle(rng);
        p += step(rng) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    }
    for (double h : {0.7, 2.5, 5.0}) {
        const Polyline2 r = fss::resampleAtSpacing(line, h);
        ASSERT_GT(r.size(), 10u);
        EXPECT_EQ(r.front(), line.front());
        double worst = 0, offLine = 0;
        for (std::size_t i = 1; i < r.size(); ++i)
            worst = std::max(worst, std::abs((r[i] - r[i - 1]).norm() - h));
        for (const Eigen::Vector2d& q : r)
            offLine = std::max(offLine, distanceToPolyline(line, q));
        EXPECT_LT(worst, 1e-9) << "h = " << h;
        EXPECT_LT(offLine, 1e-9) << "h = " << h;
    }
    // A straight line of length 10.3 at h = 1: 11 samples, the tail of 0.3 dropped.
    const Polyline2 r = fss::resampleAtSpacing(Polyline2{{0, 0}, {4, 0}, {10.3, 0}}, 1.0);
    ASSERT_EQ(r.size(), 11u);
    for (std::size_t i = 0; i < r.size(); ++i)
        EXPECT_NEAR(r[i].x(), double(i), 1e-12);
    EXPECT_TRUE(fss::resampleAtSpacing(Polyline2{}, 1.0).empty());
    EXPECT_THROW(fss::resampleAtSpacing(line, 0.0), fss::InvalidInputError);
}

TEST(Streamline, ResampledStreamlineKeepsTheSeed) {
    const DirectionField f = makeField(512, 512, circleTangent);
    StreamlineOptions o;
    o.maxLength = 100;
    const Eigen::Vector2d seed = kCentre + Eigen::Vector2d(0, 120);
    const fss::Streamline line = fss::resampleAtSpacing(fss::traceStreamline(f, seed, o), 4.0);
    EXPECT_EQ(line.points[line.seedIndex], seed);
    // 24 chords of 4 px on a circle of radius 120 span an arc of 96.004 px ≤ 100; 25 would need 100.005.
    EXPECT_EQ(line.seedIndex, 24u);
    EXPECT_EQ(line.points.size(), 49u);
    for (std::size_t i = 1; i < line.points.size(); ++i)
        EXPECT_NEAR((line.points[i] - line.points[i - 1]).norm(), 4.0, 1e-9);
}

// An attracting line (StreamlineOptions::attractor, the fishbone scan's crease following): the field is 3°
// off the line y = 40.5, so the plain streamline leaves it by L·tan 3°; with the attractor (the line within
// 1.5 pixels, along the heading) every point stays on it. A line across the heading does not attract.
TEST(Streamline, AttractorKeepsTheLineOnAnAttractingCurve) {
    const double tilt = 3 * kPi / 180;
    const Eigen::Vector2d d(std::cos(tilt), std::sin(tilt));
    const DirectionField f = makeField(300, 100, [&](const Eigen::Vector2d&) { return d; });
    const Eigen::Vector2d seed(20.0, 40.5);
    StreamlineOptions o;
    o.maxLength = 200;
    const fss::StreamlineHalf plain = fss::traceStreamlineHalf(f, seed, d, o);
    EXPECT_NEAR(plain.points.back().y() - 40.5, 200 * std::sin(tilt), 1e-6);

    auto alongLine = [](const Eigen::Vector2d& q,
                        const Eigen::Vector2d& heading) -> std::optional<Eigen::Vector2d> {
        if (std::abs(q.y() - 40.5) > 1.5 || std::abs(heading.x()) < std::cos(kPi / 6)) return std::nullopt;
        return Eigen::Vector2d(q.x(), 40.5);
    };
    o.attractor = alongLine;
    const fss::StreamlineHalf held = fss::traceStreamlineHalf(f, seed, d, o);
    EXPECT_EQ(held.stop, StreamlineStop::MaxLength);
    ASSERT_GT(held.points.size(), 300u);
    double worst = 0;
    for (std::size_t i = 0; i + 1 < held.points.size(); ++i) // the last step (to maxLength) is not moved
        worst = std::max(worst, std::abs(held.points[i].y() - 40.5));
    EXPECT_LT(worst, 1e-12);
    EXPECT_NEAR(held.length, 200.0, 1e-9);
    EXPECT_GT(held.points.back().x(), 200.0 + seed.x() - 0.1);

    // A field across the line: the attractor declines (heading check), the line crosses it unchanged.
    const DirectionField across =
        makeField(300, 100, [](const Eigen::Vector2d&) { return Eigen::Vector2d(0, 1); });
    o.maxLength = 50;
    const fss::StreamlineHalf crossing =
        fss::traceStreamlineHalf(across, Eigen::Vector2d(100, 20), {0, 1}, o);
    EXPECT_NEAR(crossing.points.back().y(), 70.0, 1e-9);
    EXPECT_NEAR(crossing.points.back().x(), 100.0, 1e-9);
}

// Two halves traced in lockstep are exactly the halves traced one after the other, whatever stops them:
// on the circle field, two seeds with different lengths and stops (image border, closed circle, max length,
// background of a cut-out).
TEST(Streamline, TwoHalvesInLockstepEqualTwoSingleHalves) {
    DirectionField f = makeField(512, 512, circleTangent, 3);
    for (int y = 300; y < 340; ++y) // a hole the circles through it stop at
        for (int x = 100; x < 140; ++x)
            f.setPixel(x, y, Eigen::Vector2d::Zero(), 0.0);
    fss::StreamlineOptions o;
    o.step = 1.0;
    o.maxTurnDeg = 12.0;
    const std::pair<fss::HalfStart, fss::HalfStart> cases[] = {
        {{{256.0, 50.0}, {1, 0}}, {{256.0, 50.0}, {-1, 0}}},   // radius 206: passes the hole
        {{{300.0, 255.0}, {0, 1}}, {{20.0, 260.0}, {0, -1}}},  // radius 44 (closes), radius 236 (border)
        {{{256.0, 150.0}, {-1, 0}}, {{256.0, 200.0}, {1, 0}}}, // different radii, both closed circles
    };
    for (double maxLength : {std::numeric_limits<double>::infinity(), 150.0})
        for (const auto& [a, b] : cases) {
            o.maxLength = maxLength;
            const std::vector<fss::StreamlineHalf> lockstep = fss::traceHalvesInLockstep(f, {a, b}, o);
            ASSERT_EQ(lockstep.size(), 2u);
            const fss::StreamlineHalf &la = lockstep[0], &lb = lockstep[1];
            const fss::StreamlineHalf sa = fss::traceStreamlineHalf(f, a.seed, a.initialDirection, o);
            const fss::StreamlineHalf sb = fss::traceStreamlineHalf(f, b.seed, b.initialDirection, o);
            for (const auto& [lock, single] : {std::pair{&la, &sa}, std::pair{&lb, &sb}}) {
                EXPECT_EQ(lock->stop, single->stop);
                EXPECT_EQ(lock->length, single->length);
                ASSERT_EQ(lock->points.size(), single->points.size());
                EXPECT_GT(lock->points.size(), 20u);
                for (std::size_t i = 0; i < lock->points.size(); ++i)
                    ASSERT_EQ(lock->points[i], single->points[i]) << "point " << i;
            }
        }
}
