#pragma once
/// \file scan_pipeline.h
/// One virtual range scan from camera to patch (DESIGN.md §1 "Scan", "Mask", "Triangulate"; data flow
/// §2): render the *reference* mesh from the scan camera, one sample per covered pixel, lasso, the
/// sampling-quality mask against the *current* mesh (rendered from the same camera), erosion and dilation,
/// triangulation of the grid. The same function serves the command line, the widgets and the Session;
/// how meshes are rendered is abstracted by MeshRenderer (GPU in FSS::render, CPU ray casting here).

#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mask.h"
#include "fss/mesh.h"
#include "fss/mesh_renderer.h"
#include "fss/progress.h"
#include "fss/sample_grid.h"
#include "fss/scan.h"
#include "fss/scan_workspace.h"
#include "fss/triangulate.h"

#include <cstddef>
#include <memory>
#include <optional>

namespace fss {

/// Everything a scan needs besides the meshes. Defaults are the command line's.
struct ScanParams {
    Camera camera;                  ///< scan camera; width × height is the scan resolution
    std::optional<Lasso> lasso;     ///< screen polygon in pixels of the scan image; none = whole image
    int erodeRadius = 1;            ///< morphological erosion radius (0 = none)
    int dilateRadius = 1;           ///< dilation radius after the erosion (never re-admits rejected samples)
    ScanOptions scan;               ///< sampling options (scan id, quality angle limit)
    QualityMaskOptions quality;     ///< quality mask (margin, forceReplace)
    TriangulateOptions triangulate; ///< triangulation thresholds
    /// Sweeps of tangential relaxation of the patch's interior vertices on the reference (connectivity and
    /// border unchanged, moves that would cross a crease, turn a face or lower the local smallest angle are
    /// refused; core/src/mesh/relax.h); 0 = none. In [0, 100].
    int relaxIterations = 0;

    /// Checks everything a scan needs before it renders: the camera (Camera::validate), the erosion and
    /// dilation radii (in [0, 1024]), relaxIterations (in [0, 100]), the lasso (validateLasso) when there is
    /// one, and the scan, quality-mask and triangulation options (their validate()). scanPatch,
    /// scanFishbonePatch and the session-file reader call it. \throw InvalidInputError with one sentence
    /// naming the problem; InvalidOptionError for an option out of
    ///        range, named as a field of ScanParams ("ScanParams::quality.margin must be in [0, 1),
    ///        not 1.5.").
    void validate() const;
};

/// Wall-clock seconds of each stage of scanPatch.
struct ScanTimings {
    double renderReference = 0; ///< render + read-back of the reference mesh
    double renderCurrent = 0;   ///< render + read-back of the current mesh (0 when it is the reference)
    double sample = 0;          ///< unprojection into the SampleGrid
    double lasso = 0;
    double qualityMask = 0;
    double morphology = 0;
    double triangulate = 0;
    double relax = 0; ///< tangential relaxation of the patch (ScanParams::relaxIterations)
    double total = 0;
};

/// Sample counts after each stage of scanPatch.
struct ScanCounts {
    std::size_t pixels = 0;          ///< width × height
    std::size_t covered = 0;         ///< samples on the reference surface (hit)
    std::size_t frontFacing = 0;     ///< of those, on front-facing reference faces (admissible)
    std::size_t wellShaped = 0;      ///< admissible after the lattice-angle mask (ScanOptions)
    std::size_t afterLasso = 0;      ///< admissible after the lasso
    std::size_t afterQuality = 0;    ///< admissible after the quality mask
    std::size_t afterMorphology = 0; ///< valid after erosion, dilation and clean-up
};

/// The result of one scan: the grid (with its masks), the patch, and the current mesh's buffers from the
/// scan camera (the stitcher uses them to find the faces under the patch).
struct ScanResult {
    SampleGrid grid;
    Patch patch;
    FrameBuffers currentBuffers;
    ScanCounts counts;
    ScanTimings timings;
};

/// params.validate() (kept for its callers).
void validateScanParams(const ScanParams& params);

/// Runs one scan. \p referenceRenderer must hold \p reference (setMesh) and \p currentRenderer
/// \p current; when \p current is the reference itself (same object, the first scan) pass the same
/// renderer: the current mesh is then not rendered again and the quality mask is skipped (input faces
/// rank lowest, every sample beats them).
/// \throw InvalidInputError with one sentence when \p params are invalid (ScanParams::validate: the camera,
///        an option out of range, the lasso), the mesh lies behind the camera,
///        the camera sees no part of the mesh, sees only the back of the surface (it is inside the mesh),
///        the lasso is degenerate or selects nothing, or nothing is left to triangulate.
///        CancelledError through \p progress.
ScanResult scanPatch(const Mesh& reference, MeshRenderer& referenceRenderer, const Mesh& current,
                     MeshRenderer& currentRenderer, const ScanParams& params, const Progress& progress = {});

/// As scanPatch above, with the buffers of \p workspace (scan_workspace.h): the same result; scan after
/// scan of one size (recycling each result's grid and patch into the workspace once it is no longer
/// needed) allocates no new memory in the CPU stages.
ScanResult scanPatch(const Mesh& reference, MeshRenderer& referenceRenderer, const Mesh& current,
                     MeshRenderer& currentRenderer, const ScanParams& params, ScanWorkspace& workspace,
                     const Progress& progress = {});

} // namespace fss
