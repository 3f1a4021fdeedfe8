// StitchOptions::validate (stitch.h): the one statement of the stitch options' ranges, used by stitchPatch
// and by the session-file reader.
#include "fss/stitch.h"

#include "base/option_check.h"

namespace fss {

void StitchOptions::validate() const {
    const detail::OptionCheck check("StitchOptions");
    check.intAtLeast("seamRings", seamRings, 0);
    check.inRange("collapseEdgeRatio", collapseEdgeRatio, 0, 0.5, false, true);
    check.nonNegative("seamGrading", seamGrading);
    check.inRange("minAngleFloorDeg", minAngleFloorDeg, 0, 30, false, true);
    check.inRange("outsideMinAngleFloorDeg", outsideMinAngleFloorDeg, 0, 30, false, true);
    check.inRange("maxViewAngleDeg", maxViewAngleDeg, 0, 90, true, true);
    check.inRange("maxNormalChangeDeg", maxNormalChangeDeg, 0, 180, false, false);
    check.positive("maxGapRatio", maxGapRatio);
    check.intAtLeast("maxTrimRounds", maxTrimRounds, 0);
    check.count("minComponentFaces", minComponentFaces);
}

} // namespace fss
