#pragma once
// The validity every remeshed closed surface must have (DESIGN.md §5), checked on its fss::Metrics: closed,
// edge-manifold, one component, no degenerate faces, no self-intersections (CGAL PMP).
#include "fss/metrics.h"

#include <gtest/gtest.h>

#include <optional>

namespace fss::test {

inline void expectClosedValidMesh(const fss::Metrics& m) {
    EXPECT_TRUE(m.closed);
    EXPECT_EQ(m.boundaryEdges, 0u);
    EXPECT_EQ(m.nonManifoldVertices, 0u);
    EXPECT_EQ(m.components, 1u);
    EXPECT_EQ(m.degenerateFaces, 0u);
    EXPECT_EQ(m.selfIntersections, std::optional<std::size_t>(0));
}

} // namespace fss::test
