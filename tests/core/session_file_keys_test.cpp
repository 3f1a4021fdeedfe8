// Session files: bad files give one sentence naming the file and the field; the keys later sessions added are
// optional, with the documented value when absent; options out of range name the field and its range.
#include "session_file_helpers.h"

using namespace session_file_test_helpers;

namespace {

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

} // namespace
