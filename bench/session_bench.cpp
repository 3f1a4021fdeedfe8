// Session accept / undo / redo of one and the same patch (128² scan, zoom 8, about 32k patch faces) on a
// ~10k-, ~100k- and ~300k-face sphere. accept = stitch + collect_garbage + finding the changed records (the
// last two are linear in the mesh); undo and redo write a step's change records back (linear in the
// change). Counters: stitch_ms (StitchReport::seconds, inside accept), overhead_ms = accept − stitch,
// history_kb (one step), mesh_kb (element arrays of the mesh after the step).
#include "fss/session.h"
#include "fss/shapes.h"

#include <benchmark/benchmark.h>

#include <chrono>

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

} // namespace

BENCHMARK(BM_SessionAccept)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(300000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);
BENCHMARK(BM_SessionUndo)->Arg(10000)->Arg(100000)->Arg(300000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SessionRedo)->Arg(10000)->Arg(100000)->Arg(300000)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
