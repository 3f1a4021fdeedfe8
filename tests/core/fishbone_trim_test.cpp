// Issue #20's rules against slivers on the creased ring and the lens torus: rib trimming, a key-rib moved by
// one pixel, closed backbones, backbones and ribs stopped at creases, ribs spaced on the surface.
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
    EXPECT_LE(worst, 2.0); // measured 0.19 px (0.61 px with key-ribs at the nearest backbone sample)
}

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
    fb.tracing.creaseBackbone =
        false; // the traced backbone's loop (CreaseBackboneRunsOnTheCrease: the crease's)
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

// Backbones on creases (FishboneOptions::creaseBackbone): a seed 2 px off a sharp ridge gives a backbone
// along the ridge's polyline. The lens torus's top ridge seen from above is closed and wholly visible: a
// closed backbone whose closing edge is as long as the others; the creased ring's ridge from the front is
// partly hidden: an open backbone ending where it turns away. Every backbone sample's surface point lies on
// the ridge (analytic distance within 0.02 h: the mesh's chords, h is a few of them), against the traced
// backbone's (printed for the record).
TEST(FishboneScan, CreaseBackboneRunsOnTheCrease) {
    const Mesh lens = lensTorus(360, 40);
    const CreaseScene scene;
    struct Case {
        const char* name;
        const Mesh* mesh;
        fss::Camera camera;
        Vector3d ridgePoint;
        double (*distance)(const Vector3d&);
        bool closed;
    };
    const std::vector<Case> cases = {
        {"lens torus top", &lens,
         lookAt(lens, Vector3d(0, 0, kLensHalf), Vector3d(1.5, 0.5, 9.0), {0, 1, 0}, 45, 160),
         Vector3d(kLensR, 0, kLensHalf), distanceToLensRidges, true},
        {"creased ring front", &scene.ring, scene.camera, Vector3d(kRidge, 0, 0), distanceToRidge, false}};
    for (const Case& c : cases) {
        fss::CpuMeshRenderer renderer;
        renderer.setMesh(*c.mesh);
        fss::FishboneCache cache;
        fss::ScanParams params;
        params.camera = c.camera;
        fss::FishboneParams fb;
        fb.seed = c.camera.project(c.ridgePoint).head<2>() + Vector2d(0, 2);
        fb.spacing = 2;
        auto offRidge = [&](const fss::FishboneScanResult& r, double& worst) {
            double sum = 0;
            int n = 0;
            worst = 0;
            for (int row = 0; row < r.grid.rows; ++row)
                if (const fss::Sample& s = r.grid.at(row, r.fishbone.backboneColumn); s.hit) {
                    const double d = c.distance(s.point) / (fb.spacing * c.camera.pixelFootprint(s.point));
                    sum += d;
                    worst = std::max(worst, d);
                    ++n;
                }
            return n ? sum / n : 0.0;
        };
        const fss::FishboneScanResult r =
            fss::scanFishbonePatch(*c.mesh, renderer, *c.mesh, renderer, params, fb, cache);
        fb.tracing.creaseBackbone = false;
        const fss::FishboneScanResult traced =
            fss::scanFishbonePatch(*c.mesh, renderer, *c.mesh, renderer, params, fb, cache);
        double worst = 0, tracedWorst = 0;
        const double mean = offRidge(r, worst), tracedMean = offRidge(traced, tracedWorst);
        const fss::FishboneGrid& g = r.fishbone;
        const int bc = g.backboneColumn, n = g.rows;
        std::printf(
            "%s: crease backbone %d samples (%s), off the ridge by %.4f h mean, %.4f h at most; traced "
            "%d samples (%s), %.4f h mean, %.4f h at most; %zu faces (traced %zu)\n",
            c.name, n, g.closed ? "closed" : "open", mean, worst, traced.fishbone.rows,
            traced.fishbone.closed ? "closed" : "open", tracedMean, tracedWorst,
            std::size_t(r.patch.mesh.number_of_faces()), std::size_t(traced.patch.mesh.number_of_faces()));
        ASSERT_GT(n, 30);
        EXPECT_LT(worst, 0.02);
        EXPECT_EQ(g.closed, c.closed);
        if (c.closed) {
            const double closing = (g.at(n - 1, bc) - g.at(0, bc)).norm(),
                         next = (g.at(1, bc) - g.at(0, bc)).norm();
            EXPECT_NEAR(closing, next, 0.1 * fb.spacing);
            EXPECT_EQ(borderCycles(r.patch.mesh), 2);
        }
        EXPECT_GT(r.patch.mesh.number_of_faces(), 300u);
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
    // Traced ribs: a crease backbone's ribs (creaseBackbone) step h footprints over the surface whatever
    // isotropicRibs says (measured: 100 % within 20 % either way).
    fb.tracing.creaseBackbone = false;
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

namespace {

// The creased ring from 75° above (topCamera), seeded 2 px inside the ridge's near point, h = 2 px.
struct RingFromAbove {
    CreaseScene scene;
    fss::Camera top = topCamera(scene);
    fss::CpuMeshRenderer renderer;
    fss::FishboneCache cache;
    fss::ScanParams params;
    fss::FishboneParams fb;
    RingFromAbove() {
        renderer.setMesh(scene.ring);
        params.camera = top;
        const Vector3d ridgeTop = top.project(Vector3d(kRidge, 0, 0));
        fb.seed = Vector2d(ridgeTop.x() - 2, ridgeTop.y());
        fb.spacing = 2;
    }
    fss::FishboneScanResult scan() {
        return fss::scanFishbonePatch(scene.ring, renderer, scene.ring, renderer, params, fb, cache);
    }
};

} // namespace

// The creased ring's ridge from 75° above (topCamera) is on the silhouette: only its upper flank shows, seen
// so obliquely (cos 63°) that the straight ribs of the crease backbone, h footprints apart on the surface,
// are 0.45 h apart on the screen. Trimmed at 1:1.5 on the screen they all went, and the scan fell back to a
// traced backbone 1.85 h off the ridge with 6.1 % of its faces below 30° (smallest 27.0°, session 20). Their
// quads are square on the surface, so they are trimmed there instead: the backbone stays on the ridge and
// every face is round in 3D (measured: 312 faces, smallest angle 35.0°, none below 30°; 39.9° since the ribs
// step onto the surface, session 22).
TEST(FishboneScan, CreaseOnTheSilhouetteKeepsRibsSquareOnTheSurface) {
    RingFromAbove ring;
    const fss::Camera& top = ring.top;
    fss::FishboneParams& fb = ring.fb;
    auto offRidge = [&](const fss::FishboneScanResult& r) {
        double sum = 0;
        int n = 0;
        for (int row = 0; row < r.grid.rows; ++row)
            if (const fss::Sample& s = r.grid.at(row, r.fishbone.backboneColumn); s.hit) {
                sum += distanceToRidge(s.point) / (fb.spacing * top.pixelFootprint(s.point));
                ++n;
            }
        return n ? sum / n : std::numeric_limits<double>::infinity();
    };
    const fss::FishboneScanResult r = ring.scan();
    fb.tracing.creaseBackbone = false;
    const fss::FishboneScanResult traced = ring.scan();
    const AngleFigures a = angleFigures(r.patch.mesh), t = angleFigures(traced.patch.mesh);
    std::printf("ring from 75° above: crease backbone %d rows, %.3f h off the ridge, %zu faces, smallest "
                "%.1f°, %.1f %% below 30°; traced backbone %.2f h off, %zu faces, %.1f°, %.1f %%\n",
                r.fishbone.rows, offRidge(r), a.faces, a.minDeg, 100 * a.below30, offRidge(traced), t.faces,
                t.minDeg, 100 * t.below30);
    EXPECT_LT(offRidge(r), 0.05);     // the crease backbone, on the ridge
    EXPECT_GT(offRidge(traced), 1.0); // what it fell back to
    EXPECT_GT(a.faces, 200u);
    EXPECT_GE(a.minDeg, 30.0);
    EXPECT_LE(a.below30, 0.02);
}

// The same view, the straight ribs' steps on the surface: each rib vertex of the patch lies one step (h
// footprints of its backbone sample) from the previous one in 3D, the first one h from the ridge, and the
// patch's faces within 2h of the ridge are within 0.92° of the creased ring's own normals (the exact surface
// of revolution, not its facets) on average. The first step used to leave the crease in the plane of the face
// seen h/2 beside it on the screen, 1.8 steps out on this oblique flank and tilted by its curvature there,
// and each step's end was taken where the viewing ray through it meets the surface, which slides along an
// oblique flank: the first rib vertices lay 1.08–1.37 h from the ridge, later steps 0.89–0.97 h, mean error
// 0.95° (session 21). Measured now: 33 first rib vertices at 1.00 h, later steps 1.00 h, 0.89°.
TEST(FishboneScan, CreaseRibsStepOneSpacingOnTheSurface) {
    RingFromAbove ring;
    const fss::Camera& top = ring.top;
    const fss::FishboneParams& fb = ring.fb;
    const fss::FishboneScanResult r = ring.scan();
    const Mesh& m = r.patch.mesh;
    const auto [gi, found] = m.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex);
    ASSERT_TRUE(found);
    const int bc = r.fishbone.backboneColumn;
    double firstLo = 1e9, firstHi = 0, stepLo = 1e9, stepHi = 0, errorSum = 0;
    int firsts = 0, errors = 0;
    for (auto v : m.vertices()) {
        const int row = gi[v].row, col = gi[v].col;
        if (col == bc) continue;
        const int inner = col > bc ? col - 1 : col + 1;
        const fss::Sample& a = r.grid.at(row, inner);
        if (!a.hit) continue;
        const double step = fb.spacing * top.pixelFootprint(r.grid.at(row, bc).point);
        const double d = (pt(m, v) - a.point).norm() / step;
        if (inner == bc) {
            firstLo = std::min(firstLo, distanceToRidge(pt(m, v)) / step);
            firstHi = std::max(firstHi, distanceToRidge(pt(m, v)) / step);
            ++firsts;
        } else {
            stepLo = std::min(stepLo, d);
            stepHi = std::max(stepHi, d);
        }
    }
    const double hWorld = fb.spacing * top.pixelFootprint(Vector3d(kRidge, 0, 0));
    for (auto f : m.faces()) {
        Vector3d c = Vector3d::Zero();
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            c += pt(m, v) / 3;
        if (distanceToRidge(c) > 2 * hWorld) continue;
        // The nearest arc's normal (the upper flank: centre s = kCentre, z = −kD).
        const double s = std::hypot(c.x(), c.y());
        const Vector3d n =
            (Vector3d(c.x() / s, c.y() / s, 0) * (s - kCentre) + Vector3d(0, 0, c.z() + kD)).normalized();
        errorSum +=
            std::acos(std::clamp(std::abs(faceNormal(m, f).dot(n)), -1.0, 1.0)) * 180 / std::numbers::pi;
        ++errors;
    }
    const double meanError = errors ? errorSum / errors : 90.0;
    std::printf(
        "ring from 75° above: %d first rib vertices %.2f–%.2f h from the ridge, later steps %.2f–%.2f h; "
        "%d faces within 2h of the ridge, mean normal error %.2f°\n",
        firsts, firstLo, firstHi, stepLo, stepHi, errors, meanError);
    EXPECT_GT(firsts, 25);
    EXPECT_GT(firstLo, 0.9);
    EXPECT_LT(firstHi, 1.1);
    EXPECT_GT(stepLo, 0.85);
    EXPECT_LT(stepHi, 1.15);
    EXPECT_GT(errors, 50);
    EXPECT_LT(meanError, 0.92);
}
