#pragma once
/// \file auto_remesh.h
/// Automatic full-surface remeshing by virtual range scanning (`fss-remesh auto`): the scans a person
/// would take in the GUI, chosen without one.
///
///  1. **Resolution from the edge length.** Every regular scan uses a parallel camera whose pixel footprint
///     is the target edge length L, so a frontal region gets edges of length L. L is given, or derived from
///     a target vertex count N through the area A of the reference: a regular triangulation has about 2N
///     triangles of area (√3/4)·L², so A ≈ N·(√3/2)·L².
///  2. **Views from the Gauss map.** The initial views are chosen greedily over a dense set of directions
///     on the sphere: each next view is the direction that sees, nearly frontally, the largest area of the
///     reference not yet served by an earlier view (normals only, occlusion ignored). CAD faces get exactly
///     frontal views; curved regions get more views, about one per cone of normals.
///  3. **One region per view.** The reference surface is partitioned among the initial views: each face goes
///     to the view that sees it (not occluded) most frontally, then the labelling is smoothed (a Potts energy
///     minimised by iterated conditional modes: sampling-angle cost against border length) and small islands
///     join their neighbours, so the regions are few and compact with short borders. Each view's scan keeps
///     only the samples on its region plus a margin of a few pixels over its neighbours and replaces whatever
///     is there, so every region is covered once by one regular grid and the seams run along the borders.
///     Each patch is stitched in at once (stitch.h). Where the stitch trimmed a patch, the same view then
///     rescans what its region still has from the input, on the same pixel grid (the fill pass).
///  4. **Coverage-driven follow-up views.** Faces still left from the input (props::faceScanId < 0) are
///     grouped into connected regions; for each, several directions around its mean normal are rendered and
///     the one that sees most of the region (occlusion included) is scanned, framed on the region, and
///     allowed to replace the faces next to it so that no thin strip of input faces survives. Repeated
///     until the coverage goal, the view budget, or no progress.
///  5. **Feature lines (optional, `fishbone`).** Sharp edges (dihedral angle above a threshold) are chained
///     into polylines between corners; each long enough chain is scanned first with a fishbone grid whose
///     hand-drawn backbone is the chain projected into a view that sees both sides of the edge, inside a
///     band-shaped lasso around it, so that samples lie on the feature line itself.
///
///  6. **Seam relaxation.** The scan grids' interiors are regular; the irregular vertices sit on the seams
///     between patches and on the faces left from the input. Like the paper's zippering, which ends by
///     optimising the seam, the last step improves that zone only (vertices with a valence ≠ 6, on faces of
///     two scans or of the input, and one ring around them): zone vertices left off the reference by the
///     stitches' collapses go back onto it where their faces allow; then, a few rounds of edge flips that
///     lower the number of irregular vertices among the four they change (or keep it and bring the
///     valences closer to 6), edge collapses that do the same (the merged vertex on the reference), and
///     tangential smoothing of the zone's vertices projected back onto the reference (closest point).
///     Feature edges (featureAngleDeg) are never flipped or collapsed and their vertices stay where they
///     are (unless off the reference); edges between an input face and a scanned one stay (no operation
///     mixes the two, so the coverage stays); no flip, collapse or move makes an angle below
///     seamRelaxMinAngleDeg (or the smallest one already there), turns a face's normal by more than the
///     stitch's maxNormalChangeDeg, or takes faces farther from the reference than they were (beyond L/20).
///     A stage of the relaxation (a round's flips, collapses or smoothing) after which the mesh would
///     intersect itself is undone and run again without touching the vertices of the intersecting faces
///     (up to three times), then, if it still would, undone and not run again. Closedness and manifoldness
///     are kept; only collapses lower the vertex count (towards the target: the seams have more vertices than
///     a regular grid).
///  7. **Crease recovery.** The views' regions meet at the sharp creases of the reference, so the seams run
///     along them, and neither pixel grid has vertices on them: the faces there bevel the creases off by up
///     to half an edge length, where the largest distances to and from the reference were. The vertex
///     nearest each corner of the creases (where three meet or one ends) moves onto it, vertices within L/2
///     of a crease (reference edges above featureAngleDeg) move onto it, vertices of valence 3 standing off
///     the reference are removed, edges that still pass a crease at a bevel are split at the crease, and
///     edges are flipped to the diagonal that follows it; each operation only where it does not raise the
///     largest distance of the faces it changes to the reference and lowers their integrated squared
///     distance, makes no angle below the stitch's minAngleFloorDeg (or the smallest already there), turns no
///     face over and makes the faces around it intersect no other (else it is undone at once; a round that
///     still makes the mesh intersect itself is undone as well). Vertices near a crease but off the reference
///     by more than L/10 (left inside a bevel by the stitches) go onto their closest reference point under
///     the same conditions. Faces turned over against the reference (folds the stitches leave at a crease)
///     and faces still farther than 0.15 L from it (looked for within 1.5 L of a crease and where a face's
///     centroid is off the reference by L/10: across a crease or a sharp bend) are repaired by the first
///     flip, move onto the crease or edge collapse that leaves no face there turned over, no new angle below
///     the floor and (for the far ones) a largest distance smaller by a fifth. No edge between a face left
///     from the input and a scanned one is flipped or collapsed. The seams are then relaxed once more (step
///     6), with the vertices put on a crease kept where they are.
///
/// Every stitch has the strong guarantee: a scan or stitch that fails is skipped (and reported), the mesh
/// is never left invalid.

#include "fss/camera.h"
#include "fss/mesh.h"
#include "fss/progress.h"
#include "fss/session.h"
#include "fss/stitch.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fss {

/// Which design autoRemesh runs.
enum class AutoEngine {
    /// Scan and stitch view after view (the file comment's steps 1-7): cost grows as views x stitch.
    V1,
    /// Issue 23: every region of the partition is sampled once with the triangular lattice at the same world
    /// spacing (regions in parallel), the patches are joined in ONE pass (the gaps between them closed by an
    /// advancing front over their boundaries, a zipper), then seams relaxed and creases recovered once. The
    /// result is validated (closed when the reference is, manifold, no self-intersections, no degenerate
    /// faces); when it fails, V1 runs instead and AutoResult::engineNote says why.
    V2,
};

/// Options of autoRemesh. Defaults are the command line's.
struct AutoOptions {
    /// The design to run (AutoEngine).
    AutoEngine engine = AutoEngine::V1;
    /// V2 only: run V1 when the V2 result fails validation (true), or return the V2 result with
    /// AutoResult::engineNote saying what is wrong with it (false: for diagnosis; the mesh may then be open,
    /// pinched or self-intersecting).
    bool fallbackToV1 = true;
    /// Target edge length in world units; 0 = derive it from targetVertices.
    double edgeLength = 0;
    /// Target vertex count when edgeLength is 0; 0 = the reference's vertex count.
    std::size_t targetVertices = 0;
    /// Scan chained sharp feature lines with fishbone grids first (see the file comment, step 5).
    bool fishbone = false;
    /// Renderer of the reference and the current mesh; empty = CpuMeshRenderer.
    RendererFactory renderer;
    /// A face counts as served by a view when the angle between its normal and the view direction is
    /// at most this (degrees); the greedy view plan stops when every face is served. In (0, 80].
    double servedAngleDeg = 40.0;
    /// A reference face may be owned by an initial view only when that view sees it (not occluded) at an
    /// angle between view ray and surface normal of at most this (degrees). In (servedAngleDeg, 85].
    double maxSamplingAngleDeg = 60.0;
    /// The same limit for the follow-up views.
    double followUpMaxSamplingAngleDeg = 70.0;
    /// Weight β of the region borders in the partition of the surface among the initial views, in edge
    /// lengths: a border of length ℓ costs β·L·ℓ against the sum of area·(1/cos θ − 1) of the faces (θ their
    /// sampling angle in the view that owns them). Larger: fewer, more compact regions and shorter seams.
    double partitionSmoothing = 0.5;
    /// Connected pieces of a view's region smaller than this area (in L²) join a neighbouring region.
    double minRegionArea = 60.0;
    /// Each initial view's patch extends this many pixels beyond its region, over its neighbours, so that
    /// the patches overlap and the stitch zippers each into the last (no strip of input faces between).
    int regionMarginPx = 2;
    /// Margin samples seen at a larger sampling angle (degrees) are left out: a margin reaching over a
    /// crease onto a face the view sees at a grazing angle makes a seam the stitch refuses. In (0, 85].
    double regionMarginMaxSamplingAngleDeg = 70.0;
    /// Passes in which every initial view rescans, on its own pixel grid, the parts of its region still left
    /// from the input (where the stitch trimmed its first patch), before the follow-up views.
    int regionFillPasses = 1;
    /// Faces whose served area share is below this fraction of the total area do not justify a view of
    /// their own in the initial plan (the follow-up views handle them).
    double minViewAreaFraction = 0.002;
    /// Stop adding follow-up views once this fraction of the area is remeshed.
    double coverageGoal = 0.999;
    /// Largest number of scans in total (initial + follow-up + fishbone).
    int maxViews = 80;
    /// Rounds of follow-up views.
    int followUpRounds = 4;
    /// Pixel footprint of the regular scans as a fraction of the edge length (a tilted surface is
    /// sampled more coarsely in one direction: < 1 compensates on average).
    double footprintRatio = 0.92;
    /// Dihedral angle (degrees between the two face normals) above which an edge is a sharp feature.
    double featureAngleDeg = 35.0;
    /// Feature chains shorter than this many edge lengths are not fishbone-scanned.
    double minFeatureLength = 6.0;
    /// Half width of the fishbone band (lasso) around a feature line, in edge lengths.
    double fishboneBandWidth = 2.5;
    /// Erosion / dilation radius of the scans' morphology.
    int morphologyRadius = 1;
    /// After the last scan, edges between two nearly coplanar faces (within 10°) are flipped where that
    /// raises the smallest angle of faces whose smallest angle is below this (degrees; 0 = no flips): seams
    /// leave such slivers when the stitch's angle floor is low.
    double flipSliversBelowDeg = 20.0;
    /// Rounds of seam relaxation after the last scan (file comment, step 6; 0 = none): each round flips the
    /// zone's edges to better valences, then smooths the zone's vertices once.
    int seamRelaxRounds = 4;
    /// No flip or move of the seam relaxation makes an angle smaller than the smaller of this and the
    /// smallest angle of the faces it changes (degrees, in [0, 60)).
    double seamRelaxMinAngleDeg = 20.0;
    /// The seam relaxation also collapses zone edges where that lowers the number of irregular vertices
    /// (the vertex count drops a little).
    bool seamRelaxCollapses = true;
    /// Rounds of crease recovery after the seam relaxation (file comment, step 7; 0 = none): each round
    /// snaps vertices onto the creases, splits edges at them, then flips edges to follow them.
    int creaseSnapRounds = 3;
    /// AutoEngine::V2 only: after the crease recovery, the faces whose smallest angle is below this (degrees;
    /// 0 = none) are repaired by local flips, collapses and tangential moves (sliver_repair.h).
    double repairSliversBelowDeg = 20.0;
    /// Options of every stitch. Faces with a smallest angle under 10° are refused (trimmed and retried), and
    /// trimming peels the patch boundary (StitchOptions::peelTrim): the regions of a small or strongly curved
    /// mesh are only a few pixels wide at the target edge length, and the wide trims cut them apart.
    StitchOptions stitch = defaultStitch();
    /// Quality-mask margin (mask.h QualityMaskOptions::margin) of the regular scans.
    double qualityMargin = 0.1;

    /// Checks every field's range: edgeLength finite and ≥ 0; servedAngleDeg in (0, 80];
    /// maxSamplingAngleDeg in (servedAngleDeg, 85]; followUpMaxSamplingAngleDeg and
    /// regionMarginMaxSamplingAngleDeg in (0, 85]; partitionSmoothing, minRegionArea and minFeatureLength
    /// finite and ≥ 0; regionMarginPx in [0, 16]; regionFillPasses, followUpRounds, seamRelaxRounds and
    /// creaseSnapRounds ≥ 0; minViewAreaFraction and coverageGoal in [0, 1]; maxViews ≥ 1; footprintRatio in
    /// (0.1, 4]; featureAngleDeg in [0, 180); fishboneBandWidth finite and > 0; morphologyRadius in
    /// [0, 1024]; flipSliversBelowDeg, seamRelaxMinAngleDeg and repairSliversBelowDeg in [0, 60);
    /// qualityMargin in [0, 1); stitch (StitchOptions::validate, named "AutoOptions::stitch.minAngleFloorDeg"
    /// ...). \throw InvalidOptionError naming the first field out of range and its range.
    void validate() const;

    /// StitchOptions with minAngleFloorDeg = 10, peelTrim on and the seam band remesh off (issue 19): auto
    /// has its own seam relaxation and crease recovery (steps 6–7) and a target vertex count, which the
    /// band's splits, graded from the patch's edges to the mesh's, do not aim at (measured with the band on:
    /// elephant 4649 vertices for a target of 2775, a cube's coverage 0.706 against 0.757; DESIGN.md §6.2).
    static StitchOptions defaultStitch() {
        StitchOptions s;
        s.minAngleFloorDeg = 10.0;
        s.peelTrim = true;
        s.remeshSeam = false;
        return s;
    }
};

/// What happened to one scan of autoRemesh.
struct AutoStep {
    /// Initial: a view's region; RegionFill: the same view rescanning what its region still has from the
    /// input (AutoOptions::regionFillPasses); FollowUp: a view aimed at faces still left from the input.
    enum class Kind { Initial, RegionFill, FollowUp, Fishbone };
    Kind kind = Kind::Initial;
    Camera camera;                     ///< the scan camera (width × height = resolution)
    std::int32_t scanId = -1;          ///< id on the faces it made (props::faceScanId)
    bool stitched = false;             ///< false: skipped, see `note`
    std::size_t patchFaces = 0;        ///< faces of the scan's patch
    std::size_t facesAdded = 0;        ///< faces the stitch added
    std::size_t facesRemoved = 0;      ///< faces the stitch removed
    std::size_t patchFacesTrimmed = 0; ///< patch faces the stitch left out (StitchReport::patchFacesTrimmed)
    double coverageAfter = 0;          ///< coverage after this step
    double seconds = 0;                ///< scan + stitch wall time
    std::string note;                  ///< why it was skipped or trimmed (empty when fully stitched)
};

/// The result of autoRemesh.
struct AutoResult {
    Mesh mesh;             ///< the remeshed surface (garbage collected)
    double edgeLength = 0; ///< the target edge length used (world units)
    double area = 0;       ///< area of the reference
    /// Fraction of the area of `mesh` made by scans (faces with props::faceScanId ≥ 0).
    double coverage = 0;
    std::size_t inputFacesLeft = 0; ///< faces of `mesh` left from the input
    double inputAreaLeft = 0;       ///< their area
    std::vector<AutoStep> steps;    ///< every scan attempted, in order
    int scansStitched = 0;          ///< steps with stitched == true
    int scansSkipped = 0;           ///< steps with stitched == false
    std::size_t featureChains = 0;  ///< feature chains found (fishbone only)
    std::size_t sliverFlips = 0;    ///< edges flipped after the last scan (AutoOptions::flipSliversBelowDeg)
    /// Edges flipped by the seam relaxation (AutoOptions::seamRelaxRounds; both passes, before and after
    /// the crease recovery).
    std::size_t seamFlips = 0;
    std::size_t seamCollapses = 0; ///< edges collapsed by the seam relaxation (both passes)
    std::size_t seamMoves = 0;     ///< vertex moves of the seam relaxation (both passes)
    std::size_t creaseSnaps = 0;   ///< vertices moved onto a crease of the reference
    std::size_t creaseSplits = 0;  ///< edges split at a crease of the reference
    std::size_t creaseFlips = 0;   ///< edges flipped to follow a crease
    /// Vertices of valence 3 removed where the face replacing their three lies closer to the reference.
    std::size_t creaseRemovals = 0;
    /// Faces turned over against the reference, or near a crease and far from it, repaired by a flip, a move
    /// onto the crease or a collapse.
    std::size_t creaseRepairs = 0;
    /// AutoEngine::V2: the sliver repair (AutoOptions::repairSliversBelowDeg): faces below the bound before
    /// and after it, its flips, collapses and moves.
    std::size_t sliversBefore = 0, sliversAfter = 0, sliverRepairFlips = 0, sliverCollapses = 0,
                sliverMoves = 0;
    /// True when a stage of the seam relaxation was undone because its result intersected itself.
    bool seamRelaxDiscarded = false;
    /// The design that made `mesh` (AutoOptions::engine, or V1 after a V2 run that failed validation).
    AutoEngine engineUsed = AutoEngine::V1;
    /// Why V2 fell back to V1 (empty otherwise).
    std::string engineNote;
    double seconds = 0;       ///< total wall time
    double planSeconds = 0;   ///< of which: view planning and coverage bookkeeping
    double scanSeconds = 0;   ///< of which: rendering, masks, triangulation
    double stitchSeconds = 0; ///< of which: stitching and the seam relaxation
    // Of stitchSeconds, with AutoEngine::V2 (0 with V1):
    double joinSeconds = 0;   ///< the one-pass join (gap closing, hole filling, repair)
    double relaxSeconds = 0;  ///< the sliver flips and the seam relaxation (both passes)
    double creaseSeconds = 0; ///< the crease recovery
    double sliverSeconds = 0; ///< the sliver repair
};

/// The edge length a regular triangulation with \p vertices vertices of a surface of area \p area has:
/// sqrt(area / (vertices · √3/2)). \throw InvalidInputError when area ≤ 0 or vertices = 0.
double edgeLengthForVertexCount(double area, std::size_t vertices);

/// Remeshes the whole visible surface of \p reference (see the file comment).
/// \param reference  a valid, consistently oriented, edge-manifold triangle mesh (closed or not).
/// \param options    see AutoOptions.
/// \param progress   fractions in [0, 1] with stages "plan", "scan i/n", "follow-up", "fishbone", "relax";
/// may
///                   cancel.
/// \return the remeshed mesh and a report; the mesh is valid after every step (strong guarantee of each
///         stitch), closed when the reference is.
/// \throw InvalidInputError when the reference is empty, not a triangle mesh, has no area, or an option is
///        out of range (one sentence naming it); CancelledError through \p progress; fss::Error from the
///        renderer factory.
AutoResult autoRemesh(const Mesh& reference, const AutoOptions& options = {}, const Progress& progress = {});

} // namespace fss
