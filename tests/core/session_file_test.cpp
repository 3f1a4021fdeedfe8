// Session files: every field of a ScanStep round-trips bit-exactly, doubles of any bit pattern survive the
// JSON text, bad files give one sentence naming the file and the field, and a replay reproduces the
// recording session's current mesh exactly.
#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/session_file.h"
#include "fss/sha256.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Json = nlohmann::ordered_json;

// Bitwise equality of doubles (distinguishes -0.0 from 0.0).
::testing::AssertionResult sameBits(double a, double b) {
    if (std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b))
        return ::testing::AssertionSuccess();
    std::ostringstream os;
    os.precision(17);
    os << a << " != " << b;
    return ::testing::AssertionFailure() << os.str();
}

void expectSame(const Vector2d& a, const Vector2d& b) {
    EXPECT_TRUE(sameBits(a.x(), b.x()));
    EXPECT_TRUE(sameBits(a.y(), b.y()));
}
void expectSame(const Vector3d& a, const Vector3d& b) {
    for (int i = 0; i < 3; ++i)
        EXPECT_TRUE(sameBits(a[i], b[i]));
}
void expectSame(const std::vector<Vector2d>& a, const std::vector<Vector2d>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
        expectSame(a[i], b[i]);
}

void expectSame(const fss::StreamlineOptions& a, const fss::StreamlineOptions& b) {
    EXPECT_TRUE(sameBits(a.step, b.step));
    EXPECT_TRUE(sameBits(a.minStep, b.minStep));
    EXPECT_TRUE(sameBits(a.maxLength, b.maxLength));
    EXPECT_TRUE(sameBits(a.minAnisotropy, b.minAnisotropy));
    EXPECT_EQ(a.lowAnisotropy, b.lowAnisotropy);
    EXPECT_TRUE(sameBits(a.maxTurnDeg, b.maxTurnDeg));
    EXPECT_EQ(a.maxSteps, b.maxSteps);
    EXPECT_FALSE(b.insideRegion);
}

// Every field of a ScanStep.
void expectSame(const fss::ScanStep& a, const fss::ScanStep& b) {
    const fss::Camera &ca = a.params.camera, &cb = b.params.camera;
    expectSame(ca.eye, cb.eye);
    expectSame(ca.focal, cb.focal);
    expectSame(ca.up, cb.up);
    EXPECT_EQ(ca.parallel, cb.parallel);
    EXPECT_TRUE(sameBits(ca.viewAngleDeg, cb.viewAngleDeg));
    EXPECT_TRUE(sameBits(ca.parallelScale, cb.parallelScale));
    EXPECT_TRUE(sameBits(ca.nearPlane, cb.nearPlane));
    EXPECT_TRUE(sameBits(ca.farPlane, cb.farPlane));
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    ASSERT_EQ(a.params.lasso.has_value(), b.params.lasso.has_value());
    if (a.params.lasso) expectSame(a.params.lasso->points, b.params.lasso->points);
    EXPECT_EQ(a.params.erodeRadius, b.params.erodeRadius);
    EXPECT_EQ(a.params.dilateRadius, b.params.dilateRadius);
    EXPECT_EQ(a.params.scan.scanId, b.params.scan.scanId);
    EXPECT_TRUE(sameBits(a.params.scan.qualityAngleLimitDeg, b.params.scan.qualityAngleLimitDeg));
    EXPECT_TRUE(sameBits(a.params.scan.maxSnapFootprints, b.params.scan.maxSnapFootprints));
    EXPECT_EQ(a.params.scan.lattice, b.params.scan.lattice);
    EXPECT_TRUE(sameBits(a.params.scan.spacingPixels, b.params.scan.spacingPixels));
    EXPECT_TRUE(sameBits(a.params.scan.spacingWorld, b.params.scan.spacingWorld));
    EXPECT_TRUE(sameBits(a.params.scan.minLatticeAngleDeg, b.params.scan.minLatticeAngleDeg));
    EXPECT_EQ(a.params.scan.warpToSurface, b.params.scan.warpToSurface);
    EXPECT_EQ(a.params.scan.warpFollowsFit, b.params.scan.warpFollowsFit);
    EXPECT_EQ(a.params.relaxIterations, b.params.relaxIterations);
    EXPECT_TRUE(sameBits(a.params.triangulate.minQuadAngleDeg, b.params.triangulate.minQuadAngleDeg));
    EXPECT_TRUE(sameBits(a.params.quality.margin, b.params.quality.margin));
    EXPECT_EQ(a.params.quality.forceReplace, b.params.quality.forceReplace);
    EXPECT_EQ(a.params.quality.searchRings, b.params.quality.searchRings);
    EXPECT_TRUE(sameBits(a.params.triangulate.maxEdgeFootprints, b.params.triangulate.maxEdgeFootprints));
    EXPECT_TRUE(sameBits(a.params.triangulate.maxSamplingAngleDeg, b.params.triangulate.maxSamplingAngleDeg));
    ASSERT_EQ(a.fishbone.has_value(), b.fishbone.has_value());
    if (a.fishbone) {
        const fss::FishboneParams &fa = *a.fishbone, &fb = *b.fishbone;
        ASSERT_EQ(fa.seed.has_value(), fb.seed.has_value());
        if (fa.seed) expectSame(*fa.seed, *fb.seed);
        EXPECT_EQ(fa.direction, fb.direction);
        EXPECT_TRUE(sameBits(fa.spacing, fb.spacing));
        expectSame(fa.keyRibs, fb.keyRibs);
        ASSERT_EQ(fa.drawnKeyRibs.size(), fb.drawnKeyRibs.size());
        for (std::size_t i = 0; i < fa.drawnKeyRibs.size(); ++i)
            expectSame(fa.drawnKeyRibs[i], fb.drawnKeyRibs[i]);
        expectSame(fa.drawnBackbone, fb.drawnBackbone);
        EXPECT_TRUE(sameBits(fa.tracing.spacing, fb.tracing.spacing));
        EXPECT_EQ(fa.tracing.extendBeyondKeyRibs, fb.tracing.extendBeyondKeyRibs);
        EXPECT_TRUE(sameBits(fa.tracing.minRibGap, fb.tracing.minRibGap));
        EXPECT_TRUE(sameBits(fa.tracing.maxRibTurnDeg, fb.tracing.maxRibTurnDeg));
        EXPECT_EQ(fa.tracing.stopRibsAtCreases, fb.tracing.stopRibsAtCreases);
        EXPECT_EQ(fa.tracing.closeLoops, fb.tracing.closeLoops);
        EXPECT_EQ(fa.tracing.stopBackboneAtCreases, fb.tracing.stopBackboneAtCreases);
        EXPECT_EQ(fa.tracing.isotropicRibs, fb.tracing.isotropicRibs);
        EXPECT_TRUE(sameBits(fa.tracing.maxRibAspect, fb.tracing.maxRibAspect));
        EXPECT_EQ(fa.tracing.spareFollowedCrease, fb.tracing.spareFollowedCrease);
        EXPECT_TRUE(sameBits(fa.tracing.minFaceAngleDeg, fb.tracing.minFaceAngleDeg));
        EXPECT_EQ(fa.tracing.minComponentFaces, fb.tracing.minComponentFaces);
        EXPECT_EQ(fa.tracing.creaseBackbone, fb.tracing.creaseBackbone);
        EXPECT_EQ(fa.tracing.continuousKeyRibs, fb.tracing.continuousKeyRibs);
        EXPECT_EQ(fa.tracing.clipRibsAtLasso, fb.tracing.clipRibsAtLasso);
        EXPECT_TRUE(sameBits(fa.tracing.peelRibEndsDeg, fb.tracing.peelRibEndsDeg));
        expectSame(fa.tracing.backboneTracing, fb.tracing.backboneTracing);
        expectSame(fa.tracing.ribTracing, fb.tracing.ribTracing);
        EXPECT_TRUE(sameBits(fa.minSeedAnisotropy, fb.minSeedAnisotropy));
        EXPECT_EQ(fa.raycast.rings, fb.raycast.rings);
        EXPECT_EQ(fa.raycast.verifyUnoccluded, fb.raycast.verifyUnoccluded);
        EXPECT_TRUE(sameBits(fa.creaseAngleDeg, fb.creaseAngleDeg));
        EXPECT_TRUE(sameBits(fa.creaseSnapRadius, fb.creaseSnapRadius));
        EXPECT_EQ(fa.samplingFactor, fb.samplingFactor);
    }
    const fss::StitchOptions &sa = a.stitch, &sb = b.stitch;
    EXPECT_EQ(sa.seamRings, sb.seamRings);
    EXPECT_EQ(sa.optimiseSeam, sb.optimiseSeam);
    EXPECT_TRUE(sameBits(sa.collapseEdgeRatio, sb.collapseEdgeRatio));
    EXPECT_TRUE(sameBits(sa.seamGrading, sb.seamGrading));
    EXPECT_TRUE(sameBits(sa.minAngleFloorDeg, sb.minAngleFloorDeg));
    EXPECT_TRUE(sameBits(sa.maxViewAngleDeg, sb.maxViewAngleDeg));
    EXPECT_TRUE(sameBits(sa.maxNormalChangeDeg, sb.maxNormalChangeDeg));
    EXPECT_TRUE(sameBits(sa.maxGapRatio, sb.maxGapRatio));
    EXPECT_EQ(sa.maxTrimRounds, sb.maxTrimRounds);
    EXPECT_EQ(sa.minComponentFaces, sb.minComponentFaces);
    EXPECT_EQ(sa.collectGarbage, sb.collectGarbage);
    EXPECT_EQ(sa.peelTrim, sb.peelTrim);
    EXPECT_TRUE(sameBits(sa.outsideMinAngleFloorDeg, sb.outsideMinAngleFloorDeg));
}

std::string slurpText(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A small mesh file in the test scratch folder (its bytes are what the sha256 covers).
std::filesystem::path writeTestMesh(const std::string& name, const fss::Mesh& mesh) {
    const auto path = fss::test::tmpPath(name);
    fss::writeMesh(mesh, path);
    return path;
}

// A regular step with every field away from its default (and awkward doubles).
fss::ScanStep regularStep() {
    fss::ScanStep s;
    fss::Camera& c = s.params.camera;
    c.eye = {0.1 + 0.2, -1.0 / 3.0, 1e-300};
    c.focal = {-0.0, 4.9406564584124654e-324, 123456789.123456789};
    c.up = {std::nextafter(1.0, 2.0), 2.0 / 3.0, -7.25};
    c.parallel = true;
    c.viewAngleDeg = 12.345678901234567;
    c.parallelScale = 0.7071067811865476;
    c.nearPlane = 0.0012345;
    c.farPlane = 98765.4321;
    c.width = 321;
    c.height = 123;
    s.params.lasso = fss::Lasso{{{10.5, 11.25}, {300.125, 12}, {150, 100.0 / 3.0}, {20, 99.9}}};
    s.params.erodeRadius = 3;
    s.params.dilateRadius = 2;
    s.params.scan.scanId = -7;
    s.params.scan.qualityAngleLimitDeg = 77.7;
    s.params.scan.maxSnapFootprints = 1.5;
    s.params.scan.lattice = fss::Lattice::Triangular;
    s.params.scan.spacingPixels = 1.75;
    s.params.scan.spacingWorld = 0.125;
    s.params.scan.minLatticeAngleDeg = 37.5;
    s.params.scan.warpToSurface = false; // not the default: the round trip keeps it
    s.params.relaxIterations = 3;
    s.params.triangulate.minQuadAngleDeg = 17.5;
    s.params.quality.margin = 0.0625;
    s.params.quality.forceReplace = true;
    s.params.quality.searchRings = 4;
    s.params.triangulate.maxEdgeFootprints = 2.75;
    s.params.triangulate.maxSamplingAngleDeg = 71.5;
    s.stitch.seamRings = 3;
    s.stitch.optimiseSeam = false;
    s.stitch.collapseEdgeRatio = 0.33;
    s.stitch.seamGrading = 0.5;
    s.stitch.minAngleFloorDeg = 2.5;
    s.stitch.maxViewAngleDeg = 80.5;
    s.stitch.maxNormalChangeDeg = 15.25;
    s.stitch.maxGapRatio = 0.2;
    s.stitch.maxTrimRounds = 9;
    s.stitch.minComponentFaces = 5;
    s.stitch.peelTrim = true;
    s.stitch.outsideMinAngleFloorDeg = 7.5;
    s.stitch.collectGarbage = true;
    return s;
}

fss::ScanStep fishboneStep() {
    fss::ScanStep s;
    s.params.camera.width = 200;
    s.params.camera.height = 150;
    fss::FishboneParams fb;
    fb.seed = Vector2d(100.25, 75.125);
    fb.direction = fss::PrincipalDirection::Max;
    fb.spacing = 3.5;
    fb.keyRibs = {{90, 70}, {110.5, 80.25}};
    fb.drawnKeyRibs = {{{1, 2}, {3, 4}, {5.5, 6.5}}, {{7, 8}, {9, 10}}};
    fb.drawnBackbone = {{20, 30}, {40, 50.5}, {60.75, 55}};
    fb.tracing.spacing = 2.5;
    fb.tracing.extendBeyondKeyRibs = false;
    fb.tracing.minRibGap = 0.5;
    fb.tracing.maxRibTurnDeg = 60;
    fb.tracing.stopRibsAtCreases = true;
    fb.tracing.closeLoops = true;
    fb.tracing.stopBackboneAtCreases = true;
    fb.tracing.isotropicRibs = true;
    fb.tracing.maxRibAspect = 1.75;
    fb.tracing.spareFollowedCrease = true;
    fb.tracing.minFaceAngleDeg = 22.5;
    fb.tracing.minComponentFaces = 30;
    fb.tracing.clipRibsAtLasso = true;
    fb.tracing.peelRibEndsDeg = 27.5;
    fb.tracing.backboneTracing.step = 0.3;
    fb.tracing.backboneTracing.minStep = 0.01;
    fb.tracing.backboneTracing.maxLength = 77.5;
    fb.tracing.backboneTracing.minAnisotropy = 0.07;
    fb.tracing.backboneTracing.lowAnisotropy = fss::LowAnisotropyPolicy::Stop;
    fb.tracing.backboneTracing.maxTurnDeg = 12.5;
    fb.tracing.backboneTracing.maxSteps = 123456;
    fb.tracing.ribTracing.step = 0.2;
    fb.tracing.ribTracing.maxLength = std::numeric_limits<double>::infinity();
    fb.tracing.ribTracing.lowAnisotropy = fss::LowAnisotropyPolicy::ContinueStraight;
    fb.minSeedAnisotropy = 0.15;
    fb.raycast.rings = 3;
    fb.raycast.verifyUnoccluded = true;
    fb.creaseAngleDeg = 42.5;
    fb.creaseSnapRadius = 0.75;
    fb.samplingFactor = 2; // divides 200 x 150 and is at most h, as FishboneParams::validate requires
    s.fishbone = fb;
    return s;
}

fss::SessionFile sampleFile(const std::filesystem::path& meshPath) {
    fss::SessionFile f;
    f.description = "every field";
    f.meshPath = meshPath;
    f.meshSha256 = fss::sha256OfFile(meshPath);
    f.renderer = "gpu";
    f.curvature.jetDegree = 3;
    f.curvature.minPoints = 30;
    f.curvature.maxRings = 4;
    f.curvature.anisotropyEpsilon = 2.5e-3;
    f.events.push_back({fss::SessionEvent::Kind::Accept, regularStep()});
    f.events.push_back({fss::SessionEvent::Kind::Accept, fishboneStep()});
    f.events.push_back({fss::SessionEvent::Kind::Undo, {}});
    f.events.push_back({fss::SessionEvent::Kind::Redo, {}});
    f.events.push_back({fss::SessionEvent::Kind::Undo, {}});
    return f;
}

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

// ---- Bad files: one sentence naming the file and the field ----------------------------------------------

class BadSessionFile : public ::testing::Test {
protected:
    void SetUp() override {
        // Per-test file names: ctest runs the tests of this fixture as parallel processes.
        name_ = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        mesh_ = writeTestMesh("session_file_bad_" + name_ + ".off", fss::shapes::icosahedron());
        fss::SessionFile f = sampleFile(mesh_);
        good_ = Json::parse(fss::sessionFileToJson(f));
    }
    // The message of loading \p text from a file "bad_<test>.session.json" next to the mesh (IoError), or
    // "(no error)".
    std::string load(const std::string& text) {
        const auto path = fss::test::tmpPath("bad_" + name_ + ".session.json");
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << text;
        }
        try {
            fss::loadSessionFile(path);
        } catch (const fss::IoError& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
            EXPECT_EQ(m.back(), '.') << m;
            EXPECT_EQ(m.rfind(path.string(), 0), 0u) << "names the file first: " << m;
            return m.substr(path.string().size());
        }
        return "(no error)";
    }
    std::string load(const Json& j) { return load(j.dump(2)); }
    std::string load(const char* text) { return load(std::string(text)); }
    Json good_;
    std::string name_;
    std::filesystem::path mesh_;
};

TEST_F(BadSessionFile, GoodFileLoads) {
    good_["mesh"]["path"] =
        mesh_.filename().string(); // relative to the session file, which is in the same folder
    EXPECT_EQ(load(good_), "(no error)");
}

TEST_F(BadSessionFile, WrongFormatOrVersion) {
    Json j = good_;
    // What an FSS reading versions 1 to 4 says of the version 5 files this one writes (the warp's
    // follow-fit key), here one version further.
    j["version"] = 6;
    EXPECT_EQ(load(j), ": version is 6, but this FSS reads versions 1 to 5 only.");
    j["version"] = "1";
    EXPECT_EQ(load(j), ": version must be a positive integer.");
    j = good_;
    j["format"] = "something-else";
    EXPECT_EQ(load(j), ": format must be \"fss-session\" (this is not an FSS session file).");
    j.erase("format");
    EXPECT_EQ(load(j), ": format is missing (a session file has \"format\": \"fss-session\").");
    EXPECT_EQ(load("[1, 2]"), " is not a session file: its JSON is not an object.");
    EXPECT_EQ(load(""), " is empty, not a session file.");
}

TEST_F(BadSessionFile, MissingFields) {
    Json j = good_;
    j["events"][0]["step"]["camera"].erase("width");
    EXPECT_EQ(load(j), ": events[0].step.camera.width is missing.");
    j = good_;
    j["events"][1]["step"]["fishbone"]["tracing"]["ribs"].erase("max_turn_deg");
    EXPECT_EQ(load(j), ": events[1].step.fishbone.tracing.ribs.max_turn_deg is missing.");
    j = good_;
    j["events"][0]["step"].erase("stitch");
    EXPECT_EQ(load(j), ": events[0].step.stitch is missing.");
    j = good_;
    j.erase("mesh");
    EXPECT_EQ(load(j), ": mesh is missing.");
    j = good_;
    j["events"][1]["step"]["grid"] = "fishbone";
    j["events"][1]["step"].erase("fishbone");
    EXPECT_EQ(load(j), ": events[1].step.fishbone is missing.");
}

// Files written before the sampling image existed sampled fishbones at the scan resolution: without the
// field they load with k = 1 and so replay as recorded; a file that has it keeps its value (0 = automatic).
TEST_F(BadSessionFile, FishboneSamplingFactorIsOptionalAndOneWhenAbsent) {
    auto samplingFactorOf = [&](const Json& j) {
        const auto path = fss::test::tmpPath("sampling_" + name_ + ".session.json");
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << j.dump(2);
        }
        const fss::SessionFile f = fss::loadSessionFile(path);
        return f.events.at(1).step.fishbone.value().samplingFactor;
    };
    Json j = good_;
    ASSERT_TRUE(j["events"][1]["step"]["fishbone"].contains("sampling_factor"));
    EXPECT_EQ(samplingFactorOf(j), 2);
    j["events"][1]["step"]["fishbone"]["sampling_factor"] = 0;
    EXPECT_EQ(samplingFactorOf(j), 0);
    j["events"][1]["step"]["fishbone"].erase("sampling_factor");
    EXPECT_EQ(samplingFactorOf(j), 1);
    EXPECT_EQ(fss::FishboneParams{}.samplingFactor, 0); // new scans choose it
}

// Files written before the backbone's loop and crease handling (issue #20) traced backbones without them:
// without the keys they load with both off and replay as recorded.
TEST_F(BadSessionFile, FishboneLoopCreaseAndSurfaceSpacingKeysAreOptionalAndOffWhenAbsent) {
    auto tracingOf = [&](const Json& j) {
        const auto path = fss::test::tmpPath("loops_" + name_ + ".session.json");
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << j.dump(2);
        }
        return fss::loadSessionFile(path).events.at(1).step.fishbone.value().tracing;
    };
    Json j = good_;
    Json& t = j["events"][1]["step"]["fishbone"]["tracing"];
    ASSERT_TRUE(t.contains("close_loops"));
    ASSERT_TRUE(t.contains("stop_backbone_at_creases"));
    ASSERT_TRUE(t.contains("isotropic_ribs"));
    EXPECT_TRUE(tracingOf(j).closeLoops);
    EXPECT_TRUE(tracingOf(j).stopBackboneAtCreases);
    EXPECT_TRUE(tracingOf(j).isotropicRibs);
    t.erase("close_loops");
    t.erase("stop_backbone_at_creases");
    t.erase("isotropic_ribs");
    EXPECT_FALSE(tracingOf(j).closeLoops);
    EXPECT_FALSE(tracingOf(j).stopBackboneAtCreases);
    EXPECT_FALSE(tracingOf(j).isotropicRibs);
}

// Files written before the sliver-free fishbone became the default (issue #20) traced with none of its rules:
// without their keys they load with each rule off and replay as recorded, although new scans have them on.
TEST_F(BadSessionFile, FishboneSliverRulesAreOffWhenAbsentAndOnByDefault) {
    auto tracingOf = [&](const Json& j) {
        const auto path = fss::test::tmpPath("slivers_" + name_ + ".session.json");
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << j.dump(2);
        }
        return fss::loadSessionFile(path).events.at(1).step.fishbone.value().tracing;
    };
    Json j = good_;
    Json& t = j["events"][1]["step"]["fishbone"]["tracing"];
    const std::vector<const char*> keys{
        "min_rib_gap",           "max_rib_turn_deg",    "max_rib_aspect",           "stop_ribs_at_creases",
        "spare_followed_crease", "close_loops",         "stop_backbone_at_creases", "isotropic_ribs",
        "min_face_angle_deg",    "min_component_faces", "crease_backbone",          "continuous_key_ribs",
        "clip_ribs_at_lasso",    "peel_rib_ends_deg"};
    for (const char* k : keys)
        ASSERT_TRUE(t.contains(k)) << k;
    const fss::FishboneOptions on = tracingOf(j);
    EXPECT_EQ(on.maxRibAspect, 1.75);
    EXPECT_TRUE(on.spareFollowedCrease);
    EXPECT_EQ(on.minFaceAngleDeg, 22.5);
    EXPECT_EQ(on.minComponentFaces, 30);
    EXPECT_TRUE(on.creaseBackbone);
    EXPECT_TRUE(on.continuousKeyRibs);
    EXPECT_TRUE(on.clipRibsAtLasso);
    EXPECT_EQ(on.peelRibEndsDeg, 27.5);
    for (const char* k : keys)
        t.erase(k);
    const fss::FishboneOptions off = tracingOf(j);
    EXPECT_EQ(off.minRibGap, 0.0);
    EXPECT_EQ(off.maxRibTurnDeg, 180.0);
    EXPECT_EQ(off.maxRibAspect, 0.0);
    EXPECT_FALSE(off.stopRibsAtCreases);
    EXPECT_FALSE(off.spareFollowedCrease);
    EXPECT_FALSE(off.closeLoops);
    EXPECT_FALSE(off.stopBackboneAtCreases);
    EXPECT_FALSE(off.isotropicRibs);
    EXPECT_EQ(off.minFaceAngleDeg, 0.0);
    EXPECT_EQ(off.minComponentFaces, 0);
    EXPECT_FALSE(off.creaseBackbone);
    EXPECT_FALSE(off.continuousKeyRibs);
    EXPECT_FALSE(off.clipRibsAtLasso);
    EXPECT_EQ(off.peelRibEndsDeg, 0.0);
    // New scans: the loop closing, the face-angle bound and the small-part drop are on (SliverTable's
    // figures, issue 20's report); the others stay off.
    const fss::FishboneOptions fresh;
    EXPECT_TRUE(fresh.closeLoops);
    EXPECT_EQ(fresh.minFaceAngleDeg, 20.0);
    EXPECT_EQ(fresh.minComponentFaces, 24);
    EXPECT_TRUE(fresh.creaseBackbone);     // session 16: backbones on creases
    EXPECT_TRUE(fresh.continuousKeyRibs);  // session 18: key-ribs between samples
    EXPECT_FALSE(fresh.clipRibsAtLasso);   // session 20: an option (no better than the peel alone)
    EXPECT_EQ(fresh.peelRibEndsDeg, 30.0); // session 20: thin rib ends peeled
    EXPECT_FALSE(fresh.stopRibsAtCreases);
    EXPECT_EQ(fresh.maxRibAspect, 0.0);
}

// Files written before the triangular lattice and the patch relaxation (issue #20) scanned on the pixel
// lattice without relaxation: without the fields they load so and replay as recorded.
TEST_F(BadSessionFile, LatticeAndRelaxationAreOptionalAndOffWhenAbsent) {
    auto stepOf = [&](const Json& j) {
        const auto path = fss::test::tmpPath("lattice_" + name_ + ".session.json");
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << j.dump(2);
        }
        return fss::loadSessionFile(path).events.at(0).step;
    };
    Json j = good_;
    ASSERT_EQ(j["events"][0]["step"]["scan"]["lattice"], "triangular");
    ASSERT_EQ(j["events"][0]["step"]["relax_iterations"], 3);
    EXPECT_EQ(stepOf(j).params.scan.lattice, fss::Lattice::Triangular);
    j["events"][0]["step"]["scan"].erase("lattice");
    j["events"][0]["step"]["scan"].erase("spacing_px");
    j["events"][0]["step"]["scan"].erase("spacing_world");
    j["events"][0]["step"].erase("relax_iterations");
    j["events"][0]["step"]["triangulate"].erase("min_quad_angle_deg");
    ASSERT_EQ(j["events"][0]["step"]["scan"]["min_lattice_angle_deg"], 37.5);
    j["events"][0]["step"]["scan"].erase("min_lattice_angle_deg");
    const fss::ScanStep old = stepOf(j);
    EXPECT_EQ(old.params.scan.lattice, fss::Lattice::Square);
    EXPECT_EQ(old.params.scan.spacingPixels, 1.0);
    EXPECT_EQ(old.params.scan.spacingWorld, 0.0);
    EXPECT_EQ(old.params.relaxIterations, 0);
    EXPECT_EQ(old.params.triangulate.minQuadAngleDeg, 0.0);
    EXPECT_EQ(old.params.scan.minLatticeAngleDeg, 0.0);
    j = good_;
    j["events"][0]["step"]["scan"]["lattice"] = "adaptive";
    EXPECT_EQ(stepOf(j).params.scan.lattice, fss::Lattice::Adaptive);
    // Written back, a step on the pixel lattice without relaxation writes the lattice and its mask (the
    // defaults are no longer those, issue #20), and none of the other fields; it reads back the same.
    fss::SessionFile f = sampleFile(mesh_);
    f.events.at(0).step.params.scan.lattice = fss::Lattice::Square;
    f.events.at(0).step.params.scan.spacingPixels = 1;
    f.events.at(0).step.params.scan.spacingWorld = 0;
    f.events.at(0).step.params.relaxIterations = 0;
    f.events.at(0).step.params.triangulate.minQuadAngleDeg = 0;
    f.events.at(0).step.params.scan.minLatticeAngleDeg = 0;
    const Json written = Json::parse(fss::sessionFileToJson(f));
    EXPECT_EQ(written["events"][0]["step"]["scan"]["lattice"], "square");
    EXPECT_EQ(written["events"][0]["step"]["scan"]["min_lattice_angle_deg"], 0.0);
    EXPECT_EQ(written["events"][0]["step"]["scan"]["spacing_px"], 1.0);
    EXPECT_EQ(written["events"][0]["step"]["scan"]["spacing_world"], 0.0);
    EXPECT_FALSE(written["events"][0]["step"].contains("relax_iterations"));
    EXPECT_FALSE(written["events"][0]["step"]["triangulate"].contains("min_quad_angle_deg"));
    const fss::ScanStep back = stepOf(written);
    EXPECT_EQ(back.params.scan.lattice, fss::Lattice::Square);
    EXPECT_EQ(back.params.scan.minLatticeAngleDeg, 0.0);
    // A step with today's defaults writes them.
    f.events.at(0).step.params.scan = fss::ScanOptions{};
    const Json fresh = Json::parse(fss::sessionFileToJson(f));
    EXPECT_EQ(fresh["events"][0]["step"]["scan"]["lattice"], "adaptive");
    EXPECT_EQ(fresh["events"][0]["step"]["scan"]["min_lattice_angle_deg"], 35.0);
    j = good_;
    j["events"][0]["step"]["scan"]["lattice"] = "hexagonal";
    EXPECT_NE(load(j).find("events[0].step.scan.lattice must be"), std::string::npos) << load(j);
    j = good_;
    j["events"][0]["step"]["scan"]["spacing_px"] = 0.1;
    EXPECT_EQ(load(j), ": events[0].step.scan.spacing_px must be in [0.25, 1024], not 0.1.");
    j = good_;
    j["events"][0]["step"]["relax_iterations"] = 101;
    EXPECT_EQ(load(j), ": events[0].step.relax_iterations must be in [0, 100], not 101.");
}

// Version 3 (issue #20): the lattice warped to the surface is on by default and always written; files
// without the key (versions 1 and 2) were recorded without it and load so, whatever their version number.
TEST_F(BadSessionFile, WarpToSurfaceIsAlwaysWrittenAndOffWhenAbsent) {
    auto warpOf = [&](const Json& j) {
        return fss::sessionFileFromJson(j.dump(2), "s.json", ".", {.verifyMesh = false})
            .events.at(0)
            .step.params.scan.warpToSurface;
    };
    EXPECT_TRUE(fss::ScanOptions{}.warpToSurface);
    EXPECT_EQ(fss::kSessionFileVersion, 5); // version 5 (session 19): the warp's follow-fit key
    EXPECT_EQ(good_["version"], 5);
    ASSERT_EQ(good_["events"][0]["step"]["scan"]["warp_to_surface"], false); // sampleFile's step: off
    EXPECT_FALSE(warpOf(good_));
    EXPECT_EQ(good_["events"][1]["step"]["scan"]["warp_to_surface"], true); // the fishbone step: default
    Json j = good_;
    j["events"][0]["step"]["scan"]["warp_to_surface"] = true;
    EXPECT_TRUE(warpOf(j));
    for (int version : {1, 2, 3, 4, 5}) {
        j["version"] = version;
        j["events"][0]["step"]["scan"].erase("warp_to_surface");
        EXPECT_FALSE(warpOf(j)) << "version " << version;
    }
    j = good_;
    j["events"][0]["step"]["scan"]["warp_to_surface"] = 1;
    EXPECT_EQ(load(j), ": events[0].step.scan.warp_to_surface must be true or false.");
    // Written as set, and read back so.
    fss::SessionFile f = sampleFile(mesh_);
    f.events.at(0).step.params.scan.warpToSurface = true;
    const Json on = Json::parse(fss::sessionFileToJson(f));
    EXPECT_EQ(on["events"][0]["step"]["scan"]["warp_to_surface"], true);
    EXPECT_TRUE(warpOf(on));
}

// Version 5 (issue #20, session 19): the warp's fit turned towards the fitted lattice is on by default and
// written only when on; files without the key (versions 1 to 4) were recorded with the session 17 fit and
// load so, whatever their version number, which keeps their replay to the same bytes.
TEST_F(BadSessionFile, WarpFollowsFitIsWrittenWhenOnAndOffWhenAbsent) {
    auto followOf = [&](const Json& j) {
        return fss::sessionFileFromJson(j.dump(2), "s.json", ".", {.verifyMesh = false})
            .events.at(0)
            .step.params.scan.warpFollowsFit;
    };
    EXPECT_TRUE(fss::ScanOptions{}.warpFollowsFit);
    fss::SessionFile f = sampleFile(mesh_);
    f.events.at(0).step.params.scan.warpFollowsFit = true;
    Json j = Json::parse(fss::sessionFileToJson(f));
    EXPECT_EQ(j["events"][0]["step"]["scan"]["warp_follows_fit"], true);
    EXPECT_TRUE(followOf(j));
    for (int version : {1, 2, 3, 4, 5}) {
        j["version"] = version;
        j["events"][0]["step"]["scan"].erase("warp_follows_fit");
        EXPECT_FALSE(followOf(j)) << "version " << version;
    }
    f.events.at(0).step.params.scan.warpFollowsFit = false;
    const Json off = Json::parse(fss::sessionFileToJson(f));
    EXPECT_FALSE(off["events"][0]["step"]["scan"].contains("warp_follows_fit"));
    EXPECT_FALSE(followOf(off));
    j = off;
    j["events"][0]["step"]["scan"]["warp_follows_fit"] = "yes";
    EXPECT_EQ(load(j), ": events[0].step.scan.warp_follows_fit must be true or false.");
}

TEST_F(BadSessionFile, WrongTypesAndValues) {
    const std::pair<std::function<void(Json&)>, std::string> cases[] = {
        {[](Json& j) { j["events"][0]["step"]["camera"]["width"] = "321"; },
         ": events[0].step.camera.width must be a positive integer of at most 8192."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["width"] = 0; },
         ": events[0].step.camera.width must be a positive integer of at most 8192."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["height"] = 12.5; },
         ": events[0].step.camera.height must be a positive integer of at most 8192."},
        {[](Json& j) {
             j["events"][0]["step"]["camera"]["eye"] = Json::array({1, 2});
         },
         ": events[0].step.camera.eye must be an array of 3 numbers."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["up"][1] = "x"; },
         ": events[0].step.camera.up[1] must be a number."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["projection"] = "fisheye"; },
         ": events[0].step.camera.projection must be one of \"perspective\", \"parallel\", not \"fisheye\"."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["far"] = 0.001; },
         ": events[0].step.camera.far must be larger than near."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["focal"] = j["events"][0]["step"]["camera"]["eye"]; },
         ": events[0].step.camera.focal must differ from eye (the camera has no viewing direction)."},
        {[](Json& j) {
             j["events"][0]["step"]["lasso"] = Json::array({Json::array({0, 0}), Json::array({1, 1})});
         },
         ": events[0].step.lasso must enclose an area (at least 3 points, not all collinear)."},
        {[](Json& j) { j["events"][0]["step"]["erode_radius"] = -1; },
         ": events[0].step.erode_radius must be in [0, 1024], not -1."},
        {[](Json& j) { j["events"][0]["step"]["quality_mask"]["force_replace"] = 1; },
         ": events[0].step.quality_mask.force_replace must be true or false."},
        {[](Json& j) { j["events"][0]["step"]["quality_mask"]["margin"] = 1.5; },
         ": events[0].step.quality_mask.margin must be in [0, 1), not 1.5."},
        {[](Json& j) { j["events"][0]["step"]["grid"] = "hexagonal"; },
         ": events[0].step.grid must be one of \"regular\", \"fishbone\", not \"hexagonal\"."},
        {[](Json& j) { j["events"][0]["step"]["fishbone"] = j["events"][1]["step"]["fishbone"]; },
         ": events[0].step.fishbone must not be given when grid is \"regular\"."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["h"] = -4; },
         ": events[1].step.fishbone.h must be in [0.5, 37.5] for a 200x150 scan: the spacing h = -4 pixels "
         "is "
         "outside it."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["direction"] = "sideways"; },
         ": events[1].step.fishbone.direction must be one of \"min\", \"max\", not \"sideways\"."},
        {[](Json& j) {
             j["events"][1]["step"]["fishbone"]["key_ribs"][1] = Json::array({1, 2, 3});
         },
         ": events[1].step.fishbone.key_ribs[1] must be an array of 2 numbers [x, y]."},
        {[](Json& j) {
             j["events"][1]["step"]["fishbone"]["seed"] = nullptr;
             j["events"][1]["step"]["fishbone"]["drawn_backbone"] = Json::array();
         },
         ": events[1].step.fishbone.seed must be given when there is no drawn backbone."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["tracing"]["backbone"]["low_anisotropy"] = true; },
         ": events[1].step.fishbone.tracing.backbone.low_anisotropy must be one of \"stop\", "
         "\"continue_straight\"."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["sampling_factor"] = 65; },
         ": events[1].step.fishbone.sampling_factor must divide the scan image's width and height: the "
         "sampling factor 65 does not divide the 200x150 scan image."},
        {[](Json& j) { j["events"][1]["step"]["stitch"]["seam_rings"] = 1.5; },
         ": events[1].step.stitch.seam_rings must be an integer."},
        {[](Json& j) { j["events"][0]["step"]["camera"]["eyes"] = 1; },
         ": events[0].step.camera has an unknown field 'eyes'."},
        {[](Json& j) { j["events"][2]["kind"] = "rotate"; },
         ": events[2].kind must be one of \"accept\", \"undo\", \"redo\", not \"rotate\"."},
        {[](Json& j) {
             j["events"] = Json::array({Json{{"kind", "undo"}}});
         },
         ": events[0] is an undo with no accepted step left to undo."},
        {[](Json& j) {
             j["events"][3]["kind"] = "redo";
             j["events"][4]["kind"] = "redo";
         },
         ": events[4] is a redo with no undone step to redo."},
        {[](Json& j) { j["events"] = Json::object(); }, ": events must be an array of events."},
        {[](Json& j) { j["renderer"] = "vulkan"; },
         ": renderer must be one of \"cpu\", \"gpu\", not \"vulkan\"."},
        {[](Json& j) { j["curvature"]["jet_degree"] = 4; }, ": curvature.jet_degree must be 2 or 3, not 4."},
        {[](Json& j) { j["mesh"]["sha256"] = "abc"; },
         ": mesh.sha256 must be 64 lowercase hexadecimal digits."},
    };
    for (const auto& [edit, expected] : cases) {
        Json j = good_;
        edit(j);
        EXPECT_EQ(load(j), expected);
    }
}

// The reader takes the ranges from the options' validate() (as the API does) and names the JSON field.
TEST_F(BadSessionFile, OptionsOutOfRangeNameTheFieldAndItsRange) {
    const std::pair<std::function<void(Json&)>, std::string> cases[] = {
        {[](Json& j) { j["events"][0]["step"]["stitch"]["min_angle_floor_deg"] = 45; },
         ": events[0].step.stitch.min_angle_floor_deg must be in [0, 30), not 45."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["min_angle_floor_deg"] = 30; },
         ": events[0].step.stitch.min_angle_floor_deg must be in [0, 30), not 30."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["outside_min_angle_floor_deg"] = -1; },
         ": events[0].step.stitch.outside_min_angle_floor_deg must be in [0, 30), not -1."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["max_view_angle_deg"] = 90; },
         ": events[0].step.stitch.max_view_angle_deg must be in (0, 90), not 90."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["collapse_edge_ratio"] = 0.5; },
         ": events[0].step.stitch.collapse_edge_ratio must be in [0, 0.5), not 0.5."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["max_normal_change_deg"] = 181; },
         ": events[0].step.stitch.max_normal_change_deg must be in [0, 180], not 181."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["seam_rings"] = -1; },
         ": events[0].step.stitch.seam_rings must be at least 0, not -1."},
        {[](Json& j) { j["events"][0]["step"]["stitch"]["max_gap_ratio"] = 0; },
         ": events[0].step.stitch.max_gap_ratio must be a positive finite number, not 0."},
        {[](Json& j) { j["events"][0]["step"]["scan"]["quality_angle_limit_deg"] = 90; },
         ": events[0].step.scan.quality_angle_limit_deg must be in (0, 90), not 90."},
        {[](Json& j) { j["events"][0]["step"]["quality_mask"]["search_rings"] = -1; },
         ": events[0].step.quality_mask.search_rings must be at least 0, not -1."},
        {[](Json& j) { j["events"][0]["step"]["triangulate"]["max_sampling_angle_deg"] = 0; },
         ": events[0].step.triangulate.max_sampling_angle_deg must be in (0, 90], not 0."},
        {[](Json& j) { j["events"][0]["step"]["dilate_radius"] = 2000; },
         ": events[0].step.dilate_radius must be in [0, 1024], not 2000."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["h"] = 40; },
         ": events[1].step.fishbone.h must be in [0.5, 37.5] for a 200x150 scan: the spacing h = 40 pixels "
         "is "
         "outside it."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["tracing"]["backbone"]["min_step"] = 0.5; },
         ": events[1].step.fishbone.tracing.backbone.min_step must be in (0, step] = (0, 0.3], not 0.5."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["tracing"]["ribs"]["max_steps"] = 0; },
         ": events[1].step.fishbone.tracing.ribs.max_steps must be in [1, 9223372036854775807], not 0."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["tracing"]["spacing"] = 0; },
         ": events[1].step.fishbone.tracing.spacing must be a positive finite number, not 0."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["crease"]["angle_deg"] = 180; },
         ": events[1].step.fishbone.crease.angle_deg must be in [0, 180), not 180."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["crease"]["snap_radius"] = 0; },
         ": events[1].step.fishbone.crease.snap_radius must be a positive finite number, not 0."},
        {[](Json& j) {
             j["events"][1]["step"]["fishbone"]["drawn_key_ribs"][1] = Json::array({{1, 2}});
         },
         ": events[1].step.fishbone.drawn_key_ribs[1] must have at least 2 points, not 1."},
        {[](Json& j) {
             j["events"][1]["step"]["fishbone"]["drawn_backbone"] = Json::array({{1, 2}});
         },
         ": events[1].step.fishbone.drawn_backbone must be empty or have at least 2 points, not 1."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["min_seed_anisotropy"] = 1.5; },
         ": events[1].step.fishbone.min_seed_anisotropy must be in [0, 1], not 1.5."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["raycast"]["rings"] = -1; },
         ": events[1].step.fishbone.raycast.rings must be at least 0, not -1."},
        {[](Json& j) { j["events"][1]["step"]["fishbone"]["sampling_factor"] = 5; },
         ": events[1].step.fishbone.sampling_factor must be at most the spacing h: the sampling factor 5 "
         "exceeds the spacing h = 3.5 pixels (the sampling image needs at least one pixel per sample)."},
        {[](Json& j) { j["curvature"]["min_points"] = 5; },
         ": curvature.min_points must be at least 6, not 5."},
        {[](Json& j) { j["curvature"]["anisotropy_epsilon"] = 0; },
         ": curvature.anisotropy_epsilon must be a positive finite number, not 0."},
    };
    for (const auto& [edit, expected] : cases) {
        Json j = good_;
        edit(j);
        EXPECT_EQ(load(j), expected);
    }
}

// Options added after version 1 was first written are optional: absent, they are what the older files were
// recorded with, and they are written only when they differ from that, so older files stay byte-identical.
TEST_F(BadSessionFile, LaterStitchOptionsAreOptional) {
    const Json& written = good_["events"][0]["step"]["stitch"];
    EXPECT_EQ(written["outside_min_angle_floor_deg"], 7.5);
    EXPECT_EQ(written["peel_trim"], true);
    const Json& defaults =
        good_["events"][1]["step"]["stitch"]; // the fishbone step has default stitch options
    EXPECT_FALSE(defaults.contains("outside_min_angle_floor_deg"));
    EXPECT_FALSE(defaults.contains("peel_trim"));

    auto stitchOf = [&](const Json& j) {
        return fss::sessionFileFromJson(j.dump(2), "s.json", ".", {.verifyMesh = false})
            .events.at(0)
            .step.stitch;
    };
    Json j = good_;
    j["events"][0]["step"]["stitch"].erase("outside_min_angle_floor_deg");
    j["events"][0]["step"]["stitch"].erase("peel_trim");
    EXPECT_EQ(stitchOf(j).outsideMinAngleFloorDeg, 0.0);
    EXPECT_FALSE(stitchOf(j).peelTrim);
    // The band remesh (stitch v2, on by default since version 2): absent = on, in a version 1 file too;
    // written only when off, and read back so.
    EXPECT_FALSE(defaults.contains("remesh_seam"));
    EXPECT_TRUE(stitchOf(j).remeshSeam);
    Json v1 = j;
    v1["version"] = 1;
    EXPECT_TRUE(stitchOf(v1).remeshSeam);
    fss::SessionFile off = sampleFile(mesh_);
    off.events[0].step.stitch.remeshSeam = false;
    const Json offJson = Json::parse(fss::sessionFileToJson(off));
    EXPECT_EQ(offJson["events"][0]["step"]["stitch"]["remesh_seam"], false);
    EXPECT_FALSE(stitchOf(offJson).remeshSeam);
    // -0.0 is not 0 bit for bit: it is written, and comes back with its sign.
    fss::SessionFile f = sampleFile(mesh_);
    f.events[0].step.stitch.outsideMinAngleFloorDeg = -0.0;
    const Json negativeZero = Json::parse(fss::sessionFileToJson(f));
    ASSERT_TRUE(negativeZero["events"][0]["step"]["stitch"].contains("outside_min_angle_floor_deg"));
    EXPECT_TRUE(std::signbit(stitchOf(negativeZero).outsideMinAngleFloorDeg));
}

TEST_F(BadSessionFile, UnknownMeshAndChangedMesh) {
    Json j = good_;
    j["mesh"]["path"] = "no_such_mesh.off";
    const auto missing = (fss::test::tmpPath("no_such_mesh.off")).lexically_normal();
    EXPECT_EQ(load(j), ": mesh.path names the mesh " + missing.string() + ", which does not exist.");
    j = good_;
    j["mesh"]["sha256"] = std::string(64, '0');
    EXPECT_EQ(load(j), ": mesh.sha256 does not match the mesh " + j["mesh"]["path"].get<std::string>() +
                           " (the file changed since the session was recorded).");
}

TEST_F(BadSessionFile, TruncatedJson) {
    const std::string text = good_.dump(2);
    const std::string message = load(text.substr(0, text.size() / 2));
    EXPECT_EQ(message.rfind(" is not valid JSON (it ends early, at line ", 0), 0u) << message;
    EXPECT_EQ(
        load("{\"format\": \"fss-session\",, }").rfind(" is not valid JSON (error at line 1, column ", 0),
        0u);
    // A missing file is an IoError too, naming it.
    EXPECT_THROW(fss::loadSessionFile(fss::test::tmpPath("no_such.session.json")), fss::IoError);
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
