// Regular-grid scan: samples lie on the reference surface (to 0.01 pixel footprints, exactly on an
// analytic plane), sampling angles equal the analytic angles, the quality formula and its monotonicity.
#include "fss/error.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/shapes.h"
#include "fss/triangulate.h"

#include <gtest/gtest.h>

#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

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

// ---- Lattices (issue #20) -------------------------------------------------------------------------------

namespace {

// The smallest angle of triangle (a, b, c), degrees.
double smallestAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    auto angle = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
        return std::acos(std::clamp((q - p).normalized().dot((r - p).normalized()), -1.0, 1.0)) / kDeg;
    };
    return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

} // namespace

TEST(Scan, TriangularLatticeIsEquilateralOnAFrontalPlane) {
    const Mesh grid = plane();
    for (bool parallel : {true, false}) {
        SCOPED_TRACE(parallel ? "parallel" : "perspective");
        const Camera cam = tiltedCamera(0, parallel);
        fss::ScanWorkspace workspace;
        fss::ScanOptions triangular;
        triangular.lattice = fss::Lattice::Triangular;
        const SampleGrid g = fss::sampleLattice(fss::rasterizeOnCpu(grid, cam), grid, workspace, triangular);
        // Rows √3/2 px apart over 64 px: 73 rows; 64 samples per row plus the shear's 36 columns and one.
        ASSERT_EQ(g.rows, 73);
        ASSERT_EQ(g.cols, 64 + 36 + 1);
        std::size_t inside = 0;
        for (int r = 0; r < g.rows; ++r)
            for (int c = 0; c < g.cols; ++c) {
                const fss::Sample& s = g.at(r, c);
                const bool onScreen =
                    s.screen.x() >= 0 && s.screen.x() < 64 && s.screen.y() >= 0 && s.screen.y() < 64;
                inside += onScreen;
                ASSERT_EQ(s.hit, onScreen); // the plane fills the view
                // The lattice: unit steps along a row, to (r+1, c) and to (r+1, c+1), on the screen.
                if (c + 1 < g.cols) {
                    EXPECT_NEAR((g.at(r, c + 1).screen - s.screen).norm(), 1.0, 1e-12);
                }
                if (r + 1 < g.rows) {
                    EXPECT_NEAR((g.at(r + 1, c).screen - s.screen).norm(), 1.0, 1e-12);
                    if (c + 1 < g.cols) {
                        EXPECT_NEAR((g.at(r + 1, c + 1).screen - s.screen).norm(), 1.0, 1e-12);
                    }
                }
                if (!s.hit) continue;
                EXPECT_LE(std::abs(s.point.z()), 1e-12 * (1 + s.point.norm())); // on the analytic plane
                const Eigen::Vector3d back = cam.project(s.point);              // on its own viewing ray
                EXPECT_NEAR(back.x(), s.screen.x(), 1e-6);
                EXPECT_NEAR(back.y(), s.screen.y(), 1e-6);
                EXPECT_NEAR(s.footprint, cam.pixelFootprint(s.point), 1e-6 * s.footprint);
                EXPECT_TRUE(s.valid);
            }
        EXPECT_EQ(g.hitCount(), inside);
        EXPECT_NEAR(double(inside), 64.0 * 64.0 / (std::sqrt(3.0) / 2.0), 64.0); // density 2/√3 per px²
        const fss::Patch patch = fss::triangulateGrid(g);
        const Mesh& m = patch.mesh;
        ASSERT_GT(m.number_of_faces(), 7000u);
        double worst = 90;
        for (auto f : m.faces()) {
            std::vector<Eigen::Vector3d> p;
            for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                p.emplace_back(m.point(v).x(), m.point(v).y(), m.point(v).z());
            worst = std::min(worst, smallestAngleDeg(p[0], p[1], p[2]));
        }
        // Parallel projection of a frontal plane: exactly equilateral; perspective (20° view angle): the
        // footprint changes by a fraction of a percent across one triangle.
        EXPECT_GE(worst, parallel ? 59.999 : 59.0);
        std::size_t interior = 0, six = 0;
        for (auto v : m.vertices()) {
            if (m.is_border(v)) continue;
            ++interior;
            six += m.degree(v) == 6;
        }
        EXPECT_GT(interior, 4000u);
        EXPECT_EQ(six, interior);
    }
}

TEST(Scan, SquareLatticeOfOnePixelIsTheRegularGrid) {
    const Mesh grid = plane();
    const Camera cam = tiltedCamera(30, false);
    const FrameBuffers fb = fss::rasterizeOnCpu(grid, cam);
    fss::ScanWorkspace workspace;
    fss::ScanOptions square;
    square.lattice = fss::Lattice::Square;
    const SampleGrid a = fss::sampleLattice(fb, grid, workspace, square);
    const SampleGrid b = fss::sampleRegularGrid(fb, grid);
    ASSERT_EQ(a.rows, b.rows);
    ASSERT_EQ(a.cols, b.cols);
    for (std::size_t i = 0; i < a.samples.size(); ++i) {
        EXPECT_EQ(a.samples[i].screen, b.samples[i].screen);
        EXPECT_EQ(a.samples[i].point, b.samples[i].point);
    }
    // A square lattice of 2 px: every other pixel centre's position, found by ray casting instead.
    square.spacingPixels = 2;
    const SampleGrid c = fss::sampleLattice(fb, grid, workspace, square);
    ASSERT_EQ(c.rows, 32);
    ASSERT_EQ(c.cols, 32);
    for (int r = 0; r < c.rows; ++r)
        for (int col = 0; col < c.cols; ++col) {
            const fss::Sample& s = c.at(r, col);
            const fss::Sample& t = b.at(2 * r, 2 * col);
            ASSERT_TRUE(s.valid);
            EXPECT_EQ(s.screen, Eigen::Vector2d(2 * col + 1.0, 2 * r + 1.0));
            // Exactly where the viewing ray through its screen position meets the analytic plane z = 0.
            const fss::Ray ray = cam.ray(s.screen.x(), s.screen.y());
            const Eigen::Vector3d expected =
                ray.origin - (ray.origin.z() / ray.direction.z()) * ray.direction;
            EXPECT_LE((s.point - expected).norm(), 1e-9 * (1 + expected.norm()));
            EXPECT_GT((s.point - t.point).norm(), 0.5 * t.footprint); // not the pixel centre's sample
            EXPECT_NEAR(s.quality, 2.0 * fss::sampleQuality(s.footprint, s.samplingAngle), 1e-5 * s.quality);
        }
}

TEST(Scan, LatticeSpacingInWorldUnits) {
    const Mesh grid = plane();
    const Camera cam = tiltedCamera(0, true); // footprint 1/64 everywhere
    fss::ScanOptions o;
    o.lattice = fss::Lattice::Triangular;
    o.spacingWorld = 3.0 / 64;
    EXPECT_NEAR(fss::latticeSpacingPixels(cam, o), 3.0, 1e-9);
    fss::ScanWorkspace workspace;
    const SampleGrid g = fss::sampleLattice(fss::rasterizeOnCpu(grid, cam), grid, workspace, o);
    EXPECT_EQ(g.rows, int(std::floor(64 / (3 * std::sqrt(3.0) / 2))));
    for (int r = 0; r + 1 < g.rows; ++r)
        for (int c = 0; c + 1 < g.cols; ++c) {
            const fss::Sample &s = g.at(r, c), &t = g.at(r + 1, c + 1), &u = g.at(r, c + 1);
            if (s.hit && t.hit) {
                EXPECT_NEAR((s.point - t.point).norm(), 3.0 / 64, 1e-9);
            }
            if (s.hit && u.hit) {
                EXPECT_NEAR((s.point - u.point).norm(), 3.0 / 64, 1e-9);
            }
        }
    o.spacingWorld = 1000; // 64 000 px
    EXPECT_THROW(fss::latticeSpacingPixels(cam, o), fss::InvalidInputError);
}

TEST(Scan, LatticeOptionsAreValidated) {
    auto messageOf = [](const fss::ScanOptions& o) -> std::string {
        try {
            o.validate();
        } catch (const fss::InvalidOptionError& e) {
            return e.what();
        }
        return "(no error)";
    };
    fss::ScanOptions o;
    EXPECT_EQ(messageOf(o), "(no error)");
    o.spacingPixels = 0.1;
    EXPECT_NE(messageOf(o).find("ScanOptions::spacingPixels must be in [0.25, 1024]"), std::string::npos)
        << messageOf(o);
    o.spacingPixels = 1;
    o.spacingWorld = -1;
    EXPECT_NE(messageOf(o).find("ScanOptions::spacingWorld"), std::string::npos) << messageOf(o);
    o.spacingWorld = 0;
    o.lattice = static_cast<fss::Lattice>(7);
    EXPECT_NE(messageOf(o).find("ScanOptions::lattice must be Triangular, Square or Adaptive, not 7"),
              std::string::npos)
        << messageOf(o);
    o.lattice = fss::Lattice::Adaptive;
    o.minLatticeAngleDeg = 60;
    EXPECT_NE(messageOf(o).find("ScanOptions::minLatticeAngleDeg must be in [0, 60)"), std::string::npos)
        << messageOf(o);
}

// A plane seen at a slant of 50°: the screen's equilateral lattice is stretched by 1/cos 50° across the
// tilt axis on the plane — smallest angle 2·asin(½ / |(½, √3/2 / cos 50°)|) = 40.7° analytically, which
// latticeAngleOnPlane and the triangulated patch both give; the adaptive lattice is compressed by cos 50° on
// the screen instead and gives equilateral triangles on the plane (with 1/cos 50° more samples); the
// lattice-angle mask drops the whole plane from the triangular lattice at 45° and none of it at 40°.
TEST(Scan, AdaptiveLatticeIsEquilateralOnATiltedPlane) {
    const Mesh grid = plane();
    const Camera cam = tiltedCamera(50, true);
    const FrameBuffers fb = fss::rasterizeOnCpu(grid, cam);
    const double stretched = 1.0 / std::cos(50 * kDeg);
    const double expected = 2 * std::asin(0.5 / std::hypot(0.5, std::sqrt(3.0) / 2 * stretched)) / kDeg;
    const fss::CameraProjector projector(cam);
    const fss::LatticeBasis triangular{{1, 0}, {-0.5, std::sqrt(3.0) / 2}};
    EXPECT_NEAR(fss::latticeAngleOnPlane(projector, {2, 2, 0}, {0, 0, 1}, triangular), expected, 1e-4);
    EXPECT_NEAR(fss::latticeAngleOnPlane(projector, {2, 2, 0}, {0, 0, 1}, {{1, 0}, {0, 1}}),
                std::atan(std::cos(50 * kDeg)) / kDeg, 1e-4); // the square lattice's right triangles
    const fss::LatticeBasis adaptive = fss::chooseAdaptiveLattice(fb, grid, 1.0, 35);
    EXPECT_NEAR(fss::latticeAngleOnPlane(projector, {2, 2, 0}, {0, 0, 1}, adaptive), 60.0, 1e-4);
    EXPECT_NEAR(std::abs(adaptive.a.x() * adaptive.b.y() - adaptive.a.y() * adaptive.b.x()),
                std::sqrt(3.0) / 2 * std::cos(50 * kDeg), 1e-9); // cell area on the screen
    auto worstAngle = [&](fss::Lattice lattice) {
        fss::ScanWorkspace workspace;
        fss::ScanOptions o;
        o.lattice = lattice;
        const SampleGrid g = fss::sampleLattice(fb, grid, workspace, o);
        const fss::Patch patch = fss::triangulateGrid(g);
        const Mesh& m = patch.mesh;
        EXPECT_GT(m.number_of_faces(), 5000u);
        double worst = 90, best = 0;
        for (auto f : m.faces()) {
            std::vector<Eigen::Vector3d> p;
            for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                p.emplace_back(m.point(v).x(), m.point(v).y(), m.point(v).z());
            const double a = smallestAngleDeg(p[0], p[1], p[2]);
            worst = std::min(worst, a);
            best = std::max(best, a);
        }
        std::size_t interior = 0, six = 0;
        for (auto v : m.vertices()) {
            if (m.is_border(v)) continue;
            ++interior;
            six += m.degree(v) == 6;
        }
        EXPECT_EQ(six, interior);
        return std::make_pair(worst, g.hitCount());
    };
    const auto [triWorst, triHits] = worstAngle(fss::Lattice::Triangular);
    const auto [adaWorst, adaHits] = worstAngle(fss::Lattice::Adaptive);
    EXPECT_NEAR(triWorst, expected, 1e-3);
    EXPECT_GE(adaWorst, 59.99);
    EXPECT_NEAR(double(adaHits) / double(triHits), stretched, 0.05 * stretched);
    // The mask, on the triangular lattice's grid.
    fss::ScanWorkspace workspace;
    fss::ScanOptions o;
    o.lattice = fss::Lattice::Triangular;
    SampleGrid g = fss::sampleLattice(fb, grid, workspace, o);
    const std::size_t admissible = g.admissibleCount();
    EXPECT_EQ(fss::applyLatticeAngleMask(g, 40.0), 0u);
    EXPECT_EQ(fss::applyLatticeAngleMask(g, 45.0), admissible);
    EXPECT_EQ(g.admissibleCount(), 0u);
    EXPECT_EQ(g.validCount(), 0u);
}
