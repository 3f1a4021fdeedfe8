// Stitching cost against mesh size (issue #4): the same 256² patch (a round lasso of radius 100 px, about
// 31k samples) stitched into the same shape — a unit UV sphere of 10k, 100k and 1M faces — through the
// ID-buffer path (stitchPatch's faceIds: the current mesh's ID render from the scan camera). Work must be
// proportional to the patch and the seam, not to the mesh: target stitch time at 1M faces < 1.5 × that at
// 10k. Also the scan time of the same patch (GPU render of the reference + sampling + masks +
// triangulation; CPU ray casting when FSS::render is not built) and the ratio stitch / scan.
//
// BM_Stitch/faces:N/spare:S   stitch time only: CPU time of the stitching thread (the machine is shared; wall
// time
//                     in the counter wall_ms); copying the mesh before each stitch is not timed.
//                     Counters: patch_faces, faces_removed, faces_added, seam_edges.
// BM_StitchWide/faces:N/spare:1  the same with a patch scanned in a 50° view (the widget's case, params()),
//                     not in the table printed after the runs.
// FSS_STITCH_REMESH=1 (0) turns the seam band remesh on (off), FSS_STITCH_CORE_BYPASS=0 the
// core bypass off (DESIGN.md §6.1), FSS_STITCH_PROFILE=1 prints the stages' CPU time per stitch.
// BM_Scan/faces:N/warp:W  scanPatch of the same view and lasso on the sphere of N faces, W = 1 the default
//                     scan (the warped lattice), W = 0 the plain adaptive lattice (ScanOptions::warpToSurface
//                     off): time = CPU time of the calling thread, wall_ms = wall time including the GL
//                     driver's own threads.
// After the runs the program prints stitch(1M) / stitch(10k) and stitch / scan per size, against both scans
// (issue 19's target is against the default scan: what a user's scan costs).
#include "fss/camera.h"
#include "fss/error.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"
#include "fss/stitch.h"

#if __has_include("fss/render/gpu_mesh_renderer.h")
#include "fss/render/gpu_mesh_renderer.h"
#define FSS_BENCH_GPU 1
#endif

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

std::unique_ptr<fss::MeshRenderer> makeRenderer() {
#ifdef FSS_BENCH_GPU
    return std::make_unique<fss::render::GpuMeshRenderer>();
#else
    return std::make_unique<fss::CpuMeshRenderer>();
#endif
}

// uvSphere(nu, nv) has 2·nu·(nv − 1) faces.
fss::Mesh sphereWith(int faces) {
    if (faces == 10000) return fss::shapes::uvSphere(100, 51);
    if (faces == 100000) return fss::shapes::uvSphere(250, 201);
    return fss::shapes::uvSphere(1000, 501);
}

// wide: a 50° view instead of 25°, the same lasso in pixels, so the patch covers several times the sphere's
// area (98k patch faces instead of 73k; faces removed at 1M: 175k instead of 23k), as the widget's accept
// test does (tests/widgets acceptLatency: the whole sphere in the view, a lasso of a third of its height:
// 250k faces removed at 1M).
fss::ScanParams params(bool wide = false) {
    fss::ScanParams p;
    fss::Camera& c = p.camera;
    c.width = c.height = 256;
    c.focal = {0, 0, 0};
    c.eye = Eigen::Vector3d(1, 0.3, 0.2).normalized() * 3.0; // near the equator, away from the poles
    c.up = {0, 0, 1};
    c.viewAngleDeg = wide ? 50 : 25;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
    fss::Lasso lasso;
    for (int i = 0; i < 64; ++i) {
        const double a = 2 * 3.14159265358979 * i / 64;
        lasso.points.emplace_back(128 + 100 * std::cos(a), 128 + 100 * std::sin(a));
    }
    p.lasso = lasso;
    p.scan.scanId = 1;
    return p;
}

struct Scene {
    fss::Mesh mesh;
    std::unique_ptr<fss::MeshRenderer> renderer;
    std::vector<std::uint32_t> ids; // ID buffer of the mesh from the scan camera
    fss::Camera camera;             // the scan camera (clipping range as rendered)
};

// The patch: scanned once from the 1M-face sphere, stitched into every size.
const fss::Patch& thePatch(bool wide = false) {
    static std::map<bool, fss::Patch> patches;
    auto it = patches.find(wide);
    if (it == patches.end()) {
        const fss::Mesh ref = sphereWith(1000000);
        auto r = makeRenderer();
        r->setMesh(ref);
        it = patches.emplace(wide, fss::scanPatch(ref, *r, ref, *r, params(wide)).patch).first;
    }
    return it->second;
}

Scene& sceneWith(int faces, bool wide = false) {
    static std::map<std::pair<int, bool>, std::unique_ptr<Scene>> cache;
    auto& s = cache[{faces, wide}];
    if (!s) {
        s = std::make_unique<Scene>();
        s->mesh = sphereWith(faces);
        // As after a first stitch: the face properties exist (creating them is O(mesh), once per session).
        s->mesh.add_property_map<fss::FaceIndex, float>(fss::props::faceQuality, fss::kInputFaceQuality);
        s->mesh.add_property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId, -1);
        s->renderer = makeRenderer();
        s->renderer->setMesh(s->mesh);
        const fss::FrameBuffers fb = s->renderer->render(params(wide).camera);
        s->ids = fb.faceId;
        s->camera = fb.camera;
    }
    return *s;
}

// FSS_STITCH_REMESH=1 / 0: the seam band remesh on / off (StitchOptions::remeshSeam; unset: the default).
fss::StitchOptions stitchOptions() {
    fss::StitchOptions o;
    if (const char* e = std::getenv("FSS_STITCH_REMESH")) o.remeshSeam = std::string(e) == "1";
    return o;
}

// Per size, one figure per run of the benchmark (--benchmark_repetitions=N: N runs); the table after the runs
// gives their medians (the machine is shared: one run can be off by a third).
// Scans by (faces, warp).
std::map<int, std::vector<double>> stitchMs, stitchWallMs;
std::map<std::pair<int, bool>, std::vector<double>> scanMs, scanCpuMs;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

void stitchBenchmark(benchmark::State& state, bool wide) {
    const int faces = int(state.range(0));
    const fss::Patch& patch = thePatch(wide);
    Scene& scene = sceneWith(faces, wide);
    fss::StitchReport report;
    double total = 0, wall = 0;
    for (auto _ : state) {
        fss::Mesh current = scene.mesh;
        if (state.range(1)) {
            // Spare capacity, as a mesh in a session has after its first stitches (its arrays grow by
            // doubling): the first growth beyond a freshly copied mesh's exact capacity reallocates every
            // property array, O(mesh) once, amortised O(1) per added element.
            const std::size_t pf = patch.mesh.number_of_faces(), pv = patch.mesh.number_of_vertices();
            current.reserve(current.number_of_vertices() + 2 * pv, current.number_of_edges() + 4 * pf,
                            current.number_of_faces() + 2 * pf);
        }
        const auto t = Clock::now();
        const double c0 = threadCpuSeconds();
        report = fss::stitchPatch(current, patch.mesh, scene.camera, stitchOptions(), scene.ids);
        const double cpu = threadCpuSeconds() - c0;
        wall += std::chrono::duration<double>(Clock::now() - t).count();
        // The machine is shared: CPU time of this thread is the stable figure (stitching is single-threaded).
        state.SetIterationTime(cpu);
        total += cpu;
        benchmark::DoNotOptimize(current);
    }
    if (state.range(1) && !wide) {
        stitchMs[faces].push_back(1e3 * total / double(state.iterations()));
        stitchWallMs[faces].push_back(1e3 * wall / double(state.iterations()));
    }
    state.counters["wall_ms"] = 1e3 * wall / double(state.iterations());
    state.counters["patch_faces"] = double(patch.mesh.number_of_faces());
    state.counters["faces_removed"] = double(report.facesRemoved);
    state.counters["faces_added"] = double(report.facesAdded);
    state.counters["seam_edges"] = double(report.seamEdges);
}

void BM_Stitch(benchmark::State& state) {
    stitchBenchmark(state, false);
}

// The widget's case (a patch over many more faces of the mesh than BM_Stitch's): not in the table below.
void BM_StitchWide(benchmark::State& state) {
    stitchBenchmark(state, true);
}

void BM_Scan(benchmark::State& state) {
    const int faces = int(state.range(0));
    Scene& scene = sceneWith(faces);
    const bool warp = state.range(1) != 0;
    fss::ScanParams p = params();
    // warp 0: the plain adaptive lattice (the patch stitched above is the default scan's either way).
    if (!warp) p.scan.warpToSurface = false;
    double total = 0;
    std::size_t patchFaces = 0;
    double wall = 0;
    for (auto _ : state) {
        const auto t = Clock::now();
        const double c0 = threadCpuSeconds();
        const fss::ScanResult r = fss::scanPatch(scene.mesh, *scene.renderer, scene.mesh, *scene.renderer, p);
        wall += std::chrono::duration<double>(Clock::now() - t).count();
        // CPU time of this thread (the GL driver's threads not included: llvmpipe renders on its own).
        state.SetIterationTime(threadCpuSeconds() - c0);
        total += threadCpuSeconds() - c0;
        patchFaces = r.patch.mesh.number_of_faces();
        benchmark::DoNotOptimize(patchFaces);
    }
    scanMs[{faces, warp}].push_back(1e3 * wall / double(state.iterations()));
    scanCpuMs[{faces, warp}].push_back(1e3 * total / double(state.iterations()));
    state.counters["wall_ms"] = 1e3 * wall / double(state.iterations());
    state.counters["patch_faces"] = double(patchFaces);
}

} // namespace

// Second argument: 1 = the mesh has spare capacity (steady state of a session), 0 = a fresh copy whose
// arrays must grow during the stitch (the first stitch into a loaded mesh).
BENCHMARK(BM_Stitch)
    ->ArgsProduct({{10000, 100000, 1000000}, {1, 0}})
    ->ArgNames({"faces", "spare"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK(BM_StitchWide)
    ->ArgsProduct({{100000, 1000000}, {1}})
    ->ArgNames({"faces", "spare"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK(BM_Scan)
    ->ArgsProduct({{10000, 100000, 1000000}, {1, 0}})
    ->ArgNames({"faces", "warp"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    // Scan and stitch side by side (issue 19's targets: stitch <= 2 x the default scan at every size, 1M /
    // 10k
    // <= 1.5); medians over the repetitions. Against the default (warped) scan and the plain one.
    for (const bool warp : {true, false}) {
        std::printf("\nagainst the %s scan\n", warp ? "default (warped)" : "plain adaptive");
        std::printf("%9s %13s %12s %14s %15s %18s %17s %5s\n", "faces", "scan wall ms", "scan CPU ms",
                    "stitch CPU ms", "stitch wall ms", "stitch/scan wall", "stitch/scan CPU", "runs");
        for (const auto& [faces, runs] : stitchMs)
            if (scanMs.count({faces, warp})) {
                const double st = median(runs), sw = median(stitchWallMs[faces]),
                             cw = median(scanMs[{faces, warp}]), cc = median(scanCpuMs[{faces, warp}]);
                std::printf("%9d %13.1f %12.1f %14.1f %15.1f %18.2f %17.2f %5zu\n", faces, cw, cc, st, sw,
                            sw / cw, st / cc, runs.size());
            }
    }
    if (stitchMs.count(10000) && stitchMs.count(1000000))
        std::printf("stitch CPU time 1M / 10k faces: %.2f (target <= 1.5)\n",
                    median(stitchMs[1000000]) / median(stitchMs[10000]));
    return 0;
}
