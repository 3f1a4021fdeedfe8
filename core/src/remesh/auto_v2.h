#pragma once
// Internal (not installed): auto v2 (issue 23, auto_remesh.h AutoEngine::V2) and the pieces of auto v1 it
// shares (view framing, the partition of the surface among the views).
#include "fss/auto_remesh.h"
#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/progress.h"

#include <Eigen/Core>

#include <vector>

namespace fss::detail {

/// A parallel camera looking along -\p from that frames \p points (plus \p margin) with square pixels of
/// side \p footprint (auto_remesh.cpp, frameParallel).
Camera frameParallelView(const Eigen::Vector3d& from, const std::vector<Eigen::Vector3d>& points,
                         double footprint, double margin);

/// The partition of the reference surface among the views whose reference buffers are \p views: label[f]
/// is the owning view or -1 (auto_remesh.cpp, partitionAmongViews).
std::vector<int> partitionSurface(const Mesh& reference, const std::vector<FrameBuffers>& views,
                                  double maxAngleDeg, double beta, double minIslandArea, int rounds);

/// The greedy Gauss-map view plan of auto v1 (unit view directions, towards the eye).
std::vector<Eigen::Vector3d> planViews(const Mesh& reference, double servedAngleDeg, double minAreaFraction,
                                       int maxViews);

/// Flips edges between nearly coplanar faces where that raises the smaller smallest angle of faces whose
/// smallest angle is below \p belowDeg (auto_remesh.cpp, flipSlivers). Returns the flips.
std::size_t flipSliverFaces(Mesh& mesh, double belowDeg, double maxDihedralDeg, int rounds);

/// autoRemesh with AutoEngine::V2 (auto_v2.cpp). Throws what autoRemesh throws; returns a result whose
/// engineUsed is V1 (and engineNote the reason) when the V2 mesh failed validation and \p fallback ran.
AutoResult autoRemeshV2(const Mesh& reference, const AutoOptions& options, const Progress& progress);

/// The target edge length of both engines: options.edgeLength, else the one that gives
/// options.targetVertices (else \p inputVertices) vertices on \p area (edgeLengthForVertexCount).
double targetEdgeLength(double area, const AutoOptions& options, std::size_t inputVertices);

} // namespace fss::detail
