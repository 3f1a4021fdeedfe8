// Issue 5, deliverable 7: a fishbone scan costs at most 2x a regular scan with the same number of samples.
//
// Per mesh (fandisk, 13k faces; a 100k-face torus), one GPU renderer (head-less) for both scans:
//  * fishbone: scanFishbonePatch with h = 2 pixels at 512² and with h = 1 pixel at 256² (the same view: the
//    same surface region and about the same number of samples; automatic mode, seed on a curved region).
//    At h = 1 the fishbone renders one pixel per sample, as the regular scan does. At h = 2 it samples by
//    default (FishboneParams::samplingFactor, argument k = 0) on the 256² image, one pixel per sample too;
//    with k = 1 it renders and computes its direction fields on all 512² pixels, four per sample;
//  * regular:  scanPatch with the same camera at the resolution whose covered-pixel count equals the
//    fishbone's sample count (calibrated once before timing: covered ∝ resolution²).
// Both scans run alternately in the same loop; counters: fishbone_ms, regular_ms, ratio =
// fishbone_ms / regular_ms (wall clock: the target), cpu_ratio (the same with the process's CPU time, all
// threads: steadier than the wall clock when the machine is shared), the two sample counts, and the stage
// times of the fishbone scan. The direction fields are lazy (computed per tile while tracing, so their cost
// is in f_trace_ms); f_dir_pixels counts the pixels they computed. Curvature and the AABB tree are
// per-reference precomputations (cached in FishboneCache, as the Session keeps them): measured once before
// the loop and reported as curvature_ms / aabb_ms, not in fishbone_ms.
#include "fss/fishbone_scan.h"
#include "fss/mesh_io.h"
#include "fss/parallel.h"
#include "fss/render/gpu_mesh_renderer.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// CPU time of the whole process (all threads, llvmpipe's included) in milliseconds: a load-independent
// companion of the wall-clock ratio when other work shares the machine.
double processCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

struct Scene {
    fss::Mesh mesh;
    fss::Camera camera;
    Eigen::Vector2d seed;
};

Eigen::AlignedBox3d bbox(const fss::Mesh& m) {
    Eigen::AlignedBox3d b;
    for (auto v : m.vertices())
        b.extend(Eigen::Vector3d(m.point(v).x(), m.point(v).y(), m.point(v).z()));
    return b;
}

Scene makeScene(int which, int resolution) {
    Scene s;
    const int R = resolution;
    if (which == 0) {
        s.mesh = fss::readMesh(std::string(FSS_BENCH_MESH_DIR) + "/fandisk.off");
        s.camera = fss::Camera::standardView(fss::StandardView::Iso, bbox(s.mesh), R, R);
        s.seed = {0.4 * R, 0.55 * R}; // on fandisk's curved middle feature (as the CLI test)
    } else {
        s.mesh = fss::shapes::torus(250, 200, 1.0, 0.35);
        s.camera = fss::Camera::standardView(fss::StandardView::Iso, bbox(s.mesh), R, R);
        const Eigen::Vector3d p =
            1.35 * Eigen::Vector3d(1, 1, 0).normalized(); // outer equator, facing the eye
        const Eigen::Vector3d q = s.camera.project(p);
        s.seed = {q.x(), q.y()};
    }
    return s;
}

void BM_FishboneVsRegular(benchmark::State& state) {
    const int h = int(state.range(1)), resolution = 256 * h;
    const Scene scene = makeScene(int(state.range(0)), resolution);
    fss::render::GpuMeshRenderer renderer;
    renderer.setMesh(scene.mesh);
    fss::FishboneCache cache;
    auto t = Clock::now();
    cache.curvature(scene.mesh);
    const double curvatureMs = msSince(t);
    t = Clock::now();
    cache.rayCaster(scene.mesh);
    const double aabbMs = msSince(t);

    fss::ScanParams fishParams;
    fishParams.camera = scene.camera;
    fss::FishboneParams fb;
    fb.seed = scene.seed;
    fb.spacing = double(h);
    fb.samplingFactor = int(state.range(2));
    const fss::FishboneScanResult probe =
        fss::scanFishbonePatch(scene.mesh, renderer, scene.mesh, renderer, fishParams, fb, cache);
    const std::size_t fishSamples = probe.counts.covered;

    // Calibrate the regular scan's resolution to the same number of samples.
    fss::ScanParams regParams;
    regParams.camera = scene.camera;
    const fss::ScanResult full = fss::scanPatch(scene.mesh, renderer, scene.mesh, renderer, regParams);
    const int res = std::max(
        8, int(std::lround(resolution * std::sqrt(double(fishSamples) / double(full.counts.covered)))));
    regParams.camera.width = regParams.camera.height = res;

    double fishCpu = 0, regCpu = 0;
    double fishMs = 0, regMs = 0, dirMs = 0, traceMs = 0, castMs = 0, renderMs = 0, maskMs = 0, triMs = 0;
    std::size_t regSamples = 0, dirPixels = 0;
    for (auto _ : state) {
        double c = processCpuMs();
        t = Clock::now();
        const fss::FishboneScanResult f =
            fss::scanFishbonePatch(scene.mesh, renderer, scene.mesh, renderer, fishParams, fb, cache);
        fishMs += msSince(t);
        fishCpu += processCpuMs() - c;
        c = processCpuMs();
        t = Clock::now();
        const fss::ScanResult r = fss::scanPatch(scene.mesh, renderer, scene.mesh, renderer, regParams);
        regMs += msSince(t);
        regCpu += processCpuMs() - c;
        regSamples = r.counts.covered;
        dirPixels = f.counts.directionPixels;
        renderMs += f.timings.renderReference * 1e3;
        dirMs += f.timings.directionField * 1e3;
        traceMs += f.timings.tracing * 1e3;
        castMs += f.timings.rayCasting * 1e3;
        maskMs += f.timings.masks * 1e3;
        triMs += f.timings.triangulate * 1e3;
        benchmark::DoNotOptimize(f.patch.mesh.number_of_faces());
        benchmark::DoNotOptimize(r.patch.mesh.number_of_faces());
    }
    const double n = double(state.iterations());
    state.counters["fishbone_ms"] = fishMs / n;
    state.counters["regular_ms"] = regMs / n;
    state.counters["ratio"] = fishMs / regMs;
    state.counters["cpu_ratio"] = fishCpu / regCpu;
    state.counters["fish_samples"] = double(fishSamples);
    state.counters["reg_samples"] = double(regSamples);
    state.counters["reg_res"] = res;
    state.counters["f_render_ms"] = renderMs / n;
    state.counters["f_dirfield_ms"] = dirMs / n;
    state.counters["f_trace_ms"] = traceMs / n;
    state.counters["f_dir_pixels"] = double(dirPixels);
    state.counters["f_raycast_ms"] = castMs / n;
    state.counters["f_masks_ms"] = maskMs / n;
    state.counters["f_tri_ms"] = triMs / n;
    state.counters["curvature_ms"] = curvatureMs;
    state.counters["aabb_ms"] = aabbMs;
    state.counters["threads"] = fss::scanThreads();
    state.counters["k"] = probe.samplingFactor;
    state.SetLabel(std::string(state.range(0) == 0 ? "fandisk" : "torus 100k") +
                   ", h = " + std::to_string(h) + " px at " + std::to_string(resolution) +
                   "², sampling image " + std::to_string(probe.grid.camera.width) + "²");
}

} // namespace

// FSS_SCAN_THREADS=N sets fss::setScanThreads(N) before the benchmarks run (both scans use it).
const bool threadsFromEnvironment = [] {
    if (const char* v = std::getenv("FSS_SCAN_THREADS")) fss::setScanThreads(std::atoi(v));
    return true;
}();

BENCHMARK(BM_FishboneVsRegular)
    ->ArgNames({"mesh", "h", "k"})
    ->Args({0, 2, 0})
    ->Args({0, 2, 1})
    ->Args({0, 1, 0})
    ->Args({1, 2, 0})
    ->Args({1, 2, 1})
    ->Args({1, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10);

BENCHMARK_MAIN();
