#pragma once
// The helpers the session file tests share (session_file_test.cpp, session_file_keys_test.cpp): bitwise
// comparisons of every field, a regular and a fishbone step, a sample file, and the BadSessionFile fixture.
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

namespace session_file_test_helpers {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Json = nlohmann::ordered_json;

// Bitwise equality of doubles (distinguishes -0.0 from 0.0).
inline ::testing::AssertionResult sameBits(double a, double b) {
    if (std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b))
        return ::testing::AssertionSuccess();
    std::ostringstream os;
    os.precision(17);
    os << a << " != " << b;
    return ::testing::AssertionFailure() << os.str();
}

inline void expectSame(const Vector2d& a, const Vector2d& b) {
    EXPECT_TRUE(sameBits(a.x(), b.x()));
    EXPECT_TRUE(sameBits(a.y(), b.y()));
}
inline void expectSame(const Vector3d& a, const Vector3d& b) {
    for (int i = 0; i < 3; ++i)
        EXPECT_TRUE(sameBits(a[i], b[i]));
}
inline void expectSame(const std::vector<Vector2d>& a, const std::vector<Vector2d>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
        expectSame(a[i], b[i]);
}

inline void expectSame(const fss::StreamlineOptions& a, const fss::StreamlineOptions& b) {
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
inline void expectSame(const fss::ScanStep& a, const fss::ScanStep& b) {
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

inline std::string slurpText(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A small mesh file in the test scratch folder (its bytes are what the sha256 covers).
inline std::filesystem::path writeTestMesh(const std::string& name, const fss::Mesh& mesh) {
    const auto path = fss::test::tmpPath(name);
    fss::writeMesh(mesh, path);
    return path;
}

// A regular step with every field away from its default (and awkward doubles).
inline fss::ScanStep regularStep() {
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

inline fss::ScanStep fishboneStep() {
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

inline fss::SessionFile sampleFile(const std::filesystem::path& meshPath) {
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

} // namespace session_file_test_helpers
