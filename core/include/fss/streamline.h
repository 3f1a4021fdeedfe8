#pragma once
/// \file streamline.h
/// 2D streamlines of a screen direction field and polylines resampled at constant spacing — the tracing
/// step of the fishbone grid (DESIGN.md §1: "the backbone is the streamline through it along one principal
/// direction, traced in 2D. Samples are placed on it at constant arc length h. Ribs are streamlines from
/// those samples along the other direction.").
///
/// Integration: classical Runge–Kutta (RK4) with sub-pixel steps on the bilinearly interpolated line field
/// (DirectionField::sample). Sign continuity: every evaluated direction is flipped to agree with the
/// previous step's direction, so a line field is followed like a vector field without ever reversing.
/// A step that leaves the admissible region is retried with half the step down to `minStep`, so a
/// streamline ends within `minStep` of the background, the image border or the region mask.

#include "fss/direction_field.h"

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

namespace fss {

/// A 2D polyline in screen coordinates (pixels, origin top-left, y down).
using Polyline2 = std::vector<Eigen::Vector2d>;

/// Why one half of a streamline ended.
enum class StreamlineStop {
    MaxLength,     ///< reached StreamlineOptions::maxLength (the end lies exactly at that length)
    Background,    ///< the next step would enter a pixel without a direction
    ImageBorder,   ///< the next step would leave the image
    OutsideRegion, ///< the next step would leave StreamlineOptions::insideRegion
    LowAnisotropy, ///< the direction becomes ill-defined (anisotropy < minAnisotropy)
    SharpTurn,     ///< consecutive steps turn by more than maxTurnDeg (a singularity or a field seam)
    Closed,        ///< the streamline came back to its seed (a closed integral curve)
    StepLimit      ///< the safety limit on the number of steps was hit
};

/// What a streamline does where the direction field's anisotropy falls below the threshold.
enum class LowAnisotropyPolicy {
    Stop,            ///< end the streamline there (StreamlineStop::LowAnisotropy)
    ContinueStraight ///< keep the previous direction until the field is defined again (crosses flat
                     ///< or umbilic regions, e.g. the planar faces beside a rounded crease): pixels
                     ///< below minAnisotropy carry the previous direction (DirectionField::sample's
                     ///< straightBelow)
};

/// Options of traceStreamline(). Lengths in pixels.
struct StreamlineOptions {
    /// RK4 step: a quarter pixel resolves the bilinear field (whose values change per pixel) with an
    /// integration error far below the field's own interpolation error.
    double step = 0.25;
    /// Smallest step tried when a step fails (see the file comment); bounds how close a line ends to a
    /// border. Must be in (0, step].
    double minStep = 1.0 / 64.0;
    /// Largest length of each half (forward, backward) of the streamline; infinity = unbounded.
    double maxLength = std::numeric_limits<double>::infinity();
    /// Stop where the interpolated anisotropy falls below this (0 never stops). 0.05: only where the
    /// principal directions are essentially undefined (umbilics, flat regions).
    double minAnisotropy = 0.05;
    /// Below minAnisotropy: stop, or continue straight.
    LowAnisotropyPolicy lowAnisotropy = LowAnisotropyPolicy::Stop;
    /// Stop when two consecutive steps turn by more than this angle, degrees. With the default step
    /// 10° per quarter pixel is a radius of curvature under 1.5 pixels: a singularity or a seam of the
    /// field, not a feature to follow.
    double maxTurnDeg = 10.0;
    /// Optional region mask: a position p is admissible when insideRegion(p) is true. Empty = no mask.
    std::function<bool(const Eigen::Vector2d&)> insideRegion{};
    /// Optional attracting curve (the fishbone scan passes the screen image of the reference's sharp creases
    /// to a traced backbone): after each accepted step (but the one ending at maxLength), attractor(q,
    /// heading) may return a point to move the step's end q to — the nearest point of a crease running
    /// along `heading` (unit). The moved end must lie where the field is defined, else q is kept. A
    /// streamline alone has no restoring force towards a crease: where the field on either side turns away
    /// from it, every small error grows, and it leaves the crease (see fishbone_scan.h).
    std::function<std::optional<Eigen::Vector2d>(const Eigen::Vector2d& q, const Eigen::Vector2d& heading)>
        attractor{};
    /// Safety limit on the number of accepted steps per half.
    std::size_t maxSteps = 1'000'000;

    /// Checks the ranges: step finite and > 0, minStep in (0, step], maxLength > 0 (infinity allowed),
    /// minAnisotropy in [0, 1], maxTurnDeg finite and > 0, maxSteps in [1, 2^63 − 1].
    /// \throw InvalidOptionError naming the field ("StreamlineOptions::step must be a positive finite
    ///        number, not 0.").
    void validate() const;
};

/// One half of a streamline: from the seed in one direction.
struct StreamlineHalf {
    Polyline2 points;  ///< points[0] is the seed
    double length = 0; ///< arc length of the polyline
    StreamlineStop stop = StreamlineStop::MaxLength;
};

/// A streamline traced both ways from a seed: points run from the backward end through the seed
/// (points[seedIndex]) to the forward end.
struct Streamline {
    Polyline2 points;
    std::size_t seedIndex = 0;
    StreamlineStop backwardStop = StreamlineStop::MaxLength;
    StreamlineStop forwardStop = StreamlineStop::MaxLength;
    /// Forward half (seed first) and backward half (seed first) as separate polylines.
    Polyline2 forward() const;
    Polyline2 backward() const;
};

/// Traces one half of a streamline from \p seed, starting along the field direction aligned with
/// \p initialDirection (RK4, sign continuity, stops as documented in StreamlineStop).
/// \pre field.sample(seed, initialDirection) exists; initialDirection non-zero and finite;
///      0 < minStep ≤ step; maxLength > 0.
/// \throw InvalidInputError when a precondition is violated (the message names the seed).
StreamlineHalf traceStreamlineHalf(const DirectionField& field, const Eigen::Vector2d& seed,
                                   const Eigen::Vector2d& initialDirection,
                                   const StreamlineOptions& options = {});

/// Where one half of a streamline starts (traceHalvesInLockstep).
struct HalfStart {
    Eigen::Vector2d seed;
    Eigen::Vector2d initialDirection;
};

/// Traces several halves on the calling thread in lockstep, one RK4 stage of each after the other: each
/// result is exactly traceStreamlineHalf's for its start (in the order of \p starts), in less time than
/// tracing them one after the other, because the halves' independent field evaluations overlap in the
/// processor (the two halves of two neighbouring ribs, for instance).
/// \pre and \throw as traceStreamlineHalf, for every start (checked before any tracing).
std::vector<StreamlineHalf> traceHalvesInLockstep(const DirectionField& field,
                                                  const std::vector<HalfStart>& starts,
                                                  const StreamlineOptions& options = {});

/// Traces a streamline both ways from \p seed (DESIGN.md §1: the backbone through the picked point, the
/// ribs through the backbone samples). "Forward" is the field direction at the seed aligned with
/// \p preferredDirection (default: the seed pixel's stored direction); when the forward half closes on
/// itself the backward half is empty.
/// \pre as traceStreamlineHalf; the seed lies on a valid pixel of the field.
/// \throw InvalidInputError when a precondition is violated.
Streamline traceStreamline(const DirectionField& field, const Eigen::Vector2d& seed,
                           const StreamlineOptions& options = {},
                           const Eigen::Vector2d& preferredDirection = Eigen::Vector2d::Zero());

/// Arc length of a polyline.
double polylineLength(const Polyline2& line);

/// Resamples \p line at constant spacing \p h (DESIGN.md §1: "samples at constant arc length h"):
/// out[0] = line[0], and each further sample is the first point further along \p line at Euclidean
/// distance exactly h from the previous sample. Every edge of the result has length h (to round-off), so
/// the result's arc length is h·(size − 1); on a polyline much finer than h this equals the arc length
/// along \p line to O(h³κ²). The tail shorter than h is dropped.
/// \pre h > 0 and finite. \throw InvalidInputError otherwise. An empty line gives an empty result.
Polyline2 resampleAtSpacing(const Polyline2& line, double h);

/// Resamples both halves of a streamline from its seed (the seed stays a sample, at the same
/// seedIndex semantics): samples at ±h, ±2h, … from the seed.
/// \pre h > 0 and finite. \throw InvalidInputError otherwise.
Streamline resampleAtSpacing(const Streamline& line, double h);

} // namespace fss
