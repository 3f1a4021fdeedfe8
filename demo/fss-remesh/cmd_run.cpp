// fss-remesh run SESSION.json -o OUT [--report R.json] [--json] [--snapshot S.png] [--snapshot-size WxH]
//                [--snapshot-view V] [--snapshot-legend] [--renderer session|auto|gpu|cpu]
//                [--no-self-intersections]
// Replays a session file head-less (session_file.h) and reports what it made.
#include "command_line.h"
#include "commands.h"
#include "mesh_files.h"
#include "stitch_json.h"
#include "terminal_progress.h"

#include "fss/camera.h"
#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"
#include "fss/render/renderer_choice.h"
#include "fss/render/snapshot.h"
#include "fss/session_file.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace fss::cli {
namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

struct RunOptions {
    std::string sessionPath, outPath, reportPath, snapshotPath, snapshotView = "iso",
                                                                rendererKind = "session";
    int snapW = 1024, snapH = 768;
    double zoom = 1;
    const CLI::Option* report = nullptr;   // given when count() > 0
    const CLI::Option* snapshot = nullptr; // given when count() > 0
    bool json = false, noSelf = false, quiet = false, legend = false;
    OutputFileOptions file;
};

int runRun(const RunOptions& o) {
    const std::string command = "fss-remesh run";
    const bool haveReport = o.report->count() > 0, haveSnapshot = o.snapshot->count() > 0, json = o.json;
    if (haveReport && o.reportPath.empty()) throw UsageError("The option --report needs a file name.");
    const auto view = parseStandardView(o.snapshotView);
    checkOutputFileOptions(o.outPath, o.file);

    const auto start = Clock::now();
    const SessionFile file = loadSessionFile(o.sessionPath);
    const double loadSeconds = since(start);

    const std::string kind = o.rendererKind == "session" ? file.renderer : o.rendererKind;
    const render::RendererSelection renderer =
        render::chooseRenderer(render::parseRendererChoice(kind).value_or(render::RendererChoice::Auto));
    if (!renderer.fallbackReason.empty())
        std::cerr << command << ": note: " << renderer.fallbackReason
                  << " Falling back to CPU ray casting.\n";
    const std::string used(render::rendererChoiceName(renderer.used));
    if (used != file.renderer)
        std::cerr << command << ": note: the session was recorded with the " << file.renderer
                  << " renderer and is replayed with the " << used << " one; the mesh may differ slightly.\n";

    TerminalProgress bar(!o.quiet);

    const auto replayStart = Clock::now();
    ReplayResult replay = replaySession(file, renderer.factory, bar.progress());
    const double replaySeconds = since(replayStart);
    const Mesh& result = replay.session.current();

    auto t = Clock::now();
    writeOutputMesh(result, &replay.session.reference(), o.outPath, o.file);
    const double writeSeconds = since(t);

    const bool wantReport = haveReport || json;
    Json report;
    double metricsSeconds = 0;
    std::optional<Metrics> metrics, inputMetrics;
    t = Clock::now();
    {
        MetricsOptions options;
        options.selfIntersections = !o.noSelf;
        options.reference = &replay.session.reference();
        bar.update(1.0, "metrics");
        metrics = computeMetrics(result, options);
        options.reference = nullptr;
        inputMetrics = computeMetrics(replay.session.reference(), options);
    }
    metricsSeconds = since(t);

    double snapshotSeconds = 0;
    render::Snapshot shot;
    if (haveSnapshot) {
        bar.update(1.0, "snapshot");
        t = Clock::now();
        Camera camera = Camera::standardView(*view, boundingBox(result), o.snapW, o.snapH);
        camera.zoom(o.zoom);
        render::SnapshotOptions options;
        if (o.rendererKind == "cpu") options.renderer = render::SnapshotOptions::Renderer::Cpu;
        options.legend = o.legend;
        shot = render::renderSnapshot(result, camera, options);
        render::writePng(shot.image, o.snapshotPath);
        snapshotSeconds = since(t);
    }
    bar.finish();

    std::size_t accepts = 0, undos = 0, redos = 0;
    for (const ReplayedEvent& e : replay.events) {
        accepts += e.kind == SessionEvent::Kind::Accept;
        undos += e.kind == SessionEvent::Kind::Undo;
        redos += e.kind == SessionEvent::Kind::Redo;
    }

    if (wantReport) {
        report["session"] = o.sessionPath;
        report["input"] = file.meshPath.string();
        report["input_sha256"] = file.meshSha256;
        report["output"] = o.outPath;
        report["renderer"] = used;
        report["renderer_recorded"] = file.renderer;
        report["counts"] = {{"events", replay.events.size()},
                            {"accepted", accepts},
                            {"undone", undos},
                            {"redone", redos},
                            {"steps_applied", replay.session.undoCount()}};
        Json events = Json::array();
        for (std::size_t i = 0; i < replay.events.size(); ++i) {
            const ReplayedEvent& e = replay.events[i];
            Json je;
            je["index"] = i;
            je["kind"] = sessionEventKindName(e.kind);
            if (e.kind == SessionEvent::Kind::Accept) {
                je["grid"] = e.fishbone ? "fishbone" : "regular";
                je["patch_faces"] = e.patchFaces;
                je["scan_s"] = e.scanSeconds;
                je["stitch_s"] = e.stitchSeconds;
            }
            je["seconds"] = e.seconds;
            if (e.stitch) je["stitch"] = stitchReportJson<Json>(*e.stitch);
            events.push_back(std::move(je));
        }
        report["events"] = std::move(events);
        report["timings_s"] = {{"load_session", loadSeconds}, {"read_mesh", replay.readSeconds},
                               {"replay", replaySeconds},     {"write", writeSeconds},
                               {"metrics", metricsSeconds},   {"snapshot", snapshotSeconds},
                               {"total", since(start)}};
        report["metrics"] = Json::parse(metricsToJson(*metrics));
        report["input_metrics"] = Json::parse(metricsToJson(*inputMetrics));
        if (haveSnapshot)
            report["snapshot"] = {
                {"file", o.snapshotPath},
                {"width", o.snapW},
                {"height", o.snapH},
                {"view", o.snapshotView},
                {"renderer", shot.renderer},
                {"covered_fraction", double(shot.covered) / (double(o.snapW) * double(o.snapH))}};
        if (haveReport) {
            const std::string tmp = o.reportPath + ".tmp" + std::to_string(::getpid());
            {
                std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
                if (!out) throw IoError("The report " + o.reportPath + " cannot be written.");
                out << report.dump(2) << "\n";
                if (!out.flush())
                    throw IoError("The report " + o.reportPath + " could not be written completely.");
            }
            std::error_code ec;
            std::filesystem::rename(tmp, o.reportPath, ec);
            if (ec)
                throw IoError("The report " + o.reportPath + " cannot be written (" + ec.message() + ").");
        }
    }

    if (json) {
        std::cout << report.dump(2) << "\n";
    } else {
        const Metrics& m = *metrics;
        std::cout << "replayed " << o.sessionPath << " (" << accepts << " scans, " << undos << " undos, "
                  << redos << " redos; " << used << " renderer) in " << replaySeconds << " s: " << m.vertices
                  << " vertices, " << m.faces << " faces, written to " << o.outPath << "\n";
        std::cout << metricsToText(m);
        if (inputMetrics) {
            const Metrics& in = *inputMetrics;
            char line[160];
            std::cout << "  compared with the input        input      output\n";
            auto row = [&](const char* label, double a, double b, const char* fmt) {
                std::snprintf(line, sizeof line, fmt, label, a, b);
                std::cout << line;
            };
            row("vertices", double(in.vertices), double(m.vertices), "    %-24s %10.0f  %10.0f\n");
            row("faces", double(in.faces), double(m.faces), "    %-24s %10.0f  %10.0f\n");
            row("valence-6 interior (%)", 100 * in.fracValence6Interior, 100 * m.fracValence6Interior,
                "    %-24s %10.1f  %10.1f\n");
            row("min angle (deg)", in.minAngleDeg, m.minAngleDeg, "    %-24s %10.2f  %10.2f\n");
            row("mean min angle (deg)", in.meanMinAngleDeg, m.meanMinAngleDeg, "    %-24s %10.2f  %10.2f\n");
            row("min angle < 30 deg (%)", 100 * in.fracMinAngleBelow30, 100 * m.fracMinAngleBelow30,
                "    %-24s %10.2f  %10.2f\n");
        }
        if (haveReport) std::cout << "report written to " << o.reportPath << "\n";
        if (haveSnapshot)
            std::cout << "snapshot (" << shot.renderer << ") written to " << o.snapshotPath << "\n";
    }
    return 0;
}

} // namespace

Subcommand addRun(CLI::App& app) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* p = addCommand(
        app, "run",
        "Replay the session file SESSION.json head-less: read its input mesh (checking its SHA-256), apply "
        "every recorded scan, undo and redo in order, and write the resulting mesh to OUT. With the renderer "
        "the session was recorded with, OUT is identical to the mesh the recording session produced.",
        "example:\n  fss-remesh run examples/fandisk.session.json -o fandisk_remeshed.ply --report "
        "report.json --snapshot fandisk.png");
    p->add_option("SESSION.json", o->sessionPath,
                  "Session file (fss-session JSON, written by fss-demo or the C++ API).")
        ->required()
        ->type_name("");
    addOutputMesh(
        *p, o->outPath,
        "Output mesh (.off .obj .ply .stl, or for FEM .msh .inp .bdf .unv .vtu .vtp; .ply keeps per-face "
        "quality and scan id). The input's face groups are carried to the output.");
    addOutputFileOptions(*p, o->file);
    o->report =
        p->add_option(
             "--report", o->reportPath,
             "Write a JSON report: every metric of 'fss-remesh info' for OUT (with Hausdorff distances to "
             "the input) and for the input, and per event the scan and stitch times and the stitch report.")
            ->type_name("R.json");
    p->add_flag("--json", o->json, "Print the same JSON report on stdout instead of the text summary.");
    o->snapshot = p->add_option("--snapshot", o->snapshotPath,
                                "Render OUT head-less into a PNG coloured by each triangle's minimum angle "
                                "(red 0, yellow 30, green 60 degrees).")
                      ->type_name("S.png")
                      ->check(CLI::Validator(
                          [](std::string& path) {
                              const std::string ext = std::filesystem::path(path).extension().string();
                              if (ext != ".png" && ext != ".PNG")
                                  throw UsageError("The snapshot " + path + " must be a .png file.");
                              return std::string();
                          },
                          "", "png file"));
    addResolution(*p, "--snapshot-size", o->snapW, o->snapH, Camera::kMaxResolution, "WxH",
                  "Size of the snapshot in pixels (default 1024x768).");
    p->add_option("--snapshot-view", o->snapshotView,
                  "View of the snapshot: iso, +x, -x, +y, -y, +z, -z (default iso).")
        ->type_name("V")
        ->check(standardViewName("--snapshot-view"));
    p->add_flag("--snapshot-legend", o->legend,
                "Append the colour legend (a VTK scalar bar, 0 to 60 degrees) at the right of the snapshot.");
    addDouble(*p, "--snapshot-zoom", o->zoom, true, "F",
              "Zoom factor of the snapshot camera (> 0, default 1: the whole mesh).");
    addRenderer(*p, o->rendererKind, {"session"},
                "session (default: the renderer the session was recorded with), auto (GPU, else CPU), gpu or "
                "cpu. Another renderer than the recording's gives a slightly different mesh.");
    p->add_flag("--no-self-intersections", o->noSelf,
                "Skip the self-intersection count in the report (slow on huge meshes).");
    p->add_flag("--quiet", o->quiet, "No progress bar (it is shown only when stderr is a terminal anyway).");
    return {p, [o] { return runRun(*o); }};
}

} // namespace fss::cli
