#pragma once
// Internal (not installed): the fishbone grid clipped at the lasso (issue 20,
// FishboneOptions::clipRibsAtLasso), for the fishbone scan (fishbone_scan.cpp).
#include "fss/fishbone.h"
#include "fss/mask.h"

#include <cstddef>

namespace fss::detail {

/// Clips every half-rib of \p grid at \p lasso (screen positions in the grid's pixels): outwards from the
/// backbone, at the first edge that leaves the lasso (the edge's first point where the polygon's non-zero
/// winding number falls to 0), the half-rib ends on the lasso curve: when the crossing lies at least
/// \p minLast of the edge from its inner vertex, the edge's outer vertex moves onto the crossing; otherwise
/// that vertex is dropped and the inner one moves onto the crossing (a last edge of 1 to 1 + minLast of its
/// length), unless the inner one is the backbone sample. Every vertex beyond is dropped. The moved vertices
/// lie 1e-3 px inside the crossing, so the lasso mask keeps them. Backbone samples outside the lasso are
/// left to the lasso mask. Returns the number of vertices dropped. \pre validateLasso(lasso) passes.
std::size_t clipRibsAtLasso(FishboneGrid& grid, const Lasso& lasso, double minLast);

} // namespace fss::detail

namespace fss {
struct SampleGrid;
}

namespace fss::detail {

/// Peels the ends of the half-ribs of a cast (and lasso-masked) open fishbone grid: the last usable sample
/// of a half-rib (valid and admissible, column ≠ \p backboneColumn) is dropped (admissible and valid
/// cleared) when a triangle of its quads with the rib's previous sample and a neighbouring row (split along
/// the triangulation's diagonal) has a 3D angle below \p minDeg; \p passes times, each on the ends the
/// previous left. Returns the number of samples dropped.
std::size_t peelSliverRibEnds(SampleGrid& grid, int backboneColumn, double minDeg, int passes);

} // namespace fss::detail
