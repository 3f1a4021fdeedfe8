// scanFishbonePatch end to end with the CPU renderer, its one-sentence errors, and the "Aliasing" check of
// issue 5: on a curved crease a fishbone aligned with the feature gives a patch whose face normals near the
// crease are at least 2x closer to the reference's, and whose Hausdorff distance is lower, than a
// pixel-grid patch of the same sample spacing. The test writes the side-by-side picture of both patches
// (docs/fishbone_vs_grid.png is a copy of it).
#include "fishbone_scenes.h"
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

using namespace fishbone_scenes;

namespace {

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

struct PatchError {
    std::size_t faces = 0;   // faces within 2h of the ridge
    double meanAngleDeg = 0; // mean angle between their normals and the closest reference faces' normals
    double hausdorff = 0;    // two-sided, near the ridge (see below)
};

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
