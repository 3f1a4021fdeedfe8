// Analytic shapes: exact counts, closedness, outward orientation (positive signed volume equal to the
// analytic volume within the discretisation error), valences.
#include "fss/error.h"
#include "fss/shapes.h"

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>

#include <gtest/gtest.h>

#include <numbers>

namespace PMP = CGAL::Polygon_mesh_processing;
using fss::Mesh;

namespace {

int valence(const Mesh& m, fss::VertexIndex v) {
    return int(m.degree(v));
}

void expectClosedOutward(const Mesh& m) {
    ASSERT_TRUE(m.is_valid(false));
    ASSERT_TRUE(CGAL::is_closed(m));
    EXPECT_TRUE(PMP::is_outward_oriented(m));
    EXPECT_GT(PMP::volume(m), 0.0);
}

} // namespace

TEST(Shapes, GridHasValenceSixInside) {
    const Mesh g = fss::shapes::grid(7, 5, 0.5);
    EXPECT_EQ(g.number_of_vertices(), 8u * 6u);
    EXPECT_EQ(g.number_of_faces(), 2u * 7u * 5u);
    int interior = 0;
    for (auto v : g.vertices())
        if (!g.is_border(v)) {
            ++interior;
            EXPECT_EQ(valence(g, v), 6);
        }
    EXPECT_EQ(interior, 6 * 4);
    EXPECT_NEAR(PMP::area(g), 7 * 5 * 0.25, 1e-12);
    // +z normals.
    for (auto f : g.faces()) {
        auto h = g.halfedge(f);
        const auto n = CGAL::normal(g.point(g.source(h)), g.point(g.target(h)), g.point(g.target(g.next(h))));
        EXPECT_GT(n.z(), 0);
    }
}

TEST(Shapes, IcosahedronIsRegular) {
    const Mesh m = fss::shapes::icosahedron(2.0);
    EXPECT_EQ(m.number_of_vertices(), 12u);
    EXPECT_EQ(m.number_of_faces(), 20u);
    expectClosedOutward(m);
    for (auto v : m.vertices()) {
        EXPECT_EQ(valence(m, v), 5);
        EXPECT_NEAR(std::sqrt(CGAL::squared_distance(m.point(v), fss::Point3(0, 0, 0))), 2.0, 1e-12);
    }
    const double edge = 2.0 / std::sin(2 * std::numbers::pi / 5);
    for (auto e : m.edges())
        EXPECT_NEAR(PMP::edge_length(e, m), edge, 1e-12);
}

TEST(Shapes, IcosphereCountsAndRadius) {
    const Mesh m = fss::shapes::icosphere(3, 1.5);
    EXPECT_EQ(m.number_of_faces(), 20u * 64u);
    EXPECT_EQ(m.number_of_vertices(), 10u * 64u + 2u);
    expectClosedOutward(m);
    EXPECT_NEAR(PMP::volume(m), 4.0 / 3.0 * std::numbers::pi * 1.5 * 1.5 * 1.5, 0.03 * 14.1);
}

TEST(Shapes, UvSphereCylinderTorusCubeAreClosedAndOutward) {
    const Mesh s = fss::shapes::uvSphere(32, 16, 1.0);
    expectClosedOutward(s);
    EXPECT_EQ(s.number_of_vertices(), 32u * 15u + 2u);
    const Mesh c = fss::shapes::cylinder(40, 10, 1.0, 3.0);
    expectClosedOutward(c);
    EXPECT_NEAR(PMP::volume(c), std::numbers::pi * 3.0, 0.02 * std::numbers::pi * 3.0);
    const Mesh t = fss::shapes::torus(64, 32, 2.0, 0.5);
    expectClosedOutward(t);
    EXPECT_EQ(t.number_of_vertices(), 64u * 32u);
    for (auto v : t.vertices())
        EXPECT_EQ(valence(t, v), 6);
    EXPECT_NEAR(PMP::volume(t), 2 * std::numbers::pi * std::numbers::pi * 2.0 * 0.25, 0.02 * 9.87);
    const Mesh k = fss::shapes::cube(3, 2.0);
    expectClosedOutward(k);
    EXPECT_EQ(k.number_of_vertices(), 6u * 9u + 2u); // 6n²+2 for n = 3
    EXPECT_NEAR(PMP::volume(k), 8.0, 1e-12);
    EXPECT_NEAR(PMP::area(k), 24.0, 1e-12);
}

TEST(Shapes, OpenCylinderHasTwoBoundaryLoops) {
    const Mesh c = fss::shapes::cylinder(12, 3, 1.0, 1.0, false);
    ASSERT_TRUE(c.is_valid(false));
    EXPECT_FALSE(CGAL::is_closed(c));
    std::size_t borderEdges = 0;
    for (auto e : c.edges())
        borderEdges += c.is_border(e) ? 1 : 0;
    EXPECT_EQ(borderEdges, 24u);
}

TEST(Shapes, RejectsAbsurdParameters) {
    EXPECT_THROW(fss::shapes::grid(0, 3), fss::InvalidInputError);
    EXPECT_THROW(fss::shapes::icosphere(11), fss::InvalidInputError);
    EXPECT_THROW(fss::shapes::torus(10, 10, 0.2, 0.5), fss::InvalidInputError);
    EXPECT_THROW(fss::shapes::cube(1, -1), fss::InvalidInputError);
}
