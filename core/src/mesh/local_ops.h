#pragma once
// Internal (not installed): the guarded local operations on a triangle mesh that the stitch's seam
// optimisation (stitch.cpp), the crease recovery (crease_snap.h), the seam relaxation (seam_relax.h) and
// `auto`'s sliver flips (auto_remesh.cpp) share: the topological guards of an edge flip and an edge collapse,
// the split of an interior edge into four triangles (and its undo), and the guard of a vertex move (no face
// of its star turned over or given an angle below a floor). Each caller adds its own geometric criteria;
// every guard here is a pure test, so where a caller tests it among its own tests does not change the result.
#include "fss/mesh.h"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace fss::detail {

/// Whether the edge of \p h may be flipped keeping \p mesh a valid edge-manifold triangle mesh: it is not a
/// border edge, its two faces' opposite corners differ and are not joined by an edge yet, and both its ends
/// keep a valence of at least 3 (they have more than 3 edges now).
bool canFlip(const Mesh& mesh, HalfedgeIndex h);

/// Whether the edge \p e may be collapsed keeping \p mesh a valid edge-manifold mesh: it satisfies the link
/// condition (CGAL::Euler::does_satisfy_link_condition) and, when \p keepOppositeValence, the two vertices
/// opposite it have more than 3 edges (they lose one).
bool canCollapse(const Mesh& mesh, EdgeIndex e, bool keepOppositeValence = true);

/// What splitEdge made.
struct EdgeSplit {
    VertexIndex vertex;   ///< the new vertex
    HalfedgeIndex first;  ///< the new edge in the face of the split halfedge (from the new vertex)
    HalfedgeIndex second; ///< the new edge in the face of its opposite
};

/// Splits the interior edge of \p h (from a to b, faces (a, b, c) and (b, a, d)) at \p at: the faces become
/// (a, q, c), (q, b, c), (b, q, d), (q, a, d); afterwards \p h runs from the new vertex q to b. The face of
/// \p h keeps its index as one of (a, q, c), (q, b, c), as does the opposite face. \pre \p h is not a
/// border edge.
EdgeSplit splitEdge(Mesh& mesh, HalfedgeIndex h, const Point3& at);

/// Undoes splitEdge(mesh, h, …) that returned \p split, when nothing else changed since.
void undoSplitEdge(Mesh& mesh, HalfedgeIndex h, const EdgeSplit& split);

/// Whether moving vertex \p v to \p to keeps its star: no face of it becomes degenerate or was, none turns
/// its normal by more than \p maxTurn (radians), and the smallest angle of the star is not below the
/// smaller of \p floor (radians) and the smallest angle before.
bool moveKeepsStar(const Mesh& mesh, VertexIndex v, const Eigen::Vector3d& to, double maxTurn, double floor);

/// The pairs of intersecting faces of \p mesh of which one lies around a vertex of \p touched (CGAL PMP's
/// exact predicates, only the faces whose bounding boxes meet those faces' tested). When the mesh was free of
/// intersections before the faces around \p touched changed (and no other face did), these are all the pairs
/// PMP::self_intersections finds on the whole mesh, found in a fraction of its time.
std::vector<std::pair<FaceIndex, FaceIndex>> intersectionsAround(const Mesh& mesh,
                                                                 const std::vector<VertexIndex>& touched);

/// The corners of the faces of \p pairs (with repeats), e.g. the vertices a stage that made those
/// intersections leaves alone when it runs again.
std::vector<VertexIndex> cornersOf(const Mesh& mesh,
                                   const std::vector<std::pair<FaceIndex, FaceIndex>>& pairs);

} // namespace fss::detail
