// The step-by-step replay engine (replay.h): stepping through a session file gives the same mesh as
// replaySession, bit for bit; the parts of a step (as the widgets run them, on two threads) give it too;
// progress, costs and errors.
#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/replay.h"
#include "fss/session_file.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

// The mesh as text in index order (points bit-exact via hexfloat, faces' vertices, f:quality and
// f:scan_id): equal strings = equal meshes.
std::string replayFingerprint(const fss::Mesh& mesh) {
    std::ostringstream out;
    out << std::hexfloat;
    for (auto v : mesh.vertices())
        out << mesh.point(v) << '\n';
    const auto quality = mesh.property_map<fss::FaceIndex, float>(fss::props::faceQuality);
    const auto scanId = mesh.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
    for (auto f : mesh.faces()) {
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            out << std::size_t(v) << ' ';
        if (quality.second) out << quality.first[f] << ' ';
        if (scanId.second) out << scanId.first[f];
        out << '\n';
    }
    return out.str();
}

std::filesystem::path exampleSession() {
    return std::filesystem::path(FSS_SOURCE_DIR) / "examples" / "fandisk.session.json";
}

TEST(SessionReplay, SteppingThroughTheExampleSessionGivesReplaySessionsMesh) {
    const fss::SessionFile file = fss::loadSessionFile(exampleSession());
    ASSERT_GT(file.events.size(), 1u);
    const fss::ReplayResult whole = fss::replaySession(file);

    fss::SessionReplay replay(file);
    EXPECT_EQ(replay.eventCount(), file.events.size());
    EXPECT_EQ(replay.nextEvent(), 0u);
    EXPECT_FALSE(replay.done());
    EXPECT_EQ(replay.fraction(), 0.0);
    EXPECT_GT(replay.readSeconds(), 0.0);
    EXPECT_EQ(replayFingerprint(replay.current()), replayFingerprint(replay.session().reference()));
    std::vector<double> fractions;
    const fss::Progress progress([&](double f, std::string_view) {
        fractions.push_back(f);
        return true;
    });
    std::size_t steps = 0;
    while (!replay.done()) {
        const std::size_t before = replay.nextEvent();
        const fss::ReplayedEvent& e = replay.step(progress);
        ++steps;
        EXPECT_EQ(replay.nextEvent(), before + 1);
        EXPECT_EQ(replay.fraction(), double(before + 1) / double(file.events.size()));
        EXPECT_EQ(e.kind, file.events[before].kind);
        if (e.kind == fss::SessionEvent::Kind::Accept) {
            ASSERT_TRUE(e.stitch.has_value());
            EXPECT_GT(e.patchFaces, 0u);
            EXPECT_GT(e.scanSeconds, 0.0);
            EXPECT_GE(e.seconds, e.scanSeconds + e.stitchSeconds);
            EXPECT_EQ(e.fishbone, file.events[before].step.fishbone.has_value());
        }
        EXPECT_EQ(replay.events().size(), steps);
    }
    EXPECT_EQ(steps, file.events.size());
    EXPECT_EQ(replay.fraction(), 1.0);
    // Progress never goes back and stays within [0, 1].
    ASSERT_FALSE(fractions.empty());
    for (std::size_t i = 1; i < fractions.size(); ++i)
        EXPECT_GE(fractions[i], fractions[i - 1]);
    EXPECT_LE(fractions.back(), 1.0);

    EXPECT_NE(replayFingerprint(whole.session.current()), replayFingerprint(whole.session.reference()));
    EXPECT_EQ(replayFingerprint(replay.current()), replayFingerprint(whole.session.current()));
    ASSERT_EQ(replay.events().size(), whole.events.size());
    for (std::size_t i = 0; i < whole.events.size(); ++i) {
        EXPECT_EQ(replay.events()[i].patchFaces, whole.events[i].patchFaces) << i;
        EXPECT_EQ(replay.events()[i].stitch.has_value(), whole.events[i].stitch.has_value()) << i;
        if (replay.events()[i].stitch && whole.events[i].stitch) {
            EXPECT_EQ(replay.events()[i].stitch->facesAdded, whole.events[i].stitch->facesAdded) << i;
        }
    }

    // A replay past the end is refused; the session can be taken over.
    EXPECT_THROW(replay.step(), fss::InvalidInputError);
    const std::unique_ptr<fss::Session> session = replay.takeSession();
    ASSERT_TRUE(session);
    EXPECT_EQ(replayFingerprint(session->current()), replayFingerprint(whole.session.current()));
}

fss::ScanStep viewStep(const fss::Mesh& mesh, fss::StandardView view, int resolution) {
    fss::ScanStep step;
    step.params.camera = fss::Camera::standardView(view, fss::boundingBox(mesh), resolution, resolution);
    step.params.scan.scanId = int(view);
    return step;
}

// The parts of a step (scan, then accept; the fishbone cache built first), as the widgets drive them on two
// threads, give the mesh replaySession gives; undo and redo too.
TEST(SessionReplay, PartsOfStepsGiveTheSameMesh) {
    const auto meshFile = fss::test::tmpPath("replay_parts.off");
    fss::writeMesh(fss::shapes::cylinder(48, 12, 1.0, 2.0, true), meshFile);
    fss::Session recorded(fss::readMesh(meshFile));
    const fss::Mesh& ref = recorded.reference();
    recorded.scan(viewStep(ref, fss::StandardView::PosX, 96));
    recorded.accept();
    fss::ScanStep fish = viewStep(ref, fss::StandardView::NegX, 96);
    fish.fishbone = fss::FishboneParams{};
    fish.fishbone->seed = Eigen::Vector2d(48.3, 48.7);
    fish.fishbone->spacing = 3;
    recorded.scan(fish);
    recorded.accept();
    recorded.undo();
    recorded.redo();
    recorded.scan(viewStep(ref, fss::StandardView::PosY, 96));
    recorded.accept();
    recorded.undo();
    const fss::SessionFile file = fss::sessionFileFromSession(recorded, meshFile);
    ASSERT_EQ(file.events.size(), 6u);

    fss::SessionReplay replay(file);
    std::size_t cacheBuilds = 0;
    while (!replay.done()) {
        const fss::SessionEvent& e = file.events[replay.nextEvent()];
        if (replay.needsFishboneCache()) {
            EXPECT_TRUE(e.step.fishbone.has_value());
            replay.buildFishboneCache();
            ++cacheBuilds;
            EXPECT_FALSE(replay.needsFishboneCache());
        }
        replay.scanNext();
        if (e.kind == fss::SessionEvent::Kind::Accept) {
            ASSERT_NE(replay.session().preview(), nullptr);
        }
        const fss::ReplayedEvent& done = replay.finishNext();
        EXPECT_EQ(done.kind, e.kind);
        EXPECT_EQ(done.stitch.has_value(), e.kind == fss::SessionEvent::Kind::Accept);
    }
    EXPECT_EQ(cacheBuilds, 1u);
    EXPECT_EQ(replayFingerprint(replay.current()), replayFingerprint(recorded.current()));
    EXPECT_EQ(replayFingerprint(replay.current()),
              replayFingerprint(fss::replaySession(file).session.current()));
    EXPECT_EQ(replay.session().undoCount(), recorded.undoCount());
    EXPECT_EQ(replay.session().redoCount(), recorded.redoCount());

    // An accept without its scan is refused, and the event stays the next one.
    fss::SessionReplay unscanned(file);
    EXPECT_THROW(unscanned.finishNext(), fss::InvalidInputError);
    EXPECT_EQ(unscanned.nextEvent(), 0u);
}

// A failing event names the file and the event, and is not counted as replayed.
TEST(SessionReplay, FailingEventNamesTheFileAndTheEvent) {
    fss::SessionFile file = fss::loadSessionFile(exampleSession());
    file.events[1].step.params.camera.eye = Eigen::Vector3d(100, 100, 100);
    file.events[1].step.params.camera.focal = Eigen::Vector3d(200, 200, 200); // looks away from the mesh
    fss::SessionReplay replay(file);
    replay.step();
    try {
        replay.step();
        FAIL() << "no error";
    } catch (const fss::InvalidInputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(exampleSession().string() + ", events[1] (accept): ", 0), 0u)
            << e.what();
    }
    EXPECT_EQ(replay.nextEvent(), 1u);
    EXPECT_EQ(replay.events().size(), 1u);
}

// The input mesh is checked against the file's SHA-256 before it is read.
TEST(SessionReplay, RefusesAChangedMesh) {
    fss::SessionFile file = fss::loadSessionFile(exampleSession());
    file.meshSha256 = std::string(64, '0');
    EXPECT_THROW(fss::SessionReplay{file}, fss::IoError);
}

} // namespace
