#pragma once
// Internal (not installed): the part of FishboneParams::validate that fishboneSamplingFactor needs.
#include "fss/fishbone_scan.h"

namespace fss::detail {

/// Checks FishboneParams::samplingFactor for \p scan: 0 (automatic) or a divisor of its width and height
/// of at most the spacing h. \throw InvalidOptionError naming FishboneParams::samplingFactor.
void validateSamplingFactor(const Camera& scan, const FishboneParams& fishbone);

} // namespace fss::detail
