// Issue 5, "Aliasing", on fandisk: one of its curved feature lines (the quarter-circle crease of 90°
// between the fan's top face and its curved side, 35 vertices, turning by 88°) is scanned from the
// bisector of the two faces at the same sample spacing h = 1 pixel, once with the pixel grid and once with a
// fishbone aligned to it; over patch faces within 2h of the feature line the fishbone's mean normal error
// must be at least 2× lower and its Hausdorff distance to the reference lower.
//
// The fishbone is drawn, as a user would draw it (DESIGN.md §1: hand-drawn backbone and key-ribs as
// interpolating splines through user points): the backbone through 9 points clicked on the feature line,
// five straight key-rib strokes across it, blended ribs in between. A fully traced fishbone (backbone from
// the middle click, with crease following) must meet the same criterion, and its backbone must stay within
// h/2 of the crease polyline over the whole inner crease.
#include "fss/fishbone_scan.h"
#include "fss/mesh_io.h"
#include "fss/raycast.h"
#include "fss/scan_pipeline.h"
#include "key_rib_move.h"
#include "patch_picture.h"
#include "test_data.h"

#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using fss::Mesh;

Vector3d pt(const Mesh& m, fss::VertexIndex v) {
    return {m.point(v).x(), m.point(v).y(), m.point(v).z()};
}

Vector3d faceNormal(const Mesh& m, fss::FaceIndex f) {
    const auto h = m.halfedge(f);
    const Vector3d a = pt(m, m.source(h)), b = pt(m, m.target(h)), c = pt(m, m.target(m.next(h)));
    return (b - a).cross(c - a).normalized();
}

double dihedralDeg(const Mesh& m, fss::EdgeIndex e) {
    const auto h = m.halfedge(e);
    return std::acos(
               std::clamp(faceNormal(m, m.face(h)).dot(faceNormal(m, m.face(m.opposite(h)))), -1.0, 1.0)) *
           180 / std::numbers::pi;
}

// Feature chains: edges sharper than minDeg, chained through vertices with exactly two such edges.
std::vector<std::vector<fss::VertexIndex>> featureChains(const Mesh& m, double minDeg) {
    std::map<std::uint32_t, std::vector<fss::HalfedgeIndex>> out; // sharp halfedges leaving each vertex
    for (auto e : m.edges())
        if (dihedralDeg(m, e) > minDeg) {
            out[m.source(m.halfedge(e)).idx()].push_back(m.halfedge(e));
            out[m.target(m.halfedge(e)).idx()].push_back(m.opposite(m.halfedge(e)));
        }
    std::vector<std::vector<fss::VertexIndex>> chains;
    std::map<std::uint32_t, bool> used; // edges
    for (auto& [v, hs] : out) {
        if (hs.size() == 2) continue; // start only at chain ends (or junctions)
        for (auto h0 : hs) {
            if (used[m.edge(h0).idx()]) continue;
            std::vector<fss::VertexIndex> chain{m.source(h0)};
            auto h = h0;
            for (;;) {
                used[m.edge(h).idx()] = true;
                const auto t = m.target(h);
                chain.push_back(t);
                const auto& next = out[t.idx()];
                if (next.size() != 2) break;
                h = (m.edge(next[0]) == m.edge(h)) ? next[1] : next[0];
                if (used[m.edge(h).idx()]) break;
            }
            chains.push_back(chain);
        }
    }
    return chains;
}

// Distance from p to the polyline (3D segments).
double distanceToPolyline(const std::vector<Vector3d>& line, const Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Vector3d a = line[i], ab = line[i + 1] - a;
        const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        best = std::min(best, (a + t * ab - p).norm());
    }
    return best;
}

struct PatchError {
    std::size_t faces = 0;   // patch faces whose centroid lies within 2h of the feature line
    double meanAngleDeg = 0; // mean angle between their normals and the closest reference face's normal
    double hausdorff = 0;    // two-sided, near the feature line (see measure)
};

// Over patch faces whose centroid lies within 2h (world) of the feature line: the mean normal angle, and
// the Hausdorff distance between those faces and the reference: patch → reference on 10 points per face,
// reference → patch on points of \p innerFeature (every 1/20 of an edge), the part of the feature line away
// from the ends of the scanned strip.
PatchError measure(const fss::Patch& patch, const fss::RayCaster& reference,
                   const std::vector<Vector3d>& feature, const std::vector<Vector3d>& innerFeature,
                   double hWorld) {
    const Mesh& m = patch.mesh;
    PatchError e;
    double angleSum = 0;
    for (auto f : m.faces()) {
        std::array<Vector3d, 3> p;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            p[std::size_t(k++)] = pt(m, v);
        const Vector3d centroid = (p[0] + p[1] + p[2]) / 3;
        if (distanceToPolyline(feature, centroid) > 2 * hWorld) continue;
        const fss::SurfacePoint closest = reference.closestPoint(centroid);
        angleSum += std::acos(
            std::clamp(faceNormal(m, f).dot(faceNormal(reference.mesh(), closest.face)), -1.0, 1.0));
        ++e.faces;
        for (double a = 0; a <= 1.0 + 1e-9; a += 1.0 / 3)
            for (double b = 0; a + b <= 1.0 + 1e-9; b += 1.0 / 3)
                e.hausdorff =
                    std::max(e.hausdorff,
                             reference.closestPoint(p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0])).distance);
    }
    e.meanAngleDeg = e.faces ? angleSum / double(e.faces) * 180 / std::numbers::pi : 0;
    const fss::RayCaster patchCaster(m);
    for (std::size_t i = 0; i + 1 < innerFeature.size(); ++i)
        for (int k = 0; k < 20; ++k) {
            const Vector3d q = innerFeature[i] + (k / 20.0) * (innerFeature[i + 1] - innerFeature[i]);
            e.hausdorff = std::max(e.hausdorff, patchCaster.closestPoint(q).distance);
        }
    return e;
}

std::vector<Vector3d> chainPoints(const Mesh& m, const std::vector<fss::VertexIndex>& chain) {
    std::vector<Vector3d> out;
    for (auto v : chain)
        out.push_back(pt(m, v));
    return out;
}

// The quarter-circle crease on top of the fan: the feature chain whose ends are nearest these corners.
std::vector<fss::VertexIndex> fanTopCrease(const Mesh& m) {
    const Vector3d endA(0.460, 0.181, 0.148), endB(0.055, -0.218, 0.218);
    std::vector<fss::VertexIndex> best;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (auto& c : featureChains(m, 25.0)) {
        const Vector3d a = pt(m, c.front()), b = pt(m, c.back());
        const double d =
            std::min((a - endA).norm() + (b - endB).norm(), (a - endB).norm() + (b - endA).norm());
        if (d < bestDistance) bestDistance = d, best = c;
    }
    return best;
}

Eigen::AlignedBox3d bbox(const Mesh& m) {
    Eigen::AlignedBox3d box;
    for (auto v : m.vertices())
        box.extend(pt(m, v));
    return box;
}

// The view: from the bisector of the two faces at the middle of \p chain (points \p line), 1.2 from its
// centroid, 200² pixels (the quarter-circle crease spans the image as a curved arc; both faces are seen at
// about 45°).
fss::Camera bisectorView(const Mesh& m, const std::vector<fss::VertexIndex>& chain,
                         const std::vector<Vector3d>& line) {
    const std::size_t mid = chain.size() / 2;
    const auto midEdge = m.halfedge(chain[mid], chain[mid + 1]);
    const Vector3d n1 = faceNormal(m, m.face(midEdge)), n2 = faceNormal(m, m.face(m.opposite(midEdge)));
    Vector3d centroid = Vector3d::Zero();
    for (const auto& p : line)
        centroid += p;
    centroid /= double(line.size());
    const Vector3d viewDir = (n1 + n2).normalized();
    fss::Camera camera;
    camera.focal = centroid;
    camera.eye = centroid + 1.2 * viewDir;
    camera.up = Vector3d(0, 0, 1);
    camera.viewAngleDeg = 30;
    camera.width = camera.height = 200;
    camera.fitClippingRange(bbox(m));
    return camera;
}

} // namespace

TEST(FishboneFandisk, DrawnFishboneRemovesTheAliasingOfACurvedCrease) {
    const Mesh m = fss::readMesh(fss::test::meshPath("fandisk.off").string());
    const std::vector<fss::VertexIndex> chain = fanTopCrease(m);
    const std::vector<Vector3d> line = chainPoints(m, chain);
    // The feature: a sharp (90°) crease, curved (it turns by more than 80° along its length).
    ASSERT_GE(line.size(), 30u);
    double turn = 0;
    for (std::size_t k = 1; k + 1 < line.size(); ++k)
        turn += std::acos(std::clamp(
            (line[k] - line[k - 1]).normalized().dot((line[k + 1] - line[k]).normalized()), -1.0, 1.0));
    EXPECT_GT(turn * 180 / std::numbers::pi, 80.0);
    const std::size_t mid = chain.size() / 2;
    const auto midEdge = m.halfedge(chain[mid], chain[mid + 1]);
    const Vector3d n1 = faceNormal(m, m.face(midEdge)), n2 = faceNormal(m, m.face(m.opposite(midEdge)));
    EXPECT_NEAR(std::acos(n1.dot(n2)) * 180 / std::numbers::pi, 90.0, 2.0);

    const fss::Camera camera = bisectorView(m, chain, line);
    // h = 1 pixel, in world units at the crease (the camera's focal point is the crease's centroid).
    const double hWorld = camera.pixelFootprint(camera.focal);

    // The user's strokes: a backbone through 9 points clicked on the crease, five straight key-ribs across
    // it, and the lasso: a band of ±15 pixels around the backbone (the same region for both scans).
    const double band = 15;
    std::vector<Vector2d> clicked, across;
    for (int i = 0; i <= 8; ++i)
        clicked.push_back(camera.project(line[std::size_t(i) * (line.size() - 1) / 8]).head<2>());
    for (std::size_t i = 0; i < clicked.size(); ++i) {
        const Vector2d t =
            (clicked[std::min(i + 1, clicked.size() - 1)] - clicked[i == 0 ? 0 : i - 1]).normalized();
        across.emplace_back(-t.y(), t.x());
    }
    fss::Lasso lasso;
    for (std::size_t i = 0; i < clicked.size(); ++i)
        lasso.points.push_back(clicked[i] + band * across[i]);
    for (std::size_t i = clicked.size(); i-- > 0;)
        lasso.points.push_back(clicked[i] - band * across[i]);
    for (auto& p : lasso.points)
        p = p.cwiseMax(Vector2d(0, 0)).cwiseMin(Vector2d(camera.width, camera.height));

    fss::CpuMeshRenderer renderer;
    renderer.setMesh(m);
    fss::FishboneCache cache;
    const fss::RayCaster& reference = cache.rayCaster(m);
    fss::ScanParams params;
    params.camera = camera;
    params.lasso = lasso;
    // The paper's pixel grid, which the fishbone is measured against (the default adaptive lattice with its
    // angle mask, issue #20, drops the steep flanks of the ridge and samples more densely).
    params.scan.lattice = fss::Lattice::Square;
    params.scan.minLatticeAngleDeg = 0;
    const fss::ScanResult grid = fss::scanPatch(m, renderer, m, renderer, params);

    fss::FishboneParams drawn;
    drawn.spacing = 1.0;
    drawn.drawnBackbone = clicked;
    for (std::size_t i = 0; i < clicked.size(); i += 2)
        drawn.drawnKeyRibs.push_back(
            {clicked[i] - band * across[i], clicked[i], clicked[i] + band * across[i]});
    const fss::FishboneScanResult fish =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, drawn, cache);

    // Traced alternatives, measured for the record (not asserted): ribs traced from the drawn backbone, and
    // a backbone traced from the middle click.
    fss::FishboneParams drawnBackboneOnly;
    drawnBackboneOnly.spacing = 1.0;
    drawnBackboneOnly.drawnBackbone = clicked;
    const fss::FishboneScanResult tracedRibs =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, drawnBackboneOnly, cache);
    fss::FishboneParams traced;
    traced.spacing = 1.0;
    traced.seed = clicked[4];
    const fss::FishboneScanResult tracedAll =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, traced, cache);
    // The same without crease following (FishboneParams::creaseAngleDeg = 0): the streamline alone.
    fss::FishboneParams tracedFree = traced;
    tracedFree.creaseAngleDeg = 0;
    const fss::FishboneScanResult tracedNoSnap =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, tracedFree, cache);

    // Away from the ends of the strip (where the lasso cuts it): the middle 3/4 of the crease.
    const std::vector<Vector3d> inner(line.begin() + std::ptrdiff_t(line.size() / 8),
                                      line.end() - std::ptrdiff_t(line.size() / 8));
    // Drift: the largest distance (in h) of a backbone sample inside the lasso from the crease polyline;
    // mean drift likewise; coverage: the fraction of the inner crease (points every 1/20 edge) within 1h of
    // the backbone's samples (so that a short backbone cannot pass).
    struct Drift {
        double worst = 0, mean = 0, coverage = 0;
        std::size_t samples = 0;
    };
    auto driftOf = [&](const fss::FishboneScanResult& r) {
        Drift d;
        std::vector<Vector3d> backbone;
        for (int row = 0; row < r.grid.rows; ++row)
            if (const fss::Sample& s = r.grid.at(row, r.fishbone.backboneColumn); s.hit && s.admissible) {
                const double e = distanceToPolyline(line, s.point) / hWorld;
                d.worst = std::max(d.worst, e);
                d.mean += e;
                ++d.samples;
                backbone.push_back(s.point);
            }
        if (d.samples) d.mean /= double(d.samples);
        std::size_t near = 0, total = 0;
        for (std::size_t i = 0; i + 1 < inner.size(); ++i)
            for (int k = 0; k < 20; ++k, ++total) {
                const Vector3d q = inner[i] + (k / 20.0) * (inner[i + 1] - inner[i]);
                double best = std::numeric_limits<double>::infinity();
                for (const Vector3d& b : backbone)
                    best = std::min(best, (b - q).norm());
                near += best < hWorld;
            }
        d.coverage = total ? double(near) / double(total) : 0;
        return d;
    };
    auto drift = [&](const fss::FishboneScanResult& r) { return driftOf(r).worst; };
    const PatchError g = measure(grid.patch, reference, line, inner, hWorld);
    const PatchError f = measure(fish.patch, reference, line, inner, hWorld);
    const PatchError tr = measure(tracedRibs.patch, reference, line, inner, hWorld);
    const PatchError ta = measure(tracedAll.patch, reference, line, inner, hWorld);
    auto print = [&](const char* what, const PatchError& e, const fss::Patch& p) {
        std::printf(
            "[ aliasing, fandisk ] %-30s %5zu faces within 2h: mean normal error %6.3f deg, Hausdorff "
            "%.2e (%.3f h); %zu patch faces\n",
            what, e.faces, e.meanAngleDeg, e.hausdorff, e.hausdorff / hWorld,
            std::size_t(p.mesh.number_of_faces()));
    };
    const Drift tracedDrift = driftOf(tracedAll), freeDrift = driftOf(tracedNoSnap);
    std::printf(
        "[ aliasing, fandisk ] h = 1 pixel = %.5f; backbone off the crease by at most %.3f h (drawn)\n",
        hWorld, drift(fish));
    std::printf(
        "[ aliasing, fandisk ] traced backbone: %zu samples in the lasso, off the crease by at most %.3f h, "
        "mean %.3f h, covers %.1f %% of the inner crease; without crease following: at most %.3f h, "
        "mean %.3f h, covers %.1f %%\n",
        tracedDrift.samples, tracedDrift.worst, tracedDrift.mean, 100 * tracedDrift.coverage, freeDrift.worst,
        freeDrift.mean, 100 * freeDrift.coverage);
    print("pixel grid", g, grid.patch);
    print("drawn backbone + key-ribs", f, fish.patch);
    print("drawn backbone, traced ribs", tr, tracedRibs.patch);
    print("traced backbone and ribs", ta, tracedAll.patch);
    const PatchError tf = measure(tracedNoSnap.patch, reference, line, inner, hWorld);
    print("traced, no crease following", tf, tracedNoSnap.patch);

    EXPECT_GT(g.faces, 500u);
    EXPECT_GT(f.faces, 500u);
    EXPECT_LT(drift(fish), 1.0);
    EXPECT_GT(g.meanAngleDeg, 5.0); // the pixel grid's staircase along the crease
    EXPECT_GE(g.meanAngleDeg, 2 * f.meanAngleDeg);
    EXPECT_LT(f.hausdorff, g.hausdorff);
    const std::size_t gridFaces = grid.patch.mesh.number_of_faces(),
                      fishFaces = fish.patch.mesh.number_of_faces();
    EXPECT_LT(double(std::max(gridFaces, fishFaces)),
              1.2 * double(std::min(gridFaces, fishFaces))); // same spacing

    // The traced fishbone (backbone from the middle click along the Min direction, which on this concave
    // crease is the direction of the smaller |k|, and traced ribs): the backbone stays on the crease over
    // all of it, and the aliasing criterion holds.
    EXPECT_GT(tracedDrift.samples, 100u);
    EXPECT_LT(tracedDrift.worst, 0.5);
    EXPECT_GT(tracedDrift.coverage, 0.99);
    EXPECT_GT(ta.faces, 500u);
    EXPECT_GE(g.meanAngleDeg, 2 * ta.meanAngleDeg);
    EXPECT_LT(ta.hausdorff, g.hausdorff);

    // The same traced fishbone at twice the resolution and h = 2 pixels (the same spacing on the surface):
    // by default (FishboneParams::samplingFactor) it samples on the 200² image, k = 2, i.e. it renders and
    // computes its direction fields at one pixel per sample like the pixel grid; with k = 1 it renders four
    // and its direction fields are twice as fine. Both keep the crease and the aliasing gain.
    fss::ScanParams params2 = params;
    params2.camera.width = params2.camera.height = 400;
    for (auto& p : params2.lasso->points)
        p *= 2.0;
    fss::FishboneParams traced2 = traced;
    traced2.spacing = 2.0;
    traced2.seed = 2.0 * clicked[4];
    traced2.creaseSnapRadius = 2.0 * traced.creaseSnapRadius; // scan pixels: the same radius on the surface
    const fss::FishboneScanResult half =
        fss::scanFishbonePatch(m, renderer, m, renderer, params2, traced2, cache);
    traced2.samplingFactor = 1;
    const fss::FishboneScanResult full =
        fss::scanFishbonePatch(m, renderer, m, renderer, params2, traced2, cache);
    EXPECT_EQ(half.samplingFactor, 2);
    EXPECT_EQ(half.grid.camera.width, 200);
    EXPECT_EQ(full.samplingFactor, 1);
    EXPECT_EQ(half.fishbone.spacing, 2.0); // the grid is reported in pixels of the 400² scan image
    // With k = 2 the 400² scan at h = 2 is the 200² scan at h = 1 (the traced one above), sample for sample.
    ASSERT_EQ(half.patch.mesh.number_of_vertices(), tracedAll.patch.mesh.number_of_vertices());
    ASSERT_EQ(half.patch.mesh.number_of_faces(), tracedAll.patch.mesh.number_of_faces());
    for (auto v : half.patch.mesh.vertices())
        ASSERT_EQ(pt(half.patch.mesh, v), pt(tracedAll.patch.mesh, v));
    for (int r = 0; r < half.fishbone.rows; ++r)
        for (int c = 0; c < half.fishbone.cols; ++c)
            if (half.fishbone.isPresent(r, c)) {
                ASSERT_EQ(half.fishbone.at(r, c), 2.0 * tracedAll.fishbone.at(r, c));
            }
    const PatchError th = measure(half.patch, reference, line, inner, hWorld);
    const PatchError tk = measure(full.patch, reference, line, inner, hWorld);
    print("traced, 400², h = 2, k = 2", th, half.patch);
    print("traced, 400², h = 2, k = 1", tk, full.patch);
    const Drift halfDrift = driftOf(half), fullDrift = driftOf(full);
    std::printf(
        "[ aliasing, fandisk ] 400², h = 2: backbone off the crease by at most %.3f h (k = 2), %.3f h "
        "(k = 1); covers %.1f %% / %.1f %%; rib vertices %zu / %zu\n",
        halfDrift.worst, fullDrift.worst, 100 * halfDrift.coverage, 100 * fullDrift.coverage,
        half.counts.ribVertices, full.counts.ribVertices);
    for (const fss::FishboneScanResult* r : {&half, &full}) {
        const Drift d = driftOf(*r);
        EXPECT_GT(d.samples, 100u);
        EXPECT_LT(d.worst, 0.5);
        EXPECT_GT(d.coverage, 0.99);
    }
    for (const PatchError* e : {&th, &tk}) {
        EXPECT_GT(e->faces, 500u);
        EXPECT_GE(g.meanAngleDeg, 2 * e->meanAngleDeg);
        EXPECT_LT(e->hausdorff, g.hausdorff);
    }

    // The picture (docs/fishbone_vs_grid_fandisk.png is a copy): both patches from a closer camera aimed at
    // the crease, side by side (pixel grid left, fishbone right).
    fss::Camera view = camera;
    view.width = view.height = 480;
    view.focal = line[line.size() / 3];
    view.zoom(3.0);
    const int W = 2 * view.width;
    std::vector<std::uint8_t> rgb(std::size_t(W) * std::size_t(view.height) * 3, 255);
    std::vector<double> zbuf(std::size_t(W) * std::size_t(view.height),
                             std::numeric_limits<double>::infinity());
    fss::test::renderShaded(grid.patch.mesh, view, rgb, zbuf, W, 0, Vector3d(1.0, 0.85, 0.7));
    fss::test::renderShaded(fish.patch.mesh, view, rgb, zbuf, W, view.width, Vector3d(0.7, 0.85, 1.0));
    for (int y = 0; y < view.height; ++y)
        for (int c = 0; c < 3; ++c)
            rgb[(std::size_t(y) * std::size_t(W) + std::size_t(view.width)) * 3 + std::size_t(c)] = 0;
    fss::test::writePng(fss::test::tmpPath("fishbone_vs_grid_fandisk.png").string(), W, view.height, rgb);
}

// Issue #20's "a key-rib moved by 1 px moves no sample by more than 2 px" on a CGAL mesh (the creased ring's
// test is on an analytic shape): the traced fishbone on fandisk's quarter-circle crease (default options,
// h = 2 px, seed at the crease's middle, bisector view: the backbone on the crease), then two traced key-ribs
// at a quarter and three quarters of its backbone, the second moved by 1 px in eight directions and across
// the midpoint of two backbone samples. With key-ribs at the nearest backbone sample (session 15) the grid
// jumped by 3.82 px across a midpoint; with continuous key-ribs (FishboneOptions::continuousKeyRibs) the
// key-rib starts where its point projects onto the backbone and the blend follows it: measured 1.93 px (moved
// along the backbone; the far ends of the ribs, where the rib field spreads the traced key-rib's 1 px),
// 0.16–0.22 px across the backbone.
TEST(FishboneFandisk, KeyRibMovedByOnePixelFigures) {
    const Mesh m = fss::readMesh(fss::test::meshPath("fandisk.off").string());
    const std::vector<fss::VertexIndex> chain = fanTopCrease(m);
    const std::vector<Vector3d> line = chainPoints(m, chain);
    fss::ScanParams params;
    params.camera = bisectorView(m, chain, line);
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(m);
    fss::FishboneCache cache;
    fss::FishboneParams fb;
    fb.spacing = 2;
    fb.seed = params.camera.project(line[line.size() / 2]).head<2>();
    const fss::FishboneScanResult traced =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, fb, cache);
    ASSERT_GT(traced.fishbone.rows, 20);
    const double worst = fss::test::largestKeyRibMove("fandisk", m, renderer, params, fb, traced, cache, 200);
    EXPECT_LE(worst, 2.0); // issue #20's bound; measured 1.93 px
}

// The CLI's drawn case (tests/cli/fishbone_scan_test.cpp, `fss-remesh scan fandisk.off --renderer cpu
// --fishbone "backbone=0.3,0.5|0.4,0.55|0.5,0.6;h=3;keyribs=0.32,0.51|0.48,0.59"`: iso view, 256²): its first
// key-rib point lies at the border of a flat face whose vertices have no principal direction, so the rib
// field is undefined there and at the nearest backbone sample. With continuous key-ribs (the default since
// session 18) that key-rib came back with both halves empty and the blend left 62 grid vertices that the
// sliver rules dropped ("Nothing is left to triangulate"); with key-ribs at the nearest sample it was empty
// too (96 faces, from the other key-rib alone). Now its half towards the defined region starts straight
// (tracedKeyRib): measured 174 faces, 179 samples.
TEST(FishboneFandisk, DrawnBackboneWithKeyRibOnAFlatFace) {
    const Mesh m = fss::readMesh(fss::test::meshPath("fandisk.off").string());
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(m);
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(m), 256, 256);
    fss::FishboneParams fb;
    fb.spacing = 3;
    for (const Vector2d& p : {Vector2d(0.3, 0.5), Vector2d(0.4, 0.55), Vector2d(0.5, 0.6)})
        fb.drawnBackbone.push_back(256 * p);
    fb.keyRibs = {256 * Vector2d(0.32, 0.51), 256 * Vector2d(0.48, 0.59)};
    ASSERT_TRUE(fb.tracing.continuousKeyRibs); // the default
    fss::FishboneCache cache;
    const fss::FishboneScanResult r = fss::scanFishbonePatch(m, renderer, m, renderer, params, fb, cache);
    fb.tracing.continuousKeyRibs = false;
    const fss::FishboneScanResult nearest =
        fss::scanFishbonePatch(m, renderer, m, renderer, params, fb, cache);
    const std::size_t faces = r.patch.mesh.number_of_faces(), before = nearest.patch.mesh.number_of_faces();
    std::printf("drawn backbone, key-rib on a flat face: %zu faces, %zu samples (key-ribs at the nearest "
                "sample: %zu faces)\n",
                faces, r.counts.covered, before);
    // The first key-rib's half adds rows of samples on its side: more than the other key-rib alone gives.
    EXPECT_GT(faces, before + before / 2);
    EXPECT_GT(r.counts.covered, nearest.counts.covered);
}
