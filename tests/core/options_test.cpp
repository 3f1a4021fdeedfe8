// Options validate themselves (issue 18): the defaults validate, and every field out of its range is refused
// with one sentence naming the struct, the field and the range — the same sentence whether the API or the
// session-file reader (which names the JSON path instead, session_file_test.cpp) calls validate().
#include "fss/auto_remesh.h"
#include "fss/curvature.h"
#include "fss/error.h"
#include "fss/fishbone.h"
#include "fss/fishbone_scan.h"
#include "fss/mask.h"
#include "fss/scan.h"
#include "fss/scan_pipeline.h"
#include "fss/stitch.h"
#include "fss/streamline.h"
#include "fss/triangulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// One field out of range: the edit of a valid struct and the sentence it must give.
template <class Options> struct Case {
    std::string field; // as InvalidOptionError::field() names it
    std::function<void(Options&)> edit;
    std::string requirement; // "must be in [0, 30), not 45"
};

// "Owner::field requirement" (appended piece by piece: GCC 12 warns falsely about chains of operator+).
std::string sentence(const char* owner, const std::string& field, const std::string& requirement,
                     const char* end = "") {
    std::string s = owner;
    s.append("::").append(field).append(" ").append(requirement).append(end);
    return s;
}

// Applies every case to \p valid and checks the error: its type, field(), requirement() and what().
template <class Options>
void expectRefused(const char* owner, const Options& valid, const std::vector<Case<Options>>& cases,
                   const std::function<void(const Options&)>& validate) {
    ASSERT_NO_THROW(validate(valid));
    for (const Case<Options>& c : cases) {
        SCOPED_TRACE(sentence(owner, c.field, c.requirement));
        Options o = valid;
        c.edit(o);
        try {
            validate(o);
            ADD_FAILURE() << "no error";
        } catch (const fss::InvalidOptionError& e) {
            EXPECT_EQ(e.owner(), owner);
            EXPECT_EQ(e.field(), c.field);
            EXPECT_EQ(e.requirement(), c.requirement);
            EXPECT_EQ(std::string(e.what()), sentence(owner, c.field, c.requirement, "."));
        }
    }
}

template <class Options> void expectRefused(const char* owner, const std::vector<Case<Options>>& cases) {
    expectRefused<Options>(owner, Options{}, cases, [](const Options& o) { o.validate(); });
}

TEST(Options, DefaultsValidate) {
    EXPECT_NO_THROW(fss::StitchOptions{}.validate());
    EXPECT_NO_THROW(fss::AutoOptions::defaultStitch().validate());
    EXPECT_NO_THROW(fss::ScanOptions{}.validate());
    EXPECT_NO_THROW(fss::QualityMaskOptions{}.validate());
    EXPECT_NO_THROW(fss::TriangulateOptions{}.validate());
    EXPECT_NO_THROW(fss::ScanParams{}.validate());
    EXPECT_NO_THROW(fss::StreamlineOptions{}.validate());
    EXPECT_NO_THROW(fss::FishboneOptions{}.validate());
    EXPECT_NO_THROW(fss::FishboneParams::defaultTracing().validate());
    fss::FishboneParams fishbone; // a seed is the one thing the defaults cannot give
    fishbone.seed = Eigen::Vector2d(128, 128);
    EXPECT_NO_THROW(fishbone.validate(fss::Camera{}));
    EXPECT_NO_THROW(fss::CurvatureOptions{}.validate());
    EXPECT_NO_THROW(fss::AutoOptions{}.validate());
}

TEST(Options, StitchOptionsNameTheField) {
    using O = fss::StitchOptions;
    expectRefused<O>(
        "StitchOptions",
        {
            {"seamRings", [](O& o) { o.seamRings = -1; }, "must be at least 0, not -1"},
            {"collapseEdgeRatio", [](O& o) { o.collapseEdgeRatio = 0.5; }, "must be in [0, 0.5), not 0.5"},
            {"collapseEdgeRatio", [](O& o) { o.collapseEdgeRatio = -0.1; }, "must be in [0, 0.5), not -0.1"},
            {"seamGrading", [](O& o) { o.seamGrading = kInf; },
             "must be a finite number of at least 0, not inf"},
            {"minAngleFloorDeg", [](O& o) { o.minAngleFloorDeg = 45; }, "must be in [0, 30), not 45"},
            {"minAngleFloorDeg", [](O& o) { o.minAngleFloorDeg = kNaN; }, "must be in [0, 30), not nan"},
            {"outsideMinAngleFloorDeg", [](O& o) { o.outsideMinAngleFloorDeg = 30; },
             "must be in [0, 30), not 30"},
            {"maxViewAngleDeg", [](O& o) { o.maxViewAngleDeg = 90; }, "must be in (0, 90), not 90"},
            {"maxViewAngleDeg", [](O& o) { o.maxViewAngleDeg = 0; }, "must be in (0, 90), not 0"},
            {"maxNormalChangeDeg", [](O& o) { o.maxNormalChangeDeg = 181; }, "must be in [0, 180], not 181"},
            {"maxGapRatio", [](O& o) { o.maxGapRatio = 0; }, "must be a positive finite number, not 0"},
            {"maxTrimRounds", [](O& o) { o.maxTrimRounds = -2; }, "must be at least 0, not -2"},
            {"minComponentFaces", [](O& o) { o.minComponentFaces = std::size_t(1) << 63; },
             "must be in [0, 9223372036854775807], not 9223372036854775808"},
        });
    // The edges themselves.
    O o;
    o.minAngleFloorDeg = std::nextafter(30.0, 0.0);
    o.outsideMinAngleFloorDeg = std::nextafter(30.0, 0.0);
    o.collapseEdgeRatio = std::nextafter(0.5, 0.0);
    o.maxViewAngleDeg = std::nextafter(90.0, 0.0);
    o.maxNormalChangeDeg = 180;
    o.seamRings = o.maxTrimRounds = 0;
    EXPECT_NO_THROW(o.validate());
}

TEST(Options, ScanOptionsNameTheField) {
    using S = fss::ScanOptions;
    expectRefused<S>("ScanOptions", {
                                        {"qualityAngleLimitDeg", [](S& o) { o.qualityAngleLimitDeg = 90; },
                                         "must be in (0, 90), not 90"},
                                        {"maxSnapFootprints", [](S& o) { o.maxSnapFootprints = -1; },
                                         "must be a finite number of at least 0, not -1"},
                                    });
    using Q = fss::QualityMaskOptions;
    expectRefused<Q>("QualityMaskOptions",
                     {
                         {"margin", [](Q& o) { o.margin = 1; }, "must be in [0, 1), not 1"},
                         {"searchRings", [](Q& o) { o.searchRings = -1; }, "must be at least 0, not -1"},
                     });
    using T = fss::TriangulateOptions;
    expectRefused<T>("TriangulateOptions",
                     {
                         {"maxEdgeFootprints", [](T& o) { o.maxEdgeFootprints = 0; },
                          "must be a positive finite number, not 0"},
                         {"maxSamplingAngleDeg", [](T& o) { o.maxSamplingAngleDeg = 90.5; },
                          "must be in (0, 90], not 90.5"},
                     });
    // ScanParams names its members' fields as its own.
    using P = fss::ScanParams;
    expectRefused<P>(
        "ScanParams",
        {
            {"erodeRadius", [](P& p) { p.erodeRadius = -1; }, "must be in [0, 1024], not -1"},
            {"dilateRadius", [](P& p) { p.dilateRadius = 1025; }, "must be in [0, 1024], not 1025"},
            {"scan.qualityAngleLimitDeg", [](P& p) { p.scan.qualityAngleLimitDeg = 0; },
             "must be in (0, 90), not 0"},
            {"quality.margin", [](P& p) { p.quality.margin = 1.5; }, "must be in [0, 1), not 1.5"},
            {"triangulate.maxEdgeFootprints", [](P& p) { p.triangulate.maxEdgeFootprints = -3; },
             "must be a positive finite number, not -3"},
        });
    // The camera and the lasso keep their own sentences.
    P p;
    p.camera.width = 0;
    EXPECT_THROW(p.validate(), fss::InvalidInputError);
    p = {};
    p.lasso = fss::Lasso{{{0, 0}, {1, 1}}};
    EXPECT_THROW(p.validate(), fss::InvalidInputError);
}

TEST(Options, FishboneOptionsNameTheField) {
    using L = fss::StreamlineOptions;
    expectRefused<L>(
        "StreamlineOptions",
        {
            {"step", [](L& o) { o.step = 0; }, "must be a positive finite number, not 0"},
            {"minStep", [](L& o) { o.minStep = 0.5; }, "must be in (0, step] = (0, 0.25], not 0.5"},
            {"maxLength", [](L& o) { o.maxLength = 0; }, "must be positive (infinity: unbounded), not 0"},
            {"minAnisotropy", [](L& o) { o.minAnisotropy = 1.5; }, "must be in [0, 1], not 1.5"},
            {"maxTurnDeg", [](L& o) { o.maxTurnDeg = kInf; }, "must be a positive finite number, not inf"},
            {"maxSteps", [](L& o) { o.maxSteps = 0; }, "must be in [1, 9223372036854775807], not 0"},
        });
    using F = fss::FishboneOptions;
    expectRefused<F>(
        "FishboneOptions",
        {
            {"spacing", [](F& o) { o.spacing = -1; }, "must be a positive finite number, not -1"},
            {"backboneTracing.step", [](F& o) { o.backboneTracing.step = kNaN; },
             "must be a positive finite number, not nan"},
            {"ribTracing.minAnisotropy", [](F& o) { o.ribTracing.minAnisotropy = -0.5; },
             "must be in [0, 1], not -0.5"},
        });

    fss::Camera camera; // 256 x 256
    fss::FishboneParams valid;
    valid.seed = Eigen::Vector2d(100.5, 120.25);
    using P = fss::FishboneParams;
    expectRefused<P>(
        "FishboneParams", valid,
        {
            {"spacing", [](P& p) { p.spacing = 65; },
             "must be in [0.5, 64] for a 256x256 scan: the spacing h = 65 pixels is outside it"},
            {"spacing", [](P& p) { p.spacing = 0.25; },
             "must be in [0.5, 64] for a 256x256 scan: the spacing h = 0.25 pixels is outside it"},
            {"seed", [](P& p) { p.seed.reset(); }, "must be given when there is no drawn backbone"},
            {"seed", [](P& p) { p.seed = Eigen::Vector2d(256, 3); },
             "must lie inside the 256x256 scan image, not (256, 3)"},
            {"seed", [](P& p) { p.seed = Eigen::Vector2d(kNaN, 3); }, "must be a finite point, not (nan, 3)"},
            {"drawnBackbone", [](P& p) { p.drawnBackbone = {Eigen::Vector2d(1, 2)}; },
             "must be empty or have at least 2 points, not 1"},
            {"drawnBackbone[1]",
             [](P& p) {
                 p.drawnBackbone = {Eigen::Vector2d(1, 2), Eigen::Vector2d(kInf, 2)};
             },
             "must be a finite point, not (inf, 2)"},
            {"keyRibs", [](P& p) { p.keyRibs = {Eigen::Vector2d(100, 120)}; },
             "must give, with the other key-ribs, none or at least two key-ribs to blend between, not 1"},
            {"keyRibs[0]",
             [](P& p) {
                 p.keyRibs = {Eigen::Vector2d(kNaN, 120), Eigen::Vector2d(100, 130)};
             },
             "must be a finite point, not (nan, 120)"},
            {"drawnKeyRibs[0]",
             [](P& p) {
                 p.drawnKeyRibs = {{Eigen::Vector2d(1, 2)}, {Eigen::Vector2d(3, 4), Eigen::Vector2d(5, 6)}};
             },
             "must have at least 2 points, not 1"},
            {"tracing.spacing", [](P& p) { p.tracing.spacing = 0; },
             "must be a positive finite number, not 0"},
            {"tracing.backboneTracing.minStep", [](P& p) { p.tracing.backboneTracing.minStep = 0; },
             "must be in (0, step] = (0, 0.5], not 0"},
            {"tracing.ribTracing.maxTurnDeg", [](P& p) { p.tracing.ribTracing.maxTurnDeg = 0; },
             "must be a positive finite number, not 0"},
            {"minSeedAnisotropy", [](P& p) { p.minSeedAnisotropy = 2; }, "must be in [0, 1], not 2"},
            {"creaseAngleDeg", [](P& p) { p.creaseAngleDeg = 180; }, "must be in [0, 180), not 180"},
            {"creaseSnapRadius", [](P& p) { p.creaseSnapRadius = 0; },
             "must be a positive finite number, not 0"},
            {"raycast.rings", [](P& p) { p.raycast.rings = -1; }, "must be at least 0, not -1"},
            {"samplingFactor", [](P& p) { p.samplingFactor = -1; },
             "must be at least 0 (0 chooses it automatically), not -1"},
            {"samplingFactor", [](P& p) { p.samplingFactor = 3; },
             "must divide the scan image's width and height: the sampling factor 3 does not divide the "
             "256x256 "
             "scan image"},
            {"samplingFactor", [](P& p) { p.samplingFactor = 8; },
             "must be at most the spacing h: the sampling factor 8 exceeds the spacing h = 4 pixels (the "
             "sampling image needs at least one pixel per sample)"},
        },
        [&](const P& p) { p.validate(camera); });
    // A drawn backbone needs no seed, and then the seed may lie anywhere (it is not used).
    P drawn;
    drawn.drawnBackbone = {{10, 10}, {200, 200}};
    EXPECT_NO_THROW(drawn.validate(camera));
    drawn.seed = Eigen::Vector2d(-5, 1000);
    EXPECT_NO_THROW(drawn.validate(camera));
}

TEST(Options, CurvatureOptionsNameTheField) {
    using C = fss::CurvatureOptions;
    expectRefused<C>("CurvatureOptions",
                     {
                         {"jetDegree", [](C& o) { o.jetDegree = 4; }, "must be 2 or 3, not 4"},
                         {"minPoints", [](C& o) { o.minPoints = 5; }, "must be at least 6, not 5"},
                         {"maxRings", [](C& o) { o.maxRings = 0; }, "must be at least 1, not 0"},
                         {"anisotropyEpsilon", [](C& o) { o.anisotropyEpsilon = 0; },
                          "must be a positive finite number, not 0"},
                     });
}

TEST(Options, AutoOptionsNameTheField) {
    using A = fss::AutoOptions;
    expectRefused<A>(
        "AutoOptions",
        {
            {"edgeLength", [](A& o) { o.edgeLength = -1; }, "must be a finite number of at least 0, not -1"},
            {"servedAngleDeg", [](A& o) { o.servedAngleDeg = 81; }, "must be in (0, 80], not 81"},
            {"maxSamplingAngleDeg", [](A& o) { o.maxSamplingAngleDeg = 40; }, "must be in (40, 85], not 40"},
            {"followUpMaxSamplingAngleDeg", [](A& o) { o.followUpMaxSamplingAngleDeg = 0; },
             "must be in (0, 85], not 0"},
            {"partitionSmoothing", [](A& o) { o.partitionSmoothing = -1; },
             "must be a finite number of at least 0, not -1"},
            {"minRegionArea", [](A& o) { o.minRegionArea = kNaN; },
             "must be a finite number of at least 0, not nan"},
            {"regionMarginPx", [](A& o) { o.regionMarginPx = 17; }, "must be in [0, 16], not 17"},
            {"regionMarginMaxSamplingAngleDeg", [](A& o) { o.regionMarginMaxSamplingAngleDeg = 86; },
             "must be in (0, 85], not 86"},
            {"regionFillPasses", [](A& o) { o.regionFillPasses = -1; }, "must be at least 0, not -1"},
            {"minViewAreaFraction", [](A& o) { o.minViewAreaFraction = 1.5; }, "must be in [0, 1], not 1.5"},
            {"coverageGoal", [](A& o) { o.coverageGoal = -0.5; }, "must be in [0, 1], not -0.5"},
            {"maxViews", [](A& o) { o.maxViews = 0; }, "must be at least 1, not 0"},
            {"followUpRounds", [](A& o) { o.followUpRounds = -1; }, "must be at least 0, not -1"},
            {"footprintRatio", [](A& o) { o.footprintRatio = 0.1; }, "must be in (0.1, 4], not 0.1"},
            {"featureAngleDeg", [](A& o) { o.featureAngleDeg = 180; }, "must be in [0, 180), not 180"},
            {"minFeatureLength", [](A& o) { o.minFeatureLength = -1; },
             "must be a finite number of at least 0, not -1"},
            {"fishboneBandWidth", [](A& o) { o.fishboneBandWidth = 0; },
             "must be a positive finite number, not 0"},
            {"morphologyRadius", [](A& o) { o.morphologyRadius = -1; }, "must be in [0, 1024], not -1"},
            {"flipSliversBelowDeg", [](A& o) { o.flipSliversBelowDeg = 60; }, "must be in [0, 60), not 60"},
            {"seamRelaxRounds", [](A& o) { o.seamRelaxRounds = -1; }, "must be at least 0, not -1"},
            {"seamRelaxMinAngleDeg", [](A& o) { o.seamRelaxMinAngleDeg = 60; }, "must be in [0, 60), not 60"},
            {"creaseSnapRounds", [](A& o) { o.creaseSnapRounds = -1; }, "must be at least 0, not -1"},
            {"repairSliversBelowDeg", [](A& o) { o.repairSliversBelowDeg = 60; },
             "must be in [0, 60), not 60"},
            {"stitch.minAngleFloorDeg", [](A& o) { o.stitch.minAngleFloorDeg = 30; },
             "must be in [0, 30), not 30"},
            {"qualityMargin", [](A& o) { o.qualityMargin = 1; }, "must be in [0, 1), not 1"},
        });
}

} // namespace
