// `fss-remesh auto` (fss::autoRemesh, engines v1 and v2) against CGAL::Polygon_mesh_processing::
// isotropic_remeshing on the eight CGAL sample meshes of issue 23, at the same target edge length (the one
// that gives the input's vertex count, auto_remesh.h edgeLengthForVertexCount). CGAL: sharp edges of 60° or
// more detected with detect_sharp_edges, passed as edge_is_constrained_map and protected
// (protect_constraints), 5 iterations. Each remesher runs once per mesh (Iterations(1)); the quality of
// every result is measured with fss::computeMetrics against the input (closed, pinched vertices,
// self-intersections, fraction of valence-6 interior vertices, smallest and mean smallest angle, Hausdorff
// distance both ways relative to the bbox diagonal) and printed side by side after the benchmarks, with the
// time ratio to CGAL, followed by where FSS's irregular vertices are (next to input faces, on feature
// edges, on seams, inside a patch).
//
//   ./build/bin/bench_auto                       # all eight meshes, v1 and v2, GPU renderer when available
//   FSS_AUTO_BENCH_MESHES=fandisk,bunny00 ./build/bin/bench_auto
//   FSS_AUTO_BENCH_ENGINES=v2 ./build/bin/bench_auto   # one engine only
//   FSS_AUTO_BENCH_FISHBONE=1 ./build/bin/bench_auto   # with --fishbone auto
//   FSS_AUTO_BENCH_FALLBACK=0 ./build/bin/bench_auto   # v2 without the fallback to v1 (its own mesh)
//
// CGAL's isotropic remeshing is a heavy translation unit: it lives here only, never in core.
#include "fss/auto_remesh.h"
#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"
#include "fss/render/gpu_mesh_renderer.h"

#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Clock = std::chrono::steady_clock;

/// Where the irregular (valence ≠ 6) vertices of a result are, by the first class that fits: next to a face
/// left from the input, on a feature edge (dihedral angle above the feature angle), on a seam (faces of
/// different scans), or inside one scan's patch.
struct Irregular {
    enum Class { Input, Feature, Seam, Patch, Count };
    std::size_t vertices[Count] = {};
    std::size_t irregular[Count] = {};
};

Irregular irregularVertices(const fss::Mesh& m, double featureAngleDeg) {
    Irregular out;
    const auto [ids, haveIds] = m.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
    const double cosFeature = std::cos(featureAngleDeg * std::numbers::pi / 180.0);
    auto normal = [&](fss::FaceIndex f) {
        const auto h = m.halfedge(f);
        return CGAL::unit_normal(m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h))));
    };
    for (fss::VertexIndex v : m.vertices()) {
        bool input = false, feature = false, seam = false;
        std::int32_t first = -2;
        for (fss::HalfedgeIndex h : CGAL::halfedges_around_target(v, m)) {
            const fss::FaceIndex f = m.face(h), g = m.face(m.opposite(h));
            if (f == fss::Mesh::null_face() || g == fss::Mesh::null_face()) continue;
            const std::int32_t id = haveIds ? ids[f] : -1;
            input = input || id < 0;
            seam = seam || (first != -2 && id != first);
            first = id;
            feature = feature || normal(f) * normal(g) < cosFeature;
        }
        const Irregular::Class c = input     ? Irregular::Input
                                   : feature ? Irregular::Feature
                                   : seam    ? Irregular::Seam
                                             : Irregular::Patch;
        ++out.vertices[c];
        if (m.degree(v) != 6) ++out.irregular[c];
    }
    return out;
}

struct Row {
    double seconds = 0;
    fss::Metrics metrics;
    double coverage = -1; // FSS only
    int scans = 0;
    Irregular irregular; // FSS only
    std::string note;    // FSS only: why v2 fell back to v1
    // FSS only: plan, scan, join, relax, crease (AutoResult; join, relax and crease are 0 for v1, whose
    // stitches, relaxation and crease recovery are all in "join").
    double stages[6] = {};
    bool have = false;
};

struct MeshResults {
    double edgeLength = 0;
    std::size_t inputVertices = 0;
    Row fss[2], cgal; // fss[0]: v1, fss[1]: v2
};

std::map<std::string, MeshResults>& results() {
    static std::map<std::string, MeshResults> r;
    return r;
}
std::vector<std::string> meshOrder;

const fss::Mesh& input(const std::string& name) {
    static std::map<std::string, fss::Mesh> cache;
    auto it = cache.find(name);
    if (it == cache.end())
        it = cache.emplace(name, fss::readMesh(std::string(FSS_BENCH_MESH_DIR) + "/" + name + ".off")).first;
    return it->second;
}

double area(const fss::Mesh& m) {
    double a = 0;
    for (fss::FaceIndex f : m.faces())
        a += std::sqrt(CGAL::squared_area(m.point(m.source(m.halfedge(f))), m.point(m.target(m.halfedge(f))),
                                          m.point(m.target(m.next(m.halfedge(f))))));
    return a;
}

fss::Metrics measure(const fss::Mesh& mesh, const fss::Mesh& reference) {
    fss::MetricsOptions mo;
    mo.reference = &reference;
    return fss::computeMetrics(mesh, mo);
}

bool gpuAvailable() {
    static const bool ok = [] {
        try {
            fss::render::GpuMeshRenderer probe;
            return true;
        } catch (const fss::Error&) {
            return false;
        }
    }();
    return ok;
}

fss::AutoOptions autoOptions() {
    fss::AutoOptions o;
    if (gpuAvailable()) o.renderer = [] { return std::make_unique<fss::render::GpuMeshRenderer>(); };
    const char* fb = std::getenv("FSS_AUTO_BENCH_FISHBONE");
    o.fishbone = fb && std::string(fb) == "1";
    const char* fallback = std::getenv("FSS_AUTO_BENCH_FALLBACK");
    o.fallbackToV1 = !(fallback && std::string(fallback) == "0");
    return o;
}

void BM_FssAuto(benchmark::State& state, std::string name, int engine) {
    const fss::Mesh& ref = input(name);
    MeshResults& r = results()[name];
    r.inputVertices = ref.number_of_vertices();
    r.edgeLength = fss::edgeLengthForVertexCount(area(ref), ref.number_of_vertices());
    fss::AutoOptions o = autoOptions();
    o.edgeLength = r.edgeLength;
    o.engine = engine == 0 ? fss::AutoEngine::V1 : fss::AutoEngine::V2;
    Row& row = r.fss[engine];
    for (auto _ : state) {
        const auto t = Clock::now();
        fss::AutoResult res = fss::autoRemesh(ref, o);
        row.seconds = std::chrono::duration<double>(Clock::now() - t).count();
        state.PauseTiming();
        row.metrics = measure(res.mesh, ref);
        row.coverage = res.coverage;
        row.scans = res.scansStitched;
        row.irregular = irregularVertices(res.mesh, o.featureAngleDeg);
        row.note = res.engineNote;
        const double rest = res.stitchSeconds - res.joinSeconds - res.relaxSeconds - res.creaseSeconds;
        const double stages[6] = {res.planSeconds,
                                  res.scanSeconds,
                                  res.joinSeconds + (res.joinSeconds > 0 ? 0 : rest - res.sliverSeconds),
                                  res.relaxSeconds,
                                  res.creaseSeconds,
                                  res.sliverSeconds};
        std::copy(std::begin(stages), std::end(stages), std::begin(row.stages));
        row.have = true;
        state.ResumeTiming();
    }
    state.counters["vertices"] = double(row.metrics.vertices);
    state.counters["coverage"] = row.coverage;
    state.counters["valence6"] = row.metrics.fracValence6Interior;
    state.counters["min_angle"] = row.metrics.minAngleDeg;
}

void BM_CgalIsotropic(benchmark::State& state, std::string name) {
    const fss::Mesh& ref = input(name);
    MeshResults& r = results()[name];
    const double L = fss::edgeLengthForVertexCount(area(ref), ref.number_of_vertices());
    const double featureAngle = 60.0;
    for (auto _ : state) {
        state.PauseTiming();
        fss::Mesh m = ref;
        state.ResumeTiming();
        const auto t = Clock::now();
        auto constrained = m.add_property_map<fss::EdgeIndex, bool>("e:is_feature", false).first;
        PMP::detect_sharp_edges(m, featureAngle, constrained);
        PMP::isotropic_remeshing(faces(m), L, m,
                                 PMP::parameters::number_of_iterations(5)
                                     .edge_is_constrained_map(constrained)
                                     .protect_constraints(true));
        m.collect_garbage();
        r.cgal.seconds = std::chrono::duration<double>(Clock::now() - t).count();
        state.PauseTiming();
        r.cgal.metrics = measure(m, ref);
        r.cgal.have = true;
        state.ResumeTiming();
    }
    state.counters["vertices"] = double(r.cgal.metrics.vertices);
    state.counters["valence6"] = r.cgal.metrics.fracValence6Interior;
    state.counters["min_angle"] = r.cgal.metrics.minAngleDeg;
}

std::string opt(const std::optional<double>& v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.5f", v ? *v : -1.0);
    return buf;
}

void printTable() {
    std::printf(
        "\nauto (FSS v1, v2) vs CGAL isotropic_remeshing (5 iterations, sharp edges >= 60 deg protected), "
        "same target edge length; renderer: %s, fishbone: %s, v2 falls back to v1: %s\n",
        gpuAvailable() ? "gpu" : "cpu", autoOptions().fishbone ? "auto" : "off",
        autoOptions().fallbackToV1 ? "yes" : "no");
    std::printf("%-16s %-4s %8s %7s %7s %6s %6s %4s %4s %4s %4s %4s %4s %6s %6s %6s %6s %9s %9s\n", "mesh",
                "who", "L", "verts", "time_s", "t/cgal", "cover", "clsd", "cmp", "loop", "pnch", "SI", "dgn",
                "val6", "minang", "meanmn", "lt30", "H_to_rel", "H_from_rel");
    for (const std::string& name : meshOrder) {
        const MeshResults& r = results()[name];
        const char* who[3] = {"v1", "v2", "cgal"};
        for (int w = 0; w < 3; ++w) {
            const Row& row = w < 2 ? r.fss[w] : r.cgal;
            if (!row.have) continue;
            const fss::Metrics& m = row.metrics;
            std::printf("%-16s %-4s %8.5f %7zu %7.2f %6.2f %6.4f %4s %4zu %4zu %4zu %4zu %4zu %6.4f %6.2f "
                        "%6.2f %6.4f %9s %9s%s%s\n",
                        name.c_str(), who[w], r.edgeLength, m.vertices, row.seconds,
                        r.cgal.have ? row.seconds / r.cgal.seconds : 0.0, w < 2 ? row.coverage : 1.0,
                        m.closed ? "yes" : "no", m.components, m.boundaryLoops, m.nonManifoldVertices,
                        m.selfIntersections.value_or(0), m.degenerateFaces, m.fracValence6Interior,
                        m.minAngleDeg, m.meanMinAngleDeg, m.fracMinAngleBelow30,
                        opt(m.hausdorffToRefRel).c_str(), opt(m.hausdorffFromRefRel).c_str(),
                        row.note.empty() ? "" : "  ", row.note.c_str());
        }
    }
    std::printf("\nFSS: seconds by stage (v1: stitches, relaxation and crease recovery all in join)\n");
    std::printf("%-16s %-4s %7s %7s %7s %7s %7s %7s %7s\n", "mesh", "who", "plan", "scan", "join", "relax",
                "crease", "sliver", "total");
    for (const std::string& name : meshOrder)
        for (int w = 0; w < 2; ++w) {
            const Row& row = results()[name].fss[w];
            if (!row.have) continue;
            std::printf("%-16s %-4s", name.c_str(), w == 0 ? "v1" : "v2");
            for (double s : row.stages)
                std::printf(" %7.2f", s);
            std::printf(" %7.2f\n", row.seconds);
        }
    std::printf("\nFSS: irregular (valence != 6) / all vertices by where they are (first class that fits)\n");
    std::printf("%-16s %-4s %15s %15s %15s %15s\n", "mesh", "who", "input_faces", "feature_edge", "seam",
                "patch_inside");
    for (const std::string& name : meshOrder)
        for (int w = 0; w < 2; ++w) {
            const Row& row = results()[name].fss[w];
            if (!row.have) continue;
            std::printf("%-16s %-4s", name.c_str(), w == 0 ? "v1" : "v2");
            for (int c = 0; c < Irregular::Count; ++c)
                std::printf(" %7zu/%-7zu", row.irregular.irregular[c], row.irregular.vertices[c]);
            std::printf("\n");
        }
    std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
    std::string list = "fandisk,bunny00,elephant,couplingdown,armadillo,blade,rotor_small,mech-holes-shark";
    if (const char* env = std::getenv("FSS_AUTO_BENCH_MESHES")) list = env;
    std::string engines = "v1,v2";
    if (const char* env = std::getenv("FSS_AUTO_BENCH_ENGINES")) engines = env;
    std::stringstream ss(list);
    for (std::string name; std::getline(ss, name, ',');)
        if (!name.empty()) meshOrder.push_back(name);
    for (const std::string& name : meshOrder) {
        for (int engine = 0; engine < 2; ++engine) {
            const std::string e = engine == 0 ? "v1" : "v2";
            if (engines.find(e) == std::string::npos) continue;
            benchmark::RegisterBenchmark(("BM_FssAuto/" + e + "/" + name).c_str(), BM_FssAuto, name, engine)
                ->Iterations(1)
                ->Unit(benchmark::kSecond)
                ->UseRealTime();
        }
        benchmark::RegisterBenchmark(("BM_CgalIsotropic/" + name).c_str(), BM_CgalIsotropic, name)
            ->Iterations(1)
            ->Unit(benchmark::kSecond)
            ->UseRealTime();
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    printTable();
    return 0;
}
