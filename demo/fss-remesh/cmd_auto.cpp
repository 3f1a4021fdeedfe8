// fss-remesh auto MESH -o OUT [--edge-length L | --target-vertices N] [--fishbone auto] [--json]
//                  [--renderer auto|gpu|cpu] [--max-views N] [--engine v1|v2] [--no-metrics]
#include "command_line.h"
#include "commands.h"
#include "mesh_files.h"
#include "terminal_progress.h"

#include "fss/auto_remesh.h"
#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"
#include "fss/render/renderer_choice.h"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <optional>

namespace fss::cli {
namespace {

const char* kindName(AutoStep::Kind kind) {
    switch (kind) {
    case AutoStep::Kind::Initial:
        return "initial";
    case AutoStep::Kind::RegionFill:
        return "region-fill";
    case AutoStep::Kind::FollowUp:
        return "follow-up";
    case AutoStep::Kind::Fishbone:
        return "fishbone";
    }
    return "?";
}

struct CliAutoOptions {
    std::string meshPath, outPath, fishbone, rendererKind = "auto", engine = "v1";
    double edgeLength = 0;
    int targetVertices = 0, maxViews = 80;
    const CLI::Option* edge = nullptr;     // --edge-length, given when count() > 0
    const CLI::Option* vertices = nullptr; // --target-vertices, given when count() > 0
    bool json = false, noMetrics = false;
    OutputFileOptions file;
};

int runAuto(const CliAutoOptions& o) {
    requireNotBoth(*o.edge, *o.vertices);
    checkOutputFileOptions(o.outPath, o.file);
    AutoOptions options;
    if (o.edge->count() > 0) options.edgeLength = o.edgeLength;
    if (o.vertices->count() > 0) options.targetVertices = std::size_t(o.targetVertices);
    options.maxViews = o.maxViews;
    options.fishbone = !o.fishbone.empty();
    options.engine = o.engine == "v1" ? AutoEngine::V1 : AutoEngine::V2;
    options.fallbackToV1 = o.engine != "v2-nofallback";

    const Mesh reference = readInputMesh(o.meshPath);
    const render::RendererSelection renderer =
        render::chooseRenderer(*render::parseRendererChoice(o.rendererKind));
    if (!renderer.fallbackReason.empty())
        std::cerr << "fss-remesh auto: note: " << renderer.fallbackReason
                  << " Falling back to CPU ray casting.\n";
    const std::string rendererUsed(render::rendererChoiceName(renderer.used));
    options.renderer = renderer.factory;

    TerminalProgress bar;
    const AutoResult result = autoRemesh(reference, options, bar.progress());
    bar.finish();
    writeOutputMesh(result.mesh, &reference, o.outPath, o.file, WriteOptions{.binary = false});

    std::optional<Metrics> metrics;
    if (!o.noMetrics) {
        MetricsOptions mo;
        mo.reference = &reference;
        metrics = computeMetrics(result.mesh, mo);
    }
    if (o.json) {
        nlohmann::json j;
        j["input"] = o.meshPath;
        j["output"] = o.outPath;
        j["renderer"] = rendererUsed;
        j["edge_length"] = result.edgeLength;
        j["input_vertices"] = reference.number_of_vertices();
        j["coverage"] = result.coverage;
        j["input_faces_left"] = result.inputFacesLeft;
        j["input_area_left"] = result.inputAreaLeft;
        j["feature_chains"] = result.featureChains;
        j["sliver_flips"] = result.sliverFlips;
        j["seam_flips"] = result.seamFlips;
        j["seam_collapses"] = result.seamCollapses;
        j["seam_moves"] = result.seamMoves;
        j["seam_relax_discarded"] = result.seamRelaxDiscarded;
        j["crease_snaps"] = result.creaseSnaps;
        j["crease_splits"] = result.creaseSplits;
        j["crease_flips"] = result.creaseFlips;
        j["crease_removals"] = result.creaseRemovals;
        j["crease_repairs"] = result.creaseRepairs;
        j["engine"] = result.engineUsed == AutoEngine::V2 ? "v2" : "v1";
        j["engine_note"] = result.engineNote;
        j["scans_stitched"] = result.scansStitched;
        j["scans_skipped"] = result.scansSkipped;
        nlohmann::json steps = nlohmann::json::array();
        for (const AutoStep& s : result.steps)
            steps.push_back(
                {{"kind", kindName(s.kind)},
                 {"scan_id", s.scanId},
                 {"resolution", {s.camera.width, s.camera.height}},
                 {"view_direction",
                  {s.camera.viewDirection().x(), s.camera.viewDirection().y(), s.camera.viewDirection().z()}},
                 {"stitched", s.stitched},
                 {"patch_faces", s.patchFaces},
                 {"faces_added", s.facesAdded},
                 {"faces_removed", s.facesRemoved},
                 {"patch_faces_trimmed", s.patchFacesTrimmed},
                 {"coverage_after", s.coverageAfter},
                 {"seconds", s.seconds},
                 {"note", s.note}});
        j["steps"] = steps;
        j["timings_s"] = {{"plan", result.planSeconds},
                          {"scan", result.scanSeconds},
                          {"stitch", result.stitchSeconds},
                          {"total", result.seconds}};
        j["metrics"] = metrics ? nlohmann::json::parse(metricsToJson(*metrics)) : nlohmann::json();
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << "remeshed " << o.meshPath << " (" << rendererUsed << ") at edge length "
                  << result.edgeLength << ": " << result.scansStitched << " scans stitched, "
                  << result.scansSkipped << " skipped, coverage " << result.coverage * 100
                  << " % of the area (" << result.inputFacesLeft << " input faces left), "
                  << result.mesh.number_of_vertices() << " vertices, " << result.mesh.number_of_faces()
                  << " faces in " << result.seconds << " s, written to " << o.outPath << "\n";
        if (!result.engineNote.empty()) std::cout << result.engineNote << "\n";
        if (metrics) std::cout << metricsToText(*metrics);
    }
    return 0;
}

} // namespace

Subcommand addAuto(CLI::App& app) {
    auto o = std::make_shared<CliAutoOptions>();
    CLI::App* p = addCommand(
        app, "auto",
        "Remesh the whole visible surface of MESH without a person: choose views that cover the surface, a "
        "scan resolution from the target edge length, scan and stitch view after view (the quality mask "
        "keeps the best view of each region), then aim extra views at what is left from the input.",
        "examples:\n  fss-remesh auto fandisk.off -o fandisk-auto.off\n"
        "  fss-remesh auto fandisk.off -o out.ply --target-vertices 10000 --fishbone auto --json\n"
        "  fss-remesh auto part.obj -o part.msh --feature-edges");
    p->add_option("MESH", o->meshPath, "The mesh to remesh (.off .obj .ply .stl .msh .vtu .vtp .vtk).")
        ->required()
        ->type_name("");
    addOutputMesh(
        *p, o->outPath,
        "Output mesh (.off .obj .ply .stl, or for FEM .msh .inp .bdf .unv .vtu .vtp; .ply keeps per-face "
        "quality and scan id). The input's face groups are carried to the output.");
    addOutputFileOptions(*p, o->file);
    o->edge = addDouble(*p, "--edge-length", o->edgeLength, true, "L", "Target edge length in model units.");
    o->vertices = addInt(*p, "--target-vertices", o->targetVertices, 4, 1 << 30, "N",
                         "Target vertex count (default: the input's); the edge length follows from the area, "
                         "area = N * (sqrt(3)/2) * L^2.");
    p->add_option("--fishbone", o->fishbone,
                  "'auto': chain the sharp feature lines of the mesh and scan each with a fishbone grid "
                  "along it first.")
        ->type_name("auto")
        ->check(oneOf("--fishbone", {"auto"}));
    p->add_option(
         "--engine", o->engine,
         "v1: scan and stitch view after view (default); v2: sample every region of the partition once "
         "and join all regions in one pass (issue 23; falls back to v1 when its result fails "
         "validation).")
        ->type_name("v1|v2")
        ->check(oneOf("--engine", {"v1", "v2", "v2-nofallback"}));
    addInt(*p, "--max-views", o->maxViews, 1, 10000, "N", "Largest number of scans (default 80).");
    addRenderer(*p, o->rendererKind, {},
                "auto (GPU, else CPU), gpu (head-less OpenGL) or cpu (ray casting).");
    p->add_flag(
        "--json", o->json,
        "Print a JSON report: edge length, coverage, every scan, timings and the metrics of the result.");
    p->add_flag("--no-metrics", o->noMetrics,
                "Leave the metrics (distance to the input, self-intersections) out of the report.");
    return {p, [o] { return runAuto(*o); }};
}

} // namespace fss::cli
