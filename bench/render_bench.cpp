// Scan rasterizer: render + read-back time of the ID/depth scan at 256², 512², 1024² for a 100k- and a
// 1M-face mesh (tori from fss::shapes: exact face counts, self-occluding like a real part), with render
// and read-back timed separately (counters render_ms / read_ms), plus the one-off cost of setMesh and the
// first render (upload).
#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/render/rasterizer.h"
#include "fss/shapes.h"

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

namespace {

// torus(nu, nv) has 2·nu·nv faces.
const fss::Mesh& torusWithFaces(int faces) {
    static std::map<int, std::unique_ptr<fss::Mesh>> cache;
    auto& m = cache[faces];
    if (!m) {
        const int nu = faces == 1000000 ? 1000 : 250;
        m = std::make_unique<fss::Mesh>(fss::shapes::torus(nu, faces / (2 * nu), 1.0, 0.35));
    }
    return *m;
}

fss::render::Rasterizer& rasterizerWith(int faces) {
    static std::map<int, std::unique_ptr<fss::render::Rasterizer>> cache;
    auto& r = cache[faces];
    if (!r) {
        r = std::make_unique<fss::render::Rasterizer>();
        r->setMesh(torusWithFaces(faces));
    }
    return *r;
}

fss::Camera scanCamera(const Eigen::AlignedBox3d& box, int resolution, int step) {
    fss::Camera c = fss::Camera::standardView(fss::StandardView::Iso, box, resolution, resolution);
    c.zoom(1.3);
    // Turn a little every iteration: a real session never scans twice from the same camera.
    const double a = 0.01 * (step % 50);
    const Eigen::Vector3d d = c.eye - c.focal;
    c.eye = c.focal + Eigen::Vector3d(std::cos(a) * d.x() - std::sin(a) * d.y(),
                                      std::sin(a) * d.x() + std::cos(a) * d.y(), d.z());
    return c;
}

void BM_Scan(benchmark::State& state) {
    const int faces = int(state.range(0)), resolution = int(state.range(1));
    fss::render::Rasterizer& r = rasterizerWith(faces);
    fss::FrameBuffers fb;
    r.render(scanCamera(r.bounds(), resolution, 0), fb); // warm: upload, shaders, framebuffer size
    double renderSum = 0, readSum = 0;
    int step = 0;
    for (auto _ : state) {
        r.render(scanCamera(r.bounds(), resolution, ++step), fb);
        renderSum += r.lastStats().renderSeconds;
        readSum += r.lastStats().readSeconds;
        benchmark::DoNotOptimize(fb.faceId.data());
    }
    state.counters["render_ms"] = benchmark::Counter(1e3 * renderSum, benchmark::Counter::kAvgIterations);
    state.counters["read_ms"] = benchmark::Counter(1e3 * readSum, benchmark::Counter::kAvgIterations);
    state.counters["covered"] = double(fb.coveredCount());
    state.SetLabel(std::to_string(faces) + " faces, " + std::to_string(resolution) + "²");
}
BENCHMARK(BM_Scan)
    ->ArgsProduct({{100000, 1000000}, {256, 512, 1024}})
    ->ArgNames({"faces", "px"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime() // CPU column: all threads (llvmpipe renders on worker threads)
    ->UseRealTime();

// setMesh + the first render at 512² (VTK uploads the buffers then): what changing the mesh costs.
void BM_SetMeshAndFirstScan(benchmark::State& state) {
    const int faces = int(state.range(0));
    const fss::Mesh& mesh = torusWithFaces(faces);
    fss::render::Rasterizer r;
    fss::FrameBuffers fb;
    r.setMesh(mesh);
    r.render(scanCamera(r.bounds(), 512, 0), fb); // shaders compiled once
    for (auto _ : state) {
        r.setMesh(mesh);
        r.render(scanCamera(r.bounds(), 512, 1), fb);
        benchmark::DoNotOptimize(fb.faceId.data());
    }
    state.SetLabel(std::to_string(faces) + " faces");
}
BENCHMARK(BM_SetMeshAndFirstScan)
    ->Arg(100000)
    ->Arg(1000000)
    ->ArgName("faces")
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime() // CPU column: all threads (llvmpipe renders on worker threads)
    ->UseRealTime();

} // namespace

BENCHMARK_MAIN();
