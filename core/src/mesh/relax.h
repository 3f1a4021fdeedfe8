#pragma once
// Internal (not installed): tangential relaxation of chosen vertices of a mesh, each projected onto a
// reference surface (issue #20, item 2). The scan pipeline relaxes each new patch with it (scan_pipeline.h,
// ScanParams::relaxIterations): the lattice's triangles are equilateral on the screen, the surface
// foreshortens them, and relaxation rounds them on the surface without changing the connectivity, so
// the interior valences stay 6. Written for any set of vertices (a stitch's seam strip as well).
//
// Own code rather than CGAL's PMP::tangential_relaxation / PMP::angle_and_area_smoothing (CGAL 5.5):
// neither projects onto a *different* surface (the reference) while relaxing, nor refuses a move that
// would cross a crease of that surface, turn a face away from the scan camera or lower the local smallest
// angle; applying CGAL's relaxation and projecting afterwards lets vertices slide over creases onto the
// neighbouring sheet (measured in relax_test, see the report of issue #20).
#include "fss/camera.h"
#include "fss/mesh.h"

#include <cstddef>
#include <vector>

namespace fss::detail {

class LocalClosestPoint;

/// Options of relaxOnReference.
struct RelaxOptions {
    int iterations = 6;             ///< sweeps over the vertices; 0 = nothing
    double step = 0.6;              ///< fraction of the tangential way to the neighbours' centroid, (0, 1]
    double creaseAngleDeg = 35.0;   ///< reference edges whose faces' normals differ more are creases
    double maxNormalTurnDeg = 20.0; ///< a move may turn no incident face's normal by more (per move)
    double maxOffFootprints = 0.5;  ///< a tangential move may leave the reference by at most this, before
                                    ///< the projection (the surface curves away: the move is refused)
};

/// What relaxOnReference did.
struct RelaxReport {
    std::size_t vertices = 0; ///< vertices given
    std::size_t onCrease = 0; ///< of those, on a crease of the reference (they slide along it only)
    std::size_t moves = 0;    ///< accepted moves (a vertex counts once per sweep)
    std::size_t refused = 0;  ///< refused moves
};

/// Moves each of \p vertices (Gauss–Seidel sweeps, in the given order) a step towards the centroid of its
/// neighbours, tangentially to the reference surface (the normal of its reference face), and then onto
/// the reference: the closest point near its reference face (closestPointNear, raycast.h). A vertex that
/// lies on a crease edge of the reference (within 10⁻⁶ footprints) moves along that edge only. A move is
/// refused when it would
///  - leave the reference by more than maxOffFootprints × the vertex's footprint before the projection,
///  - land on a reference face whose normal differs from the vertex's first reference face by more than
///    creaseAngleDeg (it would cross a crease),
///  - turn an incident face's normal by more than maxNormalTurnDeg, make it degenerate or, with
///    \p facing, turn it away from that camera,
///  - lower the smallest angle of the vertex's incident faces.
/// So no face turns over, every moved vertex lies on the reference and the connectivity is unchanged.
/// \p hints[k] is a face of \p reference at vertices[k] (updated to the face it ends on); \p footprints[k]
/// a length scale of vertices[k] (the scan's pixel footprint there).
/// \p search, when given, is a LocalClosestPoint over \p reference with one ring (LocalSearchOptions{.rings
/// = 1}) that the caller keeps across calls (its rings are collected once; the same results).
/// \pre hints and footprints have one entry per vertex; \p mesh is a triangle mesh.
RelaxReport relaxOnReference(Mesh& mesh, const Mesh& reference, const std::vector<VertexIndex>& vertices,
                             std::vector<FaceIndex>& hints, const std::vector<double>& footprints,
                             const RelaxOptions& options, const Camera* facing = nullptr,
                             LocalClosestPoint* search = nullptr);

} // namespace fss::detail
