// validate() of the fishbone options (streamline.h, fishbone.h, fishbone_scan.h): the one statement of
// their ranges, used by the tracing, by scanFishbonePatch and by the session-file reader.
#include "fishbone/fishbone_options.h"

#include "fss/fishbone.h"
#include "fss/fishbone_scan.h"
#include "fss/streamline.h"

#include "base/option_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace fss {
namespace {

using detail::optionNumber;

std::string pointText(const Eigen::Vector2d& p) {
    return "(" + optionNumber(p.x()) + ", " + optionNumber(p.y()) + ")";
}

// Three significant digits, as scanFishbonePatch's other messages give the spacing.
std::string short3(double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3g", x);
    return buf;
}

std::string imageText(const Camera& c) {
    return std::to_string(c.width) + "x" + std::to_string(c.height);
}

void finitePoint(const detail::OptionCheck& check, const std::string& field, const Eigen::Vector2d& p) {
    if (!p.allFinite()) check.fail(field, "must be a finite point, not " + pointText(p));
}

void finitePoints(const detail::OptionCheck& check, const std::string& field,
                  const std::vector<Eigen::Vector2d>& points) {
    for (std::size_t i = 0; i < points.size(); ++i)
        finitePoint(check, field + "[" + std::to_string(i) + "]", points[i]);
}

} // namespace

void StreamlineOptions::validate() const {
    const detail::OptionCheck check("StreamlineOptions");
    check.positive("step", step);
    if (!(minStep > 0 && minStep <= step))
        check.fail("minStep",
                   "must be in (0, step] = (0, " + optionNumber(step) + "], not " + optionNumber(minStep));
    if (!(maxLength > 0))
        check.fail("maxLength", "must be positive (infinity: unbounded), not " + optionNumber(maxLength));
    check.inRange("minAnisotropy", minAnisotropy, 0, 1, false, false);
    check.positive("maxTurnDeg", maxTurnDeg);
    check.count("maxSteps", maxSteps, 1);
}

void FishboneOptions::validate() const {
    const char* owner = "FishboneOptions";
    const detail::OptionCheck check(owner);
    check.positive("spacing", spacing);
    check.inRange("minRibGap", minRibGap, 0, 1, false, true);
    check.inRange("maxRibTurnDeg", maxRibTurnDeg, 0, 180, true, false);
    if (maxRibAspect != 0) check.inRange("maxRibAspect", maxRibAspect, 1, 100, false, false);
    check.inRange("minFaceAngleDeg", minFaceAngleDeg, 0, 60, false, true);
    check.inRange("peelRibEndsDeg", peelRibEndsDeg, 0, 60, false, true);
    check.intAtLeast("minComponentFaces", minComponentFaces, 0);
    detail::nestedOptions(owner, "backboneTracing.", [&] { backboneTracing.validate(); });
    detail::nestedOptions(owner, "ribTracing.", [&] { ribTracing.validate(); });
}

void FishboneParams::validate(const Camera& scanCamera) const {
    const char* owner = "FishboneParams";
    const detail::OptionCheck check(owner);
    const double maxH = std::min(scanCamera.width, scanCamera.height) / 4.0;
    if (!(std::isfinite(spacing) && spacing >= 0.5 && spacing <= maxH))
        check.fail("spacing", "must be in [0.5, " + optionNumber(maxH) + "] for a " + imageText(scanCamera) +
                                  " scan: the spacing h = " + short3(spacing) + " pixels is outside it");
    if (seed) finitePoint(check, "seed", *seed);
    if (drawnBackbone.empty() && !seed) check.fail("seed", "must be given when there is no drawn backbone");
    if (drawnBackbone.size() == 1)
        check.fail("drawnBackbone", "must be empty or have at least 2 points, not 1");
    finitePoints(check, "drawnBackbone", drawnBackbone);
    if (drawnBackbone.empty()) {
        const Eigen::Vector2d& p = *seed;
        if (!(p.x() >= 0 && p.y() >= 0 && p.x() < scanCamera.width && p.y() < scanCamera.height))
            check.fail("seed",
                       "must lie inside the " + imageText(scanCamera) + " scan image, not " + pointText(p));
    }
    finitePoints(check, "keyRibs", keyRibs);
    for (std::size_t i = 0; i < drawnKeyRibs.size(); ++i) {
        const std::string field = "drawnKeyRibs[" + std::to_string(i) + "]";
        if (drawnKeyRibs[i].size() < 2)
            check.fail(field, "must have at least 2 points, not " + std::to_string(drawnKeyRibs[i].size()));
        finitePoints(check, field, drawnKeyRibs[i]);
    }
    const std::size_t keyRibCount = keyRibs.size() + drawnKeyRibs.size();
    if (keyRibCount == 1)
        check.fail(
            drawnKeyRibs.empty() ? "keyRibs" : "drawnKeyRibs",
            "must give, with the other key-ribs, none or at least two key-ribs to blend between, not 1");
    detail::nestedOptions(owner, "tracing.", [&] { tracing.validate(); });
    check.inRange("minSeedAnisotropy", minSeedAnisotropy, 0, 1, false, false);
    check.inRange("creaseAngleDeg", creaseAngleDeg, 0, 180, false, true);
    check.positive("creaseSnapRadius", creaseSnapRadius);
    check.intAtLeast("raycast.rings", raycast.rings, 0);
    detail::validateSamplingFactor(scanCamera, *this);
}

namespace detail {

void validateSamplingFactor(const Camera& scan, const FishboneParams& fb) {
    const OptionCheck check("FishboneParams");
    const int k = fb.samplingFactor;
    if (k < 0)
        check.fail("samplingFactor",
                   "must be at least 0 (0 chooses it automatically), not " + std::to_string(k));
    if (k == 0) return;
    if (scan.width % k != 0 || scan.height % k != 0)
        check.fail("samplingFactor", "must divide the scan image's width and height: the sampling factor " +
                                         std::to_string(k) + " does not divide the " + imageText(scan) +
                                         " scan image");
    if (!(double(k) <= fb.spacing))
        check.fail("samplingFactor", "must be at most the spacing h: the sampling factor " +
                                         std::to_string(k) +
                                         " exceeds the spacing h = " + short3(fb.spacing) +
                                         " pixels (the sampling image needs at least one pixel per sample)");
}

} // namespace detail
} // namespace fss
