// fss-remesh run: a session recorded through the C++ API (CPU renderer) and replayed by the command line
// gives a byte-identical OFF; the report holds the metrics and per-event timings; bad session files fail
// with one sentence and leave OUT unwritten.
#include "fss/mesh_io.h"
#include "fss/session_file.h"

#include "run_process.h"
#include "test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_run_test {

namespace {

namespace fs = std::filesystem;
using fss::test::remeshExe;
using fss::test::runProcess;
using fss::test::tmpPath;

fss::ScanStep viewStep(const fss::Mesh& mesh, fss::StandardView view, int resolution, double zoom, int id) {
    fss::ScanStep step;
    step.params.camera = fss::Camera::standardView(view, fss::boundingBox(mesh), resolution, resolution);
    step.params.camera.zoom(zoom);
    step.params.scan.scanId = id;
    return step;
}

// One recording shared by the tests: fandisk, four regular scans, an undo, a redo, a fishbone scan on the
// cylindrical band seen from +x, another regular scan and an undo. The recording session's mesh is written
// as OFF by the API.
struct Recording {
    fs::path session = tmpPath("cli_run/recorded.session.json");
    fs::path expectedOff = tmpPath("cli_run/expected.off");
    std::size_t vertices = 0;
    std::size_t events = 0;
};

const Recording& recording() {
    static const Recording rec = [] {
        Recording r;
        fs::create_directories(r.session.parent_path());
        const fs::path mesh = fss::test::meshPath("fandisk.off");
        fss::Session s(fss::readMesh(mesh));
        const fss::Mesh& ref = s.reference();
        s.scan(viewStep(ref, fss::StandardView::Iso, 160, 1.0, 1));
        s.accept();
        s.scan(viewStep(ref, fss::StandardView::PosX, 160, 1.0, 2));
        s.accept();
        s.undo();
        s.scan(viewStep(ref, fss::StandardView::NegY, 160, 1.0, 3));
        s.accept();
        s.undo();
        s.redo();
        fss::ScanStep fish = viewStep(ref, fss::StandardView::PosX, 256, 1.0, 4);
        fish.fishbone = fss::FishboneParams{};
        fish.fishbone->seed = Eigen::Vector2d(120.3, 75.2); // on the cylindrical band below the top
        fish.fishbone->spacing = 2.0;
        s.scan(fish);
        s.accept();
        s.scan(viewStep(ref, fss::StandardView::PosZ, 128, 1.0, 5));
        s.accept();
        s.undo();
        fss::writeMesh(s.current(), r.expectedOff);
        r.vertices = s.current().number_of_vertices();
        r.events = s.events().size();
        fss::saveSessionFile(fss::sessionFileFromSession(s, mesh, "cpu"), r.session);
        return r;
    }();
    return rec;
}

TEST(CliRun, ReplayWritesTheRecordedMeshByteForByte) {
    const Recording& rec = recording();
    ASSERT_EQ(rec.events, 9u);
    const fs::path out = tmpPath("cli_run/replayed.off");
    const fs::path report = tmpPath("cli_run/report.json");
    const fs::path png = tmpPath("cli_run/snapshot.png");
    fs::remove(out);
    fs::remove(report);
    fs::remove(png);
    const auto r = runProcess(remeshExe(),
                              {"run", rec.session.string(), "-o", out.string(), "--report", report.string(),
                               "--snapshot", png.string(), "--snapshot-size", "320x240"},
                              tmpPath("cli_run"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err, ""); // no progress bar when stderr is not a terminal
    EXPECT_NE(r.out.find("replayed "), std::string::npos) << r.out;
    const std::string expected = fss::test::slurp(rec.expectedOff);
    ASSERT_FALSE(expected.empty());
    EXPECT_TRUE(fss::test::slurp(out) == expected) << "the replayed OFF differs from the recorded one";

    const nlohmann::json j = nlohmann::json::parse(fss::test::slurp(report));
    EXPECT_EQ(j["renderer"], "cpu");
    EXPECT_EQ(j["metrics"]["vertices"], rec.vertices);
    EXPECT_TRUE(j["metrics"]["closed"].get<bool>());
    EXPECT_TRUE(j["metrics"]["hausdorff_to_ref_rel"].is_number());
    EXPECT_LT(j["metrics"]["hausdorff_to_ref_rel"].get<double>(), 0.01);
    EXPECT_TRUE(j["metrics"]["hausdorff_from_ref_rel"].is_number());
    EXPECT_EQ(j["input_metrics"]["vertices"], 6475);
    EXPECT_TRUE(j["input_metrics"]["hausdorff_to_ref"].is_null());
    EXPECT_EQ(j["counts"]["accepted"], 5);
    EXPECT_EQ(j["counts"]["undone"], 3);
    EXPECT_EQ(j["counts"]["redone"], 1);
    ASSERT_EQ(j["events"].size(), rec.events);
    const auto& fishEvent = j["events"][6];
    EXPECT_EQ(fishEvent["grid"], "fishbone");
    EXPECT_GT(fishEvent["patch_faces"].get<int>(), 100);
    EXPECT_GT(fishEvent["stitch"]["faces_added"].get<int>(), 0);
    EXPECT_GE(fishEvent["scan_s"].get<double>(), 0.0);
    EXPECT_GE(fishEvent["stitch_s"].get<double>(), 0.0);
    EXPECT_FALSE(j["events"][2].contains("stitch")); // an undo
    EXPECT_EQ(j["snapshot"]["width"], 320);
    EXPECT_GT(j["snapshot"]["covered_fraction"].get<double>(), 0.1);
    // A real PNG of the asked size: signature and IHDR.
    const std::string bytes = fss::test::slurp(png);
    ASSERT_GT(bytes.size(), 33u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    auto be32 = [&](std::size_t at) {
        return (unsigned(std::uint8_t(bytes[at])) << 24) | (unsigned(std::uint8_t(bytes[at + 1])) << 16) |
               (unsigned(std::uint8_t(bytes[at + 2])) << 8) | unsigned(std::uint8_t(bytes[at + 3]));
    };
    EXPECT_EQ(be32(16), 320u);
    EXPECT_EQ(be32(20), 240u);

    // --json prints the same report on stdout.
    const auto js = runProcess(remeshExe(), {"run", rec.session.string(), "-o", out.string(), "--json"},
                               tmpPath("cli_run"));
    ASSERT_EQ(js.exitCode, 0) << js.err;
    const nlohmann::json jj = nlohmann::json::parse(js.out);
    EXPECT_EQ(jj["metrics"]["vertices"], rec.vertices);
    EXPECT_EQ(jj["events"].size(), rec.events);
    EXPECT_TRUE(fss::test::slurp(out) == expected);
}

// Writes \p text as a session file and runs it: exit 1, one sentence mentioning \p field, no OUT.
void expectRejected(const std::string& name, const std::string& text, const std::string& field) {
    const fs::path session = tmpPath("cli_run/" + name + ".session.json");
    std::ofstream(session, std::ios::binary | std::ios::trunc) << text;
    const fs::path out = tmpPath("cli_run/" + name + ".off");
    fs::remove(out);
    const auto r = runProcess(remeshExe(), {"run", session.string(), "-o", out.string()}, tmpPath("cli_run"));
    fss::test::expectCleanFailure(r, field);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(session.string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << name;
}

TEST(CliRun, BadSessionFilesFailWithOneSentence) {
    const Recording& rec = recording();
    const std::string good = fss::test::slurp(rec.session);
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(good);

    auto edited = [&](const std::function<void(nlohmann::ordered_json&)>& edit) {
        nlohmann::ordered_json copy = j;
        edit(copy);
        return copy.dump(2);
    };
    expectRejected("version", edited([](nlohmann::ordered_json& x) { x["version"] = 7; }), "version is 7");
    expectRejected("missing",
                   edited([](nlohmann::ordered_json& x) { x["events"][3]["step"]["camera"].erase("width"); }),
                   "events[3].step.camera.width is missing");
    expectRejected("type",
                   edited([](nlohmann::ordered_json& x) { x["events"][3]["step"]["camera"]["width"] = -4; }),
                   "events[3].step.camera.width must be a positive integer");
    expectRejected("mesh",
                   edited([](nlohmann::ordered_json& x) { x["mesh"]["path"] = "does_not_exist.off"; }),
                   "mesh.path");
    expectRejected("sha",
                   edited([](nlohmann::ordered_json& x) { x["mesh"]["sha256"] = std::string(64, 'a'); }),
                   "mesh.sha256");
    expectRejected("truncated", good.substr(0, good.size() / 3), "is not valid JSON");
    expectRejected("replay", edited([](nlohmann::ordered_json& x) {
                       auto& cam = x["events"][0]["step"]["camera"];
                       cam["focal"] = {cam["eye"][0].get<double>() * 2, cam["eye"][1].get<double>() * 2,
                                       cam["eye"][2].get<double>() * 2}; // looks away from the mesh
                   }),
                   "events[0] (accept)");

    // A missing session file, and command-line mistakes (exit 2).
    const auto missing =
        runProcess(remeshExe(),
                   {"run", tmpPath("cli_run/none.json").string(), "-o", tmpPath("cli_run/none.off").string()},
                   tmpPath("cli_run"));
    fss::test::expectCleanFailure(missing, "does not exist");
    const auto noOut = runProcess(remeshExe(), {"run", rec.session.string()}, tmpPath("cli_run"));
    EXPECT_EQ(noOut.exitCode, 2);
    const auto badRenderer =
        runProcess(remeshExe(), {"run", rec.session.string(), "-o", "x.off", "--renderer", "vulkan"},
                   tmpPath("cli_run"));
    EXPECT_EQ(badRenderer.exitCode, 2);
    const auto badSnapshot = runProcess(
        remeshExe(), {"run", rec.session.string(), "-o", "x.off", "--snapshot", "x.jpg"}, tmpPath("cli_run"));
    EXPECT_EQ(badSnapshot.exitCode, 2);
}

// Issue 19, DESIGN.md §6.2: the strip refill's gap fill once depended on where the allocator put CGAL's
// vertices (Lloyd moved them in address order), so a session with "refill_seam" replayed to different meshes
// under different heap layouts (session 17's binary: three meshes for three runs of one session). Recorded
// here in this process, after a heap left full of holes, and replayed by two new processes with different
// MALLOC_PERTURB_ values (other initial heap contents) and ASLR: all three meshes byte for byte equal.
TEST(CliRun, RefillSessionReplaysToTheSameBytesInNewProcesses) {
    const fs::path mesh = fss::test::meshPath("fandisk.off");
    const fs::path session = tmpPath("cli_run/refill.session.json");
    const fs::path expectedOff = tmpPath("cli_run/refill_expected.off");
    fs::create_directories(session.parent_path());
    {
        // Holes of many sizes in the heap before the recording, so its allocations land elsewhere than a
        // fresh process's.
        std::vector<std::vector<char>> junk;
        for (int i = 0; i < 4000; ++i)
            junk.emplace_back(std::size_t(16 + (i * 7919) % 3000));
        for (std::size_t i = 0; i < junk.size(); i += 2)
            std::vector<char>().swap(junk[i]);
        fss::Session s(fss::readMesh(mesh));
        const fss::Mesh& ref = s.reference();
        int id = 1;
        for (const auto view : {fss::StandardView::Iso, fss::StandardView::PosX, fss::StandardView::NegY}) {
            fss::ScanStep step = viewStep(ref, view, 160, 1.0, id++);
            step.stitch.refillSeam = true;
            s.scan(step);
            s.accept();
        }
        fss::writeMesh(s.current(), expectedOff);
        fss::saveSessionFile(fss::sessionFileFromSession(s, mesh, "cpu"), session);
    }
    const std::string expected = fss::test::slurp(expectedOff);
    ASSERT_FALSE(expected.empty());
    ASSERT_NE(fss::test::slurp(session).find("\"refill_seam\": true"), std::string::npos);
    for (const char* perturb : {"0", "85", "170"}) {
        ::setenv("MALLOC_PERTURB_", perturb, 1);
        const fs::path out = tmpPath(std::string("cli_run/refill_replayed_") + perturb + ".off");
        fs::remove(out);
        const auto r =
            runProcess(remeshExe(), {"run", session.string(), "-o", out.string()}, tmpPath("cli_run"));
        ::unsetenv("MALLOC_PERTURB_");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_TRUE(fss::test::slurp(out) == expected)
            << "MALLOC_PERTURB_=" << perturb << ": the replayed OFF differs from the recorded one";
    }
}

// The bundled example session (the README's main job) replays into a closed, self-intersection-free mesh
// that is more regular than the input and close to it.
TEST(CliRun, ExampleSessionReplays) {
    const fs::path session = fs::path(FSS_SOURCE_DIR) / "examples" / "fandisk.session.json";
    const fs::path out = tmpPath("cli_run/example.off");
    const fs::path report = tmpPath("cli_run/example_report.json");
    const auto r =
        runProcess(remeshExe(), {"run", session.string(), "-o", out.string(), "--report", report.string()},
                   tmpPath("cli_run"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(fss::test::slurp(report));
    int fishbone = 0, regular = 0;
    for (const auto& e : j["events"]) {
        ASSERT_EQ(e["kind"], "accept");
        (e["grid"] == "fishbone" ? fishbone : regular) += 1;
        EXPECT_GT(e["stitch"]["faces_added"].get<int>(), 0);
    }
    EXPECT_EQ(fishbone, 2);
    EXPECT_GE(regular, 5);
    const auto& m = j["metrics"];
    EXPECT_TRUE(m["closed"].get<bool>());
    EXPECT_EQ(m["components"], 1);
    EXPECT_EQ(m["self_intersections"], 0);
    EXPECT_EQ(m["degenerate_faces"], 0);
    EXPECT_GT(m["frac_valence6_interior"].get<double>(),
              j["input_metrics"]["frac_valence6_interior"].get<double>());
    EXPECT_LT(m["hausdorff_to_ref_rel"].get<double>(), 0.01);
    EXPECT_LT(m["hausdorff_from_ref_rel"].get<double>(), 0.01);
    // Issue 20: round triangles — the whole mesh's mean smallest angle ≥ 50° (55.0° since the session was
    // recorded on the adaptive lattice; 43.6° on the square pixel lattice), above the input's 43.5°.
    EXPECT_GE(m["mean_min_angle_deg"].get<double>(), 50.0);
    EXPECT_GT(m["mean_min_angle_deg"].get<double>(), j["input_metrics"]["mean_min_angle_deg"].get<double>());
}

} // namespace

} // namespace fss_cli_run_test
