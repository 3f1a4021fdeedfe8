// validate() of the scan's options (scan.h, mask.h, triangulate.h, scan_pipeline.h): the one statement of
// their ranges, used by the scan functions and by the session-file reader.
#include "fss/mask.h"
#include "fss/scan.h"
#include "fss/scan_pipeline.h"
#include "fss/triangulate.h"

#include "base/option_check.h"

#include <string>

namespace fss {

void ScanOptions::validate() const {
    const detail::OptionCheck check("ScanOptions");
    check.inRange("qualityAngleLimitDeg", qualityAngleLimitDeg, 0, 90, true, true);
    check.nonNegative("maxSnapFootprints", maxSnapFootprints);
    if (lattice != Lattice::Triangular && lattice != Lattice::Square && lattice != Lattice::Adaptive)
        check.fail("lattice", "must be Triangular, Square or Adaptive, not " + std::to_string(int(lattice)));
    check.inRange("spacingPixels", spacingPixels, 0.25, 1024, false, false);
    check.nonNegative("spacingWorld", spacingWorld);
    check.inRange("minLatticeAngleDeg", minLatticeAngleDeg, 0, 60, false, true);
}

void QualityMaskOptions::validate() const {
    const detail::OptionCheck check("QualityMaskOptions");
    check.inRange("margin", margin, 0, 1, false, true);
    check.intAtLeast("searchRings", searchRings, 0);
}

void TriangulateOptions::validate() const {
    const detail::OptionCheck check("TriangulateOptions");
    check.positive("maxEdgeFootprints", maxEdgeFootprints);
    check.inRange("maxSamplingAngleDeg", maxSamplingAngleDeg, 0, 90, true, false);
    check.inRange("minQuadAngleDeg", minQuadAngleDeg, 0, 90, false, true);
    check.inRange("minTriangleAngleDeg", minTriangleAngleDeg, 0, 60, false, true);
    check.intAtLeast("minComponentFaces", minComponentFaces, 0);
}

void ScanParams::validate() const {
    camera.validate();
    const char* owner = "ScanParams";
    const detail::OptionCheck check(owner);
    check.intRange("erodeRadius", erodeRadius, 0, 1024);
    check.intRange("dilateRadius", dilateRadius, 0, 1024);
    check.intRange("relaxIterations", relaxIterations, 0, 100);
    if (lasso) validateLasso(*lasso);
    detail::nestedOptions(owner, "scan.", [&] { scan.validate(); });
    detail::nestedOptions(owner, "quality.", [&] { quality.validate(); });
    detail::nestedOptions(owner, "triangulate.", [&] { triangulate.validate(); });
}

void validateScanParams(const ScanParams& params) {
    params.validate();
}

} // namespace fss
