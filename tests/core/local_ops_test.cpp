// The guarded local operations (internal: core/src/mesh/local_ops.h) on tiny hand-made meshes: each guard
// refuses exactly the operation that would break the mesh (a border edge, a valence below 3, a doubled edge,
// the link condition, a face turned over or an angle below the floor) and allows the others.
#include "mesh/local_ops.h"
#include "mesh/triangle_geometry.h"

#include "fss/shapes.h"

#include <gtest/gtest.h>

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace {

using fss::EdgeIndex;
using fss::HalfedgeIndex;
using fss::Mesh;
using fss::Point3;
using fss::VertexIndex;

/// The octahedron with corners +x, -x, +y, -y, +z, -z (vertex indices 0…5), outward oriented.
Mesh octahedron() {
    Mesh m;
    const std::array<VertexIndex, 6> v{m.add_vertex({1, 0, 0}), m.add_vertex({-1, 0, 0}),
                                       m.add_vertex({0, 1, 0}), m.add_vertex({0, -1, 0}),
                                       m.add_vertex({0, 0, 1}), m.add_vertex({0, 0, -1})};
    enum { px, nx, py, ny, pz, nz };
    for (auto [a, b, c] : std::array<std::array<int, 3>, 8>{{{px, py, pz},
                                                             {py, nx, pz},
                                                             {nx, ny, pz},
                                                             {ny, px, pz},
                                                             {py, px, nz},
                                                             {nx, py, nz},
                                                             {ny, nx, nz},
                                                             {px, ny, nz}}})
        m.add_face(v[std::size_t(a)], v[std::size_t(b)], v[std::size_t(c)]);
    return m;
}

HalfedgeIndex halfedge(const Mesh& m, int a, int b) {
    const auto [h, found] = CGAL::halfedge(VertexIndex(a), VertexIndex(b), m);
    EXPECT_TRUE(found) << a << "-" << b;
    return h;
}

TEST(LocalOps, FlipAllowedOnlyWhereTheMeshStaysValid) {
    Mesh m = octahedron();
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m));
    // +x +y: opposite corners +z and -z, not joined, both ends of valence 4.
    const HalfedgeIndex h = halfedge(m, 0, 2);
    ASSERT_TRUE(fss::detail::canFlip(m, h));
    CGAL::Euler::flip_edge(h, m);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    // -x -y has the same opposite corners, which the flip has just joined: a second flip would double it.
    EXPECT_FALSE(fss::detail::canFlip(m, halfedge(m, 1, 3)));
    // +x now has valence 3: an edge at it may not be flipped.
    ASSERT_EQ(m.degree(VertexIndex(0)), 3u);
    EXPECT_FALSE(fss::detail::canFlip(m, halfedge(m, 0, 4)));
    // Border edges never.
    const Mesh grid = fss::shapes::grid(3, 3);
    for (EdgeIndex e : grid.edges())
        if (grid.is_border(e)) {
            EXPECT_FALSE(fss::detail::canFlip(grid, grid.halfedge(e)));
        }
}

TEST(LocalOps, CollapseRefusedWhenTheLinkConditionFails) {
    Mesh m = octahedron();
    EXPECT_TRUE(fss::detail::canCollapse(m, m.edge(halfedge(m, 0, 2))));
    CGAL::Euler::flip_edge(halfedge(m, 0, 2), m); // +z and -z are now joined
    // -x +z: its faces' third corners are +y and -y, but -x and +z also share -z, so collapsing it would
    // pinch the surface (link condition).
    const EdgeIndex e = m.edge(halfedge(m, 1, 4));
    EXPECT_FALSE(fss::detail::canCollapse(m, e, false));
    EXPECT_FALSE(fss::detail::canCollapse(m, e));
    // On the icosahedron (valence 5) every edge may go; the opposite corners keep valence 4.
    const Mesh ico = fss::shapes::icosahedron();
    for (EdgeIndex f : ico.edges())
        EXPECT_TRUE(fss::detail::canCollapse(ico, f));
}

TEST(LocalOps, CollapseKeepsOppositeValenceAboveThree) {
    // On a closed mesh an edge opposite a vertex of valence 3 never satisfies the link condition; on a grid,
    // the interior edges opposite a border vertex of valence 3 do: collapsing one would leave that vertex
    // with a single face. Those are refused for the valence alone.
    const Mesh m = fss::shapes::grid(4, 4);
    std::size_t refused = 0;
    for (EdgeIndex e : m.edges()) {
        if (m.is_border(e) || !fss::detail::canCollapse(m, e, false)) continue;
        const HalfedgeIndex h = m.halfedge(e), o = m.opposite(h);
        const bool valence3 = m.degree(m.target(m.next(h))) <= 3 || m.degree(m.target(m.next(o))) <= 3;
        EXPECT_EQ(fss::detail::canCollapse(m, e), !valence3);
        refused += valence3;
    }
    EXPECT_GT(refused, 0u);
}

TEST(LocalOps, SplitEdgeMakesFourTrianglesAndUndoes) {
    Mesh m = octahedron();
    const HalfedgeIndex h = halfedge(m, 0, 2);
    const fss::FaceIndex f = m.face(h), g = m.face(m.opposite(h));
    const fss::detail::EdgeSplit s = fss::detail::splitEdge(m, h, Point3(0.5, 0.5, 0));
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(m.number_of_vertices(), 7u);
    EXPECT_EQ(m.number_of_faces(), 10u);
    EXPECT_EQ(m.point(s.vertex), Point3(0.5, 0.5, 0));
    EXPECT_EQ(m.degree(s.vertex), 4u);
    EXPECT_EQ(m.source(h), s.vertex);
    EXPECT_EQ(m.target(h), VertexIndex(2));
    EXPECT_EQ(m.source(s.first), s.vertex);
    EXPECT_EQ(m.source(s.second), s.vertex);
    // The old faces keep their indices, one on each side.
    EXPECT_TRUE(m.face(s.first) == f || m.face(m.opposite(s.first)) == f);
    EXPECT_TRUE(m.face(s.second) == g || m.face(m.opposite(s.second)) == g);
    fss::detail::undoSplitEdge(m, h, s);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(m.number_of_vertices(), 6u);
    EXPECT_EQ(m.number_of_faces(), 8u);
    EXPECT_TRUE(CGAL::halfedge(VertexIndex(0), VertexIndex(2), m).second);
    EXPECT_EQ(m.point(VertexIndex(0)), Point3(1, 0, 0));
}

TEST(LocalOps, MoveRefusedWhenAFaceTurnsOverOrAnAngleFallsBelowTheFloor) {
    const Mesh grid = fss::shapes::grid(2, 2); // the centre vertex (1, 1, 0) has valence 6
    VertexIndex centre;
    for (VertexIndex v : grid.vertices())
        if (grid.point(v) == Point3(1, 1, 0)) centre = v;
    ASSERT_EQ(grid.degree(centre), 6u);
    const double turn = std::numbers::pi / 3, floor = 20 * std::numbers::pi / 180;
    EXPECT_TRUE(fss::detail::moveKeepsStar(grid, centre, {1.1, 0.9, 0}, turn, floor));
    // Past a neighbour: the faces on that side turn over.
    EXPECT_FALSE(fss::detail::moveKeepsStar(grid, centre, {2.5, 1, 0}, turn, floor));
    // Lifted out of the plane: every normal turns by more than 60°.
    EXPECT_FALSE(fss::detail::moveKeepsStar(grid, centre, {1, 1, 3}, turn, floor));
    // Near an edge of the star: a thin face with an angle far below 20° (the grid's smallest is 45°).
    EXPECT_FALSE(fss::detail::moveKeepsStar(grid, centre, {1.9, 1, 0}, turn, floor));
    // A floor above the star's smallest angle asks only that it does not get smaller.
    EXPECT_TRUE(fss::detail::moveKeepsStar(grid, centre, {1, 1, 0}, turn, std::numbers::pi / 3));
    EXPECT_FALSE(fss::detail::moveKeepsStar(grid, centre, {1.2, 1.1, 0}, turn, std::numbers::pi / 3));
}

} // namespace

// The star's smallest angle through MinAngleOfMany and the floor test minAngleBelow
// (mesh/triangle_geometry.h) give exactly the doubles and answers of minAngle face by face, also where
// corners tie (isosceles and equilateral faces, a grid's right isosceles triangles), for degenerate faces and
// near the floor.
TEST(TriangleGeometry, StarMinAngleAndFloorTestMatchMinAngle) {
    using V = Eigen::Vector3d;
    std::vector<std::array<V, 3>> tris = {
        {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)},                    // 45, 45, 90
        {V(0, 0, 0), V(1, 0, 0), V(0.5, std::sqrt(3.0) / 2, 0)}, // equilateral
        {V(0, 0, 0), V(1, 0, 0), V(0.5, 0.1, 0)},                // isosceles cap
        {V(0, 0, 0), V(1, 0, 0), V(2, 0, 0)},                    // collinear
        {V(0, 0, 0), V(0, 0, 0), V(0, 1, 0)},                    // an edge of length zero
    };
    std::uint64_t s = 12345;
    auto rnd = [&] {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        return double(s >> 11) / double(1ULL << 53);
    };
    for (int i = 0; i < 2000; ++i)
        tris.push_back({V(rnd(), rnd(), rnd()), V(rnd(), rnd(), rnd()), V(rnd(), rnd(), rnd())});
    // Stars of 1..9 faces taken from the list (runs of ties included), also with the degenerate ones.
    for (std::size_t start = 0; start < tris.size(); start += 3)
        for (std::size_t n = 1; n <= 9 && start + n <= tris.size(); n += 4) {
            fss::detail::MinAngleOfMany many;
            double expect = std::numbers::pi;
            for (std::size_t k = start; k < start + n; ++k) {
                many.add(tris[k][0], tris[k][1], tris[k][2]);
                expect = std::min(expect, fss::detail::minAngle(tris[k][0], tris[k][1], tris[k][2]));
            }
            EXPECT_EQ(many.value(), expect) << start << " " << n;
        }
    fss::detail::MinAngleOfMany repeated; // the same face twice: every corner ties with another
    repeated.add(tris[0][0], tris[0][1], tris[0][2]);
    repeated.add(tris[0][0], tris[0][1], tris[0][2]);
    EXPECT_EQ(repeated.value(), fss::detail::minAngle(tris[0][0], tris[0][1], tris[0][2]));
    EXPECT_EQ(fss::detail::MinAngleOfMany().value(), std::numbers::pi);
    for (const auto& t : tris) {
        const double m = fss::detail::minAngle(t[0], t[1], t[2]);
        for (double limit : {m, std::nextafter(m, 0.0), std::nextafter(m, 4.0), 0.3, 0.6, 1.0, 1e-12}) {
            if (!(limit > 0)) continue;
            EXPECT_EQ(fss::detail::minAngleBelow(t[0], t[1], t[2], fss::detail::AngleLimit(limit)),
                      m < limit);
        }
    }
}
