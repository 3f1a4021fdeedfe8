// Per-pixel direction field: cylinder side view against the projected analytic principal directions,
// sphere anisotropy, bilinear sampling of a line field, bad inputs.
#include "fss/curvature.h"
#include "fss/direction_field.h"
#include "fss/error.h"
#include "fss/shapes.h"

#include "brute_force_raster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <vector>

using fss::DirectionField;
using fss::PrincipalDirection;

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

double lineAngleDeg(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * kDeg;
}

double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
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
    cam.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1.4, -1.4, -0.4), Eigen::Vector3d(1.4, 1.4, 0.4)));
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
