// auto v2's sliver repair (internal: core/src/remesh/sliver_repair.h) on a cube whose faces' grid vertices
// were pushed along the sides towards a neighbour (needles and caps on the flat sides, the creases intact):
// the repair raises the smallest angle above the bound, keeps the mesh closed, manifold, free of
// self-intersections and on the cube, keeps every vertex on a cube edge on one and the corners where they
// are; and the census sorts the slivers by where they lie.
#include "remesh/sliver_repair.h"

#include "mesh/triangle_geometry.h"

#include "fss/metrics.h"
#include "fss/raycast.h"
#include "fss/shapes.h"
#include "test_math.h"

#include "expect_valid_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

namespace {

using fss::Mesh;
using fss::VertexIndex;

/// How many of |x|, |y|, |z| of \p p are 1/2 (the cube [-1/2, 1/2]³): 1 inside a side, 2 on an edge, 3 at a
/// corner.
int sidesAt(const Eigen::Vector3d& p) {
    int n = 0;
    for (int i = 0; i < 3; ++i)
        n += std::abs(std::abs(p[i]) - 0.5) < 1e-9;
    return n;
}

double smallestAngleDeg(const Mesh& m) {
    double a = std::numbers::pi;
    for (fss::FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        a = std::min(a,
                     fss::detail::minAngle(fss::detail::pos(m, m.source(h)), fss::detail::pos(m, m.target(h)),
                                           fss::detail::pos(m, m.target(m.next(h)))));
    }
    return a * 180.0 / std::numbers::pi;
}

/// The cube with 8 × 8 quads per side, every third vertex inside a side moved in its side's plane 70 to 85 %
/// of the way to a neighbour inside the same side (seeded).
Mesh cubeWithSlivers(const Mesh& cube, unsigned seed) {
    Mesh m = cube;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> share(0.70, 0.85);
    std::size_t i = 0;
    for (VertexIndex v : m.vertices()) {
        const Eigen::Vector3d p = fss::detail::pos(m, v);
        if (sidesAt(p) != 1 || i++ % 3 != 0) continue;
        for (VertexIndex w : CGAL::vertices_around_target(m.halfedge(v), m)) {
            const Eigen::Vector3d q = fss::detail::pos(cube, w);
            if (sidesAt(q) != 1) continue;
            const Eigen::Vector3d to = p + share(rng) * (q - p);
            m.point(v) = fss::Point3(to.x(), to.y(), to.z());
            break;
        }
    }
    return m;
}

} // namespace

TEST(SliverRepair, CubeSliversAreRepairedWithTheCreasesKept) {
    const Mesh cube = fss::shapes::cube(8, 1.0);
    const fss::RayCaster caster(cube);
    for (unsigned seed : {1u, 2u, 3u}) {
        Mesh m = cubeWithSlivers(cube, seed);
        const double before = smallestAngleDeg(m);
        ASSERT_LT(before, 10.0);
        fss::detail::SliverRepairOptions o;
        o.edgeLength = 1.0 / 8;
        const fss::detail::SliverRepairReport r = fss::detail::repairSlivers(m, caster, o);
        const double after = smallestAngleDeg(m);
        std::printf("seed %u: smallest angle %.2f -> %.2f, slivers %zu -> %zu (%zu flips, %zu collapses, %zu "
                    "moves)\n",
                    seed, before, after, r.before, r.after, r.flips, r.collapses, r.moves);
        EXPECT_GT(r.before, 0u);
        EXPECT_EQ(r.after, 0u);
        EXPECT_GE(after, 20.0);
        EXPECT_TRUE(r.freeAfter);
        const fss::Metrics metrics = fss::test::metricsAgainst(m, cube);
        fss::test::expectClosedValidMesh(metrics);
        // On the cube: every vertex on its surface (the moves and collapses project onto it).
        for (VertexIndex v : m.vertices())
            EXPECT_GE(sidesAt(fss::detail::pos(m, v)), 1);
        // The creases: the 8 corners are still vertices, and the 12 edges are still covered by mesh edges
        // (every vertex on a cube edge had two neighbours on that edge; their number is unchanged).
        std::size_t corners = 0, onEdges = 0;
        for (VertexIndex v : m.vertices()) {
            const int s = sidesAt(fss::detail::pos(m, v));
            corners += s == 3;
            onEdges += s == 2;
        }
        EXPECT_EQ(corners, 8u);
        EXPECT_EQ(onEdges, 12u * 7u);
        ASSERT_TRUE(metrics.hausdorffFromRef);
        EXPECT_LT(*metrics.hausdorffFromRef, 1e-9);
    }
}

TEST(SliverRepair, CensusCountsTheSliversInsideThePatches) {
    const Mesh cube = fss::shapes::cube(8, 1.0);
    const Mesh m = cubeWithSlivers(cube, 1);
    std::size_t slivers = 0;
    for (fss::FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        slivers +=
            fss::detail::minAngle(fss::detail::pos(m, m.source(h)), fss::detail::pos(m, m.target(h)),
                                  fss::detail::pos(m, m.target(m.next(h)))) < 20.0 * std::numbers::pi / 180.0;
    }
    // No scan ids on the faces: every face counts as left from the input.
    const fss::detail::SliverCensus c = fss::detail::sliverCensus(m, cube, 1.0 / 8, 35.0, 20.0);
    EXPECT_EQ(c.total, slivers);
    EXPECT_GT(c.total, 0u);
    EXPECT_EQ(c.faces[fss::detail::SliverCensus::InputFaces], slivers);
    EXPECT_NEAR(c.minAngleDeg, smallestAngleDeg(m), 1e-9);
}
