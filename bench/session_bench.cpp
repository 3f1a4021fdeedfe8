// Session accept / undo / redo of one and the same patch (128² scan, zoom 8, about 32k patch faces) on a
// ~10k-, ~100k- and ~300k-face sphere. accept = stitch + collect_garbage + finding the changed records (the
// last two are linear in the mesh); undo and redo write a step's change records back (linear in the
// change). Counters: stitch_ms (StitchReport::seconds, inside accept), overhead_ms = accept − stitch,
// history_kb (one step), mesh_kb (element arrays of the mesh after the step).
//
// BM_AcceptLatency/faces:N (issue 19, Deliver 3): Session::accept of bench_stitch's patch (a 256² scan in a
// round lasso) on a UV sphere of 100k and 1M faces, with the GPU renderer when FSS::render is built. Time =
// wall time of accept(); counters in CPU time of the calling thread (the machine is shared): accept_cpu_ms,
// stitch_cpu_ms (fss::stitchPatch of the same preview into a copy, untimed), overhead_cpu_ms = accept −
// stitch (copies, garbage collection, history record), accept_over_stitch_cpu.
// The widget's share (RemeshWidget::accept: the worker's accept plus the view's update) is measured by
// the widget test `widgets_remesh_widget_accept_test acceptLatency` with FSS_BENCH_ACCEPT=1.
#include "fss/session.h"
#include "fss/shapes.h"
#include "fss/stitch.h"

#if __has_include("fss/render/gpu_mesh_renderer.h")
#include "fss/render/gpu_mesh_renderer.h"
#define FSS_BENCH_GPU 1
#endif

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>

namespace {

using Clock = std::chrono::steady_clock;

// uvSphere(nu, nu / 2) has about nu² faces.
fss::Session makeSession(int faces) {
    const int nu = int(std::sqrt(double(faces)));
    return fss::Session(fss::shapes::uvSphere(nu, nu / 2));
}

fss::ScanStep patchStep(const fss::Session& session) {
    fss::ScanStep step;
    step.params.camera =
        fss::Camera::standardView(fss::StandardView::PosX, fss::boundingBox(session.reference()), 128, 128);
    step.params.camera.zoom(8.0);
    step.params.scan.scanId = 1;
    return step;
}

std::size_t meshBytes(const fss::Mesh& m) {
    return m.number_of_vertices() * (sizeof(fss::Point3) + 5) + m.number_of_halfedges() * 16 +
           m.number_of_edges() + m.number_of_faces() * 5;
}

void BM_SessionAccept(benchmark::State& state) {
    fss::Session session = makeSession(int(state.range(0)));
    const fss::ScanStep step = patchStep(session);
    double stitchMs = 0, acceptMs = 0;
    std::size_t history = 0, mesh = 0;
    for (auto _ : state) {
        state.PauseTiming();
        session.scan(step);
        state.ResumeTiming();
        const auto t = Clock::now();
        const fss::StitchReport& report = session.accept();
        acceptMs += std::chrono::duration<double, std::milli>(Clock::now() - t).count();
        stitchMs += report.seconds * 1e3;
        state.PauseTiming();
        history = session.historyBytes();
        mesh = meshBytes(session.current());
        session.undo();
        state.ResumeTiming();
    }
    const double n = double(state.iterations());
    state.counters["faces"] = double(session.reference().number_of_faces());
    state.counters["stitch_ms"] = stitchMs / n;
    state.counters["overhead_ms"] = (acceptMs - stitchMs) / n;
    state.counters["history_kb"] = double(history) / 1024.0;
    state.counters["mesh_kb"] = double(mesh) / 1024.0;
}

// Undo (redo untimed) when \p timeUndo, else redo (undo untimed).
void undoOrRedo(benchmark::State& state, bool timeUndo) {
    fss::Session session = makeSession(int(state.range(0)));
    session.scan(patchStep(session));
    session.accept();
    for (auto _ : state) {
        if (!timeUndo) state.PauseTiming();
        session.undo();
        if (!timeUndo) state.ResumeTiming();
        if (timeUndo) state.PauseTiming();
        session.redo();
        if (timeUndo) state.ResumeTiming();
    }
    state.counters["faces"] = double(session.reference().number_of_faces());
}

void BM_SessionUndo(benchmark::State& state) {
    undoOrRedo(state, true);
}
void BM_SessionRedo(benchmark::State& state) {
    undoOrRedo(state, false);
}

// bench_stitch's scene: a 256² view near the equator of the unit sphere, a round lasso of radius 100 px.
fss::ScanStep latencyStep() {
    fss::ScanStep step;
    fss::Camera& c = step.params.camera;
    c.width = c.height = 256;
    c.focal = {0, 0, 0};
    c.eye = Eigen::Vector3d(1, 0.3, 0.2).normalized() * 3.0;
    c.up = {0, 0, 1};
    c.viewAngleDeg = 25;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
    fss::Lasso lasso;
    for (int i = 0; i < 64; ++i) {
        const double a = 2 * 3.14159265358979 * i / 64;
        lasso.points.emplace_back(128 + 100 * std::cos(a), 128 + 100 * std::sin(a));
    }
    step.params.lasso = lasso;
    step.params.scan.scanId = 1;
    return step;
}

double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

struct Latency {
    double acceptCpu = 0, acceptWall = 0, stitchCpu = 0, stitchWall = 0;
};
std::map<int, Latency> latency;

void BM_AcceptLatency(benchmark::State& state) {
    const int faces = int(state.range(0));
    fss::SessionOptions options;
#ifdef FSS_BENCH_GPU
    options.renderer = [] { return std::make_unique<fss::render::GpuMeshRenderer>(); };
#endif
    fss::Session session(faces == 100000 ? fss::shapes::uvSphere(250, 201) : fss::shapes::uvSphere(1000, 501),
                         options);
    const fss::ScanStep step = latencyStep();
    Latency sum;
    for (auto _ : state) {
        state.PauseTiming();
        const fss::ScanPreview& preview = session.scan(step);
        {
            // The core stitch alone, of the same preview, into a copy (the machine is shared: CPU time of
            // this thread is the stable figure; the stitch is single-threaded).
            fss::Mesh copy = session.current();
            fss::StitchOptions stitch = preview.step.stitch;
            const double c0 = threadCpuMs();
            const auto t0 = Clock::now();
            fss::stitchPatch(copy, preview.patch.mesh, preview.step.params.camera, stitch,
                             preview.currentBuffers.faceId);
            sum.stitchWall += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
            sum.stitchCpu += threadCpuMs() - c0;
        }
        state.ResumeTiming();
        const double c0 = threadCpuMs();
        const auto t = Clock::now();
        session.accept();
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t).count();
        sum.acceptCpu += threadCpuMs() - c0;
        sum.acceptWall += ms;
        state.SetIterationTime(ms * 1e-3);
        state.PauseTiming();
        session.undo();
        state.ResumeTiming();
    }
    const double n = double(state.iterations());
    latency[faces] = {sum.acceptCpu / n, sum.acceptWall / n, sum.stitchCpu / n, sum.stitchWall / n};
    state.counters["faces"] = double(session.reference().number_of_faces());
    state.counters["accept_cpu_ms"] = sum.acceptCpu / n;
    state.counters["stitch_cpu_ms"] = sum.stitchCpu / n;
    state.counters["overhead_cpu_ms"] = (sum.acceptCpu - sum.stitchCpu) / n;
    state.counters["accept_over_stitch_cpu"] = sum.acceptCpu / std::max(sum.stitchCpu, 1e-9);
}

} // namespace

BENCHMARK(BM_AcceptLatency)
    ->Arg(100000)
    ->Arg(1000000)
    ->ArgName("faces")
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);
BENCHMARK(BM_SessionAccept)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(300000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);
BENCHMARK(BM_SessionUndo)->Arg(10000)->Arg(100000)->Arg(300000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SessionRedo)->Arg(10000)->Arg(100000)->Arg(300000)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    for (const auto& [faces, l] : latency)
        std::printf(
            "faces %d: Session::accept %.1f ms CPU (%.1f wall); the stitch alone %.1f ms CPU (%.1f wall); "
            "accept / stitch %.2f (CPU)\n",
            faces, l.acceptCpu, l.acceptWall, l.stitchCpu, l.stitchWall, l.acceptCpu / l.stitchCpu);
    return 0;
}
