// Session files: every field of a ScanStep round-trips bit-exactly, doubles of any bit pattern survive the
// JSON text, bad files give one sentence naming the file and the field, and a replay reproduces the
// recording session's current mesh exactly.
// Bad files and the optional keys of later sessions: session_file_keys_test.cpp.
#include "session_file_helpers.h"

using namespace session_file_test_helpers;

namespace {

TEST(SessionFile, EveryFieldRoundTripsExactly) {
    const auto mesh = writeTestMesh("session_file_roundtrip.off", fss::shapes::icosahedron());
    const fss::SessionFile original = sampleFile(mesh);
    const auto path = fss::test::tmpPath("session_file_roundtrip.session.json");
    fss::saveSessionFile(original, path);
    const fss::SessionFile loaded = fss::loadSessionFile(path);
    EXPECT_EQ(loaded.version, fss::kSessionFileVersion);
    EXPECT_EQ(loaded.description, original.description);
    EXPECT_EQ(std::filesystem::absolute(loaded.meshPath).lexically_normal(),
              std::filesystem::absolute(mesh).lexically_normal());
    EXPECT_EQ(loaded.meshSha256, original.meshSha256);
    EXPECT_EQ(loaded.renderer, "gpu");
    EXPECT_EQ(loaded.curvature.jetDegree, 3);
    EXPECT_EQ(loaded.curvature.minPoints, 30);
    EXPECT_EQ(loaded.curvature.maxRings, 4);
    EXPECT_TRUE(sameBits(loaded.curvature.anisotropyEpsilon, 2.5e-3));
    EXPECT_EQ(loaded.source, path);
    ASSERT_EQ(loaded.events.size(), original.events.size());
    for (std::size_t i = 0; i < original.events.size(); ++i) {
        SCOPED_TRACE("event " + std::to_string(i));
        EXPECT_EQ(loaded.events[i].kind, original.events[i].kind);
        if (original.events[i].kind == fss::SessionEvent::Kind::Accept)
            expectSame(original.events[i].step, loaded.events[i].step);
    }
    // The sign of -0.0 and the subnormal survive.
    EXPECT_TRUE(std::signbit(loaded.events[0].step.params.camera.focal.x()));
    // Saving the loaded file again gives the same text.
    const auto again = fss::test::tmpPath("session_file_roundtrip2.session.json");
    fss::saveSessionFile(loaded, again);
    EXPECT_EQ(fss::test::tmpPath("x").parent_path(), again.parent_path());
    std::ifstream a(path), b(again);
    std::stringstream ta, tb;
    ta << a.rdbuf();
    tb << b.rdbuf();
    EXPECT_EQ(ta.str(), tb.str());
}

// nlohmann::json writes the shortest text that reads back to the same double: checked on random bit
// patterns over the whole finite range and on random doubles of the magnitudes cameras have.
TEST(SessionFile, DoublesRoundTripBitExactly) {
    const auto mesh = writeTestMesh("session_file_doubles.off", fss::shapes::icosahedron());
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> moderate(-1e4, 1e4);
    fss::SessionFile file;
    file.meshPath = mesh;
    file.meshSha256 = fss::sha256OfFile(mesh);
    std::vector<double> values;
    for (int i = 0; i < 3000; ++i) {
        double v;
        do
            v = std::bit_cast<double>(rng());
        while (!std::isfinite(v));
        values.push_back(v);
        values.push_back(moderate(rng));
    }
    fss::ScanStep step;
    step.params.lasso = fss::Lasso{};
    for (std::size_t i = 0; i + 1 < values.size(); i += 2)
        step.params.lasso->points.emplace_back(values[i], values[i + 1]);
    // The lasso must enclose an area to load: these corners make sure it does whatever the random points are.
    step.params.lasso->points.emplace_back(0, 0);
    step.params.lasso->points.emplace_back(1, 0);
    step.params.lasso->points.emplace_back(0, 1);
    file.events.push_back({fss::SessionEvent::Kind::Accept, step});
    const fss::SessionFile loaded =
        fss::sessionFileFromJson(fss::sessionFileToJson(file), "doubles.json", ".", {.verifyMesh = false});
    const auto& pts = loaded.events.at(0).step.params.lasso->points;
    ASSERT_EQ(pts.size(), step.params.lasso->points.size());
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < pts.size(); ++i)
        mismatches += !sameBits(pts[i].x(), step.params.lasso->points[i].x()) ||
                      !sameBits(pts[i].y(), step.params.lasso->points[i].y());
    EXPECT_EQ(mismatches, 0u);
}

TEST(SessionFile, RelativeMeshPathIsRelativeToTheSessionFile) {
    const auto dir = fss::test::tmpPath("session_file_paths");
    std::filesystem::create_directories(dir / "meshes");
    std::filesystem::create_directories(dir / "sessions");
    const auto mesh = writeTestMesh("session_file_paths/meshes/ico.off", fss::shapes::icosahedron());
    fss::SessionFile file;
    file.meshPath = std::filesystem::relative(mesh); // relative to the working directory
    file.meshSha256 = fss::sha256OfFile(mesh);
    const auto session = dir / "sessions" / "s.json";
    fss::saveSessionFile(file, session);
    const Json j = Json::parse(slurpText(session));
    EXPECT_EQ(j["mesh"]["path"], "../meshes/ico.off");
    const fss::SessionFile loaded = fss::loadSessionFile(session);
    EXPECT_TRUE(std::filesystem::equivalent(loaded.meshPath, mesh));
    // An absolute path stays absolute.
    file.meshPath = std::filesystem::absolute(mesh);
    fss::saveSessionFile(file, session);
    EXPECT_EQ(Json::parse(slurpText(session))["mesh"]["path"], file.meshPath.generic_string());
}

TEST(SessionFile, SavingRefusesWhatCannotBeStored) {
    const auto mesh = writeTestMesh("session_file_refuse.off", fss::shapes::icosahedron());
    fss::SessionFile f = sampleFile(mesh);
    f.events[0].step.params.camera.eye.x() = std::numeric_limits<double>::quiet_NaN();
    try {
        fss::sessionFileToJson(f);
        FAIL() << "no error";
    } catch (const fss::InvalidInputError& e) {
        EXPECT_STREQ(e.what(),
                     "The session cannot be saved: events[0].step.camera.eye is not a finite number.");
    }
    f = sampleFile(mesh);
    f.events[1].step.fishbone->tracing.ribTracing.insideRegion = [](const Vector2d&) { return true; };
    EXPECT_THROW(fss::sessionFileToJson(f), fss::InvalidInputError);
    f = sampleFile(mesh);
    f.events[1].step.fishbone->tracing.backboneTracing.attractor =
        [](const Vector2d& q, const Vector2d&) -> std::optional<Vector2d> { return q; };
    EXPECT_THROW(fss::sessionFileToJson(f), fss::InvalidInputError);
    f = sampleFile(mesh);
    f.renderer = "opengl";
    EXPECT_THROW(fss::sessionFileToJson(f), fss::InvalidInputError);
    EXPECT_FALSE(std::filesystem::exists(fss::test::tmpPath("refused.session.json")));
    EXPECT_THROW(fss::saveSessionFile(f, fss::test::tmpPath("refused.session.json")), fss::InvalidInputError);
    EXPECT_FALSE(std::filesystem::exists(fss::test::tmpPath("refused.session.json")));
}

// ---- Replay ---------------------------------------------------------------------------------------------

// The mesh written as text in index order (points bit-exact via hexfloat): equal strings = equal meshes.
std::string fingerprint(const fss::Mesh& mesh) {
    std::ostringstream out;
    out << std::hexfloat;
    for (auto v : mesh.vertices())
        out << mesh.point(v) << '\n';
    for (auto f : mesh.faces()) {
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            out << std::size_t(v) << ' ';
        out << '\n';
    }
    return out.str();
}

fss::ScanStep viewStep(const fss::Mesh& mesh, fss::StandardView view, int resolution, double zoom = 1.0) {
    fss::ScanStep step;
    step.params.camera = fss::Camera::standardView(view, fss::boundingBox(mesh), resolution, resolution);
    step.params.camera.zoom(zoom);
    step.params.scan.scanId = int(view);
    return step;
}

// Records a session through the API (scans, a rejected preview, an undo, a redo, a fishbone scan), saves it,
// loads it and replays it: the current meshes are identical, and so is every stitch report's face count.
TEST(SessionFile, ReplayReproducesTheRecordedMesh) {
    const auto meshFile =
        writeTestMesh("session_file_replay.off", fss::shapes::cylinder(48, 12, 1.0, 2.0, true));
    fss::Session recorded(fss::readMesh(meshFile));
    const fss::Mesh& ref = recorded.reference();
    recorded.scan(viewStep(ref, fss::StandardView::PosX, 96));
    recorded.accept();
    recorded.scan(viewStep(ref, fss::StandardView::NegY, 96));
    recorded.reject(); // not in the log
    recorded.scan(viewStep(ref, fss::StandardView::PosY, 96, 1.5));
    recorded.accept();
    recorded.undo();
    recorded.redo();
    fss::ScanStep fish = viewStep(ref, fss::StandardView::NegX, 96);
    fish.fishbone = fss::FishboneParams{};
    fish.fishbone->seed = Vector2d(48.3, 48.7);
    fish.fishbone->spacing = 3;
    recorded.scan(fish);
    recorded.accept();
    recorded.scan(viewStep(ref, fss::StandardView::PosZ, 64));
    recorded.accept();
    recorded.undo();
    ASSERT_EQ(recorded.events().size(), 7u);

    const auto path = fss::test::tmpPath("replay.session.json");
    fss::saveSessionFile(fss::sessionFileFromSession(recorded, meshFile), path);
    const fss::SessionFile loaded = fss::loadSessionFile(path);
    std::vector<std::pair<double, std::string>> reports;
    fss::ReplayResult replay =
        fss::replaySession(loaded, {}, fss::Progress([&](double f, std::string_view stage) {
                               reports.emplace_back(f, std::string(stage));
                               return true;
                           }));
    EXPECT_NE(fingerprint(recorded.current()), fingerprint(recorded.reference())); // the scans changed it
    EXPECT_EQ(fingerprint(replay.session.current()), fingerprint(recorded.current()));
    EXPECT_EQ(replay.session.undoCount(), recorded.undoCount());
    EXPECT_EQ(replay.session.redoCount(), recorded.redoCount());
    ASSERT_EQ(replay.events.size(), 7u);
    EXPECT_TRUE(replay.events[4].fishbone);
    EXPECT_GT(replay.events[4].patchFaces, 50u);
    std::size_t accepted = 0;
    for (const fss::ReplayedEvent& e : replay.events) {
        EXPECT_EQ(e.stitch.has_value(), e.kind == fss::SessionEvent::Kind::Accept);
        if (e.stitch) {
            EXPECT_GT(e.stitch->facesAdded, 0u);
            EXPECT_GT(e.scanSeconds, 0.0);
            ++accepted;
        }
    }
    EXPECT_EQ(accepted, 4u);
    // Progress is monotone from 0 to 1.
    ASSERT_FALSE(reports.empty());
    for (std::size_t i = 1; i < reports.size(); ++i)
        EXPECT_GE(reports[i].first, reports[i - 1].first - 1e-12);
    EXPECT_EQ(reports.back().first, 1.0);

    // A scan that fails on replay names the event.
    fss::SessionFile broken = loaded;
    broken.events[0].step.params.camera.eye = Vector3d(100, 100, 100);
    broken.events[0].step.params.camera.focal = Vector3d(200, 200, 200); // looks away from the mesh
    try {
        fss::replaySession(broken);
        FAIL() << "no error";
    } catch (const fss::InvalidInputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path.string() + ", events[0] (accept): ", 0), 0u) << e.what();
    }
}

// A step the reader accepts is one the stitch accepts: the options at the edges of the reader's ranges (which
// are the stitch's, StitchOptions::validate) replay without an option error.
TEST(SessionFile, WhatTheReaderAcceptsTheStitchAccepts) {
    const fss::Mesh cylinder = fss::shapes::cylinder(48, 12, 1.0, 2.0, true);
    fss::SessionFile file;
    file.meshPath = "cylinder.off";
    file.meshSha256 = std::string(64, '0');
    file.events.push_back({fss::SessionEvent::Kind::Accept, viewStep(cylinder, fss::StandardView::PosX, 96)});
    Json j = Json::parse(fss::sessionFileToJson(file));
    Json& stitch = j["events"][0]["step"]["stitch"];
    stitch["min_angle_floor_deg"] = std::nextafter(30.0, 0.0);
    stitch["outside_min_angle_floor_deg"] = std::nextafter(30.0, 0.0);
    stitch["max_view_angle_deg"] = std::nextafter(90.0, 0.0);
    stitch["collapse_edge_ratio"] = std::nextafter(0.5, 0.0);
    stitch["max_normal_change_deg"] = 180;
    stitch["seam_grading"] = 0;
    const fss::SessionFile loaded =
        fss::sessionFileFromJson(j.dump(2), "edges.json", ".", {.verifyMesh = false});
    const fss::ScanStep& step = loaded.events.at(0).step;
    EXPECT_EQ(step.stitch.minAngleFloorDeg, std::nextafter(30.0, 0.0));
    fss::Session session(cylinder);
    session.scan(step); // checks the stitch options too
    try {
        session.accept();
    } catch (const fss::InvalidOptionError& e) {
        FAIL() << "the stitch refused an option the reader accepted: " << e.what();
    } catch (const fss::InvalidInputError& e) {
        // Nothing stitchable under such floors is not an option error.
        EXPECT_EQ(std::string(e.what()).find("Options::"), std::string::npos) << e.what();
    }
    // And the other way round: what the stitch refuses, the reader refuses.
    stitch["min_angle_floor_deg"] = 30;
    EXPECT_THROW(fss::sessionFileFromJson(j.dump(2), "edges.json", ".", {.verifyMesh = false}), fss::IoError);
}

} // namespace
