#pragma once
/// \file mask_triangulate.h
/// The stages every scan shares once its SampleGrid is sampled (DESIGN.md §1 "Mask", "Triangulate"):
/// lasso, sampling-quality mask against the current mesh, morphology and grid triangulation, composed once
/// in maskAndTriangulate for regular scans (scanPatch, scan_pipeline.h), fishbone scans
/// (scanFishbonePatch, fishbone_scan.h) and the scans of `auto` (auto_remesh.h).

#include "fss/frame_buffers.h"
#include "fss/mask.h"
#include "fss/mesh.h"
#include "fss/progress.h"
#include "fss/sample_grid.h"
#include "fss/scan_workspace.h"
#include "fss/triangulate.h"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace fss {

/// A point at which maskAndTriangulate reports to its Progress: `fraction` with `stage`; none when the stage
/// is empty.
struct ProgressMark {
    double fraction = 0;
    std::string_view stage;
};

/// The mask and triangulation stages of a scan (DESIGN.md §1 "Mask", "Triangulate") as one caller wants
/// them: which masks run, with which options, where progress is reported and what the errors say. The
/// defaults are scanPatch's.
struct MaskStages {
    const Lasso* lasso = nullptr; ///< the lasso (applyLasso); none: every sample stays
    /// The current mesh for the quality mask (applyQualityMask), with its buffers from the grid's camera;
    /// none: no quality mask (the first scan, whose current mesh is the reference).
    const Mesh* current = nullptr;
    const FrameBuffers* currentBuffers = nullptr; ///< required with `current`
    QualityMaskOptions quality;                   ///< quality mask options
    /// One flag per sample: flagged samples are made admissible and valid again after the quality mask
    /// (auto's fill pass keeps what still shows input faces); none: nothing is re-admitted.
    const std::vector<char>* readmit = nullptr;
    MorphologyOptions morphology;   ///< erosion, dilation, clean-up (applyMorphology)
    TriangulateOptions triangulate; ///< triangulateGrid's thresholds
    ProgressMark atLasso;           ///< before the lasso
    ProgressMark atQuality{0.6, "quality mask"};
    ProgressMark atMorphology{0.7, "morphology"};
    ProgressMark atTriangulate{0.8, "triangulate"};
    /// Thrown when a lasso is given and no admissible sample is left after it.
    std::string lassoSelectsNothing = "The lasso selects no part of the visible surface.";
    /// Thrown when the patch is empty and the quality mask left no admissible sample.
    std::string nothingBetter = "Every sample of this scan is worse than the mesh already there, so nothing "
                                "would change (use force-replace to override).";
    /// Thrown when the patch is empty otherwise.
    std::string nothingLeft =
        "Nothing is left to triangulate after the masks; enlarge the lasso or reduce the "
        "erosion.";
};

/// Sample counts after each stage of maskAndTriangulate.
struct MaskCounts {
    std::size_t afterLasso = 0;      ///< admissible after the lasso
    std::size_t afterQuality = 0;    ///< admissible after the quality mask (and the re-admission)
    std::size_t afterMorphology = 0; ///< valid after erosion, dilation and clean-up
};

/// Wall-clock seconds of each stage of maskAndTriangulate.
struct MaskTimings {
    double lasso = 0;
    double qualityMask = 0; ///< quality mask and re-admission
    double morphology = 0;
    double triangulate = 0;
};

/// What maskAndTriangulate made.
struct MaskedPatch {
    Patch patch;
    MaskCounts counts;
    MaskTimings timings;
};

/// The stages every scan shares once its SampleGrid is sampled (regular, fishbone and automatic scans):
/// lasso → quality mask against the current mesh → re-admission → morphology → triangulation, each as
/// \p stages asks. \p grid keeps its masks.
/// \throw InvalidInputError with `stages.lassoSelectsNothing` when the lasso leaves no admissible sample,
///        `stages.nothingBetter` or `stages.nothingLeft` when the patch has no face, and as the stages
///        themselves (applyMorphology's radii); CancelledError through \p progress.
MaskedPatch maskAndTriangulate(SampleGrid& grid, const MaskStages& stages, ScanWorkspace& workspace,
                               const Progress& progress = {});

/// As maskAndTriangulate above, with fresh buffers (the same result).
MaskedPatch maskAndTriangulate(SampleGrid& grid, const MaskStages& stages, const Progress& progress = {});

} // namespace fss
