#pragma once
// Internal (not installed): auto v2 (issue 23, auto_remesh.h AutoEngine::V2) and the pieces of auto v1 it
// shares (view framing, the partition of the surface among the views).
#include "fss/auto_remesh.h"
#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/progress.h"
#include "fss/raycast.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace fss::detail {

/// A parallel camera looking along -\p from that frames \p points (plus \p margin) with square pixels of
/// side \p footprint (auto_views.cpp).
Camera frameParallelView(const Eigen::Vector3d& from, const std::vector<Eigen::Vector3d>& points,
                         double footprint, double margin);

/// The partition of the reference surface among the views whose reference buffers are \p views: label[f]
/// is the owning view or -1 (auto_views.cpp).
std::vector<int> partitionSurface(const Mesh& reference, const std::vector<FrameBuffers>& views,
                                  double maxAngleDeg, double beta, double minIslandArea, int rounds);

/// The greedy Gauss-map view plan of auto v1 (unit view directions, towards the eye).
std::vector<Eigen::Vector3d> planViews(const Mesh& reference, double servedAngleDeg, double minAreaFraction,
                                       int maxViews);

/// Flips edges between nearly coplanar faces where that raises the smaller smallest angle of faces whose
/// smallest angle is below \p belowDeg (auto_remesh.cpp, flipSlivers). Returns the flips.
std::size_t flipSliverFaces(Mesh& mesh, double belowDeg, double maxDihedralDeg, int rounds);

/// What the joined mesh of auto v2 must match (the reference's topology and the target's vertex count).
struct JoinTarget {
    bool closed = true;            ///< no boundary edge (the reference is closed)
    std::size_t components = 1;    ///< connected components (faces connected by edges), the reference's
    std::size_t boundaryLoops = 0; ///< boundary loops, the reference's
    double vertices = 0;           ///< the target's vertex count; the mesh must be within 10 % of it
    /// The reference's Euler characteristic V − E + F (its genus, with the loops and components); none:
    /// not checked. A hole filling that caps both ends of a gap around a handle keeps the loop and component
    /// counts and cuts the handle (measured on rotor_small).
    std::optional<long> eulerCharacteristic;
    /// The reference, to check that every vertex and face centroid lies within maxDistance of it; none: not
    /// checked (a cap the hole filling laid over a gap far from the surface, measured on rotor_small: 5 L).
    const RayCaster* reference = nullptr;
    double maxDistance = 0;
    /// Points of the reference (its vertices and face centroids) that must each lie within
    /// maxDistanceFromInput of the mesh: the one-sided distance from the input, which catches the parts of
    /// the input the mesh does not cover (measured on mech-holes-shark: a gap between two patches joined to
    /// a hole's border and left open, the loop count right); none: not checked.
    const std::vector<Eigen::Vector3d>* inputSamples = nullptr;
    double maxDistanceFromInput = 0;
};

/// The points of \p reference whose distance to a join validateJoin bounds: its vertices and face centroids.
std::vector<Eigen::Vector3d> inputSamples(const Mesh& reference);

/// Why \p mesh is not an acceptable result of auto v2 (an empty string when it is): a boundary loop or
/// connected component count other than \p target's, another Euler characteristic (genus), a vertex count
/// more than 10 % off (parts of the surface not sampled), open when it must be closed, a pinched vertex, a
/// degenerate face, a vertex or face centroid farther than target.maxDistance from the reference, a point of
/// target.inputSamples farther than target.maxDistanceFromInput from the mesh, a self-intersection. The first
/// failure found is named, in that order.
/// \p knownFree: the caller knows that \p mesh does not intersect itself (PMP::does_self_intersect is false:
/// a whole-mesh test of exactly this mesh, or a stage that keeps a free mesh free, said so); the whole-mesh
/// self-intersection count, the slowest check, is then skipped (its answer is 0). \p freeAfter, when not
/// null, is set to whether \p mesh is known not to intersect itself: knownFree, or no pair and no degenerate
/// face counted (whatever else failed), so that the next stage can skip its own test.
std::string validateJoin(const Mesh& mesh, const JoinTarget& target, bool knownFree = false,
                         bool* freeAfter = nullptr);

/// autoRemesh with AutoEngine::V2 (auto_v2.cpp). Throws what autoRemesh throws; returns a result whose
/// engineUsed is V1 (and engineNote the reason) when the V2 mesh failed validation and \p fallback ran.
AutoResult autoRemeshV2(const Mesh& reference, const AutoOptions& options, const Progress& progress);

/// The target edge length of both engines: options.edgeLength, else the one that gives
/// options.targetVertices (else \p inputVertices) vertices on \p area (edgeLengthForVertexCount).
double targetEdgeLength(double area, const AutoOptions& options, std::size_t inputVertices);

} // namespace fss::detail
