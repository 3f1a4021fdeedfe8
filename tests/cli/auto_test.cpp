// fss-remesh auto: automatic full-surface remeshing from the command line (head-less GPU renderer), checked
// against issue #7's criteria on CGAL's fandisk at about its own vertex count, and one clear sentence for
// each kind of bad command line.
//
// The criteria of issue #7 that FSS does not meet yet are kept, unchanged, in the DISABLED_ test below (run
// it with --gtest_also_run_disabled_tests); the numbers measured are in its comment.
#include "expect_valid_mesh.h"
#include "run_process.h"
#include "test_data.h"

#include "fss/face_groups.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_auto_test {

using fss::test::expectCleanFailure;
using fss::test::meshPath;
using fss::test::tmpPath;

namespace {

fss::test::ProcessResult remesh(const std::vector<std::string>& args) {
    return fss::test::runProcess(fss::test::remeshExe(), args, tmpPath("cli_auto"));
}

const std::string kFandisk = meshPath("fandisk.off").string();

// CGAL::Polygon_mesh_processing::isotropic_remeshing of fandisk at the same target edge length (the one of
// fandisk's vertex count, 0.019834), 3 iterations, sharp edges (35°) constrained, measured with
// fss::computeMetrics by bench/auto_bench.cpp (`FSS_AUTO_BENCH_MESHES=fandisk ./build/bin/bench_auto`):
// Hausdorff distance to / from the input relative to the bbox diagonal.
constexpr double kCgalFandiskHausdorffToRel = 0.00135;
constexpr double kCgalFandiskHausdorffFromRel = 0.00135;

struct AutoRun {
    nlohmann::json report;
    fss::Mesh mesh;
    fss::Metrics metrics;
    double scannedArea = 0, totalArea = 0;
};

// Runs `auto` on one of CGAL's sample meshes and measures the result independently.
AutoRun runAuto(const std::string& name) {
    AutoRun r;
    const std::string input = meshPath(name + ".off").string();
    const auto out = tmpPath("cli_auto/" + name + "_auto.ply");
    const auto p = remesh({"auto", input, "-o", out.string(), "--json", "--no-metrics"});
    EXPECT_EQ(p.exitCode, 0) << p.err;
    if (p.exitCode != 0) return r;
    r.report = nlohmann::json::parse(p.out);
    r.mesh = fss::readMesh(out);
    const fss::Mesh reference = fss::readMesh(input);
    fss::MetricsOptions mo;
    mo.reference = &reference;
    r.metrics = fss::computeMetrics(r.mesh, mo);
    const auto ids = r.mesh.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
    EXPECT_TRUE(ids.second) << "the PLY output keeps the scan id of every face";
    for (fss::FaceIndex f : r.mesh.faces()) {
        const auto h = r.mesh.halfedge(f);
        const double a =
            std::sqrt(CGAL::squared_area(r.mesh.point(r.mesh.source(h)), r.mesh.point(r.mesh.target(h)),
                                         r.mesh.point(r.mesh.target(r.mesh.next(h)))));
        r.totalArea += a;
        if (ids.second && ids.first[f] >= 0) r.scannedArea += a;
    }
    return r;
}

// Runs `auto` once on fandisk (shared by the tests below).
const AutoRun& fandiskRun() {
    static const AutoRun run = runAuto("fandisk");
    return run;
}

} // namespace

TEST(CliAuto, FandiskIsCoveredClosedManifoldAndFreeOfSelfIntersections) {
    ASSERT_EQ(std::getenv("DISPLAY"), nullptr) << "this test must run without an X server";
    const AutoRun& r = fandiskRun();
    ASSERT_FALSE(r.report.is_null());
    EXPECT_EQ(r.report.at("renderer").get<std::string>(), "gpu");
    EXPECT_EQ(r.report.at("input_vertices").get<int>(), 6475);
    // The edge length of 6475 vertices on fandisk's area 2.20602: sqrt(A / (N·√3/2)).
    EXPECT_NEAR(r.report.at("edge_length").get<double>(), std::sqrt(2.20602 / (6475 * std::sqrt(3.0) / 2)),
                1e-5);
    // Coverage: reported and recomputed from the faces' scan ids agree, and reach the issue's 95 %.
    const double coverage = r.report.at("coverage").get<double>();
    EXPECT_NEAR(r.scannedArea / r.totalArea, coverage, 1e-6);
    EXPECT_GE(coverage, 0.95);
    EXPECT_GT(r.report.at("scans_stitched").get<int>(), 5);
    // Valid: closed, manifold, no degenerate faces, no self-intersections (CGAL PMP).
    const fss::Metrics& m = r.metrics;
    fss::test::expectClosedValidMesh(m);
    // About the input's vertex count.
    EXPECT_NEAR(double(m.vertices), 6475.0, 0.15 * 6475.0);
    // Issue #7: minimum angle ≥ 10°.
    EXPECT_GE(m.minAngleDeg, 10.0);
    // The seam relaxation (auto_remesh.h, step 6) ran and was kept: fraction of valence-6 interior vertices
    // measured 0.791 (0.658 without it; CGAL's isotropic remeshing 0.773; the criterion, 0.90, below).
    EXPECT_GT(r.report.at("seam_flips").get<int>(), 0);
    EXPECT_GT(r.report.at("seam_collapses").get<int>(), 0);
    EXPECT_FALSE(r.report.at("seam_relax_discarded").get<bool>());
    EXPECT_GE(m.fracValence6Interior, 0.78);
    // The crease recovery (auto_remesh.h) moved vertices onto fandisk's sharp edges.
    EXPECT_GT(r.report.at("crease_snaps").get<int>(), 0);
    EXPECT_TRUE(r.report.at("crease_splits").is_number_unsigned());
    EXPECT_TRUE(r.report.at("crease_flips").is_number_unsigned());
    EXPECT_TRUE(r.report.at("crease_removals").is_number_unsigned());
    EXPECT_TRUE(r.report.at("crease_repairs").is_number_unsigned());
}

// Other closed CGAL sample meshes, curved and mechanical: the result stays valid and the seam relaxation
// raises the fraction of valence-6 interior vertices. Measured (GPU renderer) with / without the relaxation:
// elephant 0.617 / 0.439, couplingdown 0.673 / 0.575, rotor_small 0.679 / 0.447. Their coverage is still
// below the issue's 95 % (0.75, 0.50, 0.79 with the stitch's peeling trim; 0.63, 0.38, 0.45 before): at
// ~30–60 pixel views many patch pieces are trimmed by the stitch because the mesh under their boundary
// folds over itself in the scan's view.
TEST(CliAuto, OtherClosedMeshesStayValidAndGainValenceSixFromTheSeamRelaxation) {
    struct Case {
        const char* name;
        double minValence6;
    };
    for (const Case& c : {Case{"elephant", 0.60}, Case{"couplingdown", 0.65}, Case{"rotor_small", 0.65}}) {
        SCOPED_TRACE(c.name);
        const AutoRun r = runAuto(c.name);
        ASSERT_FALSE(r.report.is_null());
        const fss::Metrics& m = r.metrics;
        fss::test::expectClosedValidMesh(m);
        EXPECT_NEAR(r.scannedArea / r.totalArea, r.report.at("coverage").get<double>(), 1e-6);
        EXPECT_GT(r.report.at("seam_flips").get<int>(), 0);
        EXPECT_FALSE(r.report.at("seam_relax_discarded").get<bool>());
        EXPECT_GE(m.fracValence6Interior, c.minValence6);
    }
}

// Issue #7's regularity and distance criteria on fandisk. NOT MET YET, measured on this branch
// (bench_auto, GPU renderer; `fss-remesh auto fandisk.off -o out.ply --json` runs the same autoRemesh):
// fraction of valence-6 interior vertices 0.821 (criterion ≥ 0.90; CGAL's isotropic remeshing: 0.773; 0.658
// before the seam relaxation), Hausdorff distance to / from the input 0.00377 / 0.00241 of the bbox diagonal
// (criterion: ≤ CGAL's 0.00128 / 0.00135). With one region per view the 8 initial patches alone reach 0.77
// valence 6 at 0.88 coverage; the stitch trims them at many seams and the follow-up scans that fill those
// gaps are small and irregular; the seam relaxation's flips and collapses stop at pairs of valence-5 and -7
// vertices and at feature lines (whose vertices it does not move); 641 of the 716 irregular vertices inside
// a patch before the relaxation are next to a seam. The pixel grids also cut the sharp edges that CGAL keeps
// as constraints: the largest distances were on faces across those edges. The crease recovery
// (auto_remesh.h, step 7) moves vertices onto the creases and their corners, removes vertices of valence 3
// standing off the input, repairs folds and faces far from the input, splits and flips edges there:
// 0.00942 / 0.00975 → 0.00627 / 0.00347 (bench_auto; valence 6 0.791 → 0.809), 0.00377 / 0.00241 with the
// moves and splits whose small angles flips around them mend and the stitch's peeling trim (coverage 0.988,
// valence 6 0.821); what is left is at the creases (the largest, 0.36 L off the input: a face across a crease
// between a vertex on it and two off it, 0.48 L and 1.5 L away, that no operation of the recovery repairs
// within its conditions).
TEST(CliAuto, DISABLED_FandiskMeetsIssue7RegularityAndDistanceCriteria) {
    const AutoRun& r = fandiskRun();
    ASSERT_FALSE(r.report.is_null());
    const fss::Metrics& m = r.metrics;
    EXPECT_GE(m.fracValence6Interior, 0.90);
    ASSERT_TRUE(m.hausdorffToRefRel && m.hausdorffFromRefRel);
    EXPECT_LE(*m.hausdorffToRefRel, kCgalFandiskHausdorffToRel);
    EXPECT_LE(*m.hausdorffFromRefRel, kCgalFandiskHausdorffFromRel);
}

TEST(CliAuto, BadCommandLinesGiveOneSentence) {
    const auto out = tmpPath("cli_auto/bad.off").string();
    auto r = remesh({"auto", kFandisk});
    expectCleanFailure(r, "-o OUT");
    EXPECT_EQ(r.exitCode, 2);
    r = remesh({"auto", kFandisk, "-o", out, "--edge-length", "0.02", "--target-vertices", "1000"});
    expectCleanFailure(r, "not both");
    EXPECT_EQ(r.exitCode, 2);
    r = remesh({"auto", kFandisk, "-o", out, "--edge-length", "-1"});
    expectCleanFailure(r, "--edge-length");
    EXPECT_EQ(r.exitCode, 2);
    r = remesh({"auto", kFandisk, "-o", out, "--fishbone", "sometimes"});
    expectCleanFailure(r, "--fishbone");
    EXPECT_EQ(r.exitCode, 2);
    r = remesh({"auto", kFandisk, "-o", out, "--renderer", "quantum"});
    expectCleanFailure(r, "--renderer");
    EXPECT_EQ(r.exitCode, 2);
    r = remesh({"auto", kFandisk, "-o", tmpPath("cli_auto/bad.xyz").string()});
    expectCleanFailure(r, "extension");
    r = remesh({"auto", meshPath("no-such-mesh.off").string(), "-o", out});
    expectCleanFailure(r, "no-such-mesh.off");
    EXPECT_EQ(r.exitCode, 1);
}

TEST(CliAuto, HelpListsTheOptions) {
    const auto r = remesh({"auto", "--help"});
    EXPECT_EQ(r.exitCode, 0);
    for (const char* option : {"--edge-length", "--target-vertices", "--fishbone", "--json", "--renderer"})
        EXPECT_NE(r.out.find(option), std::string::npos) << option;
}

// ---- issue 22: the FEM hand-off ------------------------------------------------------------------------

namespace {

/// fandisk with two groups split by the plane z = mid-height, written as OBJ (`g upper` / `g lower`).
std::string twoGroupFandiskObj(const std::string& upper = "upper") {
    fss::Mesh mesh = fss::readMesh(kFandisk);
    const double mid = fss::boundingBox(mesh).center().z();
    fss::setGroupNames(mesh, {upper, "lower"});
    auto group = mesh.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceGroup).first;
    for (fss::FaceIndex f : mesh.faces()) {
        double z = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            z += mesh.point(v).z() / 3;
        group[f] = z > mid ? 0 : 1;
    }
    const auto path = tmpPath("cli_auto/fandisk_groups_" + upper + ".obj");
    std::filesystem::create_directories(path.parent_path());
    fss::writeMesh(mesh, path);
    return path.string();
}

std::map<std::string, std::pair<std::size_t, double>> infoGroups(const std::string& file) {
    const auto r = remesh({"info", file, "--json", "--no-self-intersections"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    std::map<std::string, std::pair<std::size_t, double>> out;
    if (r.exitCode != 0) return out;
    const nlohmann::json report = nlohmann::json::parse(r.out); // a named object: the loop must not dangle
    for (const auto& g : report.at("groups"))
        out[g.at("name").get<std::string>()] = {g.at("faces").get<std::size_t>(), g.at("area").get<double>()};
    return out;
}

} // namespace

// A CGAL mesh with two groups remeshed by `auto` into gmsh MSH 4.1 with feature edges: every output face
// carries a group (read back through gmsh by `info`) and each group's area is within 1 % of the input's.
TEST(CliAuto, FemHandOffCarriesGroups) {
    const std::string input = twoGroupFandiskObj();
    const auto out = tmpPath("cli_auto/fandisk_groups_auto.msh");
    const auto p = remesh({"auto", input, "-o", out.string(), "--feature-edges", "--no-metrics"});
    ASSERT_EQ(p.exitCode, 0) << p.err;
    const auto before = infoGroups(input), after = infoGroups(out.string());
    ASSERT_EQ(before.size(), 2u);
    ASSERT_EQ(after.size(), 2u) << "a face without a group would add an entry with an empty name";
    for (const char* name : {"upper", "lower"}) {
        const double a = before.at(name).second, b = after.at(name).second;
        EXPECT_NEAR(b, a, 0.01 * a) << name;
        std::printf("[ measure  ] auto: group %s area %.6g -> %.6g (%.3f %%), %zu -> %zu faces\n", name, a, b,
                    100 * (b / a - 1), before.at(name).first, after.at(name).first);
    }
    // The text report of `info` shows the groups and the quality measures FEM users check.
    const auto text = remesh({"info", out.string(), "--no-self-intersections"});
    EXPECT_NE(text.out.find("group 'upper'"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("scaled Jacobian"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("aspect ratio"), std::string::npos) << text.out;
}

TEST(CliAuto, FemHandOffBadInputIsOneSentence) {
    const std::string input = twoGroupFandiskObj();
    // Line elements cannot go into a PLY file: refused before any work.
    expectCleanFailure(remesh({"auto", input, "-o", tmpPath("cli_auto/x.ply").string(), "--feature-edges"}),
                       "--feature-edges");
    expectCleanFailure(remesh({"auto", input, "-o", tmpPath("cli_auto/x.xyz").string()}), ".msh");
    // A group name Abaqus cannot hold: one sentence, exit 1, no file.
    const auto spaced = tmpPath("cli_auto/spaced_groups.obj");
    {
        std::ofstream f(spaced);
        f << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\no my part\ng\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
    }
    // `o my part` names two groups: unknown group syntax for FSS.
    expectCleanFailure(remesh({"info", spaced.string()}), "one group per face");
    const auto inp = tmpPath("cli_auto/bad_name.inp");
    std::filesystem::remove(inp);
    const auto r = remesh({"scan", twoGroupFandiskObj("1st"), "-o", inp.string(), "--view", "iso"});
    expectCleanFailure(r, "Abaqus INP cannot hold the group name '1st'");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_FALSE(std::filesystem::exists(inp));
}

} // namespace fss_cli_auto_test
