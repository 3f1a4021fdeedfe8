#pragma once
/// \file scan.h
/// **Scan (regular grid)**, DESIGN.md §1: the reference mesh rendered from the scan camera gives one
/// sample per covered pixel centre; this file turns those buffers into a SampleGrid and defines the
/// *sampling quality* that the quality mask (mask.h) compares.
///
/// **Sampling quality** (Vorsatz et al. 2000, "Mask"): lower is better. For a sample with pixel footprint
/// f (Camera::pixelFootprint: world size of one pixel at the sample's depth) and sampling angle θ (between
/// the reversed view ray and the surface normal),
///
///     q = f / max(cos θ, cos θ_limit)          (θ_limit = ScanOptions::qualityAngleLimitDeg, 85°)
///
/// which is the expected length on the surface of a grid edge between neighbouring samples, measured in
/// the direction of steepest tilt (a one-pixel step on the screen covers f / cos θ on a surface tilted by
/// θ). Shorter edges (zoomed-in, closer camera, higher resolution) and more frontal views give a lower q;
/// the clamp keeps q finite at grazing angles.
///
/// **Face quality** of a triangle made from samples (triangleQuality; triangulate.h writes it to
/// props::faceQuality): the mean of the q of its three corner samples, so a face's q and a sample's q are
/// the same kind of number (an expected edge length in world units) and the quality mask compares them
/// directly.

#include "fss/camera_projector.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/progress.h"
#include "fss/sample_grid.h"
#include "fss/scan_workspace.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace fss {

/// The lattice of sample positions on the screen of a regular scan (sampleLattice, DESIGN.md §1).
enum class Lattice {
    /// Rows √3/2 of a spacing apart, each row shifted by half a spacing against the one before: the
    /// triangulation's grid triangles are equilateral on the screen (and on a surface facing the camera).
    Triangular,
    /// The pixel lattice of the paper: one sample per pixel centre (right isosceles triangles, 45° at best,
    /// flatter on slanted surfaces). Session files without a lattice were recorded on it (issue #20).
    Square,
    /// A triangular lattice chosen per view (chooseAdaptiveLattice): the equilateral lattice compressed on
    /// the screen along one direction by cos θ0 and turned, so that its triangles are equilateral on a
    /// plane tilted by θ0 — the (θ0, direction, turn) for which the most of the visible surface gets round
    /// triangles. A fixed screen lattice is squashed by cos θ on surfaces seen at a slant θ (issue #20).
    /// The default, with the lattice-angle mask at 35° (ScanOptions::minLatticeAngleDeg).
    Adaptive,
};

/// Options of sampleRegularGrid / sampleLattice (and setSampleOnSurface).
struct ScanOptions {
    /// Id given to the grid (SampleGrid::scanId), later to the faces it becomes (props::faceScanId).
    std::int32_t scanId = -1;
    /// θ_limit of the quality formula, degrees: beyond it the sampling angle counts as θ_limit.
    double qualityAngleLimitDeg = 85.0;
    /// The snap onto the face plane (see sampleRegularGrid) is applied only when it moves the unprojected
    /// point by at most this many pixel footprints; a larger move means the face id and the depth disagree
    /// (a corrupted ID buffer), and the unprojected point is kept.
    double maxSnapFootprints = 2.0;
    /// The lattice of sampleLattice (scanPatch). sampleRegularGrid always samples the pixel centres.
    Lattice lattice = Lattice::Adaptive;
    /// Distance between neighbouring samples of sampleLattice, in pixels of the scan image; ≥ 0.25.
    double spacingPixels = 1.0;
    /// When > 0: the spacing in world units instead, converted to pixels with the pixel footprint at the
    /// camera's focal point (latticeSpacingPixels).
    double spacingWorld = 0.0;
    /// The lattice-angle mask (applyLatticeAngleMask): a sample where the lattice's triangle, mapped onto
    /// the plane of the sample's reference face, has a smallest angle below this many degrees is not
    /// admissible — this view would sample that part of the surface too slanted for round triangles, and
    /// leaves it to another view (the paper's sampling-quality mask, on the triangles' shape). Also the
    /// angle chooseAdaptiveLattice counts coverage at (35° when 0). In [0, 60); 0 = no mask. 35° by
    /// default (issue #20: with it, the slanted rest of a view is left to views that see it rounder).
    double minLatticeAngleDeg = 35.0;
    /// Lattice::Adaptive only: the chosen lattice is then warped on the screen so that its triangles are
    /// equilateral *on the surface* under every sample, not only on the plane tilted by the lattice's θ0
    /// (warpLatticeToSurface): a view of a curved surface sees it at many slants, and one affine lattice
    /// fits only one of them. On by default (issue #20: on 65 untuned views no view below 50° mean smallest
    /// angle, 12 without). Ignored by the other lattices. Session files record it as
    /// "scan.warp_to_surface" (version 3); a file without it (version 1 or 2) was recorded without the warp.
    bool warpToSurface = true;
    /// warpToSurface only: the warp's fit turns each wanted basis towards the fitted lattice's own basis
    /// there at every round (an as-rigid-as-possible fit) instead of towards the affine lattice's, and ends
    /// on every 2nd row and column instead of every 4th (warpLatticeToSurface's \p followFit): the two
    /// sides of a sharp crease, or faces slanted in different directions around an apex, then get bases a
    /// lattice can join, and the lattice bends where they meet. On by default (issue #20, session 19: of
    /// 282 untuned views, those below a mean smallest angle of 50° from 23 to 8, those with a larger
    /// Hausdorff distance than the square lattice from 10 to 8, 4 of the 16 made worse; DESIGN.md §1).
    /// Session files record it as "scan.warp_follows_fit" (version 5) when on; absent = off, so older files
    /// scan as recorded.
    bool warpFollowsFit = true;

    /// Checks the ranges: qualityAngleLimitDeg in (0, 90), maxSnapFootprints finite and ≥ 0, lattice one of
    /// the enumerators, spacingPixels finite and in [0.25, 1024], spacingWorld finite and ≥ 0,
    /// minLatticeAngleDeg in [0, 60).
    /// \throw InvalidOptionError naming the field ("ScanOptions::qualityAngleLimitDeg must be in (0, 90), not
    ///        90.").
    void validate() const;
};

/// The spacing of \p options' lattice in pixels of \p camera's image: spacingWorld divided by the pixel
/// footprint at the camera's focal point when spacingWorld > 0, else spacingPixels.
/// \throw InvalidInputError when the world spacing gives less than 0.25 or more than 1024 pixels.
double latticeSpacingPixels(const Camera& camera, const ScanOptions& options);

/// The sampling quality q = footprint / max(cos(samplingAngle), cos(qualityAngleLimitDeg)) (see the file
/// comment). \p samplingAngle in radians.
float sampleQuality(double footprint, double samplingAngle, double qualityAngleLimitDeg = 85.0);

/// The quality of a triangle whose corners are the samples \p a, \p b, \p c: the mean of their q.
float triangleQuality(const Sample& a, const Sample& b, const Sample& c);
/// As above, from the corners' q alone.
float triangleQuality(float qa, float qb, float qc);

/// Fills \p sample as a sample of the reference surface at \p point on face \p face, seen by \p camera:
/// point, face, unit face normal, sampling angle (between the reversed viewing ray towards \p point and
/// the normal), footprint, quality, hit = true; admissible = valid = true when the face is front-facing
/// (cos θ > 0). A back-facing or degenerate face (we look at the back of the reference surface, e.g. into
/// an open mesh) gives admissible = valid = false: a patch there could not be oriented like the
/// reference. The screen position is left as it is. Shared by the regular and the fishbone scan.
/// \pre \p face is a triangle of \p reference.
void setSampleOnSurface(Sample& sample, const Mesh& reference, const Camera& camera, FaceIndex face,
                        const Eigen::Vector3d& point, const ScanOptions& options = {});

/// As setSampleOnSurface above, with the camera's matrices already computed (CameraProjector of the scan
/// camera): the same result, without inverting the camera's matrix for every sample.
void setSampleOnSurface(Sample& sample, const Mesh& reference, const CameraProjector& camera, FaceIndex face,
                        const Eigen::Vector3d& point, const ScanOptions& options = {});

/// The regular-grid scan: a SampleGrid of rows = image height, cols = image width, sample (r, c) at the
/// pixel centre (c+½, r+½), from the buffers of the *reference* mesh rendered from the scan camera.
///
/// For every covered pixel: the point is the pixel centre unprojected with the buffer's depth (in double)
/// and then **snapped onto the plane of the reference face under it** along the viewing ray through the
/// pixel centre. The ID buffer tells which face the ray hits, so intersecting the ray with that face's
/// plane gives the exact surface point; this removes the depth buffer's quantisation (24-bit depth, or
/// float) entirely, and the sample lies on the reference surface up to rounding. The rest as
/// setSampleOnSurface. Uncovered pixels give samples with hit = admissible = valid = false.
/// Cost: linear in the number of pixels.
/// \pre the buffers were rendered from \p reference (their face ids are faces of it) and have
///      camera.width × camera.height entries.
/// \throw InvalidInputError when the camera is invalid, the buffer sizes do not match the camera, or a
///        face id is not a triangle of \p reference. CancelledError through \p progress (once per row).
SampleGrid sampleRegularGrid(const FrameBuffers& referenceBuffers, const Mesh& reference,
                             const ScanOptions& options = {}, const Progress& progress = {});

/// As sampleRegularGrid above, filling the sample storage recycled into \p workspace (scan_workspace.h)
/// when there is some: the same grid, without allocating when the workspace has served a scan of this
/// size before.
SampleGrid sampleRegularGrid(const FrameBuffers& referenceBuffers, const Mesh& reference,
                             ScanWorkspace& workspace, const ScanOptions& options = {},
                             const Progress& progress = {});

/// The scan of scanPatch: the samples of \p options' lattice (ScanOptions::lattice, spacing).
///  - Lattice::Square with a spacing of 1 pixel: sampleRegularGrid (the pixel centres, bit for bit).
///  - Otherwise a lattice of screen positions, spacing s = latticeSpacingPixels: sample (r, c) at
///    x = x0 + (c − r/2)·s, y = y0 + r·(√3/2)·s for Lattice::Triangular (x = x0 + c·s, y = y0 + r·s for
///    Lattice::Square), centred in the image. The triangular lattice is stored *sheared*: its rows shift by
///    half a spacing each, so the triangulation's fixed diagonal (r, c)–(r+1, c+1) (triangulate.h) is the
///    lattice's short diagonal and every grid triangle is equilateral on the screen, with interior
///    valence 6; the grid has about rows/2 more columns than fit across the image, and the samples
///    outside it miss (hit = false). Masks work on it unchanged (their square windows in (row, column)
///    become rhombi on the screen).
///    Each sample is found as fishbone samples are (hitFromIdBuffer): the face the ID buffer shows under
///    the sample's pixel is the first guess, the viewing ray through the exact screen position is
///    intersected with it or with the faces a walk over the surface reaches. A sample whose pixel shows no
///    surface, or whose ray the walk cannot place, misses.
///    The sampling quality is multiplied by s (a coarser lattice makes longer edges, scan.h).
///  - Lattice::Adaptive: sample (r, c) at o + c·a + r·b with chooseAdaptiveLattice's basis (countFromDeg =
///    minLatticeAngleDeg, or 35), o near the image centre; rows and columns cover the image (samples
///    outside it miss); found as above.
/// \throw as sampleRegularGrid; InvalidInputError when the world spacing is out of range.
SampleGrid sampleLattice(const FrameBuffers& referenceBuffers, const Mesh& reference,
                         ScanWorkspace& workspace, const ScanOptions& options = {},
                         const Progress& progress = {});

/// The screen basis of a lattice: sample (r, c) at origin + c·a + r·b; the triangulation's triangles have
/// the screen edges a, b and a + b (triangulate.h's diagonal (r, c)–(r+1, c+1)).
struct LatticeBasis {
    Eigen::Vector2d a{1, 0};
    Eigen::Vector2d b{0, 1};
};

/// The smallest angle, in degrees, of the triangle with screen edges \p basis.a, b and a + b mapped onto
/// the plane through \p point with unit normal \p normal as \p camera sees it (the projection linearised
/// at \p point). 0 when the plane is seen edge-on.
double latticeAngleOnPlane(const CameraProjector& camera, const Eigen::Vector3d& point,
                           const Eigen::Vector3d& normal, const LatticeBasis& basis);

/// The basis of Lattice::Adaptive for \p referenceBuffers' view at \p spacing pixels: among equilateral
/// screen lattices (side \p spacing) compressed by cos θ0 (θ0 = 0°, 10°, …, 60°) along one of 12
/// directions and turned by 0°, 7.5°, …, 52.5°, the one that maximises Σ (g − 30°) over a fixed subsample
/// of at most ~3000 covered front-facing pixels with g = latticeAngleOnPlane ≥ \p countFromDeg (pixels
/// below it count 0: the mask drops them). The offset of 30° weighs roundness against coverage; it was
/// tuned on fandisk and bull (issue #20: with 0 the iso view of fandisk kept a mean smallest angle of
/// 42.8°, with 30° 54.8°). θ0 = 0 without turn (the Triangular lattice's basis) wins ties.
/// Deterministic; linear in the subsample × 584 candidates.
LatticeBasis chooseAdaptiveLattice(const FrameBuffers& referenceBuffers, const Mesh& reference,
                                   double spacing, double countFromDeg);

/// The screen positions of a lattice warped to the surface (ScanOptions::warpToSurface), row by row
/// (\p rows × \p cols, sample (r, c) at index r·cols + c), starting from the affine lattice origin + c·a +
/// r·b. At every covered front-facing pixel the wanted local basis (a', b') is the one whose triangle is
/// equilateral with side spacing × the pixel footprint on the plane of the face under the pixel (the
/// linearised map of latticeAngleOnPlane), turned to be closest to the affine basis; the positions are
/// the weighted least-squares fit of the grid's edges (a, b, a + b in (row, column)) to those local
/// bases (Poisson: 2 direct rounds on every 8th row and column, bases re-read, then one direct round on
/// every 4th, on the nodes in the image and two around). With \p followFit (ScanOptions::warpFollowsFit)
/// each wanted basis is turned to be closest to the fitted lattice's basis there instead of the affine one
/// from the second round on (as-rigid-as-possible), with 4 rounds on every 8th row and column and 2 on
/// every 2nd. Uncovered pixels keep the affine basis with a small weight. Deterministic, the same for any
/// thread count.
std::vector<Eigen::Vector2d> warpLatticeToSurface(const FrameBuffers& referenceBuffers, const Mesh& reference,
                                                  double spacing, const LatticeBasis& basis,
                                                  const Eigen::Vector2d& origin, int rows, int cols,
                                                  bool followFit = false);

/// The lattice-angle mask (ScanOptions::minLatticeAngleDeg): every admissible sample of \p grid (a
/// regular lattice: its basis is read from the screen positions of samples (0, 0), (0, 1), (1, 1)) whose
/// latticeAngleOnPlane on its reference face is below \p minAngleDeg becomes not admissible and not
/// valid. Returns how many. Nothing for \p minAngleDeg ≤ 0 or a grid with fewer than 2 rows or columns.
/// With \p localBasis (a warped lattice, ScanOptions::warpToSurface) each sample's basis is read from its
/// own neighbours' screen positions ((r, c + 1) and (r + 1, c + 1), or the ones before at the grid's end).
std::size_t applyLatticeAngleMask(SampleGrid& grid, double minAngleDeg, bool localBasis = false);

/// Where the viewing ray \p ray through screen position \p screen meets the reference, found from the
/// ID buffer (DESIGN.md §1, shared by sampleLattice and the fishbone scan).
struct IdBufferHit {
    FaceIndex face;        ///< the face hit
    Eigen::Vector3d point; ///< the hit point
    bool onHint = false;   ///< the face is the one under the sample's pixel (the first guess)
};

/// The face the ID buffer shows under the pixel of \p screen (clamped into the image), or
/// Mesh::null_face() when it shows none or a face id beyond \p reference's faces.
FaceIndex idBufferHint(const FrameBuffers& buffers, const Mesh& reference, const Eigen::Vector2d& screen);

/// The hit of \p ray with the surface near \p hint (idBufferHint of \p screen): a walk over the
/// surface from the hint towards the ray (at most \p maxWalkSteps faces; on meshes with faces smaller
/// than a pixel the hit face is often a neighbour of the hint), else the nearest hit among the faces the
/// ID buffer shows at the 8 pixels around. Nothing when neither finds one (a border or a silhouette).
/// \pre \p hint is a face of \p reference.
std::optional<IdBufferHit> hitFromIdBuffer(const FrameBuffers& buffers, const Mesh& reference, FaceIndex hint,
                                           const Ray& ray, const Eigen::Vector2d& screen, int maxWalkSteps);

} // namespace fss
