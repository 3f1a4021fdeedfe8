#pragma once
// Internal (not installed): the last step of `fss-remesh auto` (auto_remesh.h, step 6). The scans leave a
// mesh whose scan-grid interiors are regular (valence 6) and whose irregular vertices sit on the seams
// between patches, on the faces left from the input and around them. relaxSeams improves that zone only:
// valence-improving edge flips and collapses and tangential smoothing with projection onto the reference
// surface, as the paper's zippering ends by optimising the seam and as isotropic remeshing does (but no
// splits, and collapses only where they improve the valences).
#include "fss/mesh.h"

#include <cstddef>

namespace fss::detail {

/// Options of relaxSeams.
struct SeamRelaxOptions {
    /// Rounds of (flips, smoothing). 0 = nothing.
    int rounds = 4;
    /// Target edge length of the mesh (world units). A flip, collapse or move must keep the faces it makes
    /// as close to the reference as the ones it replaces, or within edgeLength / 20 (new edge midpoint for
    /// a flip, face centroids for collapses and moves).
    double edgeLength = 1.0;
    /// A flip or a move may not create an angle smaller than the smaller of this and the smallest angle
    /// of the faces it replaces (degrees).
    double minAngleDeg = 20.0;
    /// Largest angle between a new face's normal and the normal of the faces it replaces (degrees).
    double maxNormalChangeDeg = 20.0;
    /// Edges whose two faces' normals differ by more than this (degrees) are feature edges. Feature edges,
    /// border edges and the edges between a face left from the input (props::faceScanId < 0) and a scanned
    /// face are fixed: never flipped or collapsed; their vertices are not smoothed (a vertex off the
    /// reference by more than a tenth of edgeLength goes onto its closest reference point unless it is on
    /// an input face) and may absorb a free neighbour by a collapse. Every operation changes faces of one
    /// kind only (input or scanned), so the scanned area (the coverage) stays as it is. Vertices with the
    /// property kOnCreaseProperty (crease_snap.h) are fixed as well: they lie on a crease of the reference.
    double featureAngleDeg = 35.0;
    /// The zone: vertices with a valence ≠ 6, on faces of different scans or on faces left from the input
    /// (props::faceScanId < 0), grown by this many vertex rings. Only edges with all four vertices in the
    /// zone are flipped and only zone vertices move: the scan grids' regular interiors stay untouched.
    int zoneRings = 1;
    /// Also collapse zone edges (not between two fixed vertices) where that brings the valences closer to 6
    /// (lowers the vertex count a little). Flips and collapses are taken where they lower the number of
    /// vertices of valence ≠ 6 among the four they change, or keep it and lower the squared deviation.
    bool collapses = true;
    /// Smoothing step as a fraction of the way to the centroid of the neighbours, in (0, 1].
    double smoothingStep = 0.5;
    /// The caller knows that the mesh does not intersect itself (PMP::does_self_intersect is false: a
    /// whole-mesh test of exactly this mesh, or a stage that keeps a free mesh free, said so, e.g.
    /// CreaseSnapReport::freeAfter): relaxSeams skips its own whole-mesh test on entry.
    bool knownFree = false;
};

/// What relaxSeams did.
struct SeamRelaxReport {
    std::size_t zoneVertices = 0; ///< vertices in the zone
    std::size_t flips = 0;        ///< edges flipped
    std::size_t projected = 0;    ///< zone vertices off the reference moved onto it (before the rounds)
    std::size_t collapses = 0;    ///< edges collapsed
    std::size_t moves = 0;        ///< vertex moves accepted (a vertex counts once per smoothing sweep)
    /// True when a stage (the projection, or a round's flips, collapses or smoothing) still left the mesh
    /// intersecting itself, after its retries without the vertices of the intersecting faces, while the mesh
    /// before relaxSeams did not: that stage was undone (the counts are those of the stages kept) and that
    /// kind of stage was not run again.
    bool reverted = false;
    /// The mesh returned does not intersect itself (PMP::does_self_intersect is false): it did not on entry,
    /// so every stage kept was checked (the pairs of intersecting faces are all among those a stage changed
    /// and their neighbours, which are tested) and every stage undone left the mesh before it.
    bool freeAfter = false;
};

/// Improves the valences and the shapes of the faces on the seams of \p mesh (see SeamRelaxOptions) with
/// edge flips and vertex moves projected onto \p reference (closest point). Every flip keeps the mesh a
/// valid, oriented, edge-manifold triangle mesh (no flip creates an existing edge or a vertex of valence
/// < 3; collapses satisfy the link condition); border edges and their vertices are never touched. \p mesh
/// is garbage collected on return. A stage that creates self-intersections is undone and run again with the
/// vertices of the intersecting faces left alone (up to three times); if it still creates some, it is undone
/// and not run again (the other stages go on).
/// \pre \p mesh is a valid triangle mesh; \p reference is a triangle mesh (the surface \p mesh approximates).
SeamRelaxReport relaxSeams(Mesh& mesh, const Mesh& reference, const SeamRelaxOptions& options);

} // namespace fss::detail
