#pragma once
/// \file fishbone.h
/// The feature-sensitive ("fishbone") sampling grid in screen space (Vorsatz, Rössl, Kobbelt, Seidel, VMV
/// 2000; DESIGN.md §1 "Feature-sensitive (fishbone) grid").
///
///  * **Backbone**: the streamline through a picked point along one principal direction (traceBackbone),
///    or a hand-drawn interpolating spline (drawnBackbone), sampled every h.
///  * **Ribs**: from every backbone sample, the streamline along the other principal direction, both ways,
///    sampled every h (automaticFishbone / traceRib).
///  * **Key-ribs and blended ribs**: ribs only at a few backbone samples (traced or hand-drawn); every rib
///    in between is blended from its two neighbouring key-ribs by the paper's rule (blendRibShapes).
///  * The rib vertices form a rows × columns matrix, FishboneGrid: row r = the rib through backbone sample
///    r, column = index along the rib, the backbone at column `backboneColumn`. The caller casts a ray
///    through every present vertex to make a SampleGrid (DESIGN.md §1, last step).
///
/// Sides: a rib's *positive* half leaves the backbone towards n = (−t.y, t.x), t the backbone's screen
/// tangent (with y pointing down this is the right-hand side of the backbone as seen on the screen); it
/// fills the columns above backboneColumn, the negative half those below.
///
/// **Rib shapes and the blending rule.** One half of a rib with vertices p0 (on the backbone), p1, …, pn
/// and edges eᵢ = pᵢ₊₁ − pᵢ of length h is [E0, {αᵢ}]: the first edge E0 = e0 and the turning angles
/// αᵢ = ∠(eᵢ₋₁, eᵢ), i = 1 … n−1, each the signed angle (atan2(e×e', e·e'), counter-clockwise in the
/// (x, y) screen axes) from the previous edge direction to the next. Then, exactly,
///     p_k = p0 + E0 + h · Σ_{i=1}^{k−1} R(θ0) (cos Σ_{j≤i} αⱼ, sin Σ_{j≤i} αⱼ),
/// R(θ0) the rotation by the angle θ0 of E0 (the paper's formula written in E0's frame). Between key-ribs
/// [E0, {αᵢ}] and [F0, {βᵢ}], the blended rib for t ∈ [0, 1] starts at its own backbone sample p0, has
///     G0 = h · ((1−t)·E0 + t·F0) / |(1−t)·E0 + t·F0|,   γᵢ = (1−t)·αᵢ + t·βᵢ,
/// and the vertices above with (G0, γ). The negative half uses the same formula with its own first edge
/// and angles (the paper's "mirrored formula for k < 0"). Key-ribs of unequal length are blended up to
/// the shorter one (no turning angles are invented). t = (r − a)/(b − a) for the backbone sample r
/// between key-ribs at samples a < b (equal backbone spacing makes this the arc-length fraction).

#include "fss/direction_field.h"
#include "fss/streamline.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace fss {

/// Options of the fishbone construction. Lengths in pixels.
struct FishboneOptions {
    /// Sample spacing h along the backbone and the ribs (the grid's edge length in pixels). Must be > 0.
    double spacing = 4.0;
    /// Tracing of the backbone (streamline through the picked point).
    StreamlineOptions backboneTracing{};
    /// Tracing of the ribs (automatic mode and traced key-ribs). Its maxLength bounds each half-rib.
    StreamlineOptions ribTracing{};
    /// Key-rib mode: backbone samples before the first and after the last key-rib get a copy of the
    /// nearest key-rib's shape (true) or are left out of the grid (false).
    bool extendBeyondKeyRibs = true;
    /// A half-rib stops (its vertex and all beyond are left out of the grid) where it comes closer than
    /// minRibGap·h to the vertex of a neighbouring rib at the same position (ribs that pile up on the
    /// inner side of a curved backbone; issue #20). A fraction in [0, 1); 0 = no bound (the default here and
    /// in files written before it; 0.5 is the value measured in issue 20, not yet the default).
    double minRibGap = 0.0;
    /// A half-rib also stops where its edge turns more than this from the backbone's normal at its row
    /// (a rib that bends to follow the backbone makes slivers). Degrees in (0, 180]; 180 = no bound (the
    /// default here; 60 is the value measured in issue 20, not yet the default).
    double maxRibTurnDeg = 180.0;
    /// A half-rib also stops where its quad with a neighbouring rib is longer one way than this many times
    /// the other: the distance to the neighbouring rib's vertex at the same position against the rib's own
    /// edge there (ribs that fan out on the outer side of a curved backbone, or pile up on the inner side,
    /// make quads whose triangles are slivers even with right corners: 1:2 gives 26.6°). Measured on the
    /// surface when surfaceLength is set (isotropicRibs), else on the screen. 0 = no bound (the default;
    /// not yet stored in session files, issue 20), else ≥ 1.
    double maxRibAspect = 0.0;
    /// The fishbone scan stops a half-rib where an edge after its first crosses a visible crease of the
    /// reference (FishboneParams::creaseAngleDeg > 0; a rib running onto a neighbouring face of a CAD part).
    /// false here and in files written before it (true is not yet the default, issue 20).
    bool stopRibsAtCreases = false;
    /// With stopRibsAtCreases: the crease the backbone follows stops none of its ribs — a crease segment
    /// within 30° of the backbone's tangent and within 2h of the rib's backbone sample is not counted (on
    /// CAD meshes the backbone wanders about a pixel around the crease's screen image, and ribs stopped
    /// after one or two edges where their second edge crossed it back). false here and in files written
    /// before it.
    bool spareFollowedCrease = false;
    /// Loops of a traced backbone (issue 20): where the backbone comes back within h/2 of a point it passed
    /// at least 4h of arc length before, heading the same way, it is a closed curve: the loop through the
    /// seed is resampled at n = round(L/h) equal arcs (spacing L/n) and Backbone::closed is set, so that the
    /// grid's first and last rows are neighbours (FishboneGrid::closed) instead of a gap beside an overlap.
    /// A backbone that comes that close to itself otherwise (a loop not through its seed, or heading the
    /// other way) stops before it. On by default (issue 20: the lens torus top view closes with no seam
    /// gap, 26.8 → 24.9 % of faces below 30° with the face bound below); false in files written before it.
    bool closeLoops = true;
    /// Backbones on creases (issue 20): when the seed's surface point lies within 3h (pixel footprints) of a
    /// sharp crease of the reference (FishboneParams::creaseAngleDeg > 0), the fishbone scan runs the
    /// backbone along that crease's polyline, resampled every h footprints in 3D and stopped at its corners
    /// and branches, where it is hidden or leaves the image (a closed crease seen whole gives a closed
    /// backbone), instead of tracing the principal direction (which follows the noisy curvature of coarse
    /// CAD tessellations, 3–36 h off the crease). Its automatic ribs leave it perpendicular to the crease and
    /// walk straight on over the surface, stop at the next crease and are trimmed where their quads get
    /// thinner than 1:1.5 or neighbours closer than h/2; key-ribs are traced as on any backbone. On by
    /// default; false in files written before it.
    bool creaseBackbone = true;
    /// Key-ribs that move continuously (issue 20): the fishbone scan traces a picked key-rib from the point
    /// of the backbone nearest to it (Backbone::nearestPoint, tracedKeyRib), not from the nearest backbone
    /// sample, and blends the rows between key-ribs by their continuous positions (KeyRib::position), so
    /// that moving a key-rib by a pixel moves the grid by about as much instead of jumping a row (fandisk:
    /// 1.93 px for a 1 px move, 3.82 px without). On by default (session 18: the drawn case of
    /// tests/cli/fishbone_scan_test.cpp, whose first key-rib starts where the rib field is undefined, now
    /// gets a half from tracedKeyRib's straight start); off in files written before it (ribs at the nearest
    /// sample, as recorded).
    bool continuousKeyRibs = true;
    /// The fishbone scan stops a traced backbone, outwards from its seed, before its first edge that
    /// crosses a visible crease of the reference at more than 30° (FishboneParams::creaseAngleDeg > 0; a
    /// crease it runs along does not stop it). A closed backbone so cut is open. false here and in files
    /// written before it (issue 20).
    bool stopBackboneAtCreases = false;
    /// Ribs spaced on the surface (issue 20): the fishbone scan gives the traced ribs surfaceLength, so that
    /// each rib's vertices are as far apart on the surface as its backbone sample is from its neighbours
    /// (instead of h on the screen: on a surface slanted across the backbone the screen spacing makes quads
    /// up to 1/cos θ times longer one way than the other, and their triangles slivers). Automatic mode only
    /// (key-ribs are blended with the paper's constant h). false here and in files written before it.
    bool isotropicRibs = false;
    /// The fishbone scan drops both triangles of a grid quad where one of them has a 3D angle below this
    /// (TriangulateOptions::minTriangleAngleDeg; it also bounds the quad's corners, each a triangle's angle
    /// or the sum of two). Degrees in [0, 60); 0 = no bound (files written before it). 20 by default (issue
    /// 20: the smallest angle of every SliverTable patch ≥ 20°, from 0.0–18° with the paper's grid; the faces
    /// it drops are the slivers themselves, 5–60 % of a CAD patch's faces).
    double minFaceAngleDeg = 20.0;
    /// The fishbone scan drops every connected part of its patch with fewer faces than this
    /// (TriangulateOptions::minComponentFaces): the fragments left between crease stops and dropped
    /// quads. ≥ 0; 0 = none (files written before it); 24 by default (four rows of three quads).
    int minComponentFaces = 24;
    /// With a lasso (ScanParams::lasso), the fishbone scan clips every half-rib at it: each edge of a
    /// half-rib that crosses the lasso gets a vertex on the crossing (its outer vertex moved there when the
    /// crossing lies at least half the edge out, else its inner one, never the backbone sample), instead of
    /// ending at whichever whole sample is still inside. false by default and in files written before it:
    /// measured in SliverTable (session 20), it makes last edges of ½–1½ h whose trapezoids have triangles
    /// down to 20° (lens torus top with lasso 36.9° → 20.3°, side 5.4 → 6.6 % below 30°); with peelRibEndsDeg
    /// it is about even (side 0.0 %, top 32.5°), so the peel alone is the default.
    bool clipRibsAtLasso = false;
    /// The fishbone scan drops the end sample of a run of samples along a rib (at the lasso, a silhouette, a
    /// crease stop, a trimmed rib) where a triangle of its quads with the rib's previous sample has a 3D
    /// angle below this, up to three times inwards (after the ray cast and the lasso;
    /// detail::peelSliverRibEnds): rib ends cut obliquely by the patch's border made most of the faces below
    /// 30° left by minFaceAngleDeg. Degrees in [0, 60); 0 = off (files written before it). 30 by default
    /// (session 20: every SliverTable default row ≥ 24.6°, the lens torus side view with its lasso 5.4 → 0.1
    /// % below 30°).
    double peelRibEndsDeg = 30.0;
    /// The surface length of the screen segment a – b in pixel footprints (set by the fishbone scan for
    /// isotropicRibs; empty: no surface spacing). A rib's surface spacing is capped at 2.5 h of it (the
    /// triangulation drops edges longer than 3 h footprints). Must be safe to call from several threads. Not
    /// stored in session files.
    std::function<double(const Eigen::Vector2d& a, const Eigen::Vector2d& b)> surfaceLength{};

    /// Checks the ranges: spacing finite and > 0, minRibGap in [0, 1), maxRibTurnDeg in (0, 180],
    /// maxRibAspect 0 or in [1, 100], minFaceAngleDeg and peelRibEndsDeg in [0, 60), minComponentFaces ≥ 0,
    /// and both tracings (StreamlineOptions::validate, named "FishboneOptions::backboneTracing.step" ...).
    /// \throw InvalidOptionError naming the field.
    void validate() const;
};

/// The point of a backbone's polyline nearest to a screen point (Backbone::nearestPoint).
struct BackbonePoint {
    double position = 0;           ///< samples: segment index + fraction along it
    Eigen::Vector2d point{0, 0};   ///< on the polyline
    Eigen::Vector2d tangent{1, 0}; ///< unit; the samples' tangents interpolated linearly
    double distance = 0;           ///< from the query point
};

/// The backbone: samples every h along a streamline or a drawn spline.
struct Backbone {
    Polyline2 samples;         ///< consecutive samples at distance h
    std::size_t seedIndex = 0; ///< the picked point (traced backbone) or the first drawn point
    /// A closed curve (FishboneOptions::closeLoops): samples.back() is followed by samples.front() at about
    /// the spacing, and tangents wrap around.
    bool closed = false;
    /// Unit screen tangent at sample r (central difference; one-sided at the ends).
    /// \pre samples.size() ≥ 2 and r < samples.size().
    Eigen::Vector2d tangent(std::size_t r) const;
    /// Unit normal n = (−t.y, t.x) at sample r: the side of the ribs' positive halves.
    Eigen::Vector2d normal(std::size_t r) const;
    /// Index of the sample nearest to \p p (to place a key-rib at a picked point). \pre !samples.empty().
    std::size_t nearestSample(const Eigen::Vector2d& p) const;
    /// The point of the polyline through the samples (open, also when closed) nearest to \p p, with its
    /// continuous position and tangent (a continuous key-rib's start). \pre samples.size() ≥ 2.
    BackbonePoint nearestPoint(const Eigen::Vector2d& p) const;
};

/// A rib through one backbone sample: both halves start at that sample (index 0) and continue every h.
struct Rib {
    Polyline2 positive; ///< towards Backbone::normal
    Polyline2 negative; ///< the other side
};

/// A key-rib: a rib placed at backbone sample `row`.
struct KeyRib {
    std::size_t row = 0;
    Rib rib;
    /// Where along the backbone the key-rib starts, in samples (sample r at r, the middle of samples r and
    /// r + 1 at r + ½; tracedKeyRib): blended rows take t from it, so that the grid changes continuously
    /// with the key-rib's position. Negative (the default): at sample `row`.
    double position = -1;
    /// `position` when it is set, else `row`.
    double at() const { return position >= 0 ? position : double(row); }
};

/// One half of a rib in the paper's representation [E0, {αᵢ}] (see the file comment for the convention).
struct RibShape {
    Eigen::Vector2d firstEdge{0, 0};   ///< E0 = p1 − p0 (zero: a rib half without edges)
    std::vector<double> turningAngles; ///< αᵢ, i = 1 … n−1, radians in (−π, π]
    /// Number of edges n (vertices n + 1).
    std::size_t edgeCount() const { return firstEdge.isZero() ? 0 : turningAngles.size() + 1; }
};

/// The fishbone sampling grid in screen space: rows × cols positions, row-major, with presence flags.
struct FishboneGrid {
    int rows = 0;
    int cols = 0;
    int backboneColumn = 0;              ///< the column of the backbone samples
    double spacing = 0;                  ///< h
    std::vector<Eigen::Vector2d> screen; ///< rows·cols sub-pixel screen positions (unused where absent)
    std::vector<std::uint8_t> present;   ///< 1 where a rib vertex exists (and lies inside the image)
    /// Rows wrap around (a closed backbone): row rows − 1 and row 0 are neighbours, as any two consecutive
    /// rows (the fishbone scan triangulates the quads between them too).
    bool closed = false;

    std::size_t index(int r, int c) const { return std::size_t(r) * std::size_t(cols) + std::size_t(c); }
    bool isPresent(int r, int c) const {
        return r >= 0 && c >= 0 && r < rows && c < cols && present[index(r, c)] != 0;
    }
    const Eigen::Vector2d& at(int r, int c) const { return screen[index(r, c)]; }
    std::size_t presentCount() const;
};

/// Stops the half-ribs of \p grid (rows = the samples of \p backbone) where \p options' minRibGap,
/// maxRibTurnDeg or maxRibAspect says (FishboneOptions): rows in order, each half outwards from the backbone;
/// a vertex and every one beyond it on its half-rib become absent. Of two ribs that converge the one of the
/// lower row stops first, so the other goes on. Returns the number of vertices removed. \pre grid.rows ==
/// backbone.samples.size() ≥ 2.
std::size_t trimRibs(FishboneGrid& grid, const Backbone& backbone, const FishboneOptions& options);

/// The loop handling of FishboneOptions::closeLoops on a traced streamline \p line (not yet resampled):
/// the closed loop through its seed resampled at n = round(L/h) ≥ 3 equal arcs, starting at the seed
/// (Backbone::closed), or else the streamline resampled every h and cut, outwards from the seed, before
/// the first sample that comes within h/2 of a kept sample at least three samples away.
/// \pre h > 0 and finite. \throw InvalidInputError otherwise.
Backbone backboneFromStreamline(const Streamline& line, double h, bool closeLoops);

/// [E0, {αᵢ}] of one rib half whose first vertex lies on the backbone (the paper's key-rib representation).
/// Any polyline is accepted: fewer than two points give an empty shape. The turning angles are exact
/// for any edge lengths; ribFromShape reproduces the polyline exactly (to round-off) when every edge
/// after the first has length h, as for every rib sampled by this file's functions.
RibShape ribShape(const Polyline2& halfRib);

/// The paper's rib formula: vertices p0, p0 + G0, … from a start point, a shape [G0, {γᵢ}] and the
/// spacing h (see the file comment). \pre h > 0. \throw InvalidInputError otherwise.
Polyline2 ribFromShape(const Eigen::Vector2d& p0, const RibShape& shape, double h);

/// The blended shape [G0, {γᵢ}] between key-rib halves \p e = [E0, {αᵢ}] (t = 0) and \p f = [F0, {βᵢ}]
/// (t = 1): G0 = h·normalise((1−t)E0 + tF0), γᵢ = (1−t)αᵢ + tβᵢ, truncated to the shorter of the two.
/// Either shape empty gives an empty shape.
/// \pre t ∈ [0, 1], h > 0, (1−t)E0 + tF0 ≠ 0 (both halves on the same side of the backbone).
/// \throw InvalidInputError when a precondition is violated.
RibShape blendRibShapes(const RibShape& e, const RibShape& f, double t, double h);

/// Blends two key-ribs into the rib starting at backbone sample \p p0 (both halves by blendRibShapes).
/// \throw InvalidInputError as blendRibShapes.
Rib blendRibs(const Rib& a, const Rib& b, const Eigen::Vector2d& p0, double t, double h);

/// Centripetal Catmull–Rom spline through \p points (DESIGN.md §1 "drawn by hand (interpolating splines
/// in 2D)"): passes through every point, no cusps or self-intersections within a segment (centripetal
/// parametrisation, Yuksel et al. 2011); end tangents from reflected phantom points. Returns a dense
/// polyline whose segments are at most \p maxSegment long, containing every input point exactly.
/// Consecutive duplicate points are merged. \pre maxSegment > 0; points finite.
/// \throw InvalidInputError when a precondition is violated.
Polyline2 catmullRomSpline(const Polyline2& points, double maxSegment = 0.25);

/// Traces the backbone (paper: "the streamline through the picked point along one principal direction")
/// on \p backboneField from \p seed, both ways, and samples it every h from the seed.
/// \pre seed on a valid pixel of the field; options valid. \throw InvalidInputError otherwise.
Backbone traceBackbone(const DirectionField& backboneField, const Eigen::Vector2d& seed,
                       const FishboneOptions& options = {});

/// A hand-drawn backbone: a Catmull–Rom spline through \p points, sampled every h from the first point.
/// \pre at least two distinct finite points; spacing > 0. \throw InvalidInputError otherwise.
Backbone drawnBackbone(const Polyline2& points, const FishboneOptions& options = {});

/// The ribs through backbone samples first … first + count − 1, each exactly traceRib's: their halves are
/// traced in lockstep on the calling thread (traceHalvesInLockstep), which is faster than one by one.
/// \pre first + count ≤ backbone.samples.size(), backbone has ≥ 2 samples. \throw InvalidInputError
/// otherwise.
std::vector<Rib> traceRibs(const DirectionField& ribField, const Backbone& backbone, std::size_t first,
                           std::size_t count, const FishboneOptions& options = {});

/// Every rib of \p backbone (the automatic mode), in backbone order: traceRibs on groups of neighbouring
/// backbone samples, the groups on the scan threads (parallel.h); the same ribs for any thread count.
std::vector<Rib> traceAllRibs(const DirectionField& ribField, const Backbone& backbone,
                              const FishboneOptions& options = {});

/// Traces the rib through backbone sample \p row on \p ribField, both ways, each half sampled every h
/// from the backbone sample; a half whose start is undefined (background) is just the sample.
/// \pre row < backbone.samples.size(), backbone has ≥ 2 samples. \throw InvalidInputError otherwise.
Rib traceRib(const DirectionField& ribField, const Backbone& backbone, std::size_t row,
             const FishboneOptions& options = {});

/// A hand-drawn key-rib: a Catmull–Rom spline through \p points that must pass within 2h of a backbone
/// sample; the nearest sample becomes its row, the spline is split at its point nearest to that sample,
/// and each part (prefixed by the sample itself) is sampled every h and assigned to its side.
/// \pre ≥ 2 distinct finite points; the spline passes within 2h of the backbone; backbone ≥ 2 samples.
/// \throw InvalidInputError otherwise.
KeyRib drawnKeyRib(const Backbone& backbone, const Polyline2& points, const FishboneOptions& options = {});

/// Assembles ribs (one per backbone sample, ribs[r] through backbone.samples[r]) into the grid. Entries
/// outside the image [0, width] × [0, height] are marked absent (width or height ≤ 0: no test).
/// \pre ribs.size() == backbone.samples.size(). \throw InvalidInputError otherwise.
FishboneGrid assembleFishboneGrid(const Backbone& backbone, const std::vector<Rib>& ribs, double spacing,
                                  int width = 0, int height = 0);

/// Automatic mode (DESIGN.md §1, ribs from every backbone sample): the backbone through \p seed on
/// \p backboneField, then a traced rib through every backbone sample on \p ribField. Swap the two
/// fields to swap min and max. Entries outside the image are absent.
/// \pre fields of equal size; seed on a valid pixel. \throw InvalidInputError otherwise.
FishboneGrid automaticFishbone(const DirectionField& backboneField, const DirectionField& ribField,
                               const Eigen::Vector2d& seed, const FishboneOptions& options = {});

/// A key-rib traced from the point of \p backbone nearest to \p p (Backbone::nearestPoint) along the
/// backbone's interpolated normal there, on \p ribField; its position is that point's, its row the
/// nearest sample. A half whose start lies where \p ribField is undefined runs straight along the normal
/// to the first point within 8h where it is defined and is traced from there (else it stays empty).
/// \throw InvalidInputError as traceRib.
KeyRib tracedKeyRib(const DirectionField& ribField, const Backbone& backbone, const Eigen::Vector2d& p,
                    const FishboneOptions& options);

/// Key-rib mode (DESIGN.md §1, key-ribs and blended ribs): ribs only at the given key-ribs, blended
/// ribs between neighbouring key-ribs, copies of the nearest key-rib beyond the first and last
/// (options.extendBeyondKeyRibs) or no rows there. Of several key-ribs at one position the last given wins.
/// The row of backbone sample r between key-ribs at positions a < b (KeyRib::at) is their blend with
/// t = (r − a)/(b − a); a key-rib exactly at a sample is that row as it is.
/// Entries outside the image [0, width] × [0, height] are absent (width or height ≤ 0: no test).
/// \pre at least one key-rib; every key row and position ≤ backbone.samples.size() − 1; backbone ≥ 2
/// samples.
/// \throw InvalidInputError otherwise.
FishboneGrid keyRibFishbone(const Backbone& backbone, std::vector<KeyRib> keyRibs,
                            const FishboneOptions& options = {}, int width = 0, int height = 0);

} // namespace fss
