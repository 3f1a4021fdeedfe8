#pragma once
// Internal (not installed): the sharp edges of a mesh and the crease chains they form, for everyone who
// follows creases: the fishbone scan's crease following (FishboneCache::creaseEdges), the crease recovery
// (crease_snap.h), the seam relaxation's feature edges (seam_relax.h) and `auto`'s fishbone scans along
// feature lines (auto_remesh.cpp).
#include "fss/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace fss::detail {

/// The sharp edges of \p mesh, as flags by edge index (number_of_edges() + number_of_removed_edges()
/// entries): 1 for an interior edge whose two faces' normals differ by more than \p angleDeg degrees (the
/// dihedral angle bound of CGAL::Polygon_mesh_processing::detect_sharp_edges, which decides it), 0 for every
/// other edge. Border edges are not sharp (detect_sharp_edges would mark them), nor is an edge next to a
/// degenerate face (zero normal, whose angle is undefined; detect_sharp_edges would mark it).
/// \pre \p mesh is a triangle mesh; 0 < angleDeg < 180.
std::vector<char> sharpEdges(const Mesh& mesh, double angleDeg);

/// The number of sharp edges at each vertex, by vertex index.
std::vector<int> sharpDegrees(const Mesh& mesh, const std::vector<char>& sharp);

/// The corners of the creases: vertices where a crease ends or branches (one sharp edge, or three and
/// more), in vertex order.
std::vector<VertexIndex> creaseCorners(const Mesh& mesh, const std::vector<char>& sharp);

/// A crease chain: a polyline of sharp edges.
struct CreaseChain {
    std::vector<Eigen::Vector3d> points;
    /// Mean of the bisectors of the two faces' normals along the chain, weighted by edge length (unit; zero
    /// when they cancel out).
    Eigen::Vector3d bisector{0, 0, 0};
    double length = 0; ///< sum of the edge lengths
};

/// The sharp edges chained into polylines between vertices where a chain ends or branches (sharp degree
/// ≠ 2), or where the next edge's bisector turns more than \p maxBisectorTurnDeg from the chain's mean
/// bisector so far (a chain stopped there goes on as a new one); then the closed loops. Every sharp edge
/// is in exactly one chain. Chains start in halfedge order: first from their ends, then the loops.
std::vector<CreaseChain> creaseChains(const Mesh& mesh, const std::vector<char>& sharp,
                                      double maxBisectorTurnDeg);

} // namespace fss::detail
