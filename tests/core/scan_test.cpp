// Regular-grid scan: samples lie on the reference surface (to 0.01 pixel footprints, exactly on an
// analytic plane), sampling angles equal the analytic angles, the quality formula and its monotonicity.
#include "fss/error.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using fss::Camera;
using fss::FrameBuffers;
using fss::Mesh;
using fss::SampleGrid;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// A camera looking at the centre (2, 2, 0) of the plane grid [0,4]² from a tilt of `tiltDeg` around the
// x axis (0 = straight down the −z axis).
Camera tiltedCamera(double tiltDeg, bool parallel, double distance = 3.0, int size = 64) {
    Camera c;
    c.focal = {2, 2, 0};
    c.eye = c.focal + distance * Eigen::Vector3d(0, -std::sin(tiltDeg * kDeg), std::cos(tiltDeg * kDeg));
    c.up = {0, 1, 0};
    c.parallel = parallel;
    c.parallelScale = 0.5;
    c.viewAngleDeg = 20;
    c.width = c.height = size;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, -0.01), Eigen::Vector3d(4, 4, 0.01)));
    return c;
}

// The grid [0,4]² split into 80×80 quads (z = 0, normal +z).
Mesh plane() {
    return fss::shapes::grid(80, 80, 0.05);
}

} // namespace

TEST(Scan, SamplesLieOnIcosphere) {
    const Mesh sphere = fss::shapes::icosphere(5, 1.0);
    const fss::RayCaster caster(sphere);
    Camera cam = Camera::standardView(
        fss::StandardView::Iso, Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)),
        256, 256);
    FrameBuffers fb = fss::rasterizeOnCpu(caster, cam);
    // A 24-bit depth buffer (what a GPU gives): the snap onto the face plane must remove the quantisation.
    for (float& d : fb.depth)
        d = float(std::round(double(d) * 16777215.0) / 16777215.0);
    const SampleGrid grid = fss::sampleRegularGrid(fb, sphere, {.scanId = 7});
    ASSERT_EQ(grid.rows, 256);
    ASSERT_EQ(grid.cols, 256);
    EXPECT_EQ(grid.scanId, 7);
    EXPECT_EQ(grid.hitCount(), fb.coveredCount());
    EXPECT_EQ(grid.validCount(), fb.coveredCount()); // a closed sphere: every visible face is front-facing
    double worstSnapped = 0, worstUnsnapped = 0;
    for (int r = 0; r < grid.rows; ++r) {
        for (int c = 0; c < grid.cols; ++c) {
            const fss::Sample& s = grid.at(r, c);
            ASSERT_EQ(s.screen, Eigen::Vector2d(c + 0.5, r + 0.5));
            ASSERT_EQ(s.hit, fb.covered(c, r));
            if (!s.hit) {
                EXPECT_FALSE(s.valid);
                continue;
            }
            EXPECT_EQ(s.face, fb.faceAt(c, r));
            const double dist = caster.closestPoint(s.point).distance;
            worstSnapped = std::max(worstSnapped, dist / s.footprint);
            const Eigen::Vector3d raw = cam.unprojectPixelCentre(c, r, fb.depthAt(c, r));
            worstUnsnapped = std::max(worstUnsnapped, caster.closestPoint(raw).distance / s.footprint);
            // The sample projects onto its pixel centre.
            const Eigen::Vector3d back = cam.project(s.point);
            EXPECT_NEAR(back.x(), c + 0.5, 1e-6);
            EXPECT_NEAR(back.y(), r + 0.5, 1e-6);
            EXPECT_NEAR(s.normal.norm(), 1.0, 1e-12);
            EXPECT_NEAR(s.footprint, cam.pixelFootprint(s.point), 1e-6 * s.footprint);
            EXPECT_LT(s.samplingAngle, kPi / 2);
        }
    }
    std::printf("icosphere(5), 24-bit depth: worst distance %.3g footprints snapped, %.3g unprojected\n",
                worstSnapped, worstUnsnapped);
    EXPECT_LE(worstSnapped, 0.01);
    EXPECT_LE(worstSnapped, 1e-6);
}

TEST(Scan, PlaneSamplesAreExactAndAnglesAnalytic) {
    const Mesh grid = plane();
    for (bool parallel : {true, false}) {
        for (double tilt : {0.0, 30.0, 60.0}) {
            SCOPED_TRACE(testing::Message() << (parallel ? "parallel" : "perspective") << " tilt " << tilt);
            const Camera cam = tiltedCamera(tilt, parallel);
            const SampleGrid g = fss::sampleRegularGrid(fss::rasterizeOnCpu(grid, cam), grid);
            ASSERT_EQ(g.validCount(), std::size_t(64 * 64)); // the plane fills the view
            for (const fss::Sample& s : g.samples) {
                // Exactly on the analytic plane z = 0 (up to rounding of the ray/plane intersection).
                EXPECT_LE(std::abs(s.point.z()), 1e-12 * (1 + s.point.norm()));
                EXPECT_LE(std::abs(s.point.z()), 0.01 * s.footprint);
                EXPECT_EQ(s.normal, Eigen::Vector3d(0, 0, 1));
                const double expected =
                    parallel ? tilt * kDeg : std::acos((cam.eye - s.point).normalized().z());
                EXPECT_NEAR(s.samplingAngle, expected, 1e-6);
                const double fp = parallel ? 2.0 * 0.5 / 64 : cam.pixelFootprint(s.point);
                EXPECT_NEAR(s.footprint, fp, 1e-6 * fp);
                EXPECT_NEAR(s.quality, fp / std::cos(expected), 1e-5 * s.quality);
            }
        }
    }
}

TEST(Scan, QualityIsMonotone) {
    const Mesh grid = plane();
    auto centreQuality = [&](const Camera& cam) {
        const SampleGrid g = fss::sampleRegularGrid(fss::rasterizeOnCpu(grid, cam), grid);
        const fss::Sample& s = g.at(g.rows / 2, g.cols / 2);
        EXPECT_TRUE(s.valid);
        return double(s.quality);
    };
    for (bool parallel : {false, true}) {
        // Closer (perspective) / zoomed (parallel) → lower q.
        double previous = std::numeric_limits<double>::infinity();
        for (double distance : {4.0, 3.0, 2.0, 1.0}) {
            Camera cam = tiltedCamera(20, parallel, distance);
            if (parallel) cam.parallelScale = 0.2 * distance;
            const double q = centreQuality(cam);
            EXPECT_LT(q, previous);
            previous = q;
        }
        // More oblique → higher q.
        previous = 0;
        for (double tilt : {0.0, 20.0, 40.0, 60.0, 75.0}) {
            const double q = centreQuality(tiltedCamera(tilt, parallel));
            EXPECT_GT(q, previous);
            previous = q;
        }
    }
    // Higher resolution → lower q, exactly in proportion (parallel: footprint = 2·scale/height).
    const double q64 = centreQuality(tiltedCamera(30, true, 3.0, 64));
    const double q128 = centreQuality(tiltedCamera(30, true, 3.0, 128));
    EXPECT_NEAR(q128, 0.5 * q64, 1e-6 * q64);
}

TEST(Scan, QualityFormula) {
    EXPECT_FLOAT_EQ(fss::sampleQuality(0.01, 0.0), 0.01f);
    EXPECT_FLOAT_EQ(fss::sampleQuality(0.01, 60 * kDeg), 0.02f);
    // Clamped beyond the limit angle (85° by default).
    EXPECT_FLOAT_EQ(fss::sampleQuality(0.01, 89 * kDeg), float(0.01 / std::cos(85 * kDeg)));
    EXPECT_FLOAT_EQ(fss::sampleQuality(0.01, 89 * kDeg, 60.0), 0.02f);
    fss::Sample a, b, c;
    a.quality = 1;
    b.quality = 2;
    c.quality = 6;
    EXPECT_FLOAT_EQ(fss::triangleQuality(a, b, c), 3.0f);
}

TEST(Scan, BackFacingSamplesAreNotAdmissible) {
    // The grid seen from below (its normals point away from the camera).
    const Mesh grid = plane();
    Camera cam = tiltedCamera(0, true);
    cam.eye.z() = -3;
    cam.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, -0.01), Eigen::Vector3d(4, 4, 0.01)));
    const SampleGrid g = fss::sampleRegularGrid(fss::rasterizeOnCpu(grid, cam), grid);
    EXPECT_EQ(g.hitCount(), std::size_t(64 * 64));
    EXPECT_EQ(g.admissibleCount(), 0u);
    EXPECT_EQ(g.validCount(), 0u);
    EXPECT_NEAR(g.at(10, 10).samplingAngle, kPi, 1e-6);
}

TEST(Scan, RejectsBuffersOfAnotherMesh) {
    const Mesh grid = plane();
    const Camera cam = tiltedCamera(0, true, 3.0, 16);
    FrameBuffers fb = fss::rasterizeOnCpu(grid, cam);
    FrameBuffers shortBuffers = fb;
    shortBuffers.depth.pop_back();
    EXPECT_THROW(fss::sampleRegularGrid(shortBuffers, grid), fss::InvalidInputError);
    fb.faceId[5] = std::uint32_t(grid.num_faces()); // no such face
    EXPECT_THROW(fss::sampleRegularGrid(fb, grid), fss::InvalidInputError);
    try {
        fss::sampleRegularGrid(fb, grid);
    } catch (const fss::InvalidInputError& e) {
        EXPECT_NE(std::string(e.what()).find("not rendered from this mesh"), std::string::npos);
    }
}
