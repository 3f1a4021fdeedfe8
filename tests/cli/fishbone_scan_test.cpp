// fss-remesh scan --fishbone: a feature-sensitive patch of fandisk from the command line (JSON counts and
// stage timings, the patch on the reference), and one clear sentence for each malformed --fishbone spec.
#include "run_process.h"
#include "test_data.h"

#include "fss/mesh_io.h"
#include "fss/metrics.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

// A namespace of its own: the CLI tests share one program (tests/CMakeLists.txt) and each has a remesh().
namespace fss_cli_fishbone_scan_test {

using fss::test::expectCleanFailure;
using fss::test::meshPath;
using fss::test::tmpPath;

namespace {

fss::test::ProcessResult remesh(const std::vector<std::string>& args) {
    return fss::test::runProcess(fss::test::remeshExe(), args, tmpPath("cli_fishbone"));
}

const std::string kFandisk = meshPath("fandisk.off").string();

} // namespace

TEST(CliFishbone, FishboneScanOfFandisk) {
    const auto out = tmpPath("cli_fishbone/fandisk_fishbone.ply");
    const auto r = remesh({"scan", kFandisk, "-o", out.string(), "--renderer", "cpu", "--fishbone",
                           "seed=0.4,0.55;dir=min;h=3", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("grid"), "fishbone");
    EXPECT_EQ(j.at("fishbone").at("h_pixels").get<double>(), 3.0);
    const auto& c = j.at("counts");
    EXPECT_GT(c.at("rows").get<int>(), 20);
    EXPECT_GT(c.at("rib_vertices").get<int>(), 1000);
    EXPECT_GT(c.at("patch_faces").get<int>(), 500);
    for (const char* stage :
         {"curvature", "direction_field", "tracing", "ray_casting", "masks", "triangulate", "total"})
        EXPECT_GT(j.at("timings_s").at(stage).get<double>(), 0.0) << stage;

    const fss::Mesh patch = fss::readMesh(out);
    EXPECT_EQ(patch.number_of_faces(), c.at("patch_faces").get<std::size_t>());
    const fss::Mesh ref = fss::readMesh(kFandisk);
    const fss::Metrics m = fss::computeMetrics(patch, {.selfIntersections = false, .reference = &ref});
    EXPECT_EQ(m.nonManifoldVertices, 0u);
    EXPECT_LE(*m.hausdorffToRefRel, 0.01); // chords of h = 3 pixels (a 1-pixel grid: 0.0025)

    // Key-rib mode and a hand-drawn backbone work too.
    const auto drawn = remesh({"scan", kFandisk, "-o", out.string(), "--renderer", "cpu", "--fishbone",
                               "backbone=0.3,0.5|0.4,0.55|0.5,0.6;h=3"});
    EXPECT_EQ(drawn.exitCode, 0) << drawn.err;
    // With continuous key-ribs (the default since session 18) this case left nothing to triangulate: the
    // first key-rib's point lies where the rib field is undefined (beside a flat face) and both its halves
    // came back empty. Now one starts straight (tracedKeyRib): measured 174 faces (96 with key-ribs at the
    // nearest sample, FishboneFandisk.DrawnBackboneWithKeyRibOnAFlatFace); 122 since session 20's default
    // peel of rib ends whose quads have triangles below 30° (FishboneOptions::peelRibEndsDeg).
    const auto keys = remesh({"scan", kFandisk, "-o", out.string(), "--renderer", "cpu", "--fishbone",
                              "backbone=0.3,0.5|0.4,0.55|0.5,0.6;h=3;keyribs=0.32,0.51|0.48,0.59", "--json"});
    ASSERT_EQ(keys.exitCode, 0) << keys.err;
    EXPECT_GT(nlohmann::json::parse(keys.out).at("counts").at("patch_faces").get<int>(), 110);
}

TEST(CliFishbone, MalformedSpecsFailWithOneSentence) {
    const auto out = tmpPath("cli_fishbone/bad.ply").string();
    auto scan = [&](const std::string& spec) {
        return remesh({"scan", kFandisk, "-o", out, "--renderer", "cpu", "--fishbone", spec});
    };
    expectCleanFailure(scan(""), "needs a seed=X,Y or a backbone");
    expectCleanFailure(scan("seed=0.5"), "needs two numbers x,y");
    expectCleanFailure(scan("seed=a,b"), "--fishbone");
    expectCleanFailure(scan("seed=0.4,0.55;dir=sideways"), "'sideways' is not one of min, max");
    expectCleanFailure(scan("seed=0.4,0.55;colour=red"), "key 'colour' is not one of");
    expectCleanFailure(scan("seed0.4,0.55"), "is not of the form key=value");
    expectCleanFailure(scan("seed=0.4,0.55;h=0"), "spacing h = 0 pixels is outside");
    expectCleanFailure(scan("seed=0.4,0.55;h=1000"), "spacing h = 1e+03 pixels is outside");
    expectCleanFailure(scan("seed=0.4,0.55;keyribs=0.4,0.5"), "at least two points");
    expectCleanFailure(scan("backbone=0.4,0.5"), "at least two points");
    expectCleanFailure(scan("seed=0.02,0.02"), "lies on the background");
    expectCleanFailure(scan("seed=0.5,0.5;sampling=1"), "flat or isotropic region");
    expectCleanFailure(scan("seed=0.4,0.55;sampling=x"), "of --fishbone sampling is not a finite number");
    expectCleanFailure(scan("seed=0.4,0.55;sampling=2.5"), "is not an integer from 0 (automatic) to 64");
    expectCleanFailure(scan("seed=0.4,0.55;h=4;sampling=3"), "sampling factor 3 does not divide the 256x256");
    expectCleanFailure(scan("seed=0.4,0.55;h=2;sampling=4"), "sampling factor 4 exceeds the spacing h = 2");
    expectCleanFailure(scan("seed=0.4,0.55;keyribs=0.4,0.45|0.4,0.65"),
                       "pixels from the backbone, farther than 2h");
}

} // namespace fss_cli_fishbone_scan_test
