// fss-remesh scan MESH -o OUT [--into CURRENT] [--view V | --camera ...] [--parallel] [--resolution W[xH]]
// [--zoom F]
//                  [--lasso "x,y;x,y;..."] [--erode N] [--dilate N] [--lattice L] [--no-warp] [--json] ...
//                  [--fishbone
//                  "seed=X,Y[;dir=min|max][;h=PIXELS][;keyribs=X,Y|X,Y...][;backbone=X,Y|X,Y...][;sampling=K]"]
#include "command_line.h"
#include "commands.h"
#include "mesh_files.h"
#include "stitch_json.h"

#include "fss/camera.h"
#include "fss/error.h"
#include "fss/fishbone_scan.h"
#include "fss/mesh_io.h"
#include "fss/raycast.h"
#include "fss/render/renderer_choice.h"
#include "fss/scan_pipeline.h"
#include "fss/stitch.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace fss::cli {
namespace {

// The patch part of a scan's JSON counts (regular and fishbone alike).
void addPatchCounts(nlohmann::json& counts, const Patch& patch) {
    const TriangulateReport& tr = patch.report;
    counts["patch_vertices"] = patch.mesh.number_of_vertices();
    counts["patch_faces"] = patch.mesh.number_of_faces();
    counts["dropped_flipped"] = tr.flipped;
    counts["dropped_back_facing"] = tr.backFacing;
    counts["dropped_long_edges"] = tr.longEdges;
    counts["dropped_grazing"] = tr.grazing;
    counts["dropped_sliver_quads"] = tr.sliverQuads;
    counts["dropped_non_manifold"] = tr.nonManifoldTriangles;
}

// "ex,ey,ez,fx,fy,fz,ux,uy,uz[,angle]" → its 9 or 10 numbers.
std::vector<double> parseCameraNumbers(const std::string& text) {
    std::vector<double> v = parseDoubleList("--camera", text);
    if (v.size() != 9 && v.size() != 10)
        throw UsageError("The option --camera needs 9 or 10 comma-separated numbers (eye, focal point, up, "
                         "and optionally the view angle in degrees), not " +
                         std::to_string(v.size()) + ".");
    return v;
}

// The camera of --camera's numbers \p v for a mesh in \p box, at w × h pixels.
Camera makeCamera(const std::vector<double>& v, const Eigen::AlignedBox3d& box, int w, int h, bool parallel) {
    Camera c;
    c.eye = {v[0], v[1], v[2]};
    c.focal = {v[3], v[4], v[5]};
    c.up = {v[6], v[7], v[8]};
    c.viewAngleDeg = v.size() == 10 ? v[9] : 30.0;
    c.parallel = parallel;
    c.width = w;
    c.height = h;
    // A parallel camera shows the whole bounding box (its radius) around the focal point.
    c.parallelScale = 0.5 * box.diagonal().norm() * std::max(1.0, double(h) / double(w));
    c.validate();
    return c;
}

// "x,y;x,y;..." in normalised image coordinates (0,0 top-left, 1,1 bottom-right), kept normalised.
Lasso parseLasso(const std::string& text) {
    Lasso lasso;
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto semi = text.find(';', start);
        const std::string item =
            text.substr(start, semi == std::string::npos ? std::string::npos : semi - start);
        if (!item.empty()) {
            const std::vector<double> xy = parseDoubleList("--lasso", item);
            if (xy.size() != 2)
                throw UsageError("Each --lasso point needs two numbers x,y (normalised 0..1), not '" + item +
                                 "'.");
            lasso.points.emplace_back(xy[0], xy[1]);
        }
        if (semi == std::string::npos) break;
        start = semi + 1;
    }
    return lasso;
}

// \p p in normalised image coordinates → pixels of a w × h image.
Eigen::Vector2d toPixels(const Eigen::Vector2d& p, int w, int h) {
    return Eigen::Vector2d(p.x() * w, p.y() * h);
}

// The normalised \p lasso in pixels of a w × h image, checked for an enclosed area.
Lasso lassoInPixels(const Lasso& lasso, int w, int h) {
    Lasso pixels;
    for (const Eigen::Vector2d& p : lasso.points)
        pixels.points.push_back(toPixels(p, w, h));
    try {
        validateLasso(pixels);
    } catch (const InvalidInputError& e) {
        throw UsageError(std::string("The --lasso polygon is degenerate: ") + e.what());
    }
    return pixels;
}

// "x,y|x,y|..." (normalised, kept so).
std::vector<Eigen::Vector2d> parsePointList(const std::string& key, const std::string& text) {
    std::vector<Eigen::Vector2d> points;
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto bar = text.find('|', start);
        const std::string item =
            text.substr(start, bar == std::string::npos ? std::string::npos : bar - start);
        const std::vector<double> xy = parseDoubleList("--fishbone " + key, item);
        if (xy.size() != 2)
            throw UsageError("Each point of the --fishbone key '" + key +
                             "' needs two numbers x,y (normalised 0..1), not '" + item + "'.");
        points.emplace_back(xy[0], xy[1]);
        if (bar == std::string::npos) break;
        start = bar + 1;
    }
    return points;
}

// "seed=X,Y[;dir=min|max][;h=PIXELS][;keyribs=X,Y|X,Y...][;backbone=X,Y|X,Y...][;sampling=K]", points
// normalised (and kept so: see fishboneInPixels).
FishboneParams parseFishbone(const std::string& text) {
    FishboneParams fb;
    bool haveSeed = false;
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto semi = text.find(';', start);
        const std::string item =
            text.substr(start, semi == std::string::npos ? std::string::npos : semi - start);
        if (!item.empty()) {
            const auto eq = item.find('=');
            if (eq == std::string::npos)
                throw UsageError("The --fishbone item '" + item + "' is not of the form key=value.");
            const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
            if (key == "seed") {
                const std::vector<Eigen::Vector2d> p = parsePointList(key, value);
                if (p.size() != 1)
                    throw UsageError("The --fishbone seed must be one point x,y (normalised 0..1).");
                fb.seed = p.front();
                haveSeed = true;
            } else if (key == "dir") {
                if (value == "min")
                    fb.direction = PrincipalDirection::Min;
                else if (value == "max")
                    fb.direction = PrincipalDirection::Max;
                else
                    throw UsageError("The --fishbone direction '" + value + "' is not one of min, max.");
            } else if (key == "h") {
                fb.spacing = parseDouble("--fishbone h", value);
            } else if (key == "keyribs") {
                fb.keyRibs = parsePointList(key, value);
            } else if (key == "backbone") {
                fb.drawnBackbone = parsePointList(key, value);
            } else if (key == "sampling") {
                const double k = parseDouble("--fishbone sampling", value);
                if (!(k >= 0 && k <= 64) || k != std::floor(k))
                    throw UsageError("The --fishbone sampling factor '" + value +
                                     "' is not an integer from 0 (automatic) to 64.");
                fb.samplingFactor = int(k);
            } else {
                throw UsageError("The --fishbone key '" + key +
                                 "' is not one of seed, dir, h, keyribs, backbone, sampling.");
            }
        }
        if (semi == std::string::npos) break;
        start = semi + 1;
    }
    if (!haveSeed && fb.drawnBackbone.empty())
        throw UsageError("The --fishbone spec needs a seed=X,Y or a backbone=X,Y|X,Y|....");
    if (!fb.drawnBackbone.empty() && fb.drawnBackbone.size() < 2)
        throw UsageError("The --fishbone backbone needs at least two points.");
    if (fb.keyRibs.size() == 1)
        throw UsageError("The --fishbone keyribs need at least two points to blend between.");
    return fb;
}

// The normalised points of \p fishbone in pixels of a w × h image.
FishboneParams fishboneInPixels(FishboneParams fishbone, int w, int h) {
    if (fishbone.seed) fishbone.seed = toPixels(*fishbone.seed, w, h);
    for (Eigen::Vector2d& p : fishbone.keyRibs)
        p = toPixels(p, w, h);
    for (Eigen::Vector2d& p : fishbone.drawnBackbone)
        p = toPixels(p, w, h);
    return fishbone;
}

// What either kind of scan produced, with its part of the JSON report and of the text summary.
struct ScanRun {
    Patch patch;
    FrameBuffers currentBuffers; // the current mesh from the sampling camera (for the stitch)
    Camera samplingCamera;       // the scan camera, or a fishbone's sampling camera (for the stitch)
    nlohmann::json json;         // everything but input / output / renderer
    std::string summary;         // "fishbone-scanned ... in 0.1 s"
};

ScanRun fishboneScan(const Mesh& reference, MeshRenderer& renderer, const Mesh& current,
                     MeshRenderer& currentRenderer, const ScanParams& params, const FishboneParams& fishbone,
                     const std::string& meshPath, const std::string& rendererUsed) {
    FishboneCache cache;
    FishboneScanResult result =
        scanFishbonePatch(reference, renderer, current, currentRenderer, params, fishbone, cache);
    const FishboneCounts& c = result.counts;
    const FishboneTimings& t = result.timings;
    ScanRun run;
    nlohmann::json& j = run.json;
    j["grid"] = "fishbone";
    j["resolution"] = {params.camera.width, params.camera.height};
    j["fishbone"] = {{"direction", fishbone.direction == PrincipalDirection::Min ? "min" : "max"},
                     {"h_pixels", fishbone.spacing},
                     {"sampling_factor", result.samplingFactor},
                     {"key_ribs", fishbone.keyRibs.size()},
                     {"drawn_backbone", !fishbone.drawnBackbone.empty()}};
    j["counts"] = {{"rows", c.rows},
                   {"cols", c.cols},
                   {"rib_vertices", c.ribVertices},
                   {"direction_pixels", c.directionPixels},
                   {"covered", c.covered},
                   {"front_facing", c.frontFacing},
                   {"on_hint_face", c.onHintFace},
                   {"after_lasso", c.afterLasso},
                   {"after_quality", c.afterQuality},
                   {"after_morphology", c.afterMorphology}};
    addPatchCounts(j["counts"], result.patch);
    j["timings_s"] = {{"curvature", t.curvature},
                      {"ray_caster_build", t.rayCasterBuild},
                      {"render_reference", t.renderReference},
                      {"direction_field", t.directionField},
                      {"tracing", t.tracing},
                      {"ray_casting", t.rayCasting},
                      {"masks", t.masks},
                      {"triangulate", t.triangulate},
                      {"total", t.total}};
    std::ostringstream text;
    text << "fishbone-scanned " << meshPath << " at " << params.camera.width << "x" << params.camera.height
         << " (" << rendererUsed << "): " << c.rows << " ribs x " << c.cols << " columns, " << c.covered
         << " samples -> patch of " << result.patch.mesh.number_of_vertices() << " vertices, "
         << result.patch.mesh.number_of_faces() << " faces in " << t.total << " s";
    run.summary = text.str();
    run.patch = std::move(result.patch);
    run.currentBuffers = std::move(result.currentBuffers);
    run.samplingCamera = fishboneSamplingCamera(params.camera, fishbone);
    return run;
}

const char* latticeName(Lattice lattice) {
    return lattice == Lattice::Square ? "square" : lattice == Lattice::Adaptive ? "adaptive" : "triangular";
}

ScanRun regularScan(const Mesh& reference, MeshRenderer& renderer, const Mesh& current,
                    MeshRenderer& currentRenderer, const ScanParams& params, const std::string& meshPath,
                    const std::string& rendererUsed) {
    ScanResult result = scanPatch(reference, renderer, current, currentRenderer, params);
    const ScanCounts& c = result.counts;
    const ScanTimings& t = result.timings;
    ScanRun run;
    nlohmann::json& j = run.json;
    j["resolution"] = {params.camera.width, params.camera.height};
    j["lattice"] = latticeName(params.scan.lattice);
    j["warp_to_surface"] = params.scan.lattice == Lattice::Adaptive && params.scan.warpToSurface;
    j["camera"] = {{"eye", {params.camera.eye.x(), params.camera.eye.y(), params.camera.eye.z()}},
                   {"focal", {params.camera.focal.x(), params.camera.focal.y(), params.camera.focal.z()}},
                   {"up", {params.camera.up.x(), params.camera.up.y(), params.camera.up.z()}},
                   {"parallel", params.camera.parallel},
                   {"view_angle_deg", params.camera.viewAngleDeg},
                   {"parallel_scale", params.camera.parallelScale}};
    j["counts"] = {{"pixels", c.pixels},
                   {"covered", c.covered},
                   {"front_facing", c.frontFacing},
                   {"well_shaped", c.wellShaped},
                   {"after_lasso", c.afterLasso},
                   {"after_quality", c.afterQuality},
                   {"after_morphology", c.afterMorphology}};
    addPatchCounts(j["counts"], result.patch);
    j["timings_s"] = {{"render_reference", t.renderReference},
                      {"render_current", t.renderCurrent},
                      {"sample", t.sample},
                      {"lasso", t.lasso},
                      {"quality_mask", t.qualityMask},
                      {"morphology", t.morphology},
                      {"triangulate", t.triangulate},
                      {"total", t.total}};
    std::ostringstream text;
    text << "scanned " << meshPath << " at " << params.camera.width << "x" << params.camera.height << " ("
         << rendererUsed << "): " << c.covered << " covered pixels -> patch of "
         << result.patch.mesh.number_of_vertices() << " vertices, " << result.patch.mesh.number_of_faces()
         << " faces in " << t.total << " s";
    run.summary = text.str();
    run.patch = std::move(result.patch);
    run.currentBuffers = std::move(result.currentBuffers);
    run.samplingCamera = params.camera;
    return run;
}

// The next free scan id of a mesh: one more than the largest props::faceScanId (0 when it has none).
int nextScanId(const Mesh& mesh) {
    const auto [ids, has] = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    std::int32_t next = 0;
    if (has)
        for (FaceIndex f : mesh.faces())
            next = std::max(next, ids[f] + 1);
    return next;
}

// True when the two paths name the same existing file.
bool sameFile(const std::string& a, const std::string& b) {
    std::error_code ec;
    const bool same = std::filesystem::equivalent(a, b, ec);
    return !ec && same;
}

// The largest distance of a vertex of CURRENT from MESH's surface that --into accepts, as a fraction of
// MESH's bounding-box diagonal. A mesh remeshed from MESH has its vertices on MESH's surface or on the chords
// of earlier patches, far closer than this.
constexpr double kIntoMaxOffRatio = 0.01;

// --into CURRENT must be a remeshing of MESH: a patch of MESH stitched into an unrelated mesh would bridge
// the gap between the two surfaces with its seam.
void requireRemeshingOf(const Mesh& current, const std::string& currentPath, const Mesh& reference,
                        const std::string& referencePath, const Eigen::AlignedBox3d& box) {
    const RayCaster surface(reference);
    double farthest = 0;
    for (VertexIndex v : current.vertices()) {
        const auto& p = current.point(v);
        const SurfacePoint s = surface.closestPoint({p.x(), p.y(), p.z()});
        if (s.face != Mesh::null_face()) farthest = std::max(farthest, s.distance);
    }
    const double limit = kIntoMaxOffRatio * box.diagonal().norm();
    if (farthest > limit) {
        std::ostringstream text;
        text << "Nothing was stitched: " << currentPath << " is not a remeshing of " << referencePath
             << " (a vertex of it lies " << farthest << " from that surface, more than " << limit
             << ", 1 % of its bounding-box diagonal).";
        throw InvalidInputError(text.str());
    }
}

// The lattice options' defaults are the core's (ScanParams{}: issue #20).
struct ScanOptions {
    std::string meshPath, outPath, view = "iso", intoPath, rendererKind = "auto",
                                   lattice = latticeName(fss::ScanOptions{}.lattice);
    std::vector<double> camera; // --camera's numbers
    int w = 256, h = 256, erode = 1, dilate = 1, scanId = 0;
    double zoom = 1, maxEdge = 3, maxAngle = 80, margin = 0.1, spacing = 1, spacingWorld = 0,
           minQuadAngle = TriangulateOptions{}.minQuadAngleDeg,
           minLatticeAngle = fss::ScanOptions{}.minLatticeAngleDeg;
    Lasso lasso;                             // normalised
    FishboneParams fishbone;                 // normalised
    const CLI::Option* viewOption = nullptr; // the options below are given when their count() > 0
    const CLI::Option* cameraOption = nullptr;
    const CLI::Option* lassoOption = nullptr;
    const CLI::Option* fishboneOption = nullptr;
    const CLI::Option* intoOption = nullptr;
    const CLI::Option* scanIdOption = nullptr;
    OutputFileOptions file;
    bool parallel = false, json = false, force = false, noWarp = false;
};

int runScan(const ScanOptions& o) {
    requireNotBoth(*o.viewOption, *o.cameraOption);
    const std::string& meshPath = o.meshPath;
    const int w = o.w, h = o.h;
    const bool haveInto = o.intoOption->count() > 0;
    ScanParams params;
    params.erodeRadius = o.erode;
    params.dilateRadius = o.dilate;
    params.triangulate.maxEdgeFootprints = o.maxEdge;
    params.triangulate.maxSamplingAngleDeg = o.maxAngle;
    params.triangulate.minQuadAngleDeg = o.minQuadAngle;
    params.quality.margin = o.margin;
    params.quality.forceReplace = o.force;
    params.scan.scanId = o.scanId;
    params.scan.lattice = o.lattice == "square"     ? Lattice::Square
                          : o.lattice == "adaptive" ? Lattice::Adaptive
                                                    : Lattice::Triangular;
    params.scan.minLatticeAngleDeg = o.minLatticeAngle;
    params.scan.spacingPixels = o.spacing;
    params.scan.spacingWorld = o.spacingWorld;
    // The warp is a property of the adaptive lattice (ScanOptions::warpToSurface): turning it off elsewhere
    // would do nothing, so it is refused rather than silently ignored.
    if (o.noWarp && o.fishboneOption->count() > 0)
        throw UsageError("The option --no-warp applies to a regular scan's adaptive lattice, not to a "
                         "--fishbone grid.");
    if (o.noWarp && params.scan.lattice != Lattice::Adaptive)
        throw UsageError("The option --no-warp applies to the adaptive lattice only, not to --lattice " +
                         o.lattice + ".");
    params.scan.warpToSurface = !o.noWarp;

    checkOutputFileOptions(o.outPath, o.file);
    const Mesh reference = readInputMesh(meshPath);
    const Eigen::AlignedBox3d box = boundingBox(reference);
    if (o.cameraOption->count() > 0)
        params.camera = makeCamera(o.camera, box, w, h, o.parallel);
    else
        params.camera = Camera::standardView(*parseStandardView(o.view), box, w, h, o.parallel);
    params.camera.zoom(o.zoom);
    if (o.lassoOption->count() > 0) params.lasso = lassoInPixels(o.lasso, w, h);

    std::optional<FishboneParams> fishbone;
    if (o.fishboneOption->count() > 0) fishbone = fishboneInPixels(o.fishbone, w, h);

    // The current mesh: the reference itself (first scan, or --into MESH) or the mesh of --into.
    std::optional<Mesh> intoMesh;
    if (haveInto && !sameFile(o.intoPath, meshPath)) {
        intoMesh = readInputMesh(o.intoPath);
        requireRemeshingOf(*intoMesh, o.intoPath, reference, meshPath, box);
    }
    const Mesh& current = intoMesh ? *intoMesh : reference;
    if (haveInto && o.scanIdOption->count() == 0) params.scan.scanId = nextScanId(current);

    // The reference's renderer, and the current mesh's (a second GPU context that fails falls back to CPU).
    auto newRenderer = [](render::RendererChoice choice) {
        std::string why;
        std::unique_ptr<MeshRenderer> renderer = render::makeRenderer(choice, &why);
        if (!why.empty())
            std::cerr << "fss-remesh scan: note: " << why << " Falling back to CPU ray casting.\n";
        return renderer;
    };
    std::unique_ptr<MeshRenderer> renderer = newRenderer(*render::parseRendererChoice(o.rendererKind));
    const render::RendererChoice kind = render::rendererKind(*renderer);
    const std::string rendererUsed(render::rendererChoiceName(kind));
    renderer->setMesh(reference);
    std::unique_ptr<MeshRenderer> currentRenderer;
    if (intoMesh) {
        currentRenderer =
            newRenderer(kind == render::RendererChoice::Cpu ? kind : render::RendererChoice::Auto);
        currentRenderer->setMesh(*intoMesh);
    }
    MeshRenderer& renderCurrent = currentRenderer ? *currentRenderer : *renderer;
    ScanRun run =
        fishbone ? fishboneScan(reference, *renderer, current, renderCurrent, params, *fishbone, meshPath,
                                rendererUsed)
                 : regularScan(reference, *renderer, current, renderCurrent, params, meshPath, rendererUsed);

    nlohmann::json j;
    j["input"] = meshPath;
    j["output"] = o.outPath;
    j["renderer"] = render::rendererDescription(*renderer);
    j.update(run.json);
    std::string summary = run.summary;
    if (haveInto) {
        // Stitch the patch into (a copy of) the current mesh; nothing is written when that fails.
        Mesh result = current;
        StitchOptions stitchOptions;
        stitchOptions.collectGarbage = true;
        const StitchReport report =
            stitchPatch(result, run.patch.mesh, run.samplingCamera, stitchOptions, run.currentBuffers.faceId);
        writeOutputMesh(result, &reference, o.outPath, o.file, WriteOptions{.binary = false});
        j["into"] = o.intoPath;
        j["scan_id"] = params.scan.scanId;
        j["stitch"] = stitchReportJson<nlohmann::json>(report);
        j["result"] = {{"vertices", result.number_of_vertices()}, {"faces", result.number_of_faces()}};
        j["timings_s"]["stitch"] = report.seconds;
        std::ostringstream text;
        text << "; stitched into " << o.intoPath << " (scan id " << params.scan.scanId
             << "): " << report.facesRemoved << " faces replaced by " << report.facesAdded << " ("
             << report.componentsStitched << " components stitched, " << report.componentsSkipped
             << " skipped, seam min angle " << report.seamMinAngleDeg << " deg) in " << report.seconds
             << " s -> " << result.number_of_faces() << " faces, written to " << o.outPath;
        summary += text.str();
    } else {
        writeOutputMesh(run.patch.mesh, &reference, o.outPath, o.file, WriteOptions{.binary = false});
        summary += ", written to " + o.outPath;
    }
    if (o.json)
        std::cout << j.dump(2) << "\n";
    else
        std::cout << summary << "\n";
    return 0;
}

} // namespace

Subcommand addScan(CLI::App& app) {
    auto o = std::make_shared<ScanOptions>();
    CLI::App* p = addCommand(
        app, "scan",
        "Scan MESH from a camera: render it off-screen, turn every covered pixel into a sample on the "
        "surface, mask the samples and triangulate the pixel grid into a regular patch (interior valence 6), "
        "written to OUT. With --into CURRENT the patch is stitched into CURRENT and the result written to "
        "OUT.",
        "examples:\n  fss-remesh scan fandisk.off -o patch.ply --view iso --resolution 512\n"
        "  fss-remesh scan fandisk.off -o patch.ply --view +x --lasso \"0.2,0.2;0.8,0.2;0.5,0.9\" --erode 2\n"
        "  fss-remesh scan fandisk.off -o patch.ply --renderer cpu --fishbone \"seed=0.4,0.55;dir=min;h=3\"\n"
        "  fss-remesh scan fandisk.off --into fandisk.off -o step1.ply --view iso\n"
        "  fss-remesh scan fandisk.off --into step1.ply -o step2.ply --view +x --json");
    p->add_option("MESH", o->meshPath, "The reference mesh to scan (.off .obj .ply .stl).")
        ->required()
        ->type_name("");
    addOutputMesh(*p, o->outPath,
                  "Output file of the patch, or of the stitched mesh with --into (.ply keeps per-face "
                  "quality and scan id; FEM: .msh .inp .bdf .unv .vtu .vtp).");
    addOutputFileOptions(*p, o->file);
    o->viewOption = p->add_option("--view", o->view,
                                  "Standard view fitted to the mesh: iso, +x, -x, +y, -y, +z, -z (default "
                                  "iso). '+x' looks from the +x side.")
                        ->type_name("V")
                        ->check(standardViewName("--view"));
    o->cameraOption = p->add_option_function<std::string>(
                           "--camera", [o](const std::string& text) { o->camera = parseCameraNumbers(text); },
                           "Explicit camera \"ex,ey,ez,fx,fy,fz,ux,uy,uz[,angle]\": eye, focal point, up "
                           "vector and the vertical view angle in degrees (default 30).")
                          ->type_name("E,F,U[,A]");
    p->add_flag("--parallel", o->parallel, "Parallel (orthographic) projection instead of perspective.");
    addResolution(*p, "--resolution", o->w, o->h, Camera::kMaxResolution, "W[xH]",
                  "Scan resolution in pixels, 1 to 8192 per side (default 256).");
    addDouble(*p, "--zoom", o->zoom, true, "F",
              "Zoom factor > 0 (2 = twice as close, finer sampling; default 1).");
    o->lassoOption =
        p->add_option_function<std::string>(
             "--lasso", [o](const std::string& text) { o->lasso = parseLasso(text); },
             "Keep only samples inside this polygon, in normalised image coordinates (0,0 top-left, 1,1 "
             "bottom-right). Self-intersecting polygons use the non-zero winding rule.")
            ->type_name("\"x,y;x,y;...\"");
    o->fishboneOption =
        p->add_option_function<std::string>(
             "--fishbone", [o](const std::string& text) { o->fishbone = parseFishbone(text); },
             "Feature-sensitive (fishbone) grid instead of the pixel grid: "
             "\"seed=X,Y[;dir=min|max][;h=PIXELS][;keyribs=X,Y|X,Y...][;backbone=X,Y|X,Y...][;sampling=K]\". "
             "seed: a point on a curved feature; the backbone is traced through it along the min (default) "
             "or max curvature direction, ribs along the other; h: sample spacing in pixels (default 4); "
             "keyribs: ribs only at the backbone samples nearest these points (at least two), blended in "
             "between; backbone: a hand-drawn backbone through these points instead of the seed; sampling: "
             "the fishbone renders and traces on the image at 1/K of the resolution (default 0: K = the "
             "largest integer <= h dividing both sides, about one pixel per sample as a regular scan; 1 = "
             "full resolution, finer direction fields at up to h^2 times the render cost). Points in "
             "normalised image coordinates as for --lasso. --max-edge-footprints is multiplied by h/K.")
            ->type_name("SPEC");
    p->add_option("--lattice", o->lattice,
                  "Sample lattice of a regular scan: adaptive (default; a triangular lattice compressed and "
                  "turned per view so that the most of the visible surface gets round triangles despite its "
                  "slant, then warped to the surface unless --no-warp), triangular (rows offset by half a "
                  "spacing, equilateral triangles on the screen) or "
                  "square (one sample per pixel centre, the paper's pixel grid).")
        ->type_name("L")
        ->check(oneOf("--lattice", {"triangular", "square", "adaptive"}));
    p->add_flag(
        "--no-warp", o->noWarp,
        "Do not warp the adaptive lattice to the surface: sample on the one affine lattice chosen for the "
        "view (equilateral only on the plane at the view's dominant slant) instead of bending it per sample "
        "so that its triangles are equilateral on the curved surface (default: warped). Only with the "
        "adaptive lattice of a regular scan.");
    addDouble(*p, "--min-lattice-angle", o->minLatticeAngle, false, "DEG",
              "Leave to other views the surface where the lattice's triangles would have a smallest angle "
              "below DEG degrees (its slant), in [0, 60) (default 35; 0 = keep all).");
    addDouble(*p, "--spacing", o->spacing, true, "PX",
              "Sample spacing of a regular scan's lattice in pixels, 0.25 to 1024 (default 1).");
    addDouble(*p, "--spacing-world", o->spacingWorld, true, "D",
              "Sample spacing in world units instead (converted with the pixel size at the camera's focal "
              "point).");
    addInt(*p, "--erode", o->erode, 0, 64, "N", "Erosion radius in samples (default 1; 0 = none).");
    addInt(*p, "--dilate", o->dilate, 0, 64, "N",
           "Dilation radius after the erosion (default 1); never re-admits rejected samples.");
    addDouble(*p, "--max-edge-footprints", o->maxEdge, false, "X",
              "Drop triangles with an edge longer than X pixel footprints (default 3).");
    addDouble(*p, "--max-angle", o->maxAngle, false, "DEG",
              "Drop triangles seen at more than DEG degrees from frontal (default 80).");
    addDouble(*p, "--min-quad-angle", o->minQuadAngle, false, "DEG",
              "Drop both triangles of a grid quad with a 3D corner angle below DEG degrees, in [0, 90) "
              "(default 0 = no bound).");
    addDouble(*p, "--quality-margin", o->margin, false, "M",
              "A sample replaces a face only when better by this fraction (default 0.1).");
    p->add_flag("--force-replace", o->force,
                "Keep every sample regardless of the quality of the mesh already there.");
    o->intoOption =
        p->add_option(
             "--into", o->intoPath,
             "Stitch the patch into the mesh CURRENT and write the result to OUT instead of the patch. MESH "
             "stays the reference the samples come from; CURRENT's faces decide where the scan is better "
             "(quality mask) and are replaced there. Give MESH itself for the first scan and chain through "
             ".ply files, which keep each face's quality and scan id. CURRENT must be a remeshing of MESH "
             "(every vertex within 1 % of MESH's bounding-box diagonal from its surface).")
            ->type_name("CURRENT");
    o->scanIdOption = addInt(
        *p, "--scan-id", o->scanId, 0, 1 << 30, "N",
        "Scan id stored on the patch faces (default 0; with --into one more than the largest in CURRENT).");
    addRenderer(*p, o->rendererKind, {},
                "auto (GPU, else CPU), gpu (head-less OpenGL) or cpu (ray casting).");
    p->add_flag("--json", o->json,
                "Print a JSON report: counts and the timing of each stage (with --into also the stitch "
                "report under \"stitch\").");
    return {p, [o] { return runScan(*o); }};
}

} // namespace fss::cli
