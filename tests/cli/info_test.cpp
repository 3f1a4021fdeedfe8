// fss-remesh info: help, exit codes, JSON report, and one clear sentence for every kind of bad input.
#include "run_process.h"
#include "test_data.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <fstream>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_info_test {

using fss::test::expectCleanFailure;
using fss::test::meshPath;
using fss::test::remeshExe;
using fss::test::runProcess;
using fss::test::tmpPath;

namespace {

fss::test::ProcessResult remesh(const std::vector<std::string>& args) {
    return runProcess(remeshExe(), args, tmpPath("cli_info"));
}

void writeFile(const std::filesystem::path& p, const std::string& bytes) {
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
}

} // namespace

TEST(CliInfo, HelpDocumentsEveryOption) {
    const auto top = remesh({"--help"});
    EXPECT_EQ(top.exitCode, 0);
    EXPECT_NE(top.out.find("info"), std::string::npos);
    EXPECT_NE(top.out.find("scan"), std::string::npos);
    const auto r = remesh({"info", "--help"});
    EXPECT_EQ(r.exitCode, 0);
    for (const char* opt : {"--ref", "--json", "--no-self-intersections", "MESH"})
        EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}

TEST(CliInfo, UsageErrorsExitWithTwo) {
    EXPECT_EQ(remesh({}).exitCode, 2);
    const auto noArg = remesh({"info"});
    EXPECT_EQ(noArg.exitCode, 2);
    EXPECT_NE(noArg.err.find("MESH"), std::string::npos);
    const auto unknown = remesh({"info", meshPath("tetrahedron.off").string(), "--frobnicate"});
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.err.find("--frobnicate"), std::string::npos);
    EXPECT_EQ(remesh({"frobnicate"}).exitCode, 2);
}

TEST(CliInfo, JsonReportOfFandisk) {
    const auto r = remesh({"info", meshPath("fandisk.off").string(), "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("vertices").get<int>(), 6475);
    EXPECT_EQ(j.at("faces").get<int>(), 12946);
    EXPECT_EQ(j.at("edges").get<int>(), 6475 + 12946 - 2); // closed genus 0: V - E + F = 2
    EXPECT_EQ(j.at("boundary_edges").get<int>(), 0);
    EXPECT_EQ(j.at("boundary_loops").get<int>(), 0);
    EXPECT_EQ(j.at("components").get<int>(), 1);
    EXPECT_TRUE(j.at("closed").get<bool>());
    EXPECT_EQ(j.at("non_manifold_edges").get<int>(), 0);
    EXPECT_EQ(j.at("self_intersections").get<int>(), 0);
    for (const char* key : {"frac_valence6_interior", "min_angle_deg", "max_angle_deg", "mean_min_angle_deg",
                            "frac_min_angle_below_30", "frac_min_angle_below_10", "radius_ratio_mean",
                            "radius_ratio_min", "edge_length_mean", "edge_length_cv", "bbox_diagonal", "area",
                            "valence_histogram", "degenerate_faces", "non_manifold_vertices"})
        EXPECT_TRUE(j.contains(key)) << key;
    const double f6 = j.at("frac_valence6_interior").get<double>();
    EXPECT_GT(f6, 0.0);
    EXPECT_LT(f6, 1.0);
    EXPECT_TRUE(j.at("hausdorff_to_ref_rel").is_null());
}

TEST(CliInfo, ReferenceDistancesOfAMeshToItselfAreZero) {
    const auto m = meshPath("fandisk.off").string();
    const auto r = remesh({"info", m, "--ref", m, "--json", "--no-self-intersections"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j.at("hausdorff_to_ref_rel").get<double>(), 0.0, 1e-9);
    EXPECT_NEAR(j.at("hausdorff_from_ref_rel").get<double>(), 0.0, 1e-9);
    EXPECT_NEAR(j.at("rms_to_ref").get<double>(), 0.0, 1e-9);
    EXPECT_TRUE(j.at("self_intersections").is_null());
}

TEST(CliInfo, TextReportMentionsTheCounts) {
    const auto r = remesh({"info", meshPath("tetrahedron.off").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("tetrahedron.off"), std::string::npos);
    EXPECT_NE(r.out.find('4'), std::string::npos);
}

TEST(CliInfo, BadInputsGiveOneSentenceAndNonZeroExit) {
    const auto dir = tmpPath("cli_bad");
    const std::string valid = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    struct Case {
        std::string name, bytes, mention;
    };
    const std::vector<Case> cases = {
        {"empty.off", "", "empty.off"},
        {"truncated.off", valid.substr(0, valid.size() / 2), "truncated.off"},
        {"garbage.off", std::string("\x01\x02\xff\xfe garbage \x00\x13", 16), "garbage.off"},
        {"nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "nan.off"},
        {"inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", "inf.obj"},
        {"badindex.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "badindex.off"},
        {"unknown.xyz", "hello world\n", "unknown.xyz"},
        {"binary_truncated.stl",
         std::string(80, ' ') + std::string("\x10\x00\x00\x00", 4) + std::string(30, '\0'),
         "binary_truncated.stl"},
        {"nothing_left.off", "OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n", "nothing_left.off"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        writeFile(dir / c.name, c.bytes);
        expectCleanFailure(remesh({"info", (dir / c.name).string()}), c.mention);
    }
    expectCleanFailure(remesh({"info", (dir / "does_not_exist.off").string()}), "does_not_exist.off");
    expectCleanFailure(remesh({"info", dir.string()}), "cli_bad"); // a folder, not a file
}

} // namespace fss_cli_info_test
