// scanFishbonePatch end to end with the CPU renderer, its one-sentence errors, and the "Aliasing" check of
// issue 5: on a curved crease a fishbone aligned with the feature gives a patch whose face normals near the
// crease are at least 2x closer to the reference's, and whose Hausdorff distance is lower, than a
// pixel-grid patch of the same sample spacing. The test writes the side-by-side picture of both patches
// (docs/fishbone_vs_grid.png is a copy of it).
#include "fss/error.h"
#include "fss/fishbone_scan.h"
#include "fss/mesh_io.h"
#include "fss/raycast.h"
#include "fss/shapes.h"
#include "key_rib_move.h"
#include "patch_picture.h"
#include "test_data.h"

#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using fss::Mesh;

Eigen::AlignedBox3d bbox(const Mesh& m) {
    Eigen::AlignedBox3d b;
    for (auto v : m.vertices())
        b.extend(Vector3d(m.point(v).x(), m.point(v).y(), m.point(v).z()));
    return b;
}

std::string messageOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const fss::InvalidInputError& e) {
        return e.what();
    }
    return "(no error)";
}

std::string point(const Vector2d& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.1f, %.1f)", p.x(), p.y());
    return buf;
}

Vector3d pt(const Mesh& m, fss::VertexIndex v) {
    return {m.point(v).x(), m.point(v).y(), m.point(v).z()};
}

// ---- The creased ring -----------------------------------------------------------------------------------
// A surface of revolution around z whose cross-section is two circular arcs (radius rho, centres at
// s = kCentre, z = ∓d) meeting in a sharp ridge at z = 0: s(z) = kCentre + sqrt(rho² − (|z| + d)²). The
// ridge is the circle s = kRidge, z = 0 with a dihedral turn of 2·asin(d/rho) = 60°; the meridian
// curvature 1/rho exceeds the parallel one everywhere, so the ridge follows the min-curvature direction.
constexpr double kCentre = 2.0, kRho = 1.0, kD = 0.5, kHalfHeight = 0.4;
const double kRidge = kCentre + std::sqrt(kRho * kRho - kD * kD);

Mesh creasedRing(int nu, int nzHalf, bool alternateDiagonals = true) {
    Mesh m;
    const int nz = 2 * nzHalf + 1; // row nzHalf is the ridge
    std::vector<fss::VertexIndex> v(std::size_t(nu) * nz);
    for (int j = 0; j < nz; ++j) {
        const double z = kHalfHeight * (j - nzHalf) / nzHalf;
        const double s = kCentre + std::sqrt(kRho * kRho - (std::abs(z) + kD) * (std::abs(z) + kD));
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * std::numbers::pi * i / nu;
            v[std::size_t(j) * nu + i] = m.add_vertex(fss::Point3(s * std::cos(phi), s * std::sin(phi), z));
        }
    }
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i < nu; ++i) {
            const auto a = v[std::size_t(j) * nu + i], b = v[std::size_t(j) * nu + (i + 1) % nu];
            const auto c = v[std::size_t(j + 1) * nu + (i + 1) % nu], d = v[std::size_t(j + 1) * nu + i];
            // Alternating diagonals: the triangulation is mirror-symmetric about every meridian plane of
            // an even index, so the fitted principal directions on the ridge are not tilted one way. With
            // one diagonal direction throughout, the jet fits across the sharp ridge tilt the directions
            // by about a degree and a plain streamline drifts off the ridge (see the second aliasing test).
            if (!alternateDiagonals || (i + j) % 2 == 0) {
                m.add_face(a, b, c);
                m.add_face(a, c, d);
            } else {
                m.add_face(a, b, d);
                m.add_face(b, c, d);
            }
        }
    return m;
}

// Distance of a point to the ridge circle.
double distanceToRidge(const Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - kRidge, p.z());
}

struct PatchError {
    std::size_t faces = 0;   // faces within 2h of the ridge
    double meanAngleDeg = 0; // mean angle between their normals and the closest reference faces' normals
    double hausdorff = 0;    // two-sided, near the ridge (see below)
};

Vector3d faceNormal(const Mesh& m, fss::FaceIndex f) {
    std::array<Vector3d, 3> p;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
        p[std::size_t(k++)] = pt(m, v);
    return (p[1] - p[0]).cross(p[2] - p[0]).normalized();
}

// Over patch faces whose centroid lies within 2h (world) of the ridge: the mean normal angle, and the
// Hausdorff distance between those faces and the reference: patch → reference on 10 points per face,
// reference → patch on the ridge points whose screen position lies inside \p inner (away from the lasso).
PatchError measure(const fss::Patch& patch, const fss::RayCaster& reference, double hWorld,
                   const fss::Camera& camera, const Eigen::AlignedBox2d& inner) {
    const Mesh& m = patch.mesh;
    PatchError e;
    double angleSum = 0;
    for (auto f : m.faces()) {
        std::array<Vector3d, 3> p;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            p[std::size_t(k++)] = pt(m, v);
        const Vector3d centroid = (p[0] + p[1] + p[2]) / 3;
        if (distanceToRidge(centroid) > 2 * hWorld) continue;
        const fss::SurfacePoint closest = reference.closestPoint(centroid);
        const Vector3d refNormal = faceNormal(reference.mesh(), closest.face);
        const Vector3d n = faceNormal(m, f);
        angleSum += std::acos(std::clamp(n.dot(refNormal), -1.0, 1.0));
        ++e.faces;
        for (double a = 0; a <= 1.0 + 1e-9; a += 1.0 / 3)
            for (double b = 0; a + b <= 1.0 + 1e-9; b += 1.0 / 3) {
                const Vector3d q = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]);
                e.hausdorff = std::max(e.hausdorff, reference.closestPoint(q).distance);
            }
    }
    e.meanAngleDeg = e.faces ? angleSum / double(e.faces) * 180 / std::numbers::pi : 0;
    const fss::RayCaster patchCaster(m);
    for (int i = 0; i < 20000; ++i) {
        const double phi = 2 * std::numbers::pi * i / 20000;
        const Vector3d q(kRidge * std::cos(phi), kRidge * std::sin(phi), 0);
        if (camera.viewDepth(q) <= 0 || (q - camera.eye).dot(Vector3d(q.x(), q.y(), 0)) > 0)
            continue; // far side
        const Vector3d s = camera.project(q);
        if (!inner.contains(Vector2d(s.x(), s.y()))) continue;
        e.hausdorff = std::max(e.hausdorff, patchCaster.closestPoint(q).distance);
    }
    return e;
}

// ---- The crease scene -----------------------------------------------------------------------------------

struct CreaseScene {
    Mesh ring;
    fss::Camera camera;
    fss::Lasso lasso;
    Eigen::AlignedBox2d inner;

    explicit CreaseScene(bool alternateDiagonals = true) : ring(creasedRing(720, 40, alternateDiagonals)) {
        // Looking at the front of the ridge from 30° above: the ridge circle projects to a curved arc.
        const Vector3d focal(kRidge, 0, 0);
        const double elevation = 30 * std::numbers::pi / 180;
        camera.focal = focal;
        camera.eye = focal + 4.0 * Vector3d(std::cos(elevation), 0, std::sin(elevation));
        camera.up = {0, 0, 1};
        camera.viewAngleDeg = 30;
        camera.width = camera.height = 160;
        camera.fitClippingRange(bbox(ring));
        // The lasso: the middle of the image (the ridge arc and both flanks).
        const double lo = 0.15 * camera.width, hi = 0.85 * camera.width;
        lasso.points = {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
        inner = Eigen::AlignedBox2d(Vector2d(lo + 4, lo + 4), Vector2d(hi - 4, hi - 4));
    }

    Vector2d ridgeSeed() const {
        const Vector3d s = camera.project(Vector3d(kRidge, 0, 0));
        return {s.x(), s.y()};
    }
};

} // namespace

TEST(FishboneScan, AutomaticScanOfTheCreasedRingIsAManifoldPatch) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::ScanParams params;
    params.camera = scene.camera;
    fss::FishboneParams fb;
    fb.seed = scene.ridgeSeed();
    fb.spacing = 3;
    fss::FishboneCache cache;
    const fss::FishboneScanResult r =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    EXPECT_GT(r.counts.rows, 30);
    EXPECT_GT(r.counts.cols, 10);
    EXPECT_GT(r.counts.covered, r.counts.ribVertices * 9 / 10);
    // h = 3 on the 160² image: the sampling image is 80² (k = 2, the largest divisor of 160 up to 3), whose
    // pixels are about two faces wide, so about every fifth rib vertex lands on the face under its pixel
    // (at k = 1 every fourth: below).
    EXPECT_EQ(r.samplingFactor, 2);
    EXPECT_EQ(r.grid.camera.width, 80);
    EXPECT_GT(r.counts.onHintFace, r.counts.covered / 8);
    EXPECT_GT(r.patch.mesh.number_of_faces(), 500u);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(r.patch.mesh));
    EXPECT_GT(r.timings.curvature, 0.0);
    EXPECT_GT(r.timings.rayCasting, 0.0);
    // Every sample lies on the reference surface.
    const fss::RayCaster& caster = cache.rayCaster(scene.ring);
    for (auto v : r.patch.mesh.vertices())
        EXPECT_LT(caster.closestPoint(pt(r.patch.mesh, v)).distance, 1e-9);
    // The second scan reuses the cached curvature.
    const fss::FishboneScanResult again =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    EXPECT_EQ(again.timings.curvature, 0.0);
    EXPECT_EQ(again.patch.mesh.number_of_faces(), r.patch.mesh.number_of_faces());
    // The same fishbone on the full 160² image (k = 1): the faces are about a pixel wide.
    fss::FishboneParams fine = fb;
    fine.samplingFactor = 1;
    const fss::FishboneScanResult f =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fine, cache);
    EXPECT_EQ(f.samplingFactor, 1);
    EXPECT_EQ(f.grid.camera.width, 160);
    EXPECT_GT(f.counts.onHintFace, f.counts.covered / 4);
    EXPECT_GT(f.patch.mesh.number_of_faces(), 500u);
    // Both grids have the same spacing on the scan image: about as many samples.
    EXPECT_NEAR(double(r.counts.covered), double(f.counts.covered), 0.15 * double(f.counts.covered));
    // Quality as on the scan image whatever k is (footprints of the sampling camera, k times larger).
    for (const fss::FishboneScanResult* s : {&r, &f})
        for (const fss::Sample& x : s->grid.samples)
            if (x.hit) {
                const double k = s->samplingFactor;
                ASSERT_NEAR(
                    x.quality,
                    x.footprint / k /
                        std::max(std::cos(double(x.samplingAngle)),
                                 std::cos(fss::ScanOptions{}.qualityAngleLimitDeg * std::numbers::pi / 180)),
                    1e-5 * x.quality);
            }

    // Key-rib mode: two traced key-ribs on the backbone, blended in between.
    fss::FishboneParams keys = fb;
    const Vector2d seed = *fb.seed;
    keys.keyRibs = {r.fishbone.at(r.counts.rows / 4, r.fishbone.backboneColumn),
                    r.fishbone.at(3 * r.counts.rows / 4, r.fishbone.backboneColumn)};
    const fss::FishboneScanResult k =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, keys, cache);
    EXPECT_GT(k.patch.mesh.number_of_faces(), 500u);
    (void)seed;
}

TEST(FishboneScan, BadFishbonesGiveOneSentence) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::ScanParams params;
    params.camera = scene.camera;
    fss::FishboneCache cache;
    auto scan = [&](const fss::FishboneParams& fb) {
        return messageOf(
            [&] { fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache); });
    };
    fss::FishboneParams fb;
    EXPECT_EQ(scan(fb), "FishboneParams::seed must be given when there is no drawn backbone.");
    // A background pixel of the sampling image (the default h = 4 samples the 160² scan on 40²), as a
    // point of the scan image.
    const fss::Camera sampling = fss::fishboneSamplingCamera(scene.camera, fb);
    ASSERT_EQ(sampling.width, 40);
    const fss::FrameBuffers buffers = renderer.render(sampling);
    Vector2d background(-1, -1);
    for (int y = 0; y < 40 && background.x() < 0; ++y)
        for (int x = 0; x < 40 && background.x() < 0; ++x)
            if (!buffers.covered(x, y)) background = 4.0 * Vector2d(x + 0.5, y + 0.5);
    ASSERT_GE(background.x(), 0);
    fb.seed = background;
    EXPECT_EQ(scan(fb), "The fishbone seed " + point(background) +
                            " lies on the background; pick a point on the surface.");
    fb.seed = Vector2d(500, 1);
    EXPECT_EQ(scan(fb), "FishboneParams::seed must lie inside the 160x160 scan image, not (500, 1).");
    fb.seed = scene.ridgeSeed();
    fb.spacing = 100;
    EXPECT_EQ(scan(fb),
              "FishboneParams::spacing must be in [0.5, 40] for a 160x160 scan: the spacing h = 100 "
              "pixels is outside it.");
    fb.spacing = 3;
    fb.samplingFactor = -1;
    EXPECT_EQ(scan(fb),
              "FishboneParams::samplingFactor must be at least 0 (0 chooses it automatically), not -1.");
    fb.samplingFactor = 3;
    EXPECT_EQ(scan(fb),
              "FishboneParams::samplingFactor must divide the scan image's width and height: the sampling "
              "factor 3 does not divide the 160x160 scan image.");
    fb.samplingFactor = 4;
    EXPECT_EQ(scan(fb), "FishboneParams::samplingFactor must be at most the spacing h: the sampling factor 4 "
                        "exceeds the spacing h = 3 pixels (the sampling image needs at least one pixel per "
                        "sample).");
    fb.samplingFactor = 0;
    fb.keyRibs = {*fb.seed};
    EXPECT_EQ(scan(fb),
              "FishboneParams::keyRibs must give, with the other key-ribs, none or at least two key-ribs "
              "to blend between, not 1.");
    fb.keyRibs = {*fb.seed, *fb.seed + Vector2d(0.5, 0)};
    EXPECT_NE(scan(fb).find("Two key-ribs fall on the same backbone sample"), std::string::npos);
    fb.keyRibs = {*fb.seed, *fb.seed + Vector2d(0, 30)};
    EXPECT_NE(scan(fb).find("pixels from the backbone, farther than 2h = 6."), std::string::npos);

    // A flat region: the seed in the middle of a cube's face has no principal direction.
    const Mesh cube = fss::shapes::cube(8);
    fss::CpuMeshRenderer cubeRenderer;
    cubeRenderer.setMesh(cube);
    fss::ScanParams cubeParams;
    cubeParams.camera = fss::Camera::standardView(fss::StandardView::PosZ, bbox(cube), 160, 160);
    fss::FishboneParams flat;
    flat.seed = Vector2d(80.5, 80.5);
    EXPECT_EQ(
        messageOf(
            [&] { fss::scanFishbonePatch(cube, cubeRenderer, cube, cubeRenderer, cubeParams, flat, cache); }),
        "The fishbone seed (80.5, 80.5) lies on a flat or isotropic region where no principal direction "
        "is defined; pick a point on a curved feature.");
}

namespace {

struct AliasingRun {
    PatchError grid, traced, drawn;
    double tracedDrift = 0, drawnDrift = 0; // largest distance of a backbone sample from the ridge, in h
    fss::Patch gridPatch, tracedPatch;
};

// Scans the ridge of \p scene with the pixel grid and with two fishbones (traced backbone through the
// ridge point under the image centre; hand-drawn backbone through 9 projected ridge points), all with the
// same camera, lasso and sample spacing (h = 1 pixel), and measures the three patches.
AliasingRun runAliasing(const CreaseScene& scene, const char* name) {
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::FishboneCache cache;
    const fss::RayCaster& reference = cache.rayCaster(scene.ring);
    fss::ScanParams params;
    params.camera = scene.camera;
    params.lasso = scene.lasso;
    // The paper's pixel grid, which the fishbone is measured against (the default adaptive lattice with its
    // angle mask, issue #20, drops the steep flanks of the ridge and samples more densely).
    params.scan.lattice = fss::Lattice::Square;
    params.scan.minLatticeAngleDeg = 0;
    const fss::ScanResult grid = fss::scanPatch(scene.ring, renderer, scene.ring, renderer, params);

    fss::FishboneParams traced;
    traced.seed = scene.ridgeSeed();
    traced.spacing = 1.0;
    const fss::FishboneScanResult fish =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, traced, cache);
    // Hand-drawn backbone (the user's alternative to tracing, DESIGN.md §1); ribs traced.
    fss::FishboneParams drawn;
    drawn.spacing = 1.0;
    for (int i = -4; i <= 4; ++i) {
        const double phi = 0.09 * i;
        const Vector3d q = scene.camera.project(Vector3d(kRidge * std::cos(phi), kRidge * std::sin(phi), 0));
        drawn.drawnBackbone.push_back(q.head<2>());
    }
    const fss::FishboneScanResult hand =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, drawn, cache);

    const double hWorld = scene.camera.pixelFootprint(Vector3d(kRidge, 0, 0));
    auto drift = [&](const fss::FishboneScanResult& r) {
        double worst = 0;
        for (int row = 0; row < r.grid.rows; ++row)
            if (const fss::Sample& s = r.grid.at(row, r.fishbone.backboneColumn);
                s.hit && scene.inner.contains(s.screen))
                worst = std::max(worst, distanceToRidge(s.point) / hWorld);
        return worst;
    };
    AliasingRun run;
    run.grid = measure(grid.patch, reference, hWorld, scene.camera, scene.inner);
    run.traced = measure(fish.patch, reference, hWorld, scene.camera, scene.inner);
    run.drawn = measure(hand.patch, reference, hWorld, scene.camera, scene.inner);
    run.tracedDrift = drift(fish);
    run.drawnDrift = drift(hand);
    auto line = [&](const char* what, const PatchError& e) {
        std::printf(
            "[ aliasing, %s ] %-16s %4zu faces within 2h: mean normal error %6.3f deg, Hausdorff %.2e "
            "(%.3f h)\n",
            name, what, e.faces, e.meanAngleDeg, e.hausdorff, e.hausdorff / hWorld);
    };
    std::printf("[ aliasing, %s ] h = 1 pixel = %.4f; backbone off the ridge by at most %.3f h (traced), "
                "%.3f h (drawn)\n",
                name, hWorld, run.tracedDrift, run.drawnDrift);
    line("pixel grid", run.grid);
    line("traced fishbone", run.traced);
    line("drawn fishbone", run.drawn);
    run.gridPatch = grid.patch;
    run.tracedPatch = fish.patch;
    return run;
}

} // namespace

TEST(FishboneScan, FishboneRemovesTheAliasingOfACurvedCrease) {
    const CreaseScene scene;
    const AliasingRun run = runAliasing(scene, "creased ring");
    EXPECT_GT(run.grid.faces, 300u);
    EXPECT_GT(run.traced.faces, 300u);
    EXPECT_GT(run.grid.meanAngleDeg, 4.0); // the staircase: about 5 degrees
    EXPECT_LT(run.tracedDrift, 0.05);
    EXPECT_GE(run.grid.meanAngleDeg, 2 * run.traced.meanAngleDeg);
    EXPECT_GE(run.grid.meanAngleDeg, 2 * run.drawn.meanAngleDeg);
    EXPECT_LT(run.traced.hausdorff, 0.5 * run.grid.hausdorff);
    EXPECT_LT(run.drawn.hausdorff, 0.5 * run.grid.hausdorff);

    // The picture: both patches from a closer camera aimed at a part of the ridge that runs obliquely across
    // the scan image (where the pixel grid's staircase is), side by side (grid left, fishbone right).
    fss::Camera view = scene.camera;
    view.width = view.height = 480;
    view.focal = Vector3d(kRidge * std::cos(0.16), kRidge * std::sin(0.16), 0);
    view.zoom(3.0);
    const int W = 2 * view.width;
    std::vector<std::uint8_t> rgb(std::size_t(W) * std::size_t(view.height) * 3, 255);
    std::vector<double> zbuf(std::size_t(W) * std::size_t(view.height),
                             std::numeric_limits<double>::infinity());
    fss::test::renderShaded(run.gridPatch.mesh, view, rgb, zbuf, W, 0, Vector3d(1.0, 0.85, 0.7));
    fss::test::renderShaded(run.tracedPatch.mesh, view, rgb, zbuf, W, view.width, Vector3d(0.7, 0.85, 1.0));
    for (int y = 0; y < view.height; ++y)
        for (int c = 0; c < 3; ++c)
            rgb[(std::size_t(y) * std::size_t(W) + std::size_t(view.width)) * 3 + std::size_t(c)] = 0;
    fss::test::writePng(fss::test::tmpPath("fishbone_vs_grid.png").string(), W, view.height, rgb);
}

// One diagonal direction throughout: the jet fits across the sharp ridge tilt the principal directions by
// about a degree, and a plain streamline drifted off the ridge (by more than h/2 before crease following,
// FishboneParams::creaseAngleDeg); the traced backbone now stays on it, and a hand-drawn backbone too.
TEST(FishboneScan, TracedAndDrawnBackbonesRemoveTheAliasingOnASkewTriangulation) {
    const CreaseScene scene(/*alternateDiagonals=*/false);
    const AliasingRun run = runAliasing(scene, "skew ring");
    EXPECT_LT(run.tracedDrift, 0.05);
    EXPECT_LT(run.drawnDrift, 0.05);
    EXPECT_GE(run.grid.meanAngleDeg, 2 * run.traced.meanAngleDeg);
    EXPECT_LT(run.traced.hausdorff, 0.5 * run.grid.hausdorff);
    EXPECT_GE(run.grid.meanAngleDeg, 2 * run.drawn.meanAngleDeg);
    EXPECT_LT(run.drawn.hausdorff, 0.5 * run.grid.hausdorff);
}

// The hinted ray cast on a mesh whose faces are smaller than a pixel (a 100k-face torus at 128²): the face
// under a rib vertex's pixel is mostly not the face its ray hits, so the cast walks over the surface from
// it. Every rib vertex, at random sub-pixel positions, must land where the AABB tree's first intersection
// of the same ray lies (the visible surface), and miss exactly where that misses.
TEST(FishboneScan, HintedRayCastOnFacesSmallerThanAPixelMatchesTheAabbTree) {
    const Mesh torus = fss::shapes::torus(250, 200, 1.0, 0.35);
    const fss::Camera camera = fss::Camera::standardView(fss::StandardView::Iso, bbox(torus), 128, 128);
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(torus);
    const fss::FrameBuffers buffers = renderer.render(camera);
    const fss::RayCaster caster(torus);

    fss::FishboneGrid grid;
    grid.rows = 120;
    grid.cols = 120;
    grid.spacing = 1.0;
    grid.screen.resize(std::size_t(grid.rows) * std::size_t(grid.cols));
    grid.present.assign(grid.screen.size(), 1);
    std::uint64_t state = 12345;
    auto uniform = [&state] { // deterministic LCG in [0, 1)
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) * 0x1.0p-53;
    };
    for (int r = 0; r < grid.rows; ++r)
        for (int c = 0; c < grid.cols; ++c)
            grid.screen[grid.index(r, c)] = {4.0 + c + uniform(), 4.0 + r + uniform()};

    std::size_t hintHits = 0;
    const fss::SampleGrid samples = fss::rayCastFishbone(grid, buffers, torus, caster, {}, {}, &hintHits);
    std::size_t hits = 0;
    double worst = 0;
    for (int r = 0; r < grid.rows; ++r)
        for (int c = 0; c < grid.cols; ++c) {
            const Vector2d p = grid.at(r, c);
            const fss::SurfacePoint truth = caster.intersect(camera.ray(p.x(), p.y()));
            const fss::Sample& s = samples.at(r, c);
            ASSERT_EQ(s.hit, bool(truth)) << "rib vertex " << point(p);
            if (!truth) continue;
            ++hits;
            worst = std::max(worst, (s.point - truth.point).norm());
        }
    EXPECT_GT(hits, std::size_t(grid.rows * grid.cols) / 5); // the torus covers about a quarter of the window
    EXPECT_LT(worst, 1e-9);                                  // the same point on the visible surface
    std::printf("hinted ray cast on the 100k-face torus at 128²: %zu hits, %zu on the pixel's face, worst "
                "distance %.2e\n",
                hits, hintHits, worst);
    // The pixel's own face is hit by fewer than 2/3 of the rays: most of the rest needed the walk.
    EXPECT_LT(hintHits, 2 * hits / 3);
}

// ---- Sliver figures of issue #20 (item 3) ---------------------------------------------------------------

namespace {

struct AngleFigures {
    std::size_t faces = 0;
    double minDeg = 90, meanDeg = 0, below30 = 0, below10 = 0;
};

AngleFigures angleFigures(const Mesh& m) {
    AngleFigures a;
    for (auto f : m.faces()) {
        std::array<Vector3d, 3> p;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            p[std::size_t(k++)] = pt(m, v);
        double smallest = 180;
        for (int i = 0; i < 3; ++i) {
            const Vector3d u = (p[std::size_t((i + 1) % 3)] - p[std::size_t(i)]).normalized();
            const Vector3d w = (p[std::size_t((i + 2) % 3)] - p[std::size_t(i)]).normalized();
            smallest =
                std::min(smallest, std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180 / std::numbers::pi);
        }
        ++a.faces;
        a.minDeg = std::min(a.minDeg, smallest);
        a.meanDeg += smallest;
        a.below30 += smallest < 30 ? 1 : 0;
        a.below10 += smallest < 10 ? 1 : 0;
    }
    if (a.faces) {
        a.meanDeg /= double(a.faces);
        a.below30 /= double(a.faces);
        a.below10 /= double(a.faces);
    }
    return a;
}

} // namespace

// The creased ring's ridge from the crease scene's camera and from straight above (the ridge a closed circle
// on the screen), h = 2 px, with and without the lasso: the rib trimming of issue #20 (minRibGap 0.5,
// maxRibTurnDeg 60, ribs stopped at creases) and the sliver-quad bound (20°) against none. Prints the
// figures of the report; asserts what the trimming achieves today.
TEST(FishboneScan, RibTrimmingFiguresOnTheCreasedRing) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::FishboneCache cache;
    fss::Camera top = scene.camera;
    // From 75° above the ring's centre the whole ridge is in view (the silhouette on the far side).
    const double up = 75 * std::numbers::pi / 180;
    top.focal = Vector3d(0, 0, 0);
    top.eye = 9.0 * Vector3d(std::cos(up), 0, std::sin(up));
    top.viewAngleDeg = 45;
    top.up = {0, 1, 0};
    top.viewAngleDeg = 45;
    top.fitClippingRange(bbox(scene.ring));
    const Vector3d ridgeTop = top.project(Vector3d(kRidge, 0, 0));
    struct Case {
        const char* name;
        fss::Camera camera;
        Vector2d seed;
        bool lasso;
    };
    const std::vector<Case> cases = {{"front", scene.camera, scene.ridgeSeed(), false},
                                     {"front+lasso", scene.camera, scene.ridgeSeed(), true},
                                     {"top (closed)", top, Vector2d(ridgeTop.x() - 2, ridgeTop.y()), false}};
    for (const Case& c : cases)
        for (bool trim : {false, true}) {
            fss::ScanParams params;
            params.camera = c.camera;
            if (c.lasso) params.lasso = scene.lasso;
            params.triangulate.minQuadAngleDeg = trim ? 20 : 0;
            fss::FishboneParams fb;
            fb.seed = c.seed;
            fb.spacing = 2;
            if (trim) {
                fb.tracing.minRibGap = 0.5;
                fb.tracing.maxRibTurnDeg = 60;
                fb.tracing.stopRibsAtCreases = true;
            }
            const fss::FishboneScanResult r =
                fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
            const AngleFigures a = angleFigures(r.patch.mesh);
            std::printf("creased ring %-13s %-9s: %5zu faces, %3d rows, smallest %5.1f°, mean %4.1f°, %5.1f "
                        "%% < 30°, "
                        "%5.1f %% < 10°, %zu sliver quads dropped\n",
                        c.name, trim ? "trimmed" : "untrimmed", a.faces, r.counts.rows, a.minDeg, a.meanDeg,
                        100 * a.below30, 100 * a.below10, r.patch.report.sliverQuads);
            EXPECT_GT(a.faces, 100u);
            // Measured (issue #20 report): smallest 18.2° (front, with or without lasso), 27.0° (top); the
            // issue's 20° is not met on the front view, trimmed or not.
            EXPECT_GE(a.minDeg, 15.0);
            EXPECT_EQ(a.below10, 0.0);
        }
}

// A key-rib moved by 1 px (issue #20: "moves no sample by more than 2 px"): two traced key-ribs on the
// creased ring's ridge, the second moved by one pixel in eight directions; the largest screen move of a
// rib vertex present in both grids, printed (the figure of the report).
TEST(FishboneScan, KeyRibMovedByOnePixelFigures) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::FishboneCache cache;
    fss::ScanParams params;
    params.camera = scene.camera;
    fss::FishboneParams fb;
    fb.seed = scene.ridgeSeed();
    fb.spacing = 3;
    const fss::FishboneScanResult first =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    const double worst =
        fss::test::largestKeyRibMove("creased ring", scene.ring, renderer, params, fb, first, cache, 100);
    EXPECT_LE(worst, 2.0); // measured 0.61 px across a midpoint, 0 elsewhere
}

// ---- Backbone loops and crease stops (issue #20, item 3) -------------------------------------------------

namespace {

// The crease scene's ring from 75° above its centre: the whole ridge is in view, a closed curve on the
// screen (as in RibTrimmingFiguresOnTheCreasedRing).
fss::Camera topCamera(const CreaseScene& scene) {
    fss::Camera top = scene.camera;
    const double up = 75 * std::numbers::pi / 180;
    top.focal = Vector3d(0, 0, 0);
    top.eye = 9.0 * Vector3d(std::cos(up), 0, std::sin(up));
    top.up = {0, 1, 0};
    top.viewAngleDeg = 45;
    top.fitClippingRange(bbox(scene.ring));
    return top;
}

// A torus-like ring with two sharp circular ridges, on top and at the bottom of its tube: the surface of
// revolution of a lens standing upright (two circular arcs of radius rho, centres at s = R ∓ d, z = 0,
// meeting at s = R, z = ±√(rho² − d²), each ridge with a dihedral turn of 2·asin(d/rho) = 60°). Closed. Its
// meridian curvature 1/rho exceeds the parallel one, so the ridges follow the min-curvature direction, and
// the top ridge is a closed curve in full view from above.
constexpr double kLensR = 2.0, kLensRho = 0.6, kLensD = 0.3;
const double kLensHalf = std::sqrt(kLensRho * kLensRho - kLensD * kLensD);

Mesh lensTorus(int nu, int m) {
    Mesh mesh;
    const double a0 = std::acos(kLensD / kLensRho);
    std::vector<Vector2d> section; // (s, z): the outer arc bottom → top, then the inner arc top → bottom
    for (int k = 0; k < m; ++k) {
        const double a = -a0 + 2 * a0 * k / m;
        section.emplace_back(kLensR - kLensD + kLensRho * std::cos(a), kLensRho * std::sin(a));
    }
    for (int k = 0; k < m; ++k) {
        const double a = a0 - 2 * a0 * k / m;
        section.emplace_back(kLensR + kLensD - kLensRho * std::cos(a), kLensRho * std::sin(a));
    }
    const int nv = int(section.size());
    std::vector<fss::VertexIndex> v(std::size_t(nu) * std::size_t(nv));
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * std::numbers::pi * i / nu;
            v[std::size_t(j) * nu + i] = mesh.add_vertex(
                fss::Point3(section[std::size_t(j)].x() * std::cos(phi),
                            section[std::size_t(j)].x() * std::sin(phi), section[std::size_t(j)].y()));
        }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const int j1 = (j + 1) % nv, i1 = (i + 1) % nu;
            const auto a = v[std::size_t(j) * nu + i], b = v[std::size_t(j) * nu + i1];
            const auto c = v[std::size_t(j1) * nu + i1], d = v[std::size_t(j1) * nu + i];
            if ((i + j) % 2 == 0) { // alternating diagonals, as creasedRing
                mesh.add_face(a, b, c);
                mesh.add_face(a, c, d);
            } else {
                mesh.add_face(a, b, d);
                mesh.add_face(b, c, d);
            }
        }
    return mesh;
}

double distanceToLensRidges(const Vector3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - kLensR, std::abs(p.z()) - kLensHalf);
}

fss::Camera lookAt(const Mesh& mesh, const Vector3d& focal, const Vector3d& eye, const Vector3d& up,
                   double angle, int size) {
    fss::Camera c;
    c.focal = focal;
    c.eye = eye;
    c.up = up;
    c.viewAngleDeg = angle;
    c.width = c.height = size;
    c.fitClippingRange(bbox(mesh));
    return c;
}

// Border cycles of a mesh.
int borderCycles(const Mesh& m) {
    std::vector<char> seen(m.number_of_halfedges(), 0);
    int cycles = 0;
    for (auto h : m.halfedges()) {
        if (!m.is_border(h) || seen[h.idx()]) continue;
        ++cycles;
        for (auto g = h; !seen[g.idx()]; g = m.next(g))
            seen[g.idx()] = 1;
    }
    return cycles;
}

// Border edges of the patch along rib rows \p a or \p b (both end vertices on that row).
int borderEdgesAlongRows(const fss::Patch& patch, int a, int b) {
    const Mesh& m = patch.mesh;
    const auto index = m.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    int n = 0;
    for (auto e : m.edges()) {
        if (!m.is_border(e)) continue;
        const fss::GridIndex s = index[m.vertex(e, 0)], t = index[m.vertex(e, 1)];
        n += s.row == t.row && (s.row == a || s.row == b);
    }
    return n;
}

} // namespace

// A closed backbone closes the grid: the top ridge of the lens torus seen from above is a closed curve; with
// closeLoops the traced backbone is a loop whose closing edge is about h long, the grid's last and first
// ribs are neighbours, and the patch is an annulus (two border cycles, the ridge's outer and inner sides)
// with no border edge along its first or last rib. Without it the backbone runs on past its start (the
// old behaviour: a gap beside an overlap) and the first and last ribs are borders.
// (The creased ring's ridge is no such curve: it is the ring's silhouette from above.)
TEST(FishboneScan, ClosedBackboneClosesTheGridOfTheRidge) {
    const Mesh lens = lensTorus(360, 40);
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(lens);
    fss::FishboneCache cache;
    fss::ScanParams params;
    params.camera = lookAt(lens, Vector3d(0, 0, kLensHalf), Vector3d(1.5, 0.5, 9.0), {0, 1, 0}, 45, 160);
    const Vector3d ridge = params.camera.project(Vector3d(kLensR, 0, kLensHalf));
    fss::FishboneParams fb;
    fb.seed = ridge.head<2>();
    fb.spacing = 2;
    fb.tracing.closeLoops = true;
    const fss::FishboneScanResult closed =
        fss::scanFishbonePatch(lens, renderer, lens, renderer, params, fb, cache);
    fb.tracing.closeLoops = false;
    const fss::FishboneScanResult open =
        fss::scanFishbonePatch(lens, renderer, lens, renderer, params, fb, cache);
    const fss::FishboneGrid& g = closed.fishbone;
    ASSERT_TRUE(g.closed);
    EXPECT_FALSE(open.fishbone.closed);
    const int n = g.rows, bc = g.backboneColumn;
    const double closing = (g.at(n - 1, bc) - g.at(0, bc)).norm(), other = (g.at(1, bc) - g.at(0, bc)).norm();
    std::printf("closed ridge: %d rows (open: %d), closing edge %.3f px, next %.3f px; border cycles %d "
                "(open: %d); border edges along the first/last rib %d (open: %d); %zu faces (open: %zu)\n",
                n, open.fishbone.rows, closing, other, borderCycles(closed.patch.mesh),
                borderCycles(open.patch.mesh), borderEdgesAlongRows(closed.patch, 0, n - 1),
                borderEdgesAlongRows(open.patch, 0, open.fishbone.rows - 1),
                std::size_t(closed.patch.mesh.number_of_faces()),
                std::size_t(open.patch.mesh.number_of_faces()));
    EXPECT_NEAR(closing, fb.spacing, 0.25 * fb.spacing);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(closed.patch.mesh));
    EXPECT_EQ(borderCycles(closed.patch.mesh), 2);
    EXPECT_EQ(borderEdgesAlongRows(closed.patch, 0, n - 1), 0);
    EXPECT_EQ(borderCycles(open.patch.mesh), 1);
    EXPECT_GE(borderEdgesAlongRows(open.patch, 0, open.fishbone.rows - 1), 5);
    // The seam: faces with vertices on both the last and the first rib.
    const auto index =
        closed.patch.mesh.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    int seamFaces = 0;
    for (auto f : closed.patch.mesh.faces()) {
        bool first = false, last = false;
        for (auto v : CGAL::vertices_around_face(closed.patch.mesh.halfedge(f), closed.patch.mesh)) {
            first = first || index[v].row == 0;
            last = last || index[v].row == n - 1;
        }
        seamFaces += first && last;
    }
    // As many as between any two neighbouring ribs, on average.
    EXPECT_GE(double(seamFaces),
              0.8 * double(closed.patch.mesh.number_of_faces()) / double(closed.fishbone.rows));
    EXPECT_EQ(closed.grid.rows, n);
    EXPECT_EQ(closed.patch.rows, n);
    // Every patch vertex is its grid sample's point.
    for (auto v : closed.patch.mesh.vertices()) {
        const fss::GridIndex i = index[v];
        ASSERT_EQ(closed.patch.vertexAt(i.row, i.col), v);
        const fss::Sample& s = closed.grid.at(i.row, i.col);
        ASSERT_TRUE(s.valid);
        ASSERT_LT((s.point - pt(closed.patch.mesh, v)).norm(), 1e-12);
    }
}

// Backbones and ribs stop at a crease they would cross: on the creased ring's upper flank (z = 0.2, above
// the ridge at z = 0) a backbone along the max-curvature direction runs down the meridian across the ridge
// unless stopBackboneAtCreases; ribs of a backbone along the min direction run down across the ridge
// unless stopRibsAtCreases. Measured on the samples' 3D points: below the ridge by more than the first
// edge's reach (2h) there is nothing left.
TEST(FishboneScan, BackboneAndRibsStopAtTheRidge) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::FishboneCache cache;
    fss::ScanParams params;
    params.camera = scene.camera;
    const double z = 0.2, s = kCentre + std::sqrt(kRho * kRho - (z + kD) * (z + kD));
    const Vector3d seed3 = params.camera.project(Vector3d(s, 0, z));
    const double hWorld = 2 * scene.camera.pixelFootprint(Vector3d(kRidge, 0, 0));
    auto below = [&](const fss::FishboneScanResult& r, bool backboneOnly) {
        int n = 0;
        for (int row = 0; row < r.grid.rows; ++row)
            for (int c = 0; c < r.grid.cols; ++c) {
                if (backboneOnly && c != r.fishbone.backboneColumn) continue;
                const fss::Sample& x = r.grid.at(row, c);
                n += x.hit && x.point.z() < -2 * hWorld;
            }
        return n;
    };
    fss::FishboneParams fb;
    fb.seed = seed3.head<2>();
    fb.spacing = 2;
    fb.direction = fss::PrincipalDirection::Max;
    const fss::FishboneScanResult across =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    fb.tracing.stopBackboneAtCreases = true;
    const fss::FishboneScanResult stopped =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    fb.direction = fss::PrincipalDirection::Min;
    fb.tracing.stopBackboneAtCreases = false;
    const fss::FishboneScanResult ribs =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    fb.tracing.stopRibsAtCreases = true;
    const fss::FishboneScanResult ribsStopped =
        fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    std::printf(
        "creased ring, seed on the upper flank: backbone across the ridge %d samples below it (%d rows), "
        "stopped %d (%d rows); ribs %d samples below, stopped %d\n",
        below(across, true), across.fishbone.rows, below(stopped, true), stopped.fishbone.rows,
        below(ribs, false), below(ribsStopped, false));
    EXPECT_GE(below(across, true), 2);
    EXPECT_LT(stopped.fishbone.rows, across.fishbone.rows);
    EXPECT_EQ(below(stopped, true), 0);
    EXPECT_GT(stopped.fishbone.rows, 5);
    EXPECT_GT(below(ribs, false), 50);
    EXPECT_EQ(below(ribsStopped, false), 0);
}

// ---- The sliver table of issue #20 (FSS_LONG_TESTS=1) -----------------------------------------------------

namespace {

// Sharp-edge chains of a CGAL mesh (dihedral > 30°, chained through vertices with two sharp edges).
std::vector<std::vector<Vector3d>> creaseChains(const Mesh& m, fss::FishboneCache& cache) {
    const std::vector<fss::EdgeIndex>& sharp = cache.creaseEdges(m, 30.0);
    std::vector<std::vector<fss::HalfedgeIndex>> out(m.number_of_vertices());
    for (auto e : sharp) {
        out[m.source(m.halfedge(e)).idx()].push_back(m.halfedge(e));
        out[m.target(m.halfedge(e)).idx()].push_back(m.opposite(m.halfedge(e)));
    }
    std::vector<char> used(m.number_of_edges(), 0);
    std::vector<std::vector<Vector3d>> chains;
    for (auto v : m.vertices()) {
        const auto& hs = out[v.idx()];
        if (hs.empty() || hs.size() == 2) continue;
        for (auto h : hs) {
            if (used[m.edge(h).idx()]) continue;
            std::vector<Vector3d> chain{pt(m, m.source(h))};
            for (;;) {
                used[m.edge(h).idx()] = 1;
                chain.push_back(pt(m, m.target(h)));
                const auto& next = out[m.target(h).idx()];
                if (next.size() != 2) break;
                h = m.edge(next[0]) == m.edge(h) ? next[1] : next[0];
                if (used[m.edge(h).idx()]) break;
            }
            chains.push_back(std::move(chain));
        }
    }
    // Closed loops (every vertex with two sharp edges): from any unused sharp edge round to it.
    for (auto e : sharp) {
        if (used[e.idx()]) continue;
        auto h = m.halfedge(e);
        std::vector<Vector3d> chain{pt(m, m.source(h))};
        for (;;) {
            used[m.edge(h).idx()] = 1;
            chain.push_back(pt(m, m.target(h)));
            const auto& next = out[m.target(h).idx()];
            if (next.size() != 2) break;
            h = m.edge(next[0]) == m.edge(h) ? next[1] : next[0];
            if (used[m.edge(h).idx()]) break;
        }
        chains.push_back(std::move(chain));
    }
    return chains;
}

double distanceToPolyline(const std::vector<Vector3d>& line, const Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Vector3d a = line[i], ab = line[i + 1] - a;
        const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
        best = std::min(best, (a + t * ab - p).norm());
    }
    return best;
}

struct SliverCase {
    std::string name;
    const Mesh* mesh = nullptr;
    fss::Camera camera;
    Vector2d seed;
    std::function<double(const Vector3d&)> creaseDistance; // to the crease the backbone follows
    std::string tuned;                                     // "tuned" or "untuned"
};

// A view and a seed on a curved crease of a CGAL mesh: of the seven standard views at 256² and the chains of
// sharp edges turning by 30–180° over at least 12 edges, the (chain, view) whose visible middle edge is seen
// most frontally (both faces), its midpoint the seed.
std::vector<SliverCase> cgalCases(const std::string& name, const Mesh& m, fss::FishboneCache& cache) {
    const std::vector<std::vector<Vector3d>> chains = creaseChains(m, cache);
    const fss::RayCaster& caster = cache.rayCaster(m);
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(m);
    std::vector<std::pair<double, SliverCase>> perView;
    for (const fss::StandardView view :
         {fss::StandardView::Iso, fss::StandardView::PosX, fss::StandardView::NegX, fss::StandardView::PosY,
          fss::StandardView::NegY, fss::StandardView::PosZ, fss::StandardView::NegZ}) {
        const fss::Camera camera = fss::Camera::standardView(view, bbox(m), 256, 256);
        fss::Camera sampling = camera;
        sampling.width = sampling.height = 128; // k = 2 for h = 2
        const fss::FrameBuffers buffers = renderer.render(sampling);
        double bestScore = 0.3;
        std::optional<SliverCase> best;
        for (const auto& chain : chains) {
            // Windows of 12 edges: turning by 20–150° in all, at most 20° at a vertex (a smooth curve).
            for (std::size_t mid = 6; mid + 6 < chain.size(); mid += 3) {
                double total = 0, most = 0;
                for (std::size_t k = mid - 5; k <= mid + 5; ++k) {
                    const Vector3d u = (chain[k] - chain[k - 1]).normalized(),
                                   w = (chain[k + 1] - chain[k]).normalized();
                    const double a = std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180 / std::numbers::pi;
                    total += a;
                    most = std::max(most, a);
                }
                if (total < 20 || total > 150 || most > 20) continue;
                const Vector3d p = 0.5 * (chain[mid] + chain[mid - 1]);
                const Vector3d s = camera.project(p);
                if (!(s.x() > 32 && s.y() > 32 && s.x() < 224 && s.y() < 224)) continue;
                const fss::SurfacePoint hit = caster.intersect(camera.ray(s.x(), s.y()));
                if (!hit || (hit.point - p).norm() > 2 * camera.pixelFootprint(p)) continue;
                bool covered = true; // the seed's 3 × 3 pixels of the sampling image
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx)
                        covered = covered && buffers.covered(int(s.x() / 2) + dx, int(s.y() / 2) + dy);
                if (!covered) continue;
                // Frontal: the surface on both sides of the crease near the seed faces the camera.
                const Vector3d toEye = (camera.eye - p).normalized();
                const Vector3d side = (chain[mid] - chain[mid - 1]).normalized().cross(toEye).normalized();
                double score = 1;
                for (const double sign : {1.0, -1.0}) {
                    const Vector3d q = p + sign * 4 * camera.pixelFootprint(p) * side;
                    score = std::min(score, faceNormal(m, caster.closestPoint(q).face).dot(toEye));
                }
                if (score <= bestScore) continue;
                bestScore = score;
                SliverCase c;
                c.name = name + " " + fss::standardViewName(view);
                c.mesh = &m;
                c.camera = camera;
                c.seed = s.head<2>();
                c.creaseDistance = [chain](const Vector3d& q) { return distanceToPolyline(chain, q); };
                best = c;
            }
        }
        if (best) perView.emplace_back(bestScore, *best);
    }
    // The two most frontal views.
    std::stable_sort(perView.begin(), perView.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<SliverCase> out;
    for (std::size_t i = 0; i < perView.size() && i < 2; ++i)
        out.push_back(perView[i].second);
    return out;
}

} // namespace

// Where the faces below 30° of a fishbone patch are (issue #20: where the slivers come from), each counted
// under the first that applies: "crease" (its corner samples' reference normals differ by more than 30°:
// it spans a crease), "ribEnd" (a corner is the last sample of its half-rib: the rib's next vertex is not
// in the patch), "bbEnd" (a corner within 2 rows of an open grid's first or last row), "border" (a corner on
// the patch's border: lasso, masks, silhouettes), "near" (within 2 columns of the backbone), "inside".
static std::string sliverSources(const fss::FishboneScanResult& r) {
    const Mesh& m = r.patch.mesh;
    const auto [gi, found] = m.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex);
    if (!found) return "";
    const fss::SampleGrid& g = r.grid;
    const int bc = r.fishbone.backboneColumn;
    std::vector<char> inPatch(g.samples.size(), 0);
    for (auto v : m.vertices())
        inPatch[g.index(gi[v].row, gi[v].col)] = 1;
    int counts[6] = {0, 0, 0, 0, 0, 0};
    for (auto f : m.faces()) {
        std::array<Vector3d, 3> p;
        std::array<fss::VertexIndex, 3> vs;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
            vs[std::size_t(k)] = v;
            p[std::size_t(k++)] = pt(m, v);
        }
        double smallest = 180;
        for (int i = 0; i < 3; ++i) {
            const Vector3d u = (p[std::size_t((i + 1) % 3)] - p[std::size_t(i)]).normalized();
            const Vector3d w = (p[std::size_t((i + 2) % 3)] - p[std::size_t(i)]).normalized();
            smallest =
                std::min(smallest, std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180 / std::numbers::pi);
        }
        if (smallest >= 30) continue;
        bool crease = false, ribEnd = false, bbEnd = false, border = false, near = false;
        for (int i = 0; i < 3; ++i) {
            const fss::GridIndex a = gi[vs[std::size_t(i)]];
            for (int j = 0; j < 3; ++j) {
                const fss::GridIndex b = gi[vs[std::size_t(j)]];
                crease =
                    crease || g.at(a.row, a.col).normal.dot(g.at(b.row, b.col).normal) < std::cos(0.5236);
            }
            if (a.col != bc) {
                const int out = a.col + (a.col > bc ? 1 : -1);
                ribEnd = ribEnd || out < 0 || out >= g.cols || !inPatch[g.index(a.row, out)];
            }
            bbEnd = bbEnd || (!r.fishbone.closed && (a.row < 2 || a.row >= g.rows - 2));
            border = border || m.is_border(vs[std::size_t(i)]);
            near = near || std::abs(a.col - bc) <= 2;
        }
        ++counts[crease ? 0 : ribEnd ? 1 : bbEnd ? 2 : border ? 3 : near ? 4 : 5];
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "crease %d ribEnd %d bbEnd %d border %d near %d inside %d", counts[0],
                  counts[1], counts[2], counts[3], counts[4], counts[5]);
    return buf;
}

// "open", or for a closed grid the border edges along its first and last rib (the seam) against the mean
// along any other two neighbouring ribs (ribs of unequal length leave some anywhere).
static std::string closedText(const fss::FishboneScanResult& r) {
    if (!r.fishbone.closed) return "open";
    const int n = r.fishbone.rows;
    double others = 0;
    for (int row = 1; row + 1 < n; ++row)
        others += borderEdgesAlongRows(r.patch, row, row + 1);
    char buf[128];
    std::snprintf(buf, sizeof buf, "closed: %d seam border edges (%.1f elsewhere)",
                  borderEdgesAlongRows(r.patch, 0, n - 1), others / double(n - 2));
    return buf;
}

// The figures of issue #20's fishbone criteria on shapes and meshes: for each case, h = 2 px, with and
// without a lasso (a square of 0.6 W around the seed), the paper's fishbone ("paper") and the issue-20 set
// ("issue20": closeLoops, stopBackboneAtCreases, minRibGap 0.5, maxRibTurnDeg 60, stopRibsAtCreases,
// minQuadAngleDeg 20), "+iso" (that and isotropicRibs), "+aspect" (that and maxRibAspect 1.7), "+spare" (that
// and spareFollowedCrease), "+face20" (that with minFaceAngleDeg 20 for minQuadAngleDeg 20), "+comp" (that
// and minComponentFaces 24) and "default" (FishboneOptions{}): the patch's smallest angle, the share of faces
// below 30°, the mean normal error of the faces within 2h of the crease near the backbone (screen distance
// ≤ 3h to a backbone sample) against the regular grid's at the same spacing (the default scan at W/2 × H/2)
// and against the paper's pixel grid there (square lattice, no angle mask), the backbone samples' mean
// distance from the crease, whether the grid closed, where the faces below 30° lie (sliverSources) and what
// each rule dropped. Printed only. FSS_LONG_TESTS=1
// build/bin/core_tests
// --gtest_filter='FishboneScan.SliverTable'
TEST(FishboneScan, SliverTable) {
    if (!std::getenv("FSS_LONG_TESTS")) GTEST_SKIP() << "set FSS_LONG_TESTS=1";
    const CreaseScene scene;
    const Mesh lens = lensTorus(720, 60);
    std::vector<Mesh> cgal;
    std::vector<std::string> names;
    for (const char* n : {"fandisk", "anchor", "rotor", "part", "joint", "spool", "blade", "pinion"}) {
        names.emplace_back(n);
        cgal.push_back(fss::readMesh(fss::test::meshPath(std::string(n) + ".off").string()));
    }
    std::vector<fss::FishboneCache> caches(cgal.size() + 2);
    std::vector<SliverCase> cases;
    const fss::Camera top = topCamera(scene);
    const Vector3d ridgeTop = top.project(Vector3d(kRidge, 0, 0));
    cases.push_back({"ring front", &scene.ring, scene.camera, scene.ridgeSeed(), distanceToRidge, "tuned"});
    cases.push_back({"ring top (closed)", &scene.ring, top, Vector2d(ridgeTop.x() - 2, ridgeTop.y()),
                     distanceToRidge, "tuned"});
    {
        const double az = 0.7, el = 12 * std::numbers::pi / 180;
        const Vector3d focal(kRidge * std::cos(az), kRidge * std::sin(az), 0);
        const fss::Camera c = lookAt(scene.ring, focal,
                                     focal + 3.5 * Vector3d(std::cos(az + 0.5) * std::cos(el),
                                                            std::sin(az + 0.5) * std::cos(el), std::sin(el)),
                                     {0, 0, 1}, 35, 200);
        const Vector3d s = c.project(focal);
        cases.push_back({"ring oblique", &scene.ring, c, s.head<2>(), distanceToRidge, "untuned"});
    }
    {
        const double el = 35 * std::numbers::pi / 180;
        const Vector3d focal(kLensR, 0, kLensHalf);
        const fss::Camera c =
            lookAt(lens, focal, focal + 4.0 * Vector3d(std::cos(el), 0.3, std::sin(el)), {0, 0, 1}, 35, 200);
        cases.push_back(
            {"lens torus side", &lens, c, c.project(focal).head<2>(), distanceToLensRidges, "untuned"});
        const fss::Camera t =
            lookAt(lens, Vector3d(0, 0, kLensHalf), Vector3d(2.0, 0.5, 9.0), {0, 1, 0}, 45, 256);
        const Vector3d s = t.project(Vector3d(kLensR * std::cos(0.3), kLensR * std::sin(0.3), kLensHalf));
        cases.push_back({"lens torus top (closed)", &lens, t, s.head<2>(), distanceToLensRidges, "untuned"});
    }
    for (std::size_t i = 0; i < cgal.size(); ++i) {
        std::vector<SliverCase> found = cgalCases(names[i], cgal[i], caches[i]);
        if (found.empty())
            std::printf("%s: no curved crease chain found in the standard views\n", names[i].c_str());
        for (SliverCase& c : found) {
            c.tuned = names[i] == "fandisk" ? "tuned" : "untuned";
            cases.push_back(std::move(c));
        }
    }

    // The option sets (FSS_SLIVER_SETS="3,6" runs some of them; FSS_SLIVER_CASES="fandisk" only the cases
    // whose name contains it).
    const std::array<const char*, 8> setNames{"paper",  "issue20", "+iso",  "+aspect",
                                              "+spare", "+face20", "+comp", "default"};
    std::vector<int> sets;
    if (const char* e = std::getenv("FSS_SLIVER_SETS")) {
        for (const char* q = e; *q; ++q)
            if (*q >= '0' && *q <= '7') sets.push_back(*q - '0');
    } else {
        sets = {0, 1, 2, 3, 4, 5, 6, 7};
    }
    const char* only = std::getenv("FSS_SLIVER_CASES");
    std::printf("%-26s %-7s %-6s %-7s | %5s %6s %6s | %6s %6s %5s | %s\n", "case", "set", "lasso", "",
                "faces", "min°", "<30%", "nerr°", "grid°", "ratio", "closed");
    for (SliverCase& c : cases) {
        if (only && c.name.find(only) == std::string::npos) continue;
        fss::CpuMeshRenderer renderer;
        renderer.setMesh(*c.mesh);
        fss::FishboneCache cache;
        const fss::RayCaster& caster = cache.rayCaster(*c.mesh);
        {
            // The seed on a covered pixel of the sampling image (k = 2): nudged by up to 2 px if needed.
            fss::Camera sampling = c.camera;
            sampling.width /= 2;
            sampling.height /= 2;
            const fss::FrameBuffers b = renderer.render(sampling);
            auto covered = [&](const Vector2d& q) { return b.covered(int(q.x() / 2), int(q.y() / 2)); };
            for (int k = 0; k < 25 && !covered(c.seed); ++k) {
                const Vector2d q = c.seed + Vector2d(k % 5 - 2, k / 5 - 2);
                if (covered(q)) {
                    std::printf("%s: seed nudged by (%d, %d)\n", c.name.c_str(), k % 5 - 2, k / 5 - 2);
                    c.seed = q;
                }
            }
        }
        const fss::SurfacePoint seedHit = caster.intersect(c.camera.ray(c.seed.x(), c.seed.y()));
        if (!seedHit) {
            std::printf("%s: the seed misses\n", c.name.c_str());
            continue;
        }
        const double h = 2, hWorld = h * c.camera.pixelFootprint(seedHit.point);
        for (const bool lasso : {false, true})
            for (const int set : sets) {
                const char* setName = setNames.at(std::size_t(set));
                fss::ScanParams params;
                params.camera = c.camera;
                const double half = 0.3 * c.camera.width;
                fss::Lasso l;
                l.points = {c.seed + Vector2d(-half, -half), c.seed + Vector2d(half, -half),
                            c.seed + Vector2d(half, half), c.seed + Vector2d(-half, half)};
                if (lasso) params.lasso = l;
                fss::FishboneParams fb;
                fb.seed = c.seed;
                fb.spacing = h;
                if (set < 7) { // the paper's grid and session 14's sets: the later defaults off
                    fb.tracing.closeLoops = false;
                    fb.tracing.minFaceAngleDeg = 0;
                    fb.tracing.minComponentFaces = 0;
                }
                if (set > 0 && set < 7) {
                    fb.tracing.closeLoops = fb.tracing.stopBackboneAtCreases = fb.tracing.stopRibsAtCreases =
                        true;
                    fb.tracing.minRibGap = 0.5;
                    fb.tracing.maxRibTurnDeg = 60;
                    fb.tracing.isotropicRibs = set >= 2;
                    fb.tracing.maxRibAspect = set >= 3 ? 1.7 : 0.0;
                    fb.tracing.spareFollowedCrease = set >= 4;
                    if (set >= 5)
                        fb.tracing.minFaceAngleDeg = 20;
                    else
                        params.triangulate.minQuadAngleDeg = 20;
                    fb.tracing.minComponentFaces = set >= 6 ? 24 : 0;
                    // FSS_SLIVER_DROP turns single rules off again (diagnosis): g minRibGap, t maxRibTurnDeg,
                    // a maxRibAspect, r stopRibsAtCreases, b stopBackboneAtCreases, l closeLoops,
                    // i isotropicRibs, s spareFollowedCrease.
                    if (const char* d = std::getenv("FSS_SLIVER_DROP")) {
                        const std::string drop = d;
                        auto off = [&](char k) { return drop.find(k) != std::string::npos; };
                        if (off('g')) fb.tracing.minRibGap = 0;
                        if (off('t')) fb.tracing.maxRibTurnDeg = 180;
                        if (off('a')) fb.tracing.maxRibAspect = 0;
                        if (off('r')) fb.tracing.stopRibsAtCreases = false;
                        if (off('b')) fb.tracing.stopBackboneAtCreases = false;
                        if (off('l')) fb.tracing.closeLoops = false;
                        if (off('i')) fb.tracing.isotropicRibs = false;
                        if (off('s')) fb.tracing.spareFollowedCrease = false;
                    }
                }
                fss::FishboneScanResult r;
                try {
                    r = fss::scanFishbonePatch(*c.mesh, renderer, *c.mesh, renderer, params, fb, cache);
                } catch (const fss::InvalidInputError& e) {
                    std::printf("%-26s %-7s %-6s: %s\n", c.name.c_str(), setName, lasso ? "lasso" : "-",
                                e.what());
                    continue;
                }
                // The regular grid at the same spacing: the scan at W/h × H/h.
                fss::ScanParams grid = params;
                grid.triangulate.minQuadAngleDeg = 0;
                grid.camera.width = int(c.camera.width / h);
                grid.camera.height = int(c.camera.height / h);
                if (grid.lasso)
                    for (Vector2d& q : grid.lasso->points)
                        q /= h;
                const fss::ScanResult regular = fss::scanPatch(*c.mesh, renderer, *c.mesh, renderer, grid);
                // The paper's pixel grid at that spacing (the square lattice without the angle mask).
                grid.scan.lattice = fss::Lattice::Square;
                grid.scan.minLatticeAngleDeg = 0;
                const fss::ScanResult pixels = fss::scanPatch(*c.mesh, renderer, *c.mesh, renderer, grid);
                // The backbone's samples: their mean distance from the crease, in h on the surface.
                double offCrease = 0;
                std::size_t onBackbone = 0;
                for (int row = 0; row < r.grid.rows; ++row)
                    if (const fss::Sample& s = r.grid.at(row, r.fishbone.backboneColumn); s.hit && s.valid) {
                        offCrease += c.creaseDistance(s.point) / hWorld;
                        ++onBackbone;
                    }
                offCrease /= double(std::max<std::size_t>(onBackbone, 1));
                std::vector<Vector2d> backbone;
                for (int row = 0; row < r.fishbone.rows; ++row)
                    if (r.fishbone.isPresent(row, r.fishbone.backboneColumn))
                        backbone.push_back(r.fishbone.at(row, r.fishbone.backboneColumn));
                auto nearError = [&](const Mesh& m) {
                    double sum = 0;
                    std::size_t n = 0;
                    for (auto f : m.faces()) {
                        Vector3d centroid = Vector3d::Zero();
                        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                            centroid += pt(m, v) / 3;
                        if (c.creaseDistance(centroid) > 2 * hWorld) continue;
                        const Vector2d s = c.camera.project(centroid).head<2>();
                        bool near = false;
                        for (const Vector2d& b : backbone)
                            near = near || (b - s).norm() <= 3 * h;
                        if (!near) continue;
                        const Vector3d ref = faceNormal(*c.mesh, caster.closestPoint(centroid).face);
                        sum += std::acos(std::clamp(faceNormal(m, f).dot(ref), -1.0, 1.0)) * 180 /
                               std::numbers::pi;
                        ++n;
                    }
                    return n ? sum / double(n) : std::numeric_limits<double>::quiet_NaN();
                };
                const AngleFigures a = angleFigures(r.patch.mesh);
                const double fishError = nearError(r.patch.mesh), gridError = nearError(regular.patch.mesh),
                             pixelError = nearError(pixels.patch.mesh);
                std::printf("%-26s %-7s %-6s %-7s | %5zu %6.1f %6.1f | %6.2f %6.2f %5.2f | pixel grid %5.2f "
                            "ratio %4.2f, backbone off the crease %.2f h | %s | %s | "
                            "grid %dx%d, %zu rib vertices, dropped: trim %zu creaseStop %zu sliverQuad %zu "
                            "smallPart %zu\n",
                            c.name.c_str(), setName, lasso ? "lasso" : "-", c.tuned.c_str(), a.faces,
                            a.minDeg, 100 * a.below30, fishError, gridError, fishError / gridError,
                            pixelError, fishError / pixelError, offCrease, closedText(r).c_str(),
                            sliverSources(r).c_str(), r.fishbone.rows, r.fishbone.cols, r.counts.ribVertices,
                            r.counts.trimmed, r.counts.creaseStopped, r.patch.report.sliverQuads,
                            r.patch.report.smallParts);
                if (const char* dir = std::getenv("FSS_SLIVER_PICTURES")) {
                    // The patch coloured by its faces' smallest angle (grey ≥ 30°, yellow < 30°, orange <
                    // 20°, red < 10°): the whole view left, three times closer around the seed right.
                    fss::Camera view = c.camera, close = c.camera;
                    view.width = view.height = close.width = close.height = 512;
                    close.focal = seedHit.point;
                    close.zoom(3.0);
                    const int W = 2 * view.width;
                    std::vector<std::uint8_t> rgb(std::size_t(W) * std::size_t(view.height) * 3, 255);
                    std::vector<double> zbuf(std::size_t(W) * std::size_t(view.height),
                                             std::numeric_limits<double>::infinity());
                    const Mesh& pm = r.patch.mesh;
                    auto tint = [&](fss::FaceIndex f) {
                        std::array<Vector3d, 3> q;
                        int k = 0;
                        for (auto v : CGAL::vertices_around_face(pm.halfedge(f), pm))
                            q[std::size_t(k++)] = pt(pm, v);
                        double smallest = 180;
                        for (int i = 0; i < 3; ++i) {
                            const Vector3d u = (q[std::size_t((i + 1) % 3)] - q[std::size_t(i)]).normalized();
                            const Vector3d w = (q[std::size_t((i + 2) % 3)] - q[std::size_t(i)]).normalized();
                            smallest = std::min(smallest, std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180 /
                                                              std::numbers::pi);
                        }
                        // Bright: the flat shading darkens faces turned from its light.
                        return 3.0 * (smallest < 10   ? Vector3d(1.0, 0.1, 0.1)
                                      : smallest < 20 ? Vector3d(1.0, 0.55, 0.1)
                                      : smallest < 30 ? Vector3d(1.0, 0.95, 0.2)
                                                      : Vector3d(0.8, 0.85, 0.9));
                    };
                    fss::test::renderShaded(pm, view, rgb, zbuf, W, 0, tint);
                    fss::test::renderShaded(pm, close, rgb, zbuf, W, view.width, tint);
                    std::string file = c.name + "_" + setName + (lasso ? "_lasso" : "");
                    for (char& ch : file)
                        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                    fss::test::writePng(std::string(dir) + "/" + file + ".png", W, view.height, rgb);
                }
                EXPECT_GT(a.faces, 0u);
            }
    }
}

// Ribs spaced on the surface (FishboneOptions::isotropicRibs): on the creased ring's front view the lower
// flank is seen at about 60° and the upper one frontally, so ribs spaced h on the screen have surface edges
// up to twice the backbone's spacing on the lower flank. With isotropicRibs each rib edge's surface length
// (the samples' 3D points) is the backbone's surface spacing at its row: the share of rib edges within 20 %
// of it, over edges that do not cross the ridge.
TEST(FishboneScan, IsotropicRibsAreSpacedOnTheSurface) {
    const CreaseScene scene;
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(scene.ring);
    fss::FishboneCache cache;
    fss::ScanParams params;
    params.camera = scene.camera;
    fss::FishboneParams fb;
    fb.seed = scene.ridgeSeed();
    fb.spacing = 2;
    auto within = [&](bool isotropic) {
        fb.tracing.isotropicRibs = isotropic;
        const fss::FishboneScanResult r =
            fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
        const fss::SampleGrid& g = r.grid;
        const int bc = r.fishbone.backboneColumn;
        std::size_t edges = 0, good = 0;
        for (int row = 1; row + 1 < g.rows; ++row) {
            const fss::Sample &a = g.at(row - 1, bc), &b = g.at(row + 1, bc);
            if (!a.hit || !b.hit) continue;
            const double spacing = 0.5 * (a.point - b.point).norm();
            for (int c = 1; c < g.cols; ++c) {
                const fss::Sample &p = g.at(row, c - 1), &q = g.at(row, c);
                if (!p.hit || !q.hit || !r.fishbone.isPresent(row, c) || !r.fishbone.isPresent(row, c - 1))
                    continue;
                if ((p.point.z() > 0) != (q.point.z() > 0)) continue; // across the ridge
                const double ratio = (p.point - q.point).norm() / spacing;
                ++edges;
                good += ratio > 0.8 && ratio < 1.25;
            }
        }
        std::printf(
            "creased ring front, %s ribs: %zu rib edges, %.1f %% within 20 %% of the backbone's surface "
            "spacing\n",
            isotropic ? "isotropic" : "screen-spaced", edges, 100.0 * double(good) / double(edges));
        EXPECT_GT(edges, 500u);
        return double(good) / double(edges);
    };
    const double screen = within(false), surface = within(true);
    EXPECT_GT(surface, 0.9);
    EXPECT_LT(screen, 0.85); // measured 95.0 % and 80.2 %
}
