// fss-remesh scan --into: chained scans stitched through PLY files keep the mesh invariants (checked here
// with CGAL), raise the fraction of valence-6 vertices, respect better earlier scans; failures write nothing.
#include "run_process.h"
#include "test_data.h"

#include "fss/mesh_io.h"

#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_scan_into_test {

namespace PMP = CGAL::Polygon_mesh_processing;
using fss::test::expectCleanFailure;
using fss::test::meshPath;
using fss::test::tmpPath;

namespace {

fss::test::ProcessResult remesh(const std::vector<std::string>& args) {
    return fss::test::runProcess(fss::test::remeshExe(), args, tmpPath("cli_scan_into"));
}

// Edge-manifold, consistently oriented (outward), closed, no self-intersections, no degenerate faces.
void expectInvariants(const fss::Mesh& m, const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m));
    ASSERT_TRUE(CGAL::is_triangle_mesh(m));
    EXPECT_TRUE(CGAL::is_closed(m));
    // Edge-manifold: no two edges join the same pair of vertices (a halfedge mesh cannot hold three faces
    // on one edge; a duplicated edge is how a non-manifold edge would appear).
    std::set<std::pair<std::size_t, std::size_t>> pairs;
    for (auto e : m.edges()) {
        const std::size_t a = m.source(m.halfedge(e)), b = m.target(m.halfedge(e));
        EXPECT_TRUE(pairs.emplace(std::min(a, b), std::max(a, b)).second)
            << "duplicate edge " << a << "-" << b;
    }
    std::size_t pinched = 0;
    for (auto v : m.vertices())
        pinched += PMP::is_non_manifold_vertex(v, m);
    EXPECT_EQ(pinched, 0u);
    // Consistent orientation is structural in a valid halfedge mesh; outward: positive enclosed volume.
    EXPECT_GT(PMP::volume(m), 0.0);
    std::size_t degenerate = 0;
    for (auto f : m.faces())
        degenerate += PMP::is_degenerate_triangle_face(f, m);
    EXPECT_EQ(degenerate, 0u);
    EXPECT_FALSE(PMP::does_self_intersect(m));
}

// Fraction of the vertices of a closed mesh (all interior) with valence 6.
double fracValence6(const fss::Mesh& m) {
    std::size_t six = 0;
    for (auto v : m.vertices())
        six += m.degree(v) == 6;
    return double(six) / double(m.number_of_vertices());
}

std::set<std::int32_t> scanIds(const fss::Mesh& m) {
    std::set<std::int32_t> ids;
    const auto [map, has] = m.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
    if (has)
        for (auto f : m.faces())
            ids.insert(map[f]);
    return ids;
}

void chainTwoScans(const std::string& name, const std::string& view1, const std::string& view2,
                   const std::string& resolution, const std::vector<std::string>& lattice = {}) {
    SCOPED_TRACE(name);
    const std::string input = meshPath(name + ".off").string();
    const std::string step1 = tmpPath("cli_scan_into/" + name + "_1.ply").string();
    const std::string step2 = tmpPath("cli_scan_into/" + name + "_2.ply").string();
    std::filesystem::remove(step1);
    std::filesystem::remove(step2);
    const fss::Mesh original = fss::readMesh(input);
    expectInvariants(original, "input");

    // First scan: the reference is its own current mesh.
    std::vector<std::string> args1{"scan",   input, "--into",       input,      "-o",    step1,
                                   "--view", view1, "--resolution", resolution, "--json"};
    args1.insert(args1.end(), lattice.begin(), lattice.end());
    const auto r1 = remesh(args1);
    ASSERT_EQ(r1.exitCode, 0) << r1.err;
    const auto j1 = nlohmann::json::parse(r1.out);
    EXPECT_EQ(j1.at("into"), input);
    EXPECT_EQ(j1.at("scan_id"), 0);
    EXPECT_GT(j1.at("stitch").at("faces_added").get<int>(), 1000);
    EXPECT_GE(j1.at("stitch").at("components_stitched").get<int>(), 1);
    for (const char* key :
         {"faces_removed", "seam_edges", "seam_length", "seam_min_angle_deg", "seam_faces",
          "components_skipped", "pieces_stitched", "patch_faces_trimmed", "collapses", "flips", "skipped",
          "seconds", "seam_frac_min_angle_above_25", "seam_frac_min_angle_above_30", "seam_vertices",
          "seam_valence_histogram", "seam_frac_valence_5_to_7"})
        EXPECT_TRUE(j1.at("stitch").contains(key)) << key;
    EXPECT_GT(j1.at("counts").at("patch_faces").get<int>(), 0); // the patch counts are still there
    EXPECT_GE(j1.at("timings_s").at("stitch").get<double>(), 0.0);
    const fss::Mesh mesh1 = fss::readMesh(step1);
    EXPECT_EQ(mesh1.number_of_faces(), j1.at("result").at("faces").get<std::size_t>());
    expectInvariants(mesh1, "after scan 1");
    EXPECT_EQ(scanIds(mesh1), (std::set<std::int32_t>{-1, 0}));

    // Second scan from another view into the first result (PLY: quality and scan ids travel along).
    std::vector<std::string> args2{"scan",   input, "--into",       step1,      "-o",    step2,
                                   "--view", view2, "--resolution", resolution, "--json"};
    args2.insert(args2.end(), lattice.begin(), lattice.end());
    const auto r2 = remesh(args2);
    ASSERT_EQ(r2.exitCode, 0) << r2.err;
    const auto j2 = nlohmann::json::parse(r2.out);
    EXPECT_EQ(j2.at("scan_id"), 1); // the next free id
    EXPECT_GT(j2.at("stitch").at("faces_added").get<int>(), 1000);
    // Where the first scan is better the new samples were dropped by the quality mask.
    EXPECT_LT(j2.at("counts").at("after_quality").get<int>(), j2.at("counts").at("after_lasso").get<int>());
    const fss::Mesh mesh2 = fss::readMesh(step2);
    expectInvariants(mesh2, "after scan 2");
    EXPECT_EQ(scanIds(mesh2), (std::set<std::int32_t>{-1, 0, 1}));

    const double v0 = fracValence6(original), v1 = fracValence6(mesh1), v2 = fracValence6(mesh2);
    std::printf("%s: valence-6 fraction %.3f -> %.3f -> %.3f, faces %u -> %u -> %u\n", name.c_str(), v0, v1,
                v2, unsigned(original.number_of_faces()), unsigned(mesh1.number_of_faces()),
                unsigned(mesh2.number_of_faces()));
    EXPECT_GT(v1, v0 + 0.02);
    EXPECT_GT(v2, v0 + 0.02);
    // The tool's own metric agrees.
    const auto info = remesh({"info", step2, "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NEAR(nlohmann::json::parse(info.out).at("frac_valence6_interior").get<double>(), v2, 1e-12);
}

} // namespace

// On the square pixel lattice: with the default adaptive lattice the lattice-angle mask (35°) already
// leaves to the iso scan all of the surface where it is the better one (elephant -y: 8268 samples after the
// lasso, 8268 after the quality mask), so the quality mask would drop nothing here (issue #20).
TEST(CliScanInto, ChainedScansOfElephantKeepInvariantsAndRaiseRegularity) {
    chainTwoScans("elephant", "iso", "-y", "256", {"--lattice", "square", "--min-lattice-angle", "0"});
}

// On the default lattice (adaptive, 35° mask).

TEST(CliScanInto, ChainedScansOfCouplingdownKeepInvariantsAndRaiseRegularity) {
    chainTwoScans("couplingdown", "iso", "+x", "160");
}

TEST(CliScanInto, FishboneScanStitchesToo) {
    const std::string input = meshPath("fandisk.off").string();
    const std::string step1 = tmpPath("cli_scan_into/fandisk_1.ply").string();
    const std::string step2 = tmpPath("cli_scan_into/fandisk_2.ply").string();
    const auto r1 =
        remesh({"scan", input, "--into", input, "-o", step1, "--view", "iso", "--resolution", "128"});
    ASSERT_EQ(r1.exitCode, 0) << r1.err;
    EXPECT_NE(r1.out.find("stitched into"), std::string::npos) << r1.out;
    const auto r2 = remesh({"scan", input, "--into", step1, "-o", step2, "--view", "iso", "--fishbone",
                            "seed=0.4,0.55;dir=min;h=3", "--json"});
    ASSERT_EQ(r2.exitCode, 0) << r2.err;
    const auto j = nlohmann::json::parse(r2.out);
    EXPECT_EQ(j.at("grid"), "fishbone");
    EXPECT_GT(j.at("stitch").at("faces_added").get<int>(), 100);
    const fss::Mesh mesh2 = fss::readMesh(step2);
    EXPECT_EQ(mesh2.number_of_faces(), j.at("result").at("faces").get<std::size_t>());
    expectInvariants(mesh2, "fishbone into fandisk");
    EXPECT_TRUE(scanIds(mesh2).count(1));
}

TEST(CliScanInto, FailuresSaySoAndWriteNothing) {
    const std::string input = meshPath("elephant.off").string();
    const auto out = tmpPath("cli_scan_into/never.ply");
    std::filesystem::remove(out);
    // CURRENT missing.
    expectCleanFailure(
        remesh({"scan", input, "--into", tmpPath("cli_scan_into/missing.ply").string(), "-o", out.string()}),
        "missing.ply");
    EXPECT_FALSE(std::filesystem::exists(out));
    // CURRENT not a mesh.
    const auto bad = tmpPath("cli_scan_into/bad.off");
    { std::ofstream(bad) << "this is not a mesh\n"; }
    expectCleanFailure(remesh({"scan", input, "--into", bad.string(), "-o", out.string()}), "bad.off");
    EXPECT_FALSE(std::filesystem::exists(out));
    // Nothing stitched: CURRENT (a small tetrahedron) is not where the elephant's patch lies.
    expectCleanFailure(
        remesh({"scan", input, "--into", meshPath("tetrahedron.off").string(), "-o", out.string()}),
        "stitched");
    EXPECT_FALSE(std::filesystem::exists(out));
    // Unsupported output extension: a usage error before anything is read.
    const auto usage =
        remesh({"scan", input, "--into", input, "-o", tmpPath("cli_scan_into/x.abc").string()});
    EXPECT_EQ(usage.exitCode, 2) << usage.err;
}

} // namespace fss_cli_scan_into_test
