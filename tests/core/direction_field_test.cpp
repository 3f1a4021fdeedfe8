// Per-pixel direction field: cylinder side view against the projected analytic principal directions,
// sphere anisotropy, bilinear sampling of a line field, bad inputs.
#include "fss/curvature.h"
#include "fss/direction_field.h"
#include "fss/error.h"
#include "fss/shapes.h"
#include "test_math.h"

#include "brute_force_raster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

using fss::DirectionField;
using fss::PrincipalDirection;

namespace {

using fss::test::kDeg;
using fss::test::median;

double lineAngleDeg(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * kDeg;
}

fss::Camera sideCamera(bool parallel) {
    fss::Camera c;
    c.eye = {5, 0.3, 1.2};
    c.focal = {0, 0, 1};
    c.up = {0, 0, 1};
    c.parallel = parallel;
    c.viewAngleDeg = 30;
    c.parallelScale = 1.3;
    c.width = 200;
    c.height = 200;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 2)));
    return c;
}

// Screen direction of the world direction d at p (the same finite difference as the field, done here
// on the analytic point and direction).
Eigen::Vector2d projectDirection(const fss::Camera& c, const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
    const double eps = 1e-4 * c.pixelFootprint(p);
    const Eigen::Vector3d a = c.project(p - eps * d), b = c.project(p + eps * d);
    return Eigen::Vector2d(b.x() - a.x(), b.y() - a.y()).normalized();
}

// First intersection of the pixel ray with the infinite cylinder x² + y² = 1.
std::optional<Eigen::Vector3d> hitCylinder(const fss::Ray& ray) {
    const Eigen::Vector2d o = ray.origin.head<2>(), d = ray.direction.head<2>();
    const double A = d.squaredNorm(), B = o.dot(d), C = o.squaredNorm() - 1;
    const double disc = B * B - A * C;
    if (disc < 0 || A == 0) return std::nullopt;
    const double t = (-B - std::sqrt(disc)) / A;
    if (t < 0) return std::nullopt;
    return ray.origin + t * ray.direction;
}

struct SideViewErrors {
    std::vector<double> maxErr, minErr, aniso;
};

SideViewErrors cylinderSideView(bool parallel) {
    const fss::Mesh mesh = fss::shapes::cylinder(128, 32, 1.0, 2.0, /*capped=*/true);
    const fss::CurvatureField curv = fss::estimateCurvature(mesh);
    const fss::Camera cam = sideCamera(parallel);
    const fss::FrameBuffers fb = fss::test::bruteForceRaster(mesh, cam);
    EXPECT_GT(fb.coveredCount(), 10000u);
    const DirectionField maxField = fss::computeDirectionField(mesh, curv, fb, {PrincipalDirection::Max});
    const DirectionField minField = fss::computeDirectionField(mesh, curv, fb, {PrincipalDirection::Min});
    EXPECT_EQ(maxField.width, cam.width);
    SideViewErrors e;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            EXPECT_EQ(maxField.isValid(x, y), fb.covered(x, y));
            if (!fb.covered(x, y)) continue;
            const std::optional<Eigen::Vector3d> p = hitCylinder(cam.ray(x + 0.5, y + 0.5));
            // Side of the cylinder, away from the rims (the caps' creases) and the silhouettes.
            if (!p || p->z() < 0.25 || p->z() > 1.75) continue;
            const Eigen::Vector3d toEye = (cam.eye - *p).normalized(), normal(p->x(), p->y(), 0);
            if (normal.dot(parallel ? Eigen::Vector3d(-cam.viewDirection()) : toEye) < 0.2) continue;
            const Eigen::Vector3d around(-p->y(), p->x(), 0), axis(0, 0, 1);
            e.maxErr.push_back(
                lineAngleDeg(maxField.direction[maxField.index(x, y)], projectDirection(cam, *p, around)));
            e.minErr.push_back(
                lineAngleDeg(minField.direction[minField.index(x, y)], projectDirection(cam, *p, axis)));
            e.aniso.push_back(maxField.anisotropy[maxField.index(x, y)]);
        }
    std::printf("[ cylinder side view, %s ] %zu pixels: max dir median %.4f deg, worst %.4f deg; min dir "
                "median %.4f deg, worst %.4f deg; median anisotropy %.4f\n",
                parallel ? "parallel" : "perspective", e.maxErr.size(), median(e.maxErr),
                *std::max_element(e.maxErr.begin(), e.maxErr.end()), median(e.minErr),
                *std::max_element(e.minErr.begin(), e.minErr.end()), median(e.aniso));
    return e;
}

} // namespace

TEST(DirectionField, CylinderSideViewMatchesProjectedAnalyticDirections) {
    for (bool parallel : {false, true}) {
        const SideViewErrors e = cylinderSideView(parallel);
        ASSERT_GT(e.maxErr.size(), 5000u);
        EXPECT_LE(median(e.maxErr), 0.1);
        EXPECT_LE(median(e.minErr), 0.1);
        EXPECT_LE(*std::max_element(e.maxErr.begin(), e.maxErr.end()), 0.5);
        EXPECT_LE(*std::max_element(e.minErr.begin(), e.minErr.end()), 0.5);
        EXPECT_GE(median(e.aniso), 0.95);
    }
}

TEST(DirectionField, SphereHasLowAnisotropy) {
    const fss::Mesh mesh = fss::shapes::icosphere(4);
    const fss::CurvatureField curv = fss::estimateCurvature(mesh);
    fss::Camera cam;
    cam.eye = {0, 0, 4};
    cam.width = cam.height = 96;
    cam.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
    const fss::FrameBuffers fb = fss::test::bruteForceRaster(mesh, cam);
    const DirectionField f = fss::computeDirectionField(mesh, curv, fb);
    ASSERT_GT(f.validCount(), 3000u);
    std::vector<double> a;
    for (std::size_t i = 0; i < f.valid.size(); ++i)
        if (f.valid[i]) a.push_back(f.anisotropy[i]);
    EXPECT_LT(median(a), 0.02);
    EXPECT_LT(*std::max_element(a.begin(), a.end()), 0.05);
}

TEST(DirectionField, SampleAlignsSignsAndInterpolatesBilinearly) {
    DirectionField f(4, 3);
    const double a0 = 0.2, a1 = 0.6;
    // Column 0 at angle a0, column 1 at angle a1 but stored with a flipped sign: a line field.
    for (int y = 0; y < 3; ++y) {
        f.setPixel(0, y, {std::cos(a0), std::sin(a0)}, 1.0);
        f.setPixel(1, y, {-std::cos(a1), -std::sin(a1)}, 0.5);
    }
    EXPECT_EQ(f.validCount(), 6u);
    // At a pixel centre: that pixel's direction, sign from the reference.
    auto s = f.sample({0.5, 1.5}, {-1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->direction.x(), -std::cos(a0), 1e-15);
    EXPECT_NEAR(s->direction.y(), -std::sin(a0), 1e-15);
    // Half way between the centres of columns 0 and 1: bilinear weights ½, ½ times the anisotropies 1 and
    // ½ on the aligned vectors; the anisotropy itself is the plain mean.
    const Eigen::Vector2d d0(std::cos(a0), std::sin(a0)), d1(std::cos(a1), std::sin(a1));
    s = f.sample({1.0, 1.5}, {1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR((s->direction - (0.5 * d0 + 0.25 * d1).normalized()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(s->anisotropy, 0.75, 1e-7);
    // A quarter of the way: bilinear weights ¾, ¼.
    s = f.sample({0.75, 1.5}, {1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR((s->direction - (0.75 * d0 + 0.125 * d1).normalized()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(s->anisotropy, 0.875, 1e-7);
    // Equal anisotropies: the plain normalised average, the bisector half way.
    DirectionField g(2, 1);
    g.setPixel(0, 0, d0, 0.3);
    g.setPixel(1, 0, -d1, 0.3);
    s = g.sample({1.0, 0.5}, {1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR(std::atan2(s->direction.y(), s->direction.x()), 0.5 * (a0 + a1), 1e-12);
    // Anisotropy 0 everywhere (a plane): still a plain average, never undefined.
    g.setPixel(0, 0, d0, 0.0);
    g.setPixel(1, 0, -d1, 0.0);
    s = g.sample({1.0, 0.5}, {1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR(std::atan2(s->direction.y(), s->direction.x()), 0.5 * (a0 + a1), 1e-12);
    EXPECT_EQ(s->anisotropy, 0.0);
    // Invalid neighbours (column 2) are left out: between columns 1 and 2 the result is column 1's.
    s = f.sample({1.9, 1.5}, {1, 0});
    ASSERT_TRUE(s);
    EXPECT_NEAR(std::atan2(s->direction.y(), s->direction.x()), a1, 1e-12);
    // The containing pixel must be valid; outside the image nothing.
    EXPECT_FALSE(f.sample({2.1, 1.5}, {1, 0}));
    EXPECT_FALSE(f.sample({-0.1, 1.5}, {1, 0}));
    EXPECT_FALSE(f.sample({0.5, 3.1}, {1, 0}));
    // Image border positions are inside.
    EXPECT_TRUE(f.sample({0.0, 0.0}, {1, 0}));
    EXPECT_TRUE(f.sample({0.5, 3.0}, {1, 0}));
    // setPixel with a zero vector invalidates.
    f.setPixel(0, 0, Eigen::Vector2d::Zero());
    EXPECT_FALSE(f.isValid(0, 0));
}

TEST(DirectionField, BadInputsThrow) {
    const fss::Mesh mesh = fss::shapes::icosphere(1);
    const fss::CurvatureField curv = fss::estimateCurvature(mesh);
    fss::Camera cam;
    cam.eye = {0, 0, 4};
    cam.width = cam.height = 32;
    fss::FrameBuffers fb = fss::test::bruteForceRaster(mesh, cam);
    EXPECT_NO_THROW(fss::computeDirectionField(mesh, curv, fb));
    // Curvature of another mesh.
    const fss::CurvatureField other = fss::estimateCurvature(fss::shapes::icosphere(2));
    EXPECT_THROW(fss::computeDirectionField(mesh, other, fb), fss::InvalidInputError);
    // A face id that the mesh does not have.
    fss::FrameBuffers bad = fb;
    bad.faceId[bad.index(16, 16)] = 100000;
    EXPECT_THROW(fss::computeDirectionField(mesh, curv, bad), fss::InvalidInputError);
    // Buffers of the wrong size.
    bad = fb;
    bad.depth.pop_back();
    EXPECT_THROW(fss::computeDirectionField(mesh, curv, bad), fss::InvalidInputError);
    EXPECT_THROW(DirectionField(-1, 3), fss::InvalidInputError);
}

TEST(DirectionField, BothFieldsInOnePassEqualTwoSingleFields) {
    const fss::Mesh mesh = fss::shapes::torus(60, 30, 1.0, 0.35);
    const fss::CurvatureField curv = fss::estimateCurvature(mesh);
    fss::Camera cam;
    cam.eye = {2.5, 1.0, 3.0};
    cam.width = cam.height = 96;
    cam.fitClippingRange(
        Eigen::AlignedBox3d(Eigen::Vector3d(-1.4, -1.4, -0.4), Eigen::Vector3d(1.4, 1.4, 0.4)));
    const fss::FrameBuffers fb = fss::test::bruteForceRaster(mesh, cam);
    const fss::DirectionFieldPair both = fss::computeDirectionFields(mesh, curv, fb);
    const DirectionField mn = fss::computeDirectionField(mesh, curv, fb, {fss::PrincipalDirection::Min});
    const DirectionField mx = fss::computeDirectionField(mesh, curv, fb, {fss::PrincipalDirection::Max});
    ASSERT_GT(mn.validCount(), 2000u);
    EXPECT_EQ(both.min.valid, mn.valid);
    EXPECT_EQ(both.max.valid, mx.valid);
    EXPECT_EQ(both.min.anisotropy, mn.anisotropy);
    EXPECT_EQ(both.max.anisotropy, mx.anisotropy);
    for (std::size_t i = 0; i < mn.direction.size(); ++i) {
        ASSERT_EQ(both.min.direction[i], mn.direction[i]) << i;
        ASSERT_EQ(both.max.direction[i], mx.direction[i]) << i;
    }
}

namespace {

// A torus seen obliquely (both principal directions well defined almost everywhere) with its buffers.
struct TorusScene {
    fss::Mesh mesh = fss::shapes::torus(60, 30, 1.0, 0.35);
    fss::CurvatureField curv = fss::estimateCurvature(mesh);
    fss::FrameBuffers fb;
    TorusScene() {
        fss::Camera cam;
        cam.eye = {2.5, 1.0, 3.0};
        cam.width = 90; // neither divisible by the tile sizes below nor square
        cam.height = 77;
        cam.fitClippingRange(
            Eigen::AlignedBox3d(Eigen::Vector3d(-1.4, -1.4, -0.4), Eigen::Vector3d(1.4, 1.4, 0.4)));
        fb = fss::test::bruteForceRaster(mesh, cam);
    }
};

// Sub-pixel positions spread over the image, including its border and corners.
std::vector<Eigen::Vector2d> probePositions(int w, int h) {
    std::vector<Eigen::Vector2d> out = {{0, 0}, {double(w), double(h)}, {double(w), 0}, {0.5, double(h)}};
    std::uint32_t state = 12345;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return double(state >> 8) / double(1u << 24);
    };
    for (int i = 0; i < 3000; ++i)
        out.emplace_back(next() * w, next() * h);
    return out;
}

void expectSameSample(const std::optional<fss::DirectionSample>& a,
                      const std::optional<fss::DirectionSample>& b, const Eigen::Vector2d& p) {
    ASSERT_EQ(a.has_value(), b.has_value()) << p.transpose();
    if (!a) return;
    ASSERT_EQ(a->direction, b->direction) << p.transpose();
    ASSERT_EQ(a->anisotropy, b->anisotropy) << p.transpose();
}

} // namespace

TEST(DirectionField, LazyFieldEqualsStoredFieldBitForBit) {
    const TorusScene s;
    for (PrincipalDirection dir : {PrincipalDirection::Min, PrincipalDirection::Max}) {
        const DirectionField stored = fss::computeDirectionField(s.mesh, s.curv, s.fb, {dir});
        ASSERT_GT(stored.validCount(), 2000u);
        for (int tile : {1, 7, 16, 500}) {
            SCOPED_TRACE("tile " + std::to_string(tile));
            // Samples first (the tiles are computed by sample), then every pixel.
            const DirectionField lazy = fss::lazyDirectionField(s.mesh, s.curv, s.fb, {dir, tile});
            EXPECT_TRUE(lazy.isLazy());
            EXPECT_EQ(lazy.computedPixels(), 0u);
            EXPECT_EQ(lazy.width, stored.width);
            EXPECT_EQ(lazy.height, stored.height);
            for (const Eigen::Vector2d& p : probePositions(lazy.width, lazy.height)) {
                const Eigen::Vector2d ref(std::cos(p.x()), std::sin(p.y()));
                expectSameSample(lazy.sample(p, ref), stored.sample(p, ref), p);
                expectSameSample(lazy.sample(p, ref, 0.3), stored.sample(p, ref, 0.3), p);
            }
            for (int y = 0; y < lazy.height; ++y)
                for (int x = 0; x < lazy.width; ++x) {
                    const fss::DirectionPixel px = lazy.pixel(x, y);
                    const std::size_t i = stored.index(x, y);
                    ASSERT_EQ(px.valid, stored.valid[i] != 0) << x << "," << y;
                    ASSERT_EQ(px.direction, stored.direction[i]) << x << "," << y;
                    ASSERT_EQ(px.anisotropy, stored.anisotropy[i]) << x << "," << y;
                    ASSERT_EQ(lazy.isValid(x, y), stored.isValid(x, y));
                }
            EXPECT_EQ(lazy.computedPixels(), std::size_t(lazy.width) * std::size_t(lazy.height));
            EXPECT_EQ(lazy.validCount(), stored.validCount());
        }
    }
}

TEST(DirectionField, LazyFieldComputesOnlyTheTilesItIsAskedFor) {
    const TorusScene s;
    const DirectionField stored = fss::computeDirectionField(s.mesh, s.curv, s.fb, {PrincipalDirection::Min});
    // Tile corners (8k, 8k) whose pixel is on the torus: the first and the last, at least two tiles apart.
    std::vector<int> onSurface;
    for (int k = 1; k < 9; ++k)
        if (stored.isValid(8 * k, 8 * k)) onSurface.push_back(k);
    ASSERT_GE(onSurface.size(), 2u);
    const int corner = onSurface.front(), far = onSurface.back();
    ASSERT_GE(far - corner, 2);
    const DirectionField lazy = fss::lazyDirectionField(s.mesh, s.curv, s.fb, {PrincipalDirection::Min, 8});
    // A sample in the middle of a tile touches that tile only.
    (void)lazy.sample({8.0 * far + 4.5, 8.0 * far + 4.5}, {1, 0});
    EXPECT_EQ(lazy.computedPixels(), 64u);
    // On a tile corner on the surface: the four tiles around it.
    EXPECT_TRUE(lazy.sample({8.0 * corner, 8.0 * corner}, {1, 0}));
    EXPECT_EQ(lazy.computedPixels(), 5u * 64u);
    // A bottom-right border tile is smaller (90 = 11·8 + 2, 77 = 9·8 + 5).
    (void)lazy.isValid(89, 76);
    EXPECT_EQ(lazy.computedPixels(), 5u * 64u + 2u * 5u);
    // A copy shares the computed tiles.
    const DirectionField copy = lazy;
    EXPECT_EQ(copy.computedPixels(), lazy.computedPixels());
}

TEST(DirectionField, LazyFieldIsThreadSafe) {
    const TorusScene s;
    const DirectionField stored = fss::computeDirectionField(s.mesh, s.curv, s.fb, {PrincipalDirection::Max});
    const DirectionField lazy = fss::lazyDirectionField(s.mesh, s.curv, s.fb, {PrincipalDirection::Max, 4});
    const std::vector<Eigen::Vector2d> probes = probePositions(lazy.width, lazy.height);
    // Every thread samples the same positions in the same order: they race for the same tiles.
    std::vector<std::vector<std::optional<fss::DirectionSample>>> results(4);
    std::vector<std::thread> threads;
    for (std::size_t t = 0; t < results.size(); ++t)
        threads.emplace_back([&, t] {
            for (const Eigen::Vector2d& p : probes)
                results[t].push_back(lazy.sample(p, {1, 1}));
        });
    for (std::thread& t : threads)
        t.join();
    for (const auto& r : results)
        for (std::size_t i = 0; i < probes.size(); ++i)
            expectSameSample(r[i], stored.sample(probes[i], {1, 1}), probes[i]);
}

TEST(DirectionField, LazyFieldBadInputsThrow) {
    const TorusScene s;
    EXPECT_THROW(fss::lazyDirectionField(s.mesh, s.curv, s.fb, {PrincipalDirection::Min, 0}),
                 fss::InvalidInputError);
    const fss::CurvatureField other = fss::estimateCurvature(fss::shapes::icosphere(2));
    EXPECT_THROW(fss::lazyDirectionField(s.mesh, other, s.fb), fss::InvalidInputError);
    fss::FrameBuffers bad = s.fb;
    bad.depth.pop_back();
    EXPECT_THROW(fss::lazyDirectionField(s.mesh, s.curv, bad), fss::InvalidInputError);
    // A bad face id throws when its tile is computed, not before, and again on the next access.
    bad = s.fb;
    bad.faceId[bad.index(60, 50)] = 100000;
    const DirectionField lazy = fss::lazyDirectionField(s.mesh, s.curv, bad, {PrincipalDirection::Min, 8});
    EXPECT_NO_THROW((void)lazy.pixel(10, 10));
    EXPECT_THROW((void)lazy.pixel(61, 51), fss::InvalidInputError);
    EXPECT_THROW((void)lazy.sample({60.5, 50.5}, {1, 0}), fss::InvalidInputError);
    // Lazy pixels are computed, not set.
    DirectionField copy = lazy;
    EXPECT_THROW(copy.setPixel(1, 1, {1, 0}), fss::InvalidInputError);
}
