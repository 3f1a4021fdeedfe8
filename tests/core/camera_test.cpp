// Camera maths: matrices against closed forms, project/unproject round trips, rays, footprints,
// standard views and validation of bad parameters.
#include "fss/camera.h"
#include "fss/camera_projector.h"
#include "fss/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using fss::Camera;

namespace {

Camera makeCamera(bool parallel) {
    Camera c;
    c.eye = {3, 2, 5};
    c.focal = {0.5, -0.2, 0.1};
    c.up = {0, 0, 1};
    c.parallel = parallel;
    c.viewAngleDeg = 40;
    c.parallelScale = 1.7;
    c.nearPlane = 0.5;
    c.farPlane = 20;
    c.width = 320;
    c.height = 200;
    return c;
}

} // namespace

TEST(Camera, ViewMatrixMapsEyeToOriginAndFocalToNegativeZ) {
    const Camera c = makeCamera(false);
    const Eigen::Matrix4d v = c.viewMatrix();
    const Eigen::Vector4d e = v * c.eye.homogeneous();
    EXPECT_NEAR(e.head<3>().norm(), 0.0, 1e-12);
    const Eigen::Vector4d f = v * c.focal.homogeneous();
    const double dist = (c.focal - c.eye).norm();
    EXPECT_NEAR(f.x(), 0.0, 1e-12);
    EXPECT_NEAR(f.y(), 0.0, 1e-12);
    EXPECT_NEAR(f.z(), -dist, 1e-12);
    // Rotation part is orthonormal.
    const Eigen::Matrix3d r = v.block<3, 3>(0, 0);
    EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
}

TEST(Camera, PerspectiveFrustumEdgesMapToImageBorders) {
    Camera c = makeCamera(false);
    // A point on the upper frustum edge at depth d: y = d·tan(angle/2) in eye coordinates.
    const double d = 7.0, t = std::tan(0.5 * c.viewAngleDeg * std::numbers::pi / 180.0);
    const Eigen::Matrix4d vinv = c.viewMatrix().inverse();
    const Eigen::Vector3d topCentre = (vinv * Eigen::Vector4d(0, d * t, -d, 1)).head<3>();
    const Eigen::Vector3d s = c.project(topCentre);
    EXPECT_NEAR(s.x(), c.width / 2.0, 1e-9);
    EXPECT_NEAR(s.y(), 0.0, 1e-9);
    const Eigen::Vector3d rightCentre = (vinv * Eigen::Vector4d(d * t * c.aspect(), 0, -d, 1)).head<3>();
    const Eigen::Vector3d s2 = c.project(rightCentre);
    EXPECT_NEAR(s2.x(), c.width, 1e-9);
    EXPECT_NEAR(s2.y(), c.height / 2.0, 1e-9);
    // Near plane → depth 0, far plane → depth 1.
    EXPECT_NEAR(c.project((vinv * Eigen::Vector4d(0, 0, -c.nearPlane, 1)).head<3>()).z(), 0.0, 1e-12);
    EXPECT_NEAR(c.project((vinv * Eigen::Vector4d(0, 0, -c.farPlane, 1)).head<3>()).z(), 1.0, 1e-9);
}

TEST(Camera, ParallelProjectionMapsScaleToBorders) {
    const Camera c = makeCamera(true);
    const Eigen::Matrix4d vinv = c.viewMatrix().inverse();
    const Eigen::Vector3d p =
        (vinv * Eigen::Vector4d(c.parallelScale * c.aspect(), -c.parallelScale, -3, 1)).head<3>();
    const Eigen::Vector3d s = c.project(p);
    EXPECT_NEAR(s.x(), c.width, 1e-9);
    EXPECT_NEAR(s.y(), c.height, 1e-9);
    EXPECT_NEAR(c.pixelFootprint(p), 2 * c.parallelScale / c.height, 1e-15);
}

TEST(Camera, UnprojectInvertsProjectAtRandomPoints) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (bool parallel : {false, true}) {
        const Camera c = makeCamera(parallel);
        for (int i = 0; i < 1000; ++i) {
            const double sx = u(rng) * c.width, sy = u(rng) * c.height, z = 0.05 + 0.9 * u(rng);
            const Eigen::Vector3d w = c.unproject(sx, sy, z);
            const Eigen::Vector3d back = c.project(w);
            EXPECT_NEAR(back.x(), sx, 1e-7);
            EXPECT_NEAR(back.y(), sy, 1e-7);
            EXPECT_NEAR(back.z(), z, 1e-9);
        }
    }
}

TEST(Camera, RaysPassThroughTheirPixel) {
    for (bool parallel : {false, true}) {
        const Camera c = makeCamera(parallel);
        const fss::Ray r = c.ray(100.25, 37.5);
        EXPECT_NEAR(r.direction.norm(), 1.0, 1e-12);
        if (!parallel) {
            EXPECT_TRUE(r.origin.isApprox(c.eye));
        } else {
            EXPECT_NEAR(r.direction.dot(c.viewDirection()), 1.0, 1e-12);
        }
        for (double t : {1.0, 4.0, 9.0}) {
            const Eigen::Vector3d s = c.project(r.origin + t * r.direction);
            EXPECT_NEAR(s.x(), 100.25, 1e-7);
            EXPECT_NEAR(s.y(), 37.5, 1e-7);
        }
    }
}

TEST(Camera, PixelFootprintMatchesNeighbourUnprojection) {
    const Camera c = makeCamera(false);
    const Eigen::Vector3d p = c.focal;
    const double z = c.project(p).z();
    const Eigen::Vector3d s = c.project(p);
    const Eigen::Vector3d a = c.unproject(s.x(), s.y(), z), b = c.unproject(s.x() + 1, s.y(), z);
    // Neighbouring pixels at the same window depth are one footprint apart (up to the off-axis tilt).
    EXPECT_NEAR((a - b).norm() / c.pixelFootprint(p), 1.0, 1e-6);
}

TEST(Camera, StandardViewsSeeTheWholeBox) {
    const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, 2, 0), Eigen::Vector3d(3, 4, 1));
    for (auto view :
         {fss::StandardView::Iso, fss::StandardView::PosX, fss::StandardView::NegX, fss::StandardView::PosY,
          fss::StandardView::NegY, fss::StandardView::PosZ, fss::StandardView::NegZ}) {
        for (bool parallel : {false, true}) {
            for (auto [w, h] : {std::pair{256, 256}, std::pair{400, 100}, std::pair{100, 400}}) {
                const Camera c = Camera::standardView(view, box, w, h, parallel);
                EXPECT_EQ(fss::parseStandardView(fss::standardViewName(view)), view);
                for (int i = 0; i < 8; ++i) {
                    const Eigen::Vector3d s =
                        c.project(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)));
                    EXPECT_GE(s.x(), 0);
                    EXPECT_LE(s.x(), w);
                    EXPECT_GE(s.y(), 0);
                    EXPECT_LE(s.y(), h);
                    EXPECT_GT(s.z(), 0);
                    EXPECT_LT(s.z(), 1);
                }
            }
        }
    }
    // +x looks from +x towards -x.
    const Camera c = Camera::standardView(fss::StandardView::PosX, box, 64, 64);
    EXPECT_TRUE(c.viewDirection().isApprox(Eigen::Vector3d(-1, 0, 0)));
}

TEST(Camera, ZoomHalvesTheVisibleExtent) {
    Camera c = makeCamera(false);
    const double before = c.pixelFootprint(c.focal);
    c.zoom(2);
    EXPECT_NEAR(c.pixelFootprint(c.focal), before / 2, 1e-12);
    Camera p = makeCamera(true);
    p.zoom(4);
    EXPECT_NEAR(p.parallelScale, 1.7 / 4, 1e-15);
    EXPECT_THROW(p.zoom(0), fss::InvalidInputError);
    EXPECT_THROW(p.zoom(std::nan("")), fss::InvalidInputError);
}

TEST(Camera, ValidateRejectsBadParameters) {
    EXPECT_NO_THROW(makeCamera(false).validate());
    auto bad = [](auto mutate) {
        Camera c = makeCamera(false);
        mutate(c);
        return c;
    };
    EXPECT_THROW(bad([](Camera& c) { c.width = 0; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.height = -3; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.width = 9000; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.focal = c.eye; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.up = c.focal - c.eye; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.viewAngleDeg = 180; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.nearPlane = 0; }).validate(), fss::InvalidInputError);
    EXPECT_THROW(bad([](Camera& c) { c.eye.x() = std::nan(""); }).validate(), fss::InvalidInputError);
    try {
        bad([](Camera& c) { c.width = 0; }).validate();
    } catch (const fss::InvalidInputError& e) {
        EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos);
    }
}

TEST(Camera, FitClippingRangeIsTightAndRejectsBoxBehind) {
    Camera c = makeCamera(false);
    const Eigen::AlignedBox3d box(Eigen::Vector3d(-0.5, -0.5, -0.5), Eigen::Vector3d(0.5, 0.5, 0.5));
    c.focal = {0, 0, 0};
    c.eye = {0, 0, 10};
    c.up = {0, 1, 0};
    c.fitClippingRange(box);
    EXPECT_NEAR(c.nearPlane, 9.5, 1e-2);
    EXPECT_NEAR(c.farPlane, 10.5, 1e-2);
    EXPECT_LT(c.nearPlane, 9.5);
    EXPECT_GT(c.farPlane, 10.5);
    c.focal = {0, 0, 20}; // looking away
    EXPECT_THROW(c.fitClippingRange(box), fss::InvalidInputError);
}

TEST(CameraProjector, MatchesTheCameraMethods) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-3, 3), s(0, 1);
    for (bool parallel : {false, true}) {
        const Camera c = makeCamera(parallel);
        const fss::CameraProjector p(c);
        EXPECT_LT((p.viewDirection() - c.viewDirection()).norm(), 1e-15);
        for (int i = 0; i < 200; ++i) {
            const Eigen::Vector3d w(u(rng), u(rng), u(rng));
            const Eigen::Vector3d a = c.project(w), b = p.project(w);
            EXPECT_LT((a - b).norm(), 1e-12 * std::max(1.0, a.norm()));
            const double sx = s(rng) * c.width, sy = s(rng) * c.height, z = s(rng);
            EXPECT_LT((c.unproject(sx, sy, z) - p.unproject(sx, sy, z)).norm(), 1e-12);
            EXPECT_LT((c.unprojectPixelCentre(i % c.width, i % c.height, z) -
                       p.unprojectPixelCentre(i % c.width, i % c.height, z))
                          .norm(),
                      1e-12);
            const fss::Ray r = c.ray(sx, sy), q = p.ray(sx, sy);
            EXPECT_LT((r.origin - q.origin).norm(), 1e-12);
            EXPECT_LT((r.direction - q.direction).norm(), 1e-12);
            EXPECT_NEAR(c.pixelFootprint(w), p.pixelFootprint(w), 1e-12);
            EXPECT_NEAR(c.viewDepth(w), p.viewDepth(w), 1e-12);
        }
    }
}

// The regular scan unprojects every pixel centre with unprojectPixelCentreWithRay: it must give exactly
// (bit for bit) unprojectPixelCentre and ray, or scans would change.
TEST(CameraProjector, PixelCentreWithRayIsBitIdenticalToUnprojectAndRay) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> depth(0, 1);
    for (bool parallel : {false, true}) {
        for (const auto& [w, h] : {std::pair{640, 480}, std::pair{257, 1031}}) {
            Camera c = makeCamera(parallel);
            c.width = w;
            c.height = h;
            const fss::CameraProjector p(c);
            std::size_t mismatches = 0;
            for (int py = 0; py < h; py += 3) {
                for (int px = 0; px < w; px += 2) {
                    const double z = depth(rng); // a float depth, as the depth buffer holds
                    const auto got = p.unprojectPixelCentreWithRay(px, py, z);
                    const Eigen::Vector3d point = p.unprojectPixelCentre(px, py, z);
                    const fss::Ray ray = p.ray(px + 0.5, py + 0.5);
                    mismatches += !(got.point == point && got.ray.origin == ray.origin &&
                                    got.ray.direction == ray.direction);
                }
            }
            EXPECT_EQ(mismatches, 0u) << (parallel ? "parallel " : "perspective ") << w << "x" << h;
        }
    }
}
