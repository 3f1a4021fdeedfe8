// The row-parallel scan stages (parallel.h) give exactly the serial result: every sample field, every
// mask flag, every patch array, for 1, 2 and 3 threads (3 makes blocks of unequal size), on fandisk with
// a lasso, a quality mask that drops part of the samples, morphology and a mirrored grid.
#include "fss/error.h"
#include "fss/mask.h"
#include "fss/parallel.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/scan_workspace.h"
#include "fss/triangulate.h"
#include "test_data.h"

#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace {

fss::Mesh load(const std::string& name) {
    fss::Mesh m;
    if (!CGAL::IO::read_polygon_mesh(fss::test::meshPath(name).string(), m))
        ADD_FAILURE() << "cannot read " << name;
    return m;
}

struct ThreadsGuard {
    explicit ThreadsGuard(int n) { fss::setScanThreads(n); }
    ~ThreadsGuard() { fss::setScanThreads(0); }
};

struct ScanRun {
    fss::SampleGrid grid;
    std::size_t droppedLasso = 0, droppedQuality = 0;
    fss::MorphologyReport morphology;
    fss::Patch patch, mirroredPatch;
};

// Columns reversed: the same samples, mirrored on the screen (as a fishbone grid may be).
fss::SampleGrid mirrored(const fss::SampleGrid& g) {
    fss::SampleGrid m = g;
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c)
            m.at(r, c) = g.at(r, g.cols - 1 - c);
    return m;
}

ScanRun scan(int threads, const fss::Mesh& reference, const fss::FrameBuffers& buffers,
             const fss::Mesh& current) {
    ThreadsGuard guard(threads);
    ScanRun run;
    run.grid = fss::sampleRegularGrid(buffers, reference, {.scanId = 7});
    const double w = buffers.width(), h = buffers.height();
    run.droppedLasso = fss::applyLasso(run.grid, {{{0.05 * w, 0.1 * h},
                                                   {0.95 * w, 0.2 * h},
                                                   {0.5 * w, 0.5 * h},
                                                   {0.9 * w, 0.95 * h},
                                                   {0.1 * w, 0.8 * h}}});
    run.droppedQuality = fss::applyQualityMask(run.grid, current, buffers);
    run.morphology = fss::applyMorphology(run.grid, {.radius = 1});
    run.patch = fss::triangulateGrid(run.grid);
    run.mirroredPatch = fss::triangulateGrid(mirrored(run.grid));
    return run;
}

void expectSameSamples(const fss::SampleGrid& a, const fss::SampleGrid& b) {
    ASSERT_EQ(a.samples.size(), b.samples.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.samples.size(); ++i) {
        const fss::Sample &s = a.samples[i], &t = b.samples[i];
        const bool same = s.screen == t.screen && s.point == t.point && s.normal == t.normal &&
                          s.face == t.face &&
                          std::memcmp(&s.samplingAngle, &t.samplingAngle, sizeof(float)) == 0 &&
                          std::memcmp(&s.footprint, &t.footprint, sizeof(float)) == 0 &&
                          std::memcmp(&s.quality, &t.quality, sizeof(float)) == 0 && s.hit == t.hit &&
                          s.admissible == t.admissible && s.valid == t.valid;
        differing += same ? 0 : 1;
    }
    EXPECT_EQ(differing, 0u);
}

void expectSameMesh(const fss::Patch& a, const fss::Patch& b) {
    const fss::Mesh &m = a.mesh, &n = b.mesh;
    ASSERT_EQ(m.num_vertices(), n.num_vertices());
    ASSERT_EQ(m.num_halfedges(), n.num_halfedges());
    ASSERT_EQ(m.num_faces(), n.num_faces());
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(a.vertexOfSample, b.vertexOfSample);
    const auto gm = m.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    const auto gn = n.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    std::size_t differing = 0;
    for (auto v : m.vertices())
        differing += (m.point(v) == n.point(v) && m.halfedge(v) == n.halfedge(v) && gm[v] == gn[v]) ? 0 : 1;
    for (auto h : m.halfedges())
        differing += (m.target(h) == n.target(h) && m.next(h) == n.next(h) && m.face(h) == n.face(h)) ? 0 : 1;
    const auto qm = m.property_map<fss::FaceIndex, float>(fss::props::faceQuality).first;
    const auto qn = n.property_map<fss::FaceIndex, float>(fss::props::faceQuality).first;
    for (auto f : m.faces())
        differing += (m.halfedge(f) == n.halfedge(f) && qm[f] == qn[f]) ? 0 : 1;
    EXPECT_EQ(differing, 0u);
    EXPECT_EQ(a.report.faces, b.report.faces);
    EXPECT_EQ(a.report.quads, b.report.quads);
    EXPECT_EQ(a.report.flipped, b.report.flipped);
    EXPECT_EQ(a.report.backFacing, b.report.backFacing);
    EXPECT_EQ(a.report.longEdges, b.report.longEdges);
    EXPECT_EQ(a.report.grazing, b.report.grazing);
    EXPECT_EQ(a.report.nonManifoldTriangles, b.report.nonManifoldTriangles);
}

} // namespace

TEST(ParallelStages, ThreadCountIsValidated) {
    EXPECT_THROW(fss::setScanThreads(-1), fss::InvalidInputError);
    fss::setScanThreads(3);
    EXPECT_EQ(fss::scanThreads(), 3);
    fss::setScanThreads(0);
    EXPECT_GE(fss::scanThreads(), 1);
}

TEST(ParallelStages, EveryThreadCountGivesTheSerialResult) {
    const fss::Mesh reference = load("fandisk.off");
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(reference), 181, 173);
    const fss::FrameBuffers buffers = fss::rasterizeOnCpu(reference, camera);
    // The current mesh: the reference whose faces have qualities, those on one side better than any sample
    // of this scan (so the quality mask drops the samples on it), the others input faces.
    fss::Mesh current = reference;
    auto quality =
        current.add_property_map<fss::FaceIndex, float>(fss::props::faceQuality, fss::kInputFaceQuality)
            .first;
    const double middle = fss::boundingBox(reference).center().x();
    for (auto f : current.faces())
        if (current.point(current.target(current.halfedge(f))).x() < middle) quality[f] = 1e-9f;

    const ScanRun serial = scan(1, reference, buffers, current);
    // The scenario exercises every stage: each drops or adds something.
    EXPECT_GT(serial.droppedLasso, 1000u);
    EXPECT_GT(serial.droppedQuality, 1000u);
    EXPECT_GT(serial.morphology.eroded, 100u);
    EXPECT_GT(serial.patch.report.faces, 5000u);
    EXPECT_GT(serial.mirroredPatch.report.faces, 5000u); // the other diagonal: a different, as large patch
    for (int threads : {2, 3}) {
        SCOPED_TRACE(threads);
        const ScanRun parallel = scan(threads, reference, buffers, current);
        expectSameSamples(serial.grid, parallel.grid);
        EXPECT_EQ(parallel.droppedLasso, serial.droppedLasso);
        EXPECT_EQ(parallel.droppedQuality, serial.droppedQuality);
        EXPECT_EQ(parallel.morphology.eroded, serial.morphology.eroded);
        EXPECT_EQ(parallel.morphology.restored, serial.morphology.restored);
        EXPECT_EQ(parallel.morphology.untriangulatable, serial.morphology.untriangulatable);
        expectSameMesh(serial.patch, parallel.patch);
        expectSameMesh(serial.mirroredPatch, parallel.mirroredPatch);
    }
}

// The lattice warped to the surface (warpLatticeToSurface, issue #20): its per-pixel bases are computed in
// row blocks, one per thread; the warp and the lattice's samples are bit-identical for 1, 2 and 3 threads.
TEST(ParallelStages, WarpedLatticeIsTheSameForEveryThreadCount) {
    const fss::Mesh reference = load("fandisk.off");
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(reference), 181, 173);
    const fss::FrameBuffers buffers = fss::rasterizeOnCpu(reference, camera);
    const fss::LatticeBasis basis = fss::chooseAdaptiveLattice(buffers, reference, 1.0, 35.0);
    const Eigen::Vector2d origin(-40.0, -30.0);
    const int rows = 320, cols = 300;
    // Both fits (ScanOptions::warpFollowsFit): the session 17 one, as old session files replay, and the
    // default, whose edge targets (turned by the fit's node bases) are computed in row blocks too.
    auto warp = [&](int threads, bool followFit) {
        ThreadsGuard guard(threads);
        return fss::warpLatticeToSurface(buffers, reference, 1.0, basis, origin, rows, cols, followFit);
    };
    auto lattice = [&](int threads) {
        ThreadsGuard guard(threads);
        fss::ScanWorkspace workspace;
        return fss::sampleLattice(buffers, reference, workspace, {.scanId = 7}); // adaptive, warped
    };
    const std::vector<Eigen::Vector2d> serial = warp(1, false), serialFollow = warp(1, true);
    const fss::SampleGrid serialGrid = lattice(1);
    ASSERT_EQ(serial.size(), std::size_t(rows) * std::size_t(cols));
    // The warp moves the lattice (fandisk's iso view is slanted differently on every face).
    double moved = 0;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            moved = std::max(
                moved, (serial[std::size_t(r * cols + c)] - (origin + c * basis.a + r * basis.b)).norm());
    EXPECT_GT(moved, 1.0); // measured 1.95 px
    EXPECT_GT(serialGrid.admissibleCount(), 10000u);
    for (int threads : {2, 3}) {
        SCOPED_TRACE(threads);
        const std::vector<Eigen::Vector2d> parallel = warp(threads, false), follow = warp(threads, true);
        ASSERT_EQ(parallel.size(), serial.size());
        ASSERT_EQ(follow.size(), serial.size());
        std::size_t differing = 0, differingFollow = 0;
        for (std::size_t i = 0; i < serial.size(); ++i) {
            differing += serial[i] == parallel[i] ? 0 : 1;
            differingFollow += serialFollow[i] == follow[i] ? 0 : 1;
        }
        EXPECT_EQ(differing, 0u);
        EXPECT_EQ(differingFollow, 0u);
        expectSameSamples(serialGrid, lattice(threads));
    }
}

TEST(ParallelStages, AnErrorInAnyBlockIsReported) {
    const fss::Mesh reference = load("fandisk.off");
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(reference), 64, 64);
    fss::FrameBuffers buffers = fss::rasterizeOnCpu(reference, camera);
    // A face id the mesh does not have, in the last covered pixel (the last block's rows).
    for (std::size_t i = buffers.faceId.size(); i-- > 0;)
        if (buffers.faceId[i] != fss::FrameBuffers::kNoFace) {
            buffers.faceId[i] = std::uint32_t(reference.num_faces() + 5);
            break;
        }
    for (int threads : {1, 2, 3}) {
        ThreadsGuard guard(threads);
        EXPECT_THROW(fss::sampleRegularGrid(buffers, reference), fss::InvalidInputError) << threads;
    }
}
