// One regular scan, stage by stage, at 256², 512², 1024² of a 100k- and a 1M-face torus, on the square
// pixel lattice (lattice:0) and the triangular lattice (lattice:1, sampleLattice): GPU render and
// read-back (Rasterizer statistics) against our CPU stages (unprojection into the SampleGrid, lasso,
// quality mask against the current mesh, erosion + dilation, grid triangulation). The paper claims the
// sampling adds "only few overhead" to the render: target CPU stages ≤ 30 % of render + read-back.
// Counters: render_ms, read_ms, sample_ms, lasso_ms, quality_ms, morph_ms, triangulate_ms (wall clock),
// cpu_ms = their sum and cpu_over_gpu = cpu_ms / (render_ms + read_ms), the ratio; threads = the
// threads our stages use (fss::scanThreads(); set FSS_SCAN_THREADS=1 for the serial figures) and
// cpu_work_ms = the CPU time all threads of the process spent in our stages (unlike the wall-clock
// figures, it hardly changes when other processes compete for the cores); faults = minor page faults of
// the process during our stages (first touches of freshly allocated memory), per scan.
//
// The scans run as an interactive session runs them, one after the other with one fss::ScanWorkspace:
// each scan's grid and patch are recycled into it when the next scan starts, so the stages refill memory
// they used before instead of faulting in fresh pages (scan_workspace.h). The first scan, which allocates,
// is not measured. FSS_SCAN_FRESH=1 measures without a workspace instead (every scan allocates afresh).
//
// floor_ms (not part of cpu_ms) is a lower bound for any implementation that returns these results: only
// making the outputs of a scan of this size in the same memory as the scans (recycled, or fresh with
// FSS_SCAN_FRESH=1) — the SampleGrid of rows × cols samples (one field of every sample written) and the
// Patch with the patch's vertex, edge and face counts (Surface_mesh sized, its points, halfedge
// connectivity and our three properties written with trivial values, vertexOfSample) — and no
// computation at all. floor_over_gpu = floor_ms / (render_ms + read_ms): the ratio no implementation
// can go below.
//
// What a real scan pays: setMesh() uploads the mesh to the GL at the first render after it, once; every
// later scan of the same mesh renders without an upload (Rasterizer::uploadCount). So the scene renders
// once before it is measured, and a benchmark whose timed renders upload anything fails. (Google Benchmark
// reports the last of its runs, and with a 1 M-face mesh a one-iteration run can be the reported one:
// without the warm-up that run's render_ms held the upload, about 1.9 s under load against 0.3–0.5 s.)
#include "fss/camera.h"
#include "fss/mask.h"
#include "fss/metrics.h"
#include "fss/parallel.h"
#include "fss/render/gpu_mesh_renderer.h"
#include "fss/render/rasterizer.h"
#include "fss/scan.h"
#include "fss/scan_pipeline.h"
#include "fss/scan_workspace.h"
#include "fss/shapes.h"
#include "fss/triangulate.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <sys/resource.h>

namespace {

// The outputs of a scan with the given grid and patch sizes, written without computing anything (see
// floor_ms in the file comment). Returns something that depends on every output so nothing is elided.
// \p grid and \p patch are the storage to write into: empty ones (fresh memory) or those of the last call.
std::size_t writeOutputsOnly(int rows, int cols, std::size_t vertices, std::size_t edges, std::size_t faces,
                             fss::SampleGrid& grid, fss::Patch& patch) {
    grid.rows = rows;
    grid.cols = cols;
    grid.samples.resize(std::size_t(rows) * std::size_t(cols));
    for (fss::Sample& s : grid.samples)
        s.quality = 1.0f;
    patch.rows = rows;
    patch.cols = cols;
    patch.vertexOfSample.assign(grid.samples.size(), fss::Mesh::null_vertex());
    fss::Mesh& mesh = patch.mesh;
    mesh.resize(0, 0, 0);
    mesh.resize(fss::Mesh::size_type(vertices), fss::Mesh::size_type(edges), fss::Mesh::size_type(faces));
    auto gridIndex =
        mesh.add_property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex, fss::GridIndex{})
            .first;
    auto quality = mesh.add_property_map<fss::FaceIndex, float>(fss::props::faceQuality, 0.0f).first;
    auto scanId = mesh.add_property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId, -1).first;
    for (std::size_t v = 0; v < vertices; ++v) {
        const fss::VertexIndex vi(static_cast<fss::Mesh::size_type>(v));
        mesh.point(vi) = fss::Point3(double(v), 0.0, 0.0);
        gridIndex[vi] = {std::int32_t(v / std::size_t(cols)), std::int32_t(v % std::size_t(cols))};
        mesh.set_halfedge(vi, fss::HalfedgeIndex(static_cast<fss::Mesh::size_type>(v)));
        patch.vertexOfSample[v] = vi;
    }
    for (std::size_t h = 0; h < 2 * edges; ++h) {
        const fss::HalfedgeIndex hi(static_cast<fss::Mesh::size_type>(h));
        mesh.set_target(hi, fss::VertexIndex(static_cast<fss::Mesh::size_type>(h % vertices)));
        mesh.set_next(hi, fss::HalfedgeIndex(static_cast<fss::Mesh::size_type>((h + 2) % (2 * edges))));
        mesh.set_face(hi, fss::FaceIndex(static_cast<fss::Mesh::size_type>(h % faces)));
    }
    for (std::size_t f = 0; f < faces; ++f) {
        const fss::FaceIndex fi(static_cast<fss::Mesh::size_type>(f));
        mesh.set_halfedge(fi, fss::HalfedgeIndex(static_cast<fss::Mesh::size_type>(3 * f)));
        quality[fi] = 1.0f;
        scanId[fi] = 0;
    }
    return mesh.number_of_halfedges() + grid.samples.size() + std::size_t(patch.vertexOfSample.back().idx());
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// CPU time of all threads of the process, milliseconds.
double processCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// Minor page faults of the process so far.
double minorFaults() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_minflt);
}

struct Scene {
    fss::Mesh mesh;
    fss::Mesh current; // the mesh with a face-quality property, as after a first stitch
    fss::render::Rasterizer rasterizer;
    Eigen::AlignedBox3d box;
};

// torus(nu, nv) has 2·nu·nv faces: a self-occluding closed surface with exact face counts.
Scene& sceneWith(int faces) {
    static std::map<int, std::unique_ptr<Scene>> cache;
    auto& s = cache[faces];
    if (!s) {
        s = std::make_unique<Scene>();
        const int nu = faces >= 1000000 ? 1000 : faces >= 100000 ? 250 : 100;
        s->mesh = fss::shapes::torus(nu, faces / (2 * nu), 1.0, 0.35);
        s->rasterizer.setMesh(s->mesh);
        s->current = s->mesh;
        s->current.add_property_map<fss::FaceIndex, float>(fss::props::faceQuality, fss::kInputFaceQuality);
        for (auto v : s->mesh.vertices()) {
            const auto& p = s->mesh.point(v);
            s->box.extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
        }
        // The one-off upload of the mesh happens here, not in a measured scan (see the file comment).
        s->rasterizer.render(fss::Camera::standardView(fss::StandardView::Iso, s->box, 64, 64));
    }
    return *s;
}

void BM_ScanStages(benchmark::State& state) {
    const int faces = int(state.range(0)), res = int(state.range(1));
    fss::ScanOptions scanOptions; // lattice 0: the square pixel lattice, 1: the triangular one (issue #20)
    scanOptions.lattice = state.range(2) != 0 ? fss::Lattice::Triangular : fss::Lattice::Square;
    Scene& scene = sceneWith(faces);
    const fss::Camera camera = fss::Camera::standardView(fss::StandardView::Iso, scene.box, res, res);
    const fss::Lasso lasso{
        {{0.1 * res, 0.1 * res}, {0.9 * res, 0.15 * res}, {0.8 * res, 0.9 * res}, {0.15 * res, 0.8 * res}}};
    double render = 0, read = 0, sample = 0, lassoMs = 0, quality = 0, morph = 0, tri = 0, work = 0;
    double faults = 0, floor = 0;
    std::size_t patchFaces = 0;
    const bool fresh = std::getenv("FSS_SCAN_FRESH") && std::atoi(std::getenv("FSS_SCAN_FRESH")) != 0;
    fss::ScanWorkspace workspace;
    fss::SampleGrid grid, floorGrid;
    fss::Patch patch, floorPatch;
    // One unmeasured scan: the workspace's first use allocates, as a session's first scan does.
    const auto scanOnce = [&](const fss::FrameBuffers& buffers, auto&& timed) {
        if (!fresh) { // the previous scan's outputs are no longer needed
            workspace.recycle(std::move(grid));
            workspace.recycle(std::move(patch));
        } else {
            workspace.release();
            grid = fss::SampleGrid();
            patch = fss::Patch();
        }
        timed([&] { grid = fss::sampleLattice(buffers, scene.mesh, workspace, scanOptions); }, sample);
        timed([&] { fss::applyLasso(grid, lasso); }, lassoMs);
        // The current mesh is the input itself here, with face qualities (without them the mask need not
        // know which face is closest): every sample looks up its face.
        timed([&] { fss::applyQualityMask(grid, scene.current, buffers); }, quality);
        timed([&] { fss::applyMorphology(grid, {.radius = 1}, workspace); }, morph);
        timed([&] { patch = fss::triangulateGrid(grid, {}, workspace); }, tri);
    };
    scanOnce(scene.rasterizer.render(camera), [](auto&& stage, double&) { stage(); });
    writeOutputsOnly(grid.rows, grid.cols, patch.mesh.number_of_vertices(), patch.mesh.number_of_edges(),
                     patch.mesh.number_of_faces(), floorGrid, floorPatch);
    const std::uint64_t uploads = scene.rasterizer.uploadCount();
    for (auto _ : state) {
        const fss::FrameBuffers buffers = scene.rasterizer.render(camera);
        render += scene.rasterizer.lastStats().renderSeconds * 1e3;
        read += scene.rasterizer.lastStats().readSeconds * 1e3;
        const double cpu0 = processCpuMs(), faults0 = minorFaults();
        scanOnce(buffers, [&](auto&& stage, double& ms) {
            const auto t = Clock::now();
            stage();
            ms += msSince(t);
        });
        work += processCpuMs() - cpu0;
        faults += minorFaults() - faults0;
        patchFaces = patch.mesh.number_of_faces();
        benchmark::DoNotOptimize(patchFaces);
        if (fresh) {
            floorGrid = fss::SampleGrid();
            floorPatch = fss::Patch();
        }
        const auto t = Clock::now();
        benchmark::DoNotOptimize(writeOutputsOnly(grid.rows, grid.cols, patch.mesh.number_of_vertices(),
                                                  patch.mesh.number_of_edges(), patchFaces, floorGrid,
                                                  floorPatch));
        floor += msSince(t);
    }
    if (scene.rasterizer.uploadCount() != uploads) {
        state.SkipWithError("the measured renders uploaded the mesh: render_ms is not what a scan pays");
        return;
    }
    const double n = double(state.iterations());
    const double cpu = (sample + lassoMs + quality + morph + tri) / n;
    state.counters["render_ms"] = render / n;
    state.counters["read_ms"] = read / n;
    state.counters["sample_ms"] = sample / n;
    state.counters["lasso_ms"] = lassoMs / n;
    state.counters["quality_ms"] = quality / n;
    state.counters["morph_ms"] = morph / n;
    state.counters["triangulate_ms"] = tri / n;
    state.counters["cpu_ms"] = cpu;
    state.counters["cpu_over_gpu"] = cpu / ((render + read) / n);
    state.counters["patch_faces"] = double(patchFaces);
    state.counters["threads"] = fss::scanThreads();
    state.counters["cpu_work_ms"] = work / n;
    state.counters["faults"] = faults / n;
    state.counters["floor_ms"] = floor / n;
    state.counters["floor_over_gpu"] = (floor / n) / ((render + read) / n);
}

// The whole regular scan (scanPatch, with a workspace as a session scans) on the default adaptive lattice,
// warped to the surface (warp:1, ScanOptions::warpToSurface, the default since session file version 3) or
// not (warp:0): what the warp costs (issue #20). The first scan is not measured (allocations, upload).
// Counters: sample_ms (the lattice chosen, warped and sampled), scan_ms (render to patch), patch_faces and
// mean_min_angle (the patch's mean smallest angle, degrees: what the warp buys). The scan times of every
// run are kept for the table of warped / plain that main prints at the end (issue #20's target: ≤ 2).
std::map<std::pair<int, int>, std::vector<double>> warpScanMs; // (faces, warp) -> scan_ms of each run

void BM_ScanWarp(benchmark::State& state) {
    const int faces = int(state.range(0)), res = int(state.range(1));
    Scene& scene = sceneWith(faces);
    static std::map<int, std::unique_ptr<fss::render::GpuMeshRenderer>> renderers; // scanPatch's interface
    auto& renderer = renderers[faces];
    if (!renderer) {
        renderer = std::make_unique<fss::render::GpuMeshRenderer>();
        renderer->setMesh(scene.mesh);
    }
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(fss::StandardView::Iso, scene.box, res, res);
    params.scan.lattice = fss::Lattice::Adaptive;
    params.scan.warpToSurface = state.range(2) != 0;
    fss::ScanWorkspace workspace;
    fss::ScanResult result = fss::scanPatch(scene.mesh, *renderer, scene.mesh, *renderer, params, workspace);
    double sample = 0, total = 0;
    for (auto _ : state) {
        workspace.recycle(std::move(result.grid));
        workspace.recycle(std::move(result.patch));
        result = fss::scanPatch(scene.mesh, *renderer, scene.mesh, *renderer, params, workspace);
        sample += result.timings.sample * 1e3;
        total += result.timings.total * 1e3;
        benchmark::DoNotOptimize(result.patch.mesh.number_of_faces());
    }
    const double n = double(state.iterations());
    state.counters["sample_ms"] = sample / n;
    state.counters["scan_ms"] = total / n;
    warpScanMs[{faces, int(state.range(2))}].push_back(total / n);
    state.counters["patch_faces"] = double(result.patch.mesh.number_of_faces());
    state.counters["mean_min_angle"] =
        fss::computeMetrics(result.patch.mesh, {.selfIntersections = false}).meanMinAngleDeg;
}

} // namespace

// FSS_SCAN_THREADS=N sets fss::setScanThreads(N) before the benchmarks run.
const bool threadsFromEnvironment = [] {
    if (const char* v = std::getenv("FSS_SCAN_THREADS")) fss::setScanThreads(std::atoi(v));
    return true;
}();

BENCHMARK(BM_ScanStages)
    ->ArgsProduct({{100000, 1000000}, {256, 512, 1024}, {0, 1}})
    ->ArgNames({"faces", "res", "lattice"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_ScanWarp)
    ->ArgsProduct({{10000, 100000}, {256}, {0, 1}})
    ->ArgNames({"faces", "res", "warp"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    // The warped scan against the plain adaptive one (BM_ScanWarp), medians over the repetitions.
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    };
    bool header = false;
    for (const auto& [key, runs] : warpScanMs) {
        const auto plain = warpScanMs.find({key.first, 0});
        if (key.second == 0 || plain == warpScanMs.end()) continue;
        if (!header)
            std::printf("\n%9s %14s %15s %13s %5s\n", "faces", "plain scan ms", "warped scan ms",
                        "warped/plain", "runs");
        header = true;
        const double p = median(plain->second), w = median(runs);
        std::printf("%9d %14.1f %15.1f %13.2f %5zu\n", key.first, p, w, w / p, runs.size());
    }
    if (header) std::printf("target: warped/plain <= 2 at every size (issue #20)\n");
    return 0;
}
