#pragma once
/// \file stitch.h
/// Stitching (mesh zippering, Turk & Levoy 1994, as modified by Vorsatz et al., VMV 2000): a scanned patch
/// replaces the part of the current mesh it covers in the scan's view.
///
/// In the scan camera's view the problem is two-dimensional. The current mesh's faces under the patch
/// boundary (front-facing, not grazing, on the patch's sheet) are projected; the patch's boundary vertices
/// and edges are inserted into that projected triangulation as constraints (a constrained Delaunay
/// triangulation with exact predicates performs the paper's face / edge splits and edge flips); where a
/// patch boundary edge crosses a mesh edge the new vertex lies *on that mesh edge in 3D*, so the geometry
/// outside the patch does not move. A patch boundary vertex within snapping distance of an edge at the rim of
/// that region (typically a crease whose other face the view does not see) moves onto it and the face beyond
/// is split along the edge in its own plane, so no sliver is left between the patch and the crease. The mesh
/// faces inside the boundary are removed (those under the patch
/// whole), the patch is glued in sharing the boundary vertices, and the seam is optimised: short edges
/// collapsed, the pieces outside the patch refined towards the patch's edge length (new vertices on the old
/// surface), edges flipped for angles and valence — never flipping a face in the view, folding the surface
/// or moving a vertex. Every change is checked on a local copy before the mesh is modified.

#include "fss/camera.h"
#include "fss/mesh.h"
#include "fss/progress.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fss {

/// Options of stitchPatch. The defaults suit regular scans of 1 sample per pixel.
struct StitchOptions {
    /// Rings of vertices around the seam that the seam optimisation may change; the seamRings − 1 rings of
    /// mesh faces around the faces cut by the seam are opened to it too.
    int seamRings = 2;
    /// Improve the seam after gluing: by the strip refill when refillSeam is set, else (or where the refill
    /// cannot be made or fails the checks) by collapsing short seam edges and flipping edges for quality.
    bool optimiseSeam = true;
    /// Version 2 of the seam (DESIGN.md §6.2): the faces along the glued seam (the new faces with a vertex on
    /// the seam or next to it) are replaced by a constrained Delaunay triangulation of their region in the
    /// view, refined for quality (CGAL's 2D mesher, 25 deg in the view, no boundary edge split) and smoothed
    /// (CGAL's 2D Lloyd), with the strip's border and creases kept; new vertices lie on the glued surface
    /// (ray cast from the scan camera). Off by default: on fandisk's +y 256² scan it measured worse than
    /// version 1's repair (smallest seam angle 3.7 vs ≥ 10 deg; issue 19). Session files write it only when
    /// on ("refill_seam": true), so files without it replay as before.
    bool refillSeam = false;
    /// Version 2 of the seam, design B (DESIGN.md §6.2, stitch/band_remesh.h): after version 1's glue and
    /// repair, the band of new faces along the seam (both sides, about three rings wide) is remeshed in 3D on
    /// the glued surface: splits, collapses and flips towards the local edge length (graded from the patch's
    /// to the mesh's) and valence 6, tangential relaxation with projection; the band's border and creases
    /// stay. Where the band comes out worse than version 1 left it (smallest angle) or fails the checks,
    /// version 1's result is used. On by default (issue 19): better than version 1 on every untuned mesh
    /// measured (DESIGN.md §6.2). Session files (version 2) write it only when off ("remesh_seam": false).
    bool remeshSeam = true;
    /// Seam edges shorter than this × the patch's median edge length are collapsed. The same fraction of
    /// the local patch edge length (in pixels) is the distance within which a patch boundary vertex is
    /// snapped onto a mesh vertex or edge, and a mesh vertex onto a patch boundary edge.
    double collapseEdgeRatio = 0.4;
    /// Outside the patch, edges of the re-triangulated mesh faces near the seam are split (new vertices on
    /// the old surface) where longer than 4/3 × (the patch's median edge length + seamGrading × their
    /// distance from the seam): a graded transition from the patch to the mesh. 0 disables the refinement.
    double seamGrading = 1.0;
    /// A face made by the stitch whose smallest angle is below this (degrees) is not accepted (unless the
    /// triangle it comes from already had a smaller one): the patch is trimmed there and retried.
    double minAngleFloorDeg = 1.0;
    /// A floor (degrees) for the pieces of mesh faces outside the patch only (slivers between the patch
    /// boundary and an old edge the seam cannot change, e.g. at a crease): below it the patch is trimmed
    /// there and retried. The larger of this and minAngleFloorDeg applies to those pieces. Off (0) by
    /// default: such pieces are often thin by nature (a big face of a coarse mesh cut near a corner by the
    /// patch boundary, its old vertices fixed) and then only trimming satisfies a floor; 10 brings the
    /// fandisk seam test's angles within bounds (smallest 11.1 deg) at the cost of trimming more of the
    /// patch, and makes coarse meshes (icosphere level 3) refuse whole patches.
    double outsideMinAngleFloorDeg = 0.0;
    /// Current-mesh faces seen at a larger angle between normal and view ray (degrees) are not stitched to;
    /// the patch is trimmed away from them.
    double maxViewAngleDeg = 85.0;
    /// A seam collapse or flip may turn no face normal by more than this (degrees): no folds.
    double maxNormalChangeDeg = 20.0;
    /// A patch boundary vertex whose distance to the current surface along its view ray exceeds this × (the
    /// longest edge of the face under it + the patch's median edge length) is trimmed: the patch does not
    /// belong to that surface there (an occluder, another sheet).
    double maxGapRatio = 0.25;
    /// Rounds of trimming a component (removing the patch faces at places that cannot be stitched safely)
    /// before it is skipped.
    int maxTrimRounds = 16;
    /// How a problem at the patch boundary is trimmed. Off: every patch vertex near it (at a fold of the mesh
    /// under the boundary, of the patch triangles within the snapping distance plus one patch edge of the
    /// hidden face) goes, with all its faces, a band two to three edges wide per round. On (peeling): only
    /// the patch's boundary vertices among those go (when there are any), and at a fold only the patch
    /// triangles within the snapping distance of the hidden face count: one layer of faces per round, the
    /// boundary moving off the problem in as many rounds as it takes. Wide bands cut thin patches apart into
    /// pieces too small to stitch; peeling keeps them (autoRemesh: CGAL's elephant goes from 0.635 to 0.755
    /// of its area remeshed, bunny00 from 0.979 to 0.991). Off by default so that sessions replay to the same
    /// mesh.
    bool peelTrim = false;
    /// Components (and pieces left by trimming) with fewer faces are not stitched: a few isolated triangles
    /// only add seam.
    std::size_t minComponentFaces = 8;
    /// Call collect_garbage() on the mesh at the end (renumbers all indices, O(mesh)). When false the
    /// removed elements stay as garbage that later additions reuse.
    bool collectGarbage = false;
    /// Test hook: makes the final check of every component fail, to exercise the strong guarantee.
    bool failValidationForTesting = false;

    /// Checks every field's range: seamRings ≥ 0, collapseEdgeRatio in [0, 0.5), seamGrading ≥ 0,
    /// minAngleFloorDeg and outsideMinAngleFloorDeg in [0, 30), maxViewAngleDeg in (0, 90),
    /// maxNormalChangeDeg in [0, 180], maxGapRatio > 0, maxTrimRounds ≥ 0, minComponentFaces ≤ 2^63 − 1
    /// (every number finite). stitchPatch and the session-file reader call it, so the two accept the same.
    /// \throw InvalidOptionError naming the first field out of range and its range
    ///        ("StitchOptions::minAngleFloorDeg must be in [0, 30), not 45.").
    void validate() const;
};

/// What stitchPatch did.
struct StitchReport {
    std::size_t facesRemoved =
        0;                      ///< faces of the current mesh replaced ("faces replaced" of the seam report)
    std::size_t facesAdded = 0; ///< faces added (patch faces, re-triangulated pieces around the seam)
    std::size_t seamEdges = 0;  ///< edges of the final seam (patch boundary ↔ old mesh)
    double seamLength = 0;      ///< 3D length of the seam
    /// Smallest angle (degrees) of the new faces touching the seam (180 when none). After a strip refill the
    /// faces touching the seam are the new faces with a vertex in the refilled strip.
    double seamMinAngleDeg = 180;
    /// Fraction of the faces touching the seam whose smallest angle is ≥ 25°.
    double seamFracMinAngleAbove25 = 1;
    /// Fraction of the faces touching the seam whose smallest angle is ≥ 30° (issue 19's target: ≥ 0.98).
    double seamFracMinAngleAbove30 = 1;
    std::size_t seamFaces = 0; ///< number of faces touching the seam
    /// Seam vertices (after a strip refill: every vertex of the refilled strip, its border included; else
    /// the vertices of the seam line), counted once per stitched piece.
    std::size_t seamVertices = 0;
    /// Valence histogram of the seam vertices: seamValenceHistogram[k] of them have k edges (empty when
    /// there are none; the last entry is the largest valence).
    std::vector<std::size_t> seamValenceHistogram;
    /// Fraction of the seam vertices of valence 5, 6 or 7 (1 when none; issue 19's target: ≥ 0.9).
    double seamFracValence5To7 = 1;
    /// Patch components glued in (wholly or the part left by trimming).
    int componentsStitched = 0;
    /// Patch components left out entirely, each with a sentence in `skipped`.
    int componentsSkipped = 0;
    /// Pieces glued in (a component trimmed apart counts each piece).
    int piecesStitched = 0;
    /// Patch faces left out (trimmed, dropped, or in skipped components).
    std::size_t patchFacesTrimmed = 0;
    std::size_t collapses = 0; ///< seam edge collapses performed
    std::size_t flips = 0;     ///< seam edge flips performed
    /// One sentence per skipped component (and one for patch faces dropped as back-facing).
    std::vector<std::string> skipped;
    double seconds = 0; ///< wall time
};

/// Zippers \p patch into \p current (DESIGN.md §1 "Stitch", §6).
///
/// \param current  the mesh being remeshed; a valid, consistently oriented, edge- and vertex-manifold
///                 triangle mesh (it may have boundary and garbage).
/// \param patch    the scan's patch: triangles facing \p scanCamera, edge-manifold, possibly with holes and
///                 several components; face properties props::faceQuality / props::faceScanId are copied
///                 into \p current when present (and created there with kInputFaceQuality / -1 for the
///                 existing faces).
/// \param scanCamera the camera of the scan that produced the patch.
/// \param options  see StitchOptions.
/// \param faceIds  optional ID buffer of \p current from \p scanCamera (width × height, row 0 at the top,
///                 FrameBuffers::kNoFace for background): finds the faces under the patch in time
///                 proportional to the patch. When empty, the faces are found by projecting all faces of
///                 \p current (O(mesh)).
///
/// Each patch component (connected through vertices) is stitched on its own: the region under it is
/// re-triangulated in the view, the result is checked on a local copy (edge- and vertex-manifold,
/// consistently oriented, no degenerate or needle faces, every new face facing the camera (pieces of a face
/// the view does not see keep that face's plane and orientation), no new self-intersections among the touched
/// faces and their neighbours, border edges — so holes, boundary loops and closedness — unchanged), the exact
/// sequence of edits is rehearsed on a second local copy, and only then applied. Where a component cannot be
/// stitched safely (it reaches past a silhouette, the mesh's border or a hole, a grazing face, a fold or
/// occlusion contour of the mesh in the view, another sheet), its patch faces there are trimmed and the rest
/// retried; a component that cannot be made stitchable is skipped and reported. Faces of \p current not under
/// the patch and not within seamRings of its seam keep their indices, vertices and positions. Removed
/// elements are left as garbage that later additions reuse (see StitchOptions::collectGarbage); face indices
/// of \p current therefore stay valid between calls.
///
/// \return what was done, with seam quality figures.
/// \throw InvalidInputError when the camera, the patch, the options (StitchOptions::validate, naming the
///        field) or the ID buffer are invalid, or when no component could be stitched (the sentence gives
///        the first reason). Strong guarantee: all checks of a component run before \p current is touched,
///        so an exception leaves \p current unchanged bit for bit (short of running out of memory while a
///        checked component is being applied).
/// \param progress reports (stage "stitch", fractions that never decrease, below 1 until the last component
///                 is applied) and may cancel: before each component and each trim round, and inside a
///                 component's computation every few thousand elementary operations (faces visited,
///                 triangulation insertions, seam collapses and flips, …), so even a patch that is one big
///                 component stops after a bounded amount of work.
/// \throw CancelledError when \p progress asks to stop. A component is computed and checked without touching
///        \p current and then applied without asking \p progress, so a cancel abandons the component being
///        computed and never interrupts an application: \p current is then a valid mesh that holds the
///        components glued in before (if any) — every invariant holds, but it is not the mesh of before the
///        call unless the cancel came during the first component's computation. Callers that need all or
///        nothing stitch a copy (Session::accept does).
/// \param stitchedPatchFaces optional: set to one entry per face index of \p patch, 1 for the faces glued in
///                 (what will replace the mesh), 0 for those trimmed, dropped or in skipped components (the
///                 mesh stays as it was there); their count is patch.number_of_faces() −
///                 StitchReport::patchFacesTrimmed. Lets a caller show what a stitch keeps (a trial stitch on
///                 a copy).
StitchReport stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                         const StitchOptions& options = {}, std::span<const std::uint32_t> faceIds = {},
                         const Progress& progress = {},
                         std::vector<std::uint8_t>* stitchedPatchFaces = nullptr);

} // namespace fss
