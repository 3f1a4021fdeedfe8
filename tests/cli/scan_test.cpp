// fss-remesh scan: the patch of a real mesh from the command line (GPU head-less and CPU), JSON report,
// lasso subsets, PLY attributes, and one clear sentence for each kind of bad scan.
#include "run_process.h"
#include "test_data.h"

#include "fss/mesh_io.h"
#include "fss/metrics.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cstdlib>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_scan_test {

using fss::test::expectCleanFailure;
using fss::test::meshPath;
using fss::test::tmpPath;

namespace {

fss::test::ProcessResult remesh(const std::vector<std::string>& args) {
    return fss::test::runProcess(fss::test::remeshExe(), args, tmpPath("cli_scan"));
}

const std::string kFandisk = meshPath("fandisk.off").string();

} // namespace

// The scan must run with no X server: the CTest environment of this program has DISPLAY unset.
TEST(CliScan, HeadlessIsoScanOfFandiskIsRegularAndClose) {
    ASSERT_EQ(std::getenv("DISPLAY"), nullptr) << "this test must run without an X server";
    const auto out = tmpPath("cli_scan/fandisk_iso.ply");
    const auto r = remesh({"scan", kFandisk, "-o", out.string(), "--view", "iso", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("resolution"), nlohmann::json({256, 256}));
    EXPECT_EQ(j.at("renderer").get<std::string>().rfind("gpu", 0), 0u) << j.at("renderer");
    const auto& c = j.at("counts");
    EXPECT_EQ(c.at("pixels").get<int>(), 256 * 256);
    EXPECT_GT(c.at("covered").get<int>(), 10000);
    for (const char* stage :
         {"render_reference", "sample", "lasso", "quality_mask", "morphology", "triangulate", "total"})
        EXPECT_GE(j.at("timings_s").at(stage).get<double>(), 0.0) << stage;

    fss::ReadReport report;
    const fss::Mesh patch = fss::readMesh(out, &report);
    EXPECT_EQ(patch.number_of_faces(), c.at("patch_faces").get<std::size_t>());
    EXPECT_TRUE(report.hasFaceQuality);
    EXPECT_TRUE(report.hasScanId);
    const fss::Mesh ref = fss::readMesh(kFandisk);
    const fss::Metrics m = fss::computeMetrics(patch, {.selfIntersections = false, .reference = &ref});
    EXPECT_GE(m.fracValence6Interior, 0.98);
    EXPECT_EQ(m.nonManifoldVertices, 0u);
    EXPECT_LE(*m.hausdorffToRefRel, 0.0025);
    // Edges never span a silhouette: at most 3 pixel footprints (footprint ≈ 2·d·tan(15°)/256 at the mesh).
    const double footprintUpper = 2.0 * 3.0 * std::tan(15.0 * 3.14159265 / 180.0) / 256.0; // eye at d < 3
    for (auto e : patch.edges()) {
        const auto h = patch.halfedge(e);
        EXPECT_LE(
            std::sqrt(CGAL::squared_distance(patch.point(patch.source(h)), patch.point(patch.target(h)))),
            3.0 * footprintUpper);
    }
}

TEST(CliScan, CpuRendererGivesTheSamePatchSize) {
    const auto gpu = remesh({"scan", kFandisk, "-o", tmpPath("cli_scan/g.off").string(), "--view", "+x",
                             "--resolution", "96", "--json"});
    const auto cpu = remesh({"scan", kFandisk, "-o", tmpPath("cli_scan/c.off").string(), "--view", "+x",
                             "--resolution", "96", "--json", "--renderer", "cpu"});
    ASSERT_EQ(gpu.exitCode, 0) << gpu.err;
    ASSERT_EQ(cpu.exitCode, 0) << cpu.err;
    const auto g = nlohmann::json::parse(gpu.out).at("counts"),
               c = nlohmann::json::parse(cpu.out).at("counts");
    EXPECT_EQ(nlohmann::json::parse(cpu.out).at("renderer"), "cpu");
    // The GPU and the exact CPU ray caster may disagree on a few pixel centres lying on edges.
    EXPECT_NEAR(g.at("covered").get<double>(), c.at("covered").get<double>(),
                0.002 * c.at("covered").get<double>());
    EXPECT_NEAR(g.at("patch_faces").get<double>(), c.at("patch_faces").get<double>(),
                0.01 * c.at("patch_faces").get<double>());
}

TEST(CliScan, LassoSelectsAStrictSubsetIndependentOfResolution) {
    auto facesWith = [](const std::vector<std::string>& extra, const std::string& res) {
        std::vector<std::string> args{"scan",   kFandisk, "-o",           tmpPath("cli_scan/l.off").string(),
                                      "--view", "+x",     "--resolution", res,
                                      "--json"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = remesh(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return r.exitCode == 0 ? nlohmann::json::parse(r.out).at("counts") : nlohmann::json();
    };
    const auto full = facesWith({}, "128");
    const auto part = facesWith({"--lasso", "0.3,0.3;0.7,0.3;0.7,0.7;0.3,0.7"}, "128");
    const auto partFine = facesWith({"--lasso", "0.3,0.3;0.7,0.3;0.7,0.7;0.3,0.7"}, "256");
    ASSERT_FALSE(full.is_null() || part.is_null() || partFine.is_null());
    EXPECT_LT(part.at("after_lasso").get<int>(), full.at("after_lasso").get<int>());
    EXPECT_LT(part.at("patch_faces").get<int>(), full.at("patch_faces").get<int>());
    // Normalised lasso coordinates: the same region at twice the resolution has about 4× the samples.
    EXPECT_NEAR(partFine.at("after_lasso").get<double>() / part.at("after_lasso").get<double>(), 4.0, 0.2);
}

// The adaptive lattice is warped to the surface by default (issue #20); --no-warp scans the plain affine
// lattice, and is refused where it would mean nothing.
TEST(CliScan, NoWarpScansThePlainAdaptiveLattice) {
    const fss::Mesh ref = fss::readMesh(kFandisk);
    auto scan = [&](const std::vector<std::string>& extra, const std::string& name) {
        const auto out = tmpPath("cli_scan/" + name + ".off");
        std::vector<std::string> args{"scan",       kFandisk, "-o",     out.string(),   "--view", "iso",
                                      "--renderer", "cpu",    "--json", "--resolution", "128"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = remesh(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        const auto j = nlohmann::json::parse(r.exitCode == 0 ? r.out : "{}");
        const fss::Metrics m = fss::computeMetrics(fss::readMesh(out), {.selfIntersections = false});
        return std::pair{j, m};
    };
    const auto [warpJson, warp] = scan({}, "warp");
    const auto [plainJson, plain] = scan({"--no-warp"}, "plain");
    EXPECT_EQ(warpJson.at("lattice"), "adaptive");
    EXPECT_EQ(warpJson.at("warp_to_surface"), true);
    EXPECT_EQ(plainJson.at("lattice"), "adaptive");
    EXPECT_EQ(plainJson.at("warp_to_surface"), false);
    // The warp keeps round triangles where the view is slanted, so the 35° mask leaves far less of fandisk's
    // iso view to other views (measured at 128²: area 0.779 against 0.529, mean smallest angle 52.2° against
    // 55.0° on the smaller patch, none below 30° in either); both patches stay regular.
    EXPECT_GT(warp.area, 1.3 * plain.area);
    EXPECT_GE(warp.meanMinAngleDeg, 50.0);
    EXPECT_LE(warp.fracMinAngleBelow30, 0.02);
    EXPECT_GE(warp.fracValence6Interior, 0.9);
    EXPECT_GE(plain.fracValence6Interior, 0.9);

    const std::string out = tmpPath("cli_scan/nowarp_bad.ply").string();
    const auto square = remesh({"scan", kFandisk, "-o", out, "--lattice", "square", "--no-warp"});
    expectCleanFailure(square, "--no-warp");
    EXPECT_EQ(square.exitCode, 2);
    EXPECT_NE(square.err.find("--lattice square"), std::string::npos) << square.err;
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--fishbone", "seed=0.4,0.55", "--no-warp"}),
                       "--no-warp");
}

TEST(CliScan, BadScansFailWithOneSentence) {
    const std::string out = tmpPath("cli_scan/bad.ply").string();
    for (const char* res : {"0", "-5", "9000", "abc", "100x0"}) {
        SCOPED_TRACE(res);
        expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--resolution", res}), "--resolution");
    }
    // Camera inside the closed mesh: fandisk's interior point near its centroid looks at back faces only.
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--camera", "0,0,0.1,0,1,0.1,0,0,1"}), "inside");
    // Looking away from the mesh.
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--camera", "10,0,0,20,0,0,0,0,1"}), "behind");
    // An empty view: the mesh is beside the camera's narrow field.
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--camera", "10,0,0,10,5,0,0,0,1,5"}), "mesh");
    // Degenerate lassos.
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--lasso", "0.1,0.1;0.5,0.5;0.9,0.9"}), "lasso");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--lasso", "0.1,0.1;0.2"}), "lasso");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--lasso", "0,0;0.02,0;0,0.02"}), "lasso");
    // Other absurd parameters.
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--zoom", "0"}), "--zoom");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--view", "sideways"}), "--view");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--camera", "1,2,3"}), "--camera");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", out, "--erode", "-1"}), "--erode");
    expectCleanFailure(remesh({"scan", kFandisk}), "-o");
    expectCleanFailure(remesh({"scan", kFandisk, "-o", tmpPath("cli_scan/x.abc").string()}), "extension");
    expectCleanFailure(remesh({"scan", tmpPath("cli_scan/missing.off").string(), "-o", out}), "missing.off");
}

} // namespace fss_cli_scan_test
