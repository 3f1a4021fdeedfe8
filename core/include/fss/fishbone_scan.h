#pragma once
/// \file fishbone_scan.h
/// One feature-sensitive ("fishbone") scan from camera to patch (DESIGN.md §1, "Feature-sensitive
/// (fishbone) grid", last paragraph; Vorsatz, Rössl, Kobbelt, Seidel, VMV 2000): render the *reference*
/// mesh from the scan camera, build the screen direction fields of its principal curvature directions
/// (lazily: only the pixel tiles the streamlines come near are computed, lazyDirectionField),
/// trace (or take the drawn) backbone and ribs into a FishboneGrid, cast a ray from the eye through every
/// rib vertex onto the reference surface — the ID buffer's face under the vertex is the first guess, a
/// local search around it finishes, the AABB tree is the fallback — and then mask and triangulate the
/// resulting SampleGrid exactly like a regular scan (scan_pipeline.h): lasso, sampling quality against the
/// current mesh, erosion and dilation, triangulateGrid (screen-flipped quads, i.e. crossing ribs, are
/// dropped). The patch is stitched like any other.
///
/// Principal curvatures and the reference's AABB tree depend only on the reference mesh: they live in a
/// caller-owned FishboneCache, computed on the first scan and reused by every later one (the Session
/// keeps it with the reference).

#include "fss/curvature.h"
#include "fss/direction_field.h"
#include "fss/fishbone.h"
#include "fss/raycast.h"
#include "fss/scan_pipeline.h"

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

namespace fss {

/// What a fishbone scan precomputes once per reference mesh: principal curvatures (estimateCurvature) and
/// the reference's RayCaster. Owned by the caller; it references the mesh given to get(), which must stay
/// alive and unchanged while the cache holds it (call clear() before changing or destroying it).
class FishboneCache {
public:
    FishboneCache();
    ~FishboneCache();
    FishboneCache(FishboneCache&&) noexcept;
    FishboneCache& operator=(FishboneCache&&) noexcept;

    /// Curvature of \p reference, estimated on the first call for this mesh (options used then) and cached.
    /// A different mesh (other object or other vertex / face count) replaces the cache.
    /// \throw as estimateCurvature (the cache is left as it was).
    const CurvatureField& curvature(const Mesh& reference, const CurvatureOptions& options = {},
                                    const Progress& progress = {});
    /// RayCaster (AABB tree) of \p reference, built on the first call for this mesh and cached.
    /// \throw as RayCaster's constructor.
    const RayCaster& rayCaster(const Mesh& reference);
    /// True when the RayCaster of \p reference is already built.
    bool hasRayCaster(const Mesh& reference) const;
    /// Seconds the curvature estimate took when it was computed (0 before).
    double curvatureSeconds() const { return curvatureSeconds_; }
    /// Seconds the AABB tree took when it was built (0 before).
    double rayCasterSeconds() const { return rayCasterSeconds_; }
    /// The sharp edges of \p reference: interior edges whose faces' normals differ by more than
    /// \p minDihedralDeg degrees (CGAL's detect_sharp_edges; mesh/features.h), found on the first call for
    /// this mesh and threshold and cached (a call with another threshold recomputes them). Cost O(edges).
    const std::vector<EdgeIndex>& creaseEdges(const Mesh& reference, double minDihedralDeg);
    /// True when the curvature of \p reference is already cached.
    bool hasCurvature(const Mesh& reference) const;
    /// Forgets everything (the mesh is no longer referenced).
    void clear();

private:
    bool holds(const Mesh& reference) const;
    void bind(const Mesh& reference);
    const Mesh* mesh_ = nullptr;
    std::size_t vertices_ = 0, faces_ = 0;
    std::optional<CurvatureField> curvature_;
    std::unique_ptr<RayCaster> caster_;
    std::optional<std::vector<EdgeIndex>> creases_;
    double creaseAngleDeg_ = 0;
    double curvatureSeconds_ = 0, rayCasterSeconds_ = 0;
};

/// How the fishbone grid of a scan is built. Positions in pixels of the scan image (camera.h).
///
/// Modes: **automatic** (a traced backbone through `seed`, a traced rib through every backbone sample);
/// **key-rib** (`keyRibs` and/or `drawnKeyRibs` non-empty: ribs traced only at the backbone samples nearest
/// the key-rib points, or drawn; blended ribs in between, fishbone.h keyRibFishbone); the backbone is
/// traced through `seed` or, when `drawnBackbone` is given, the spline through its points.
struct FishboneParams {
    std::optional<Eigen::Vector2d> seed;                    ///< picked point of a traced backbone
    PrincipalDirection direction = PrincipalDirection::Min; ///< the backbone's direction; ribs the other
    double spacing = 4.0;                 ///< h: sample spacing in pixels, in [0.5, min(W, H)/4]
    std::vector<Eigen::Vector2d> keyRibs; ///< key-rib mode: traced key-ribs at these points (≥ 2)
    std::vector<Polyline2> drawnKeyRibs;  ///< key-rib mode: hand-drawn key-ribs (splines)
    Polyline2 drawnBackbone;              ///< hand-drawn backbone (≥ 2 points) instead of seed
    /// Tracing options (its spacing is replaced by `spacing`): steps in pixels of the sampling image (the
    /// direction field's, see samplingFactor), a finite maxLength in pixels of the scan image. The default
    /// continues straight across isotropic regions, which CAD meshes' flat faces need. An unbounded
    /// (infinite) maxLength becomes the image diagonal for the backbone (each way) and half of it for each
    /// rib half.
    FishboneOptions tracing = defaultTracing();
    /// A traced backbone needs the seed's interpolated anisotropy to reach this (else the principal
    /// directions are undefined there: flat or umbilic region).
    double minSeedAnisotropy = 0.1;
    /// Crease following of a traced backbone: where the backbone runs within `creaseSnapRadius` pixels of
    /// the visible image of a sharp crease of the reference (an edge whose dihedral angle exceeds
    /// `creaseAngleDeg`, FishboneCache::creaseEdges) and along it (within 30°), each step is moved onto
    /// the crease (StreamlineOptions::attractor). Without it a backbone seeded on a sharp crease drifts off:
    /// the principal directions of the faces beside a crease are those of the smooth sides (on fandisk's
    /// curved crease the min direction of the curved side is across the crease, one triangle away), so
    /// the crease is no attracting streamline of the field and small errors grow. 0 turns it off.
    double creaseAngleDeg = 30.0;
    /// See creaseAngleDeg; pixels of the scan image (> 0).
    double creaseSnapRadius = 1.5;
    /// Local search of the hinted ray casts.
    LocalSearchOptions raycast{};
    /// The sampling image's resolution divisor k (fishboneSamplingFactor): the reference (and the current
    /// mesh, for the quality mask and the stitch) are rendered at (W/k) × (H/k), the scan camera's frustum
    /// at 1/k of its resolution, and the fishbone is traced there: the scan with spacing h on W × H is the
    /// scan with spacing h/k on (W/k) × (H/k) — seed, key-ribs, drawn curves, lasso, maxLength and the
    /// crease snap radius divided by k, the tracing steps as they are (pixels of the direction field). A
    /// regular scan renders one pixel per sample; with k = ⌊h⌋ a fishbone renders about one per sample
    /// too, instead of h² (issue 5: at most twice the cost of a regular scan of as many samples). The
    /// samples themselves are exact either way (rays from the eye onto the reference), and their quality
    /// (Sample::quality) is that of the scan image's pixel footprint whatever k is, so the quality mask
    /// ranks the patch the same; the direction field is k times coarser, which costs some alignment: on
    /// fandisk's curved crease at 400², h = 2 px, the mean normal error near the crease is 1.0° with k = 2
    /// and 0.6° with k = 1 (the pixel grid's: 8.5°; tests/core/fishbone_fandisk_test.cpp).
    /// 0 (the default) = automatic: the largest integer k ≤ h that divides both W and H; k ≥ 1 requests
    /// that divisor (it must divide W and H and be at most h). Session files written before this option
    /// replay with k = 1 (the scan resolution), as they were recorded.
    int samplingFactor = 0;

    /// Checks the fishbone for a scan with \p scanCamera: spacing in [0.5, min(W, H)/4]; a seed or a drawn
    /// backbone (empty or ≥ 2 points); a traced backbone's seed inside the W × H image; no key-ribs or at
    /// least two (keyRibs and drawnKeyRibs together), each drawn key-rib with ≥ 2 points; every point
    /// finite; tracing (FishboneOptions::validate); minSeedAnisotropy in [0, 1]; creaseAngleDeg in
    /// [0, 180); creaseSnapRadius finite and > 0; raycast.rings ≥ 0; samplingFactor 0 or a divisor of W and
    /// H of at most h. scanFishbonePatch and the session-file reader call it.
    /// \throw InvalidOptionError naming the field ("FishboneParams::creaseAngleDeg must be in [0, 180), not
    ///        180.").
    void validate(const Camera& scanCamera) const;

    /// Tracing with LowAnisotropyPolicy::ContinueStraight; RK4 steps of half a pixel for the backbone and of
    /// one pixel for the ribs (rib turns limited to 12° per step, which ends ribs at field seams about where
    /// 10° per half pixel did). Sessions store these options, so older sessions replay with their own.
    static FishboneOptions defaultTracing();
};

/// Wall-clock seconds of each stage of scanFishbonePatch.
struct FishboneTimings {
    double curvature = 0;       ///< curvature estimate (0 when the cache held it)
    double rayCasterBuild = 0;  ///< AABB tree of the reference (0 when the cache held it)
    double renderReference = 0; ///< render + read-back of the reference
    double renderCurrent = 0;   ///< render of the current mesh (0 when it is the reference)
    double directionField = 0;  ///< setting up the (lazy) screen direction fields
    double tracing = 0;         ///< backbone, ribs, grid assembly, and computing the direction fields' tiles
                                ///< the streamlines come near (FishboneCounts::directionPixels)
    double rayCasting = 0;      ///< rib vertex → ray → sample
    double masks = 0;           ///< lasso + quality mask + morphology
    double triangulate = 0;
    double total = 0; ///< everything, including the cached stages when computed here
};

/// Sample counts after each stage of scanFishbonePatch.
struct FishboneCounts {
    int rows = 0, cols = 0;          ///< grid size (rows = ribs)
    std::size_t ribVertices = 0;     ///< present entries of the fishbone grid
    std::size_t trimmed = 0;         ///< rib vertices removed by trimRibs (automatic mode)
    std::size_t creaseStopped = 0;   ///< rib vertices removed by FishboneOptions::stopRibsAtCreases
    std::size_t lassoClipped = 0;    ///< rib vertices removed by FishboneOptions::clipRibsAtLasso
    std::size_t peeled = 0;          ///< samples dropped by FishboneOptions::peelRibEndsDeg
    std::size_t directionPixels = 0; ///< direction field pixels computed (backbone's + ribs' fields)
    std::size_t covered = 0;         ///< rays that hit the reference
    std::size_t frontFacing = 0;     ///< of those, on front-facing faces
    std::size_t onHintFace = 0;      ///< hits on the ID buffer's face under the rib vertex itself
    std::size_t afterLasso = 0;
    std::size_t afterQuality = 0;
    std::size_t afterMorphology = 0;
};

/// The result of a fishbone scan: the screen grid, the SampleGrid with its masks, the patch, and the
/// current mesh's buffers from the sampling camera (for the stitcher: stitch with
/// fishboneSamplingCamera(params.camera, fishbone) and currentBuffers.faceId).
struct FishboneScanResult {
    FishboneGrid fishbone; ///< the traced grid, in pixels of the scan image (camera.width × height)
    SampleGrid grid;       ///< the samples; grid.camera is the sampling camera (fitted clipping range)
    Patch patch;
    FrameBuffers currentBuffers; ///< the current mesh from the sampling camera
    int samplingFactor = 1;      ///< k actually used (FishboneParams::samplingFactor)
    FishboneCounts counts;
    FishboneTimings timings;
};

/// Casts a ray from the eye through every present vertex of \p fishbone (Camera::ray of the buffers'
/// camera) onto \p reference: the face of \p referenceBuffers under the vertex's pixel is the first guess
/// (then the faces under the 8 neighbouring pixels, nearest hit), and RayCaster::intersect with that hint
/// (local search, AABB fallback) answers the rest. As RayCaster's hinted query, a guess is trusted to be
/// unoccluded unless `search.verifyUnoccluded` (then every ray goes through the caster). Returns a SampleGrid
/// of the same rows × cols whose sample (r, c) has screen = the rib vertex and the rest from
/// setSampleOnSurface; absent vertices and misses are not hit. \p hintHits (optional) receives how many hits
/// lie on the hint face itself. \pre \p caster holds \p reference and \p referenceBuffers were rendered from
/// it. \throw InvalidInputError when the buffers' sizes do not match their camera.
SampleGrid rayCastFishbone(const FishboneGrid& fishbone, const FrameBuffers& referenceBuffers,
                           const Mesh& reference, const RayCaster& caster, const ScanOptions& options = {},
                           const LocalSearchOptions& search = {}, std::size_t* hintHits = nullptr);

/// The sampling image's divisor k for a fishbone scan with \p fishbone on the scan camera \p scan
/// (FishboneParams::samplingFactor): the explicit factor when one is given, else the largest integer
/// k ≤ h dividing both width and height (1 when h < 2).
/// \throw InvalidInputError when an explicit factor does not divide the scan's width and height, exceeds h,
///        or is negative.
int fishboneSamplingFactor(const Camera& scan, const FishboneParams& fishbone);

/// The camera a fishbone scan samples with: \p scan at (width/k) × (height/k), k =
/// fishboneSamplingFactor(scan, fishbone), with the same frustum (so screen point p of the scan image is
/// p/k of the sampling image); \p scan itself when k = 1. The stitcher takes this camera with
/// FishboneScanResult::currentBuffers. \throw as fishboneSamplingFactor.
Camera fishboneSamplingCamera(const Camera& scan, const FishboneParams& fishbone);

/// Runs one fishbone scan (see the file comment); parallel to scanPatch, with the same renderer contract
/// (\p referenceRenderer holds \p reference, \p currentRenderer \p current; pass the same renderer and
/// `current == reference` for the first scan, which skips the quality mask). Triangulation accepts edges
/// up to `params.triangulate.maxEdgeFootprints · h/k` footprints of the sampling camera (grid edges are h
/// pixels of the scan image long, h/k of the sampling image). All positions in \p params and \p fishbone
/// (seed, key-ribs, drawn curves, lasso) are in pixels of the scan image; the scan itself runs on the
/// sampling image (FishboneParams::samplingFactor, fishboneSamplingCamera).
/// \throw InvalidInputError with one sentence when: \p params are invalid (ScanParams::validate);
///        \p fishbone is (FishboneParams::validate: h not in [0.5, min(W, H)/4], neither a seed nor a drawn
///        backbone, the seed outside the image, one key-rib, ...); the seed lies on the background, or on a
///        flat / isotropic region; two key-ribs fall on one backbone sample, or one lies farther than 2h from
///        the backbone; the backbone has fewer than two samples; or nothing is left to triangulate.
///        CancelledError through \p progress.
FishboneScanResult scanFishbonePatch(const Mesh& reference, MeshRenderer& referenceRenderer,
                                     const Mesh& current, MeshRenderer& currentRenderer,
                                     const ScanParams& params, const FishboneParams& fishbone,
                                     FishboneCache& cache, const Progress& progress = {});

} // namespace fss
