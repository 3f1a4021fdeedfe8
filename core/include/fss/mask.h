#pragma once
/// \file mask.h
/// **Mask**, DESIGN.md §1: which samples of a scan become the patch.
///  1. Lasso: a user-drawn screen polygon; samples outside are dropped (applyLasso).
///  2. Sampling quality: a sample is dropped where the current mesh is already better there
///     (applyQualityMask; the quality is defined in scan.h).
///  3. Morphology on the grid: erosion, then a dilation that never re-admits samples that failed 1–2
///     (an opening), then removal of samples that cannot form a triangle (applyMorphology) — removing
///     isolated samples, spikes and one-sample bridges so that the patch boundary is clean.
///
/// Flags (sample_grid.h): the lasso and quality tests clear `admissible` and `valid`; morphology changes
/// only `valid` and keeps valid ⊆ admissible. All functions work on arbitrary sub-pixel screen positions
/// (fishbone grids) except where the grid neighbourhood is used, which is the (row, col) neighbourhood.

#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/sample_grid.h"
#include "fss/scan_workspace.h"

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace fss {

/// A closed screen polygon (pixels, top-left origin, y down; the last point connects back to the first).
/// It may be concave and self-intersecting: the **non-zero winding rule** decides what is inside (a point
/// is inside when the polygon winds around it a non-zero number of times, in either direction), so a
/// figure-eight selects both loops and a pentagram selects its centre pentagon too — every region the
/// user's stroke encloses is selected, however often or in whichever direction it was circled. Points
/// exactly on the polygon's boundary are inside. All decisions use exact predicates (CGAL Epick 2D
/// orientation and exact coordinate comparisons), so points on or near an edge are classified exactly.
struct Lasso {
    std::vector<Eigen::Vector2d> points;
};

/// Checks that \p lasso encloses an area.
/// \throw InvalidInputError when a coordinate is not finite, when it has fewer than 3 distinct points, or
///        when all its points are collinear (zero area).
void validateLasso(const Lasso& lasso);

/// True when the screen point \p p is inside \p lasso (non-zero winding rule, boundary included; exact).
/// O(m) per call for m lasso points; applyLasso indexes the lasso once for a whole grid.
/// \pre validateLasso(lasso) passes (not checked; an empty lasso contains nothing).
bool insideLasso(const Lasso& lasso, const Eigen::Vector2d& p);

/// Lasso mask: clears `admissible` and `valid` of every sample whose screen position lies outside
/// \p lasso. Cost O(samples · k + m log m) for a lasso of m edges, k of which span a sample's row.
/// \return the number of admissible samples that were dropped.
/// \throw InvalidInputError as validateLasso.
std::size_t applyLasso(SampleGrid& grid, const Lasso& lasso);

/// Options of applyQualityMask.
struct QualityMaskOptions {
    /// Relative margin against churn: a sample replaces an existing face only when its quality is better
    /// by this fraction, q_sample < (1 − margin) · q_face. Re-scanning from (nearly) the same view then
    /// changes nothing, while a clearly closer or more frontal scan replaces.
    double margin = 0.1;
    /// Keep every admissible sample regardless of quality (the user forces a replacement).
    bool forceReplace = false;
    /// Vertex rings searched around the current best face in the local closest-point walk (raycast.h).
    int searchRings = 2;

    /// Checks the ranges: margin in [0, 1), searchRings ≥ 0.
    /// \throw InvalidOptionError naming the field ("QualityMaskOptions::margin must be in [0, 1), not 1.5.").
    void validate() const;
};

/// Sampling-quality mask against the *current* mesh. For every admissible sample, the face of
/// \p currentBuffers under the sample's screen position (pixel floor(x), floor(y)) is the first guess;
/// a local walk on \p current (closestPointNear, `options.searchRings` rings) finds the face closest to
/// the sample's point (a sample within 10⁻³ pixel footprints of the first guess is on it: the guess is
/// taken without a walk). The sample stays admissible only when its quality is better than that face's
/// quality, q_sample < (1 − margin) · q_face, where q_face is the face's props::faceQuality, or
/// kInputFaceQuality for faces without one (input faces: every sample beats them; a NaN counts as none).
/// Samples whose pixel shows no face of \p current (or lies outside the image) stay admissible: the
/// current mesh is not under them. `options.forceReplace` keeps every sample. Dropped samples lose
/// `admissible` and `valid`. Cost: linear in the samples (times the size of the local search).
/// \pre \p currentBuffers are \p current rendered from the grid's camera (same image size).
/// \return the number of admissible samples that were dropped.
/// \throw InvalidInputError when the buffers' size differs from the grid's camera, a buffer face id is not
///        a face of \p current; InvalidOptionError when \p options are out of range (validate()).
std::size_t applyQualityMask(SampleGrid& grid, const Mesh& current, const FrameBuffers& currentBuffers,
                             const QualityMaskOptions& options = {});

/// Morphological erosion of `valid` with the square structuring element of side 2·radius+1 (the
/// 8-neighbourhood for radius 1, Chebyshev distance ≤ radius): a sample stays valid only when every
/// sample of the square around it exists (inside the grid) and is valid. Radius 0 changes nothing.
/// \return the number of samples that lost `valid`. \throw InvalidInputError when radius < 0.
std::size_t erode(SampleGrid& grid, int radius = 1);

/// Morphological dilation of `valid` with the same square: a sample becomes valid when some sample of
/// the square around it is valid — but only when it is `admissible`: dilation never re-admits samples
/// that failed coverage, the lasso or the quality test. erode(r) then dilate(r) is an opening: it removes
/// isolated samples, spikes and bridges thinner than 2r+1 samples and keeps everything else unchanged.
/// \return the number of samples that gained `valid`. \throw InvalidInputError when radius < 0.
std::size_t dilate(SampleGrid& grid, int radius = 1);

/// Clears `valid` of every sample that is not a corner of any grid quad whose four corners are valid:
/// such samples cannot become part of a triangle (triangulate.h uses whole quads).
/// \return the number of samples that lost `valid`.
std::size_t removeUntriangulatableSamples(SampleGrid& grid);

/// Options of applyMorphology.
struct MorphologyOptions {
    /// Radius of the opening (erode, then dilate). 1 removes isolated samples, one- and two-sample-wide
    /// spikes and bridges; 0 only removes untriangulatable samples.
    int radius = 1;
    /// Radius of the dilation when it differs from the erosion's; -1 (the default) = `radius`.
    int dilateRadius = -1;
};

/// What applyMorphology changed.
struct MorphologyReport {
    std::size_t eroded = 0;           ///< samples that lost `valid` in the erosion
    std::size_t restored = 0;         ///< samples that got it back in the dilation
    std::size_t untriangulatable = 0; ///< samples removed by removeUntriangulatableSamples
};

/// The paper's morphology step: erode(radius), dilate(dilateRadius, or radius when it is -1),
/// removeUntriangulatableSamples — the same result as calling the three, with one read and one write of
/// the samples. \throw InvalidInputError when options.radius < 0 or options.dilateRadius < -1.
MorphologyReport applyMorphology(SampleGrid& grid, const MorphologyOptions& options = {});

/// As applyMorphology above, with the per-sample buffers of \p workspace (scan_workspace.h) instead of
/// fresh ones.
MorphologyReport applyMorphology(SampleGrid& grid, const MorphologyOptions& options,
                                 ScanWorkspace& workspace);

} // namespace fss
