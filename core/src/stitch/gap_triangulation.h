#pragma once
// Stitch v2, stage "gap triangulation" (DESIGN.md §6.2 step 3): the gap between the hole cut into the current
// mesh and the pulled-back patch, seen in the scan's view, is a planar polygon with holes whose boundary
// vertices are all kept. It is filled by a constrained Delaunay triangulation refined for quality with CGAL's
// 2D mesher (Steiner points in the interior only: no boundary edge is split, so the faces on either side of
// the gap stay as they are) and smoothed by Lloyd steps (CGAL's move function, vertices in a fixed order).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace fss::stitch {

/// The gap's boundary in the view (2D, front-facing triangles counter-clockwise).
struct GapBoundary {
    std::vector<Eigen::Vector2d> points;         ///< kept vertices (hole boundary, patch boundary, creases)
    std::vector<std::array<int, 2>> constraints; ///< edges that must appear (indices into points)
    /// One point inside every region bounded by the constraints that is NOT to be filled (inside each patch
    /// boundary loop, inside holes of the mesh). The region outside all constraints is never filled.
    std::vector<Eigen::Vector2d> excludeSeeds;
    /// Alternatively (when set): is a point inside the gap? Asked once per region bounded by the
    /// constraints, at the centroid of one of its triangles; the regions where it says no are not filled.
    std::function<bool(const Eigen::Vector2d&)> inside;
};

/// How the gap is filled.
struct GapOptions {
    /// Angle bound of the refinement (degrees, in the view). CGAL's mesher terminates for bounds up to about
    /// 20.7 deg with edge refinement; without it (our case) faces it cannot improve are left, so a higher
    /// bound only costs Steiner points.
    double minAngleDeg = 25.0;
    /// Target edge length at a point of the view (pixels); none (empty) means angles only.
    std::function<double(const Eigen::Vector2d&)> size;
    /// Lloyd iterations after the first refinement (0: none); the mesh is refined again afterwards.
    int lloydIterations = 10;
    /// Upper bound on Steiner points, as a multiple of the boundary's points (a safety net).
    double maxSteinerPerBoundaryPoint = 20.0;
};

/// The filled gap.
struct GapTriangulation {
    bool ok = false;
    std::string reason;                  ///< why not, when !ok (constraints crossing, …)
    std::vector<Eigen::Vector2d> points; ///< GapBoundary::points first (same indices), then Steiner points
    std::vector<std::array<int, 3>> triangles; ///< counter-clockwise in the view
    std::size_t boundaryPoints = 0;            ///< = GapBoundary::points.size()
};

/// Fills the gap (see GapBoundary). Input points not used by any constraint are kept as vertices too.
GapTriangulation triangulateGap(const GapBoundary& boundary, const GapOptions& options = {});

} // namespace fss::stitch
