#pragma once
// Internal (not installed): a step of `fss-remesh auto` (auto_remesh.h, step 7) after the last scan. The
// regular scans sample the reference on pixel grids that do not follow its sharp creases, and the views'
// regions meet at the creases, so the seams run along them: the faces there cut the creases off (a bevel up
// to about half an edge length deep), which is where the largest distances to and from the reference lie.
// snapToCreases recovers the creases locally, as feature-preserving remeshers do with a feature skeleton.
// Each round: the vertex nearest each corner of the creases (where three or more meet, or one ends) moves
// onto it; vertices near a crease of the reference move onto it (vertices near one but left off the reference
// move onto the reference); vertices of valence 3 whose faces stand off the reference are removed; faces
// turned over against the reference (folds the stitches leave at a crease) and faces near a crease still far
// from the reference are repaired by a flip, a move onto the crease or a collapse; edges that cross a crease
// far from any vertex are split at the crease; and edges are flipped to the diagonal that follows the crease.
// Each operation is taken only where it brings the faces it changes closer to the reference (or unfolds
// them). auto runs it between two seam relaxations (seam_relax.h): the second one keeps the vertices put on a
// crease where they are.
#include "fss/mesh.h"

#include <cstddef>

namespace fss::detail {

/// Name of the `bool` vertex property snapToCreases sets on the vertices it put on a crease: the seam
/// relaxation keeps them where they are (seam_relax.h). Internal; autoRemesh removes it from its result.
inline constexpr const char* kOnCreaseProperty = "v:fss_on_crease";

/// Options of snapToCreases.
struct CreaseSnapOptions {
    /// Target edge length of the mesh (world units): the scale of every distance below.
    double edgeLength = 1.0;
    /// Reference edges whose two faces' normals differ by more than this (degrees) form the creases.
    double creaseAngleDeg = 35.0;
    /// A vertex within this many edge lengths of a crease may move onto its closest crease point.
    double snapRadius = 0.5;
    /// No operation makes an angle smaller than the smaller of this and the smallest angle of the faces it
    /// replaces (degrees).
    double minAngleDeg = 10.0;
    /// Faces farther from the reference than this many edge lengths (sampled; looked for within 1.5 edge
    /// lengths of a crease and where a face's centroid is off the reference by a tenth of one) are repaired
    /// (a flip, a move onto the crease, a collapse) or get their longest edge split at the reference (at the
    /// crease when it passes within the snap radius), where that brings them closer.
    double errorSplitDistance = 0.15;
    /// Rounds of (snaps, splits, flips); 0 = nothing.
    int rounds = 3;
    /// The caller knows that the mesh does not intersect itself (PMP::does_self_intersect is false: a
    /// whole-mesh test of exactly this mesh, or a stage that keeps a free mesh free, said so, e.g.
    /// SeamRelaxReport::freeAfter): snapToCreases skips its own whole-mesh test on entry.
    bool knownFree = false;
};

/// What snapToCreases did.
struct CreaseSnapReport {
    std::size_t creaseEdges = 0; ///< reference edges above the crease angle
    std::size_t snaps = 0;       ///< vertices moved onto a crease
    std::size_t splits = 0;      ///< edges split at a crease (one new vertex each)
    std::size_t flips = 0;       ///< edges flipped
    /// Vertices of valence 3 removed (their three faces merged into one closer to the reference).
    std::size_t removals = 0;
    /// Faces turned over against the reference, or far from it, repaired by a flip or a collapse.
    std::size_t repairs = 0;
    /// Rounds whose result intersected itself (while the mesh before did not) and were undone.
    int roundsReverted = 0;
    /// The mesh returned does not intersect itself (PMP::does_self_intersect is false): it did not on entry
    /// and every round kept was tested on the whole mesh (a round undone leaves the mesh before it).
    bool freeAfter = false;
};

/// Brings the faces of \p mesh near the creases of \p reference onto them (see the file comment). Border
/// vertices never move; no edge between a face left from the input (props::faceScanId < 0) and a scanned
/// face is flipped, and no edge is collapsed or vertex removed unless all faces around it are of one kind,
/// so the scanned area changes only as much as a vertex moved onto a crease or a split shifts it. Every
/// moved or new vertex lies on a crease of the reference (or a corner of them), or (a vertex near a crease
/// that was off the reference by more than edgeLength / 10, a split or collapse away from a crease) at its
/// closest reference point.
/// The repairs of faces turned over or far from the reference (CreaseSnapReport::repairs) take the first
/// operation after which no face there is turned over (normal against the reference's normal at the point
/// closest to its centroid), no angle is below the floor (or the smallest one before), and the largest
/// distance to the reference is no larger (turned over) or smaller by a fifth (far). The other operations:
/// Each operation must not raise the largest distance to the reference of the faces it changes and must
/// lower their integrated squared distance (both sampled at centroids, edge midpoints and three inner
/// points; a flip by a fifth at least, and only where its two faces are farther than edgeLength / 50 from
/// the reference, so that flips follow creases rather than noise), keep every new face's normal within 90°
/// of the faces it replaces (or the new face within edgeLength / 10 of the reference and within 60° of its
/// normal there: the faces a bevel folds over say nothing of the surface's side), create no angle below the
/// floor (CreaseSnapOptions::minAngleDeg), and keep the mesh a valid edge-manifold triangle mesh (flips: no
/// existing edge, valence ≥ 3). An operation after which the faces within two vertex rings of it intersect
/// each other is undone at once; a round whose result still intersects itself (while the mesh before did not)
/// is undone as a whole. New faces keep the scan id and quality of the face they split. The vertices put on a
/// crease get the property kOnCreaseProperty (true). \p mesh is garbage collected on return. \pre \p mesh is
/// a valid triangle mesh; \p reference is a triangle mesh (the surface \p mesh approximates).
CreaseSnapReport snapToCreases(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& options);

} // namespace fss::detail
