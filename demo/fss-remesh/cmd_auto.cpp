// fss-remesh auto MESH -o OUT [--edge-length L | --target-vertices N] [--fishbone auto] [--json]
//                  [--renderer auto|gpu|cpu] [--max-views N] [--no-metrics]
#include "args.h"
#include "commands.h"
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

} // namespace

int runAuto(const std::vector<std::string>& args) {
    std::string meshPath, outPath, edgeText, verticesText, fishboneText, rendererKind = "auto",
                                                                         maxViewsText = "80";
    bool haveEdge = false, haveVertices = false, haveFishbone = false, json = false, noMetrics = false;
    ArgParser p(
        "fss-remesh auto",
        "Remesh the whole visible surface of MESH without a person: choose views that cover the surface, a "
        "scan resolution from the target edge length, scan and stitch view after view (the quality mask "
        "keeps the best view of each region), then aim extra views at what is left from the input.");
    p.positional("MESH", "The mesh to remesh (.off .obj .ply .stl).", &meshPath);
    p.option("-o", "OUT", "Output mesh (.ply keeps per-face quality and scan id).", &outPath);
    p.option("--output", "OUT", "Same as -o.", &outPath);
    p.option("--edge-length", "L", "Target edge length in model units.", &edgeText, &haveEdge);
    p.option("--target-vertices", "N",
             "Target vertex count (default: the input's); the edge length follows from the area, "
             "area = N * (sqrt(3)/2) * L^2.",
             &verticesText, &haveVertices);
    p.option("--fishbone", "auto",
             "'auto': chain the sharp feature lines of the mesh and scan each with a fishbone grid along it "
             "first.",
             &fishboneText, &haveFishbone);
    p.option("--max-views", "N", "Largest number of scans (default 80).", &maxViewsText);
    p.option("--renderer", "R", "auto (GPU, else CPU), gpu (head-less OpenGL) or cpu (ray casting).",
             &rendererKind);
    p.flag("--json",
           "Print a JSON report: edge length, coverage, every scan, timings and the metrics of the result.",
           &json);
    p.flag("--no-metrics", "Leave the metrics (distance to the input, self-intersections) out of the report.",
           &noMetrics);
    p.epilog("examples:\n  fss-remesh auto fandisk.off -o fandisk-auto.off\n"
             "  fss-remesh auto fandisk.off -o out.ply --target-vertices 10000 --fishbone auto --json");
    if (!p.parse(args)) return 0;

    if (outPath.empty()) throw UsageError("'fss-remesh auto' needs an output file: -o OUT.");
    if (!isSupportedMeshFile(outPath))
        throw UsageError("The output file " + outPath + " has no supported extension (.off .obj .ply .stl).");
    if (haveEdge && haveVertices)
        throw UsageError("Give either --edge-length or --target-vertices, not both.");
    if (rendererKind != "auto" && rendererKind != "gpu" && rendererKind != "cpu")
        throw UsageError("The value '" + rendererKind + "' of --renderer is not one of auto, gpu, cpu.");
    if (haveFishbone && fishboneText != "auto")
        throw UsageError("The value '" + fishboneText + "' of --fishbone is not 'auto'.");
    AutoOptions options;
    if (haveEdge) {
        options.edgeLength = parseDouble("--edge-length", edgeText);
        if (!(options.edgeLength > 0)) throw UsageError("The value of --edge-length must be positive.");
    }
    if (haveVertices)
        options.targetVertices = std::size_t(parseInt("--target-vertices", verticesText, 4, 1 << 30));
    options.maxViews = parseInt("--max-views", maxViewsText, 1, 10000);
    options.fishbone = haveFishbone;

    const Mesh reference = readMesh(meshPath);
    const render::RendererSelection renderer =
        render::chooseRenderer(*render::parseRendererChoice(rendererKind));
    if (!renderer.fallbackReason.empty())
        std::cerr << "fss-remesh auto: note: " << renderer.fallbackReason
                  << " Falling back to CPU ray casting.\n";
    const std::string rendererUsed(render::rendererChoiceName(renderer.used));
    options.renderer = renderer.factory;

    TerminalProgress bar;
    const AutoResult result = autoRemesh(reference, options, bar.progress());
    bar.finish();
    writeMesh(result.mesh, outPath, WriteOptions{.binary = false});

    std::optional<Metrics> metrics;
    if (!noMetrics) {
        MetricsOptions mo;
        mo.reference = &reference;
        metrics = computeMetrics(result.mesh, mo);
    }
    if (json) {
        nlohmann::json j;
        j["input"] = meshPath;
        j["output"] = outPath;
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
        std::cout << "remeshed " << meshPath << " (" << rendererUsed << ") at edge length "
                  << result.edgeLength << ": " << result.scansStitched << " scans stitched, "
                  << result.scansSkipped << " skipped, coverage " << result.coverage * 100
                  << " % of the area (" << result.inputFacesLeft << " input faces left), "
                  << result.mesh.number_of_vertices() << " vertices, " << result.mesh.number_of_faces()
                  << " faces in " << result.seconds << " s, written to " << outPath << "\n";
        if (metrics) std::cout << metricsToText(*metrics);
    }
    return 0;
}

} // namespace fss::cli
