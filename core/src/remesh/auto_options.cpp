// AutoOptions::validate (auto_remesh.h): the one statement of autoRemesh's option ranges.
#include "fss/auto_remesh.h"

#include "base/option_check.h"

namespace fss {

void AutoOptions::validate() const {
    const char* owner = "AutoOptions";
    const detail::OptionCheck check(owner);
    check.intRange("engine", int(engine), int(AutoEngine::V1), int(AutoEngine::V2));
    check.nonNegative("edgeLength", edgeLength);
    check.inRange("servedAngleDeg", servedAngleDeg, 0, 80, true, false);
    check.inRange("maxSamplingAngleDeg", maxSamplingAngleDeg, servedAngleDeg, 85, true, false);
    check.inRange("followUpMaxSamplingAngleDeg", followUpMaxSamplingAngleDeg, 0, 85, true, false);
    check.nonNegative("partitionSmoothing", partitionSmoothing);
    check.nonNegative("minRegionArea", minRegionArea);
    check.intRange("regionMarginPx", regionMarginPx, 0, 16);
    check.inRange("regionMarginMaxSamplingAngleDeg", regionMarginMaxSamplingAngleDeg, 0, 85, true, false);
    check.intAtLeast("regionFillPasses", regionFillPasses, 0);
    check.inRange("minViewAreaFraction", minViewAreaFraction, 0, 1, false, false);
    check.inRange("coverageGoal", coverageGoal, 0, 1, false, false);
    check.intAtLeast("maxViews", maxViews, 1);
    check.intAtLeast("followUpRounds", followUpRounds, 0);
    check.inRange("footprintRatio", footprintRatio, 0.1, 4, true, false);
    check.inRange("featureAngleDeg", featureAngleDeg, 0, 180, false, true);
    check.nonNegative("minFeatureLength", minFeatureLength);
    check.positive("fishboneBandWidth", fishboneBandWidth);
    check.intRange("morphologyRadius", morphologyRadius, 0, 1024);
    check.inRange("flipSliversBelowDeg", flipSliversBelowDeg, 0, 60, false, true);
    check.inRange("repairSliversBelowDeg", repairSliversBelowDeg, 0, 60, false, true);
    check.intAtLeast("seamRelaxRounds", seamRelaxRounds, 0);
    check.inRange("seamRelaxMinAngleDeg", seamRelaxMinAngleDeg, 0, 60, false, true);
    check.intAtLeast("creaseSnapRounds", creaseSnapRounds, 0);
    detail::nestedOptions(owner, "stitch.", [&] { stitch.validate(); });
    check.inRange("qualityMargin", qualityMargin, 0, 1, false, true);
}

} // namespace fss
