#pragma once
// Stitch v2 (DESIGN.md §6.2): the seam strip is filled anew by construction. Given a draft of the stitched
// surface on a local mesh (the patch glued in, pieces of the old faces around it), the faces of a strip
// along the seam are replaced: their boundary, sharp edges (creases) and the vertices the caller keeps stay;
// the rest of the strip is filled by a constrained Delaunay triangulation with quality refinement in the
// scan's view (gap_triangulation.h) whose new vertices are lifted onto the draft surface by the scan camera's
// rays (lift.h). This file only computes the fill; the caller edits its mesh and validates the result.

#include "fss/camera.h"
#include "fss/mesh.h"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace fss::stitch {

/// What to refill and how.
struct StripRefillInput {
    const Mesh* mesh = nullptr;   ///< the local mesh holding the draft
    std::vector<FaceIndex> strip; ///< its faces to replace: front-facing, a height field in the view
    std::function<Eigen::Vector2d(VertexIndex)> uv; ///< view position of a vertex (lift.h: viewPoint)
    std::function<bool(VertexIndex)> keep;          ///< vertices that must stay (besides the strip boundary)
    const Camera* camera = nullptr;                 ///< the scan camera
    /// Edges between two strip faces whose normals differ by more than this (degrees) are creases: kept as
    /// constraints with their vertices.
    double creaseAngleDeg = 30.0;
    /// Angle bound of the refinement in the view (degrees).
    double minAngleDeg = 25.0;
    /// Largest edge length in the fill (pixels); 0: the longest boundary edge.
    double maxEdge = 0.0;
    int lloydIterations = 10;
};

/// The fill: vertices (kept ones first, then new ones) and triangles over them.
struct StripRefill {
    bool ok = false;
    std::string reason;                        ///< why not, when !ok
    std::vector<VertexIndex> kept;             ///< kept mesh vertices: fill vertices 0 … kept.size() − 1
    std::vector<Eigen::Vector3d> fresh;        ///< new vertices: fill vertices kept.size() …
    std::vector<Eigen::Vector2d> freshUv;      ///< their view positions
    std::vector<std::array<int, 3>> triangles; ///< counter-clockwise in the view
    std::vector<FaceIndex> parent;             ///< per triangle: the strip face under its centroid
};

/// Computes the fill of the strip (see StripRefillInput). !ok (with a reason) where the strip cannot be
/// filled this way: constraints crossing or touching in the view, a new vertex not over the strip.
StripRefill refillStrip(const StripRefillInput& input);

} // namespace fss::stitch
