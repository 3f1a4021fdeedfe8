// The crease recovery of `fss-remesh auto` (internal: core/src/remesh/crease_snap.h) on the cube, whose
// creases and corners are known exactly. Each test damages a regular triangulation of the cube in one way
// the stitches do (a corner cut off, a vertex standing off a face, a fold) and checks that snapToCreases
// repairs exactly that: the result is measured against the cube itself, never against the code's own view.
#include "remesh/crease_snap.h"
#include "remesh/seam_relax.h"

#include "auto_cube.h"
#include "mesh_text.h"
#include "test_math.h"

#include "fss/metrics.h"
#include "fss/shapes.h"

#include "expect_valid_mesh.h"

#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <Eigen/Geometry>

#include <cmath>

namespace {

using fss::test::metricsAgainst;

constexpr int kN = 8;         // quads per side of the cube
constexpr double kSide = 1.0; // side of the cube
constexpr double kL = kSide / kN;

fss::VertexIndex vertexAt(const fss::Mesh& m, const Eigen::Vector3d& p) {
    for (fss::VertexIndex v : m.vertices())
        if ((fss::test::position(m, v) - p).norm() < 1e-12) return v;
    return fss::Mesh::null_vertex();
}

// Distance of \p p to the surface of the cube [-1/2, 1/2]³.
double distanceToCube(const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = p.cwiseAbs() - Eigen::Vector3d::Constant(kSide / 2);
    const double outside = q.cwiseMax(0.0).norm();
    return outside > 0 ? outside : -q.maxCoeff();
}

fss::detail::CreaseSnapOptions options() {
    fss::detail::CreaseSnapOptions o;
    o.edgeLength = kL;
    return o;
}

// Faces whose normal points into the cube (the outward normal of the side their centroid is closest to).
std::size_t facesTurnedOver(const fss::Mesh& m) {
    std::size_t n = 0;
    for (fss::FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Eigen::Vector3d a = fss::test::position(m, m.source(h)),
                              b = fss::test::position(m, m.target(h)),
                              c = fss::test::position(m, m.target(m.next(h)));
        const Eigen::Vector3d centroid = (a + b + c) / 3.0;
        int axis = 0;
        centroid.cwiseAbs().maxCoeff(&axis);
        Eigen::Vector3d outward = Eigen::Vector3d::Zero();
        outward[axis] = centroid[axis] > 0 ? 1 : -1;
        n += (b - a).cross(c - a).dot(outward) <= 0;
    }
    return n;
}

} // namespace

// A corner cut off: the vertex at a corner of the cube moved inside by 0.3 L along each axis (0.52 L from the
// corner, 0.3 L from every side). A vertex near a crease goes to its closest crease point, which here is on
// one of the three edges and not the corner; the corner sweep must put it on the corner itself.
TEST(CreaseSnap, MovesTheVertexNearACornerOntoTheCorner) {
    const fss::Mesh cube = fss::shapes::cube(kN, kSide);
    fss::Mesh m = cube;
    const Eigen::Vector3d corner(0.5, 0.5, 0.5);
    const fss::VertexIndex v = vertexAt(m, corner);
    ASSERT_NE(v, fss::Mesh::null_vertex());
    const Eigen::Vector3d moved = corner - Eigen::Vector3d::Constant(0.3 * kL);
    m.point(v) = fss::Point3(moved.x(), moved.y(), moved.z());
    const fss::Metrics before = metricsAgainst(m, cube);

    const fss::detail::CreaseSnapReport r = fss::detail::snapToCreases(m, cube, options());
    EXPECT_EQ(r.creaseEdges, 12u * kN);
    EXPECT_GE(r.snaps, 1u);
    EXPECT_NE(vertexAt(m, corner), fss::Mesh::null_vertex()) << "no vertex on the corner";
    // Every vertex is back on the cube, the vertex count is the cube's, and the corner is no longer cut.
    for (fss::VertexIndex w : m.vertices())
        EXPECT_LT(distanceToCube(fss::test::position(m, w)), 1e-12);
    EXPECT_EQ(m.number_of_vertices(), cube.number_of_vertices());
    const fss::Metrics after = metricsAgainst(m, cube);
    fss::test::expectClosedValidMesh(after);
    ASSERT_TRUE(before.hausdorffFromRef && after.hausdorffFromRef);
    EXPECT_GT(*before.hausdorffFromRef, 0.4 * kL); // the corner, 0.52 L from the moved vertex
    EXPECT_LT(*after.hausdorffFromRef, 1e-9);
}

// A vertex standing off a face: a vertex of valence 3 inserted in a triangle in the middle of a side (no
// crease within three edge lengths) and lifted 0.3 L off it, as the stitches leave in a bevel. Removing it
// gives the original triangle back.
TEST(CreaseSnap, RemovesAVertexOfValenceThreeStandingOffTheSurface) {
    const fss::Mesh cube = fss::shapes::cube(kN, kSide);
    fss::Mesh m = cube;
    // A triangle of the +z side near its centre.
    fss::FaceIndex target;
    for (fss::FaceIndex f : m.faces()) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (fss::VertexIndex w : CGAL::vertices_around_face(m.halfedge(f), m))
            c += fss::test::position(m, w) / 3.0;
        if (std::abs(c.z() - 0.5) < 1e-12 && c.head<2>().norm() < kL) target = f;
    }
    ASSERT_NE(target, fss::Mesh::null_face());
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (fss::VertexIndex w : CGAL::vertices_around_face(m.halfedge(target), m))
        c += fss::test::position(m, w) / 3.0;
    const fss::HalfedgeIndex h = CGAL::Euler::add_center_vertex(m.halfedge(target), m);
    const fss::VertexIndex apex = m.target(h);
    m.point(apex) = fss::Point3(c.x(), c.y(), c.z() + 0.3 * kL);
    ASSERT_EQ(m.degree(apex), 3u);
    const fss::Metrics before = metricsAgainst(m, cube);

    const fss::detail::CreaseSnapReport r = fss::detail::snapToCreases(m, cube, options());
    EXPECT_EQ(r.removals, 1u);
    EXPECT_EQ(m.number_of_vertices(), cube.number_of_vertices());
    EXPECT_EQ(m.number_of_faces(), cube.number_of_faces());
    for (fss::VertexIndex w : m.vertices())
        EXPECT_LT(distanceToCube(fss::test::position(m, w)), 1e-12);
    const fss::Metrics after = metricsAgainst(m, cube);
    fss::test::expectClosedValidMesh(after);
    ASSERT_TRUE(before.hausdorffToRef && after.hausdorffToRef);
    EXPECT_NEAR(*before.hausdorffToRef, 0.3 * kL, 1e-9);
    EXPECT_LT(*after.hausdorffToRef, 1e-9);
    EXPECT_NEAR(after.area, 6.0 * kSide * kSide, 1e-9);
}

// A fold next to a crease: a vertex on the +z side one edge length from the edge y = 1/2 is pushed across
// its neighbour towards the edge (1.4 L in +y), so that faces around it turn over and overlap their
// neighbours in the plane. The repair must leave no face turned over, no self-intersection, every vertex on
// the cube, and the area of the cube (no overlap left).
TEST(CreaseSnap, RepairsAFoldNextToACrease) {
    const fss::Mesh cube = fss::shapes::cube(kN, kSide);
    fss::Mesh m = cube;
    const fss::VertexIndex v = vertexAt(m, Eigen::Vector3d(0.0, 0.5 - 2 * kL, 0.5));
    ASSERT_NE(v, fss::Mesh::null_vertex());
    const Eigen::Vector3d moved(0.0, 0.5 - 0.6 * kL, 0.5);
    m.point(v) = fss::Point3(moved.x(), moved.y(), moved.z());
    ASSERT_GT(facesTurnedOver(m), 0u);
    const fss::Metrics before = metricsAgainst(m, cube);
    ASSERT_TRUE(before.selfIntersections);
    EXPECT_GT(*before.selfIntersections, 0u);

    const fss::detail::CreaseSnapReport r = fss::detail::snapToCreases(m, cube, options());
    EXPECT_GE(r.repairs, 1u);
    EXPECT_EQ(facesTurnedOver(m), 0u);
    for (fss::VertexIndex w : m.vertices())
        EXPECT_LT(distanceToCube(fss::test::position(m, w)), 1e-12);
    const fss::Metrics after = metricsAgainst(m, cube);
    fss::test::expectClosedValidMesh(after); // includes no self-intersection
    EXPECT_NEAR(after.area, 6.0 * kSide * kSide, 1e-9);
    EXPECT_GE(after.minAngleDeg, 10.0 - 1e-9);
}

// A face the crease runs through, far from its corners: the cube's triangulation around the edge
// {y = 1/2, z = 1/2} is bevelled: its vertices pulled down one side by more than the snap radius, as where
// two scans meet at a crease without a vertex on it. The recovery (splits at the crease, moves onto it, flips
// along it) must keep every vertex on the cube and bring the distance both ways below a tenth of an edge
// length.
TEST(CreaseSnap, BringsABevelledCreaseBackOntoTheCube) {
    const fss::Mesh cube = fss::shapes::cube(kN, kSide);
    fss::Mesh m = cube;
    // The edge's vertices (y = z = 1/2, away from the corners) move to z = 1/2 − 0.6 L (down the side
    // y = 1/2, beyond the snap radius L/2): the faces between them and the +z side's next row bevel the
    // crease by 0.51 L.
    for (fss::VertexIndex w : m.vertices()) {
        const Eigen::Vector3d p = fss::test::position(m, w);
        if (std::abs(p.y() - 0.5) < 1e-12 && std::abs(p.z() - 0.5) < 1e-12 && std::abs(p.x()) < 0.5 - 1e-9)
            m.point(w) = fss::Point3(p.x(), p.y(), p.z() - 0.6 * kL);
    }
    const fss::Metrics before = metricsAgainst(m, cube);
    ASSERT_TRUE(before.hausdorffFromRef);
    EXPECT_GT(*before.hausdorffFromRef, 0.45 * kL);

    const fss::detail::CreaseSnapReport r = fss::detail::snapToCreases(m, cube, options());
    EXPECT_GT(r.splits + r.snaps + r.repairs, 0u);
    for (fss::VertexIndex w : m.vertices())
        EXPECT_LT(distanceToCube(fss::test::position(m, w)), 1e-12);
    const fss::Metrics after = metricsAgainst(m, cube);
    fss::test::expectClosedValidMesh(after);
    ASSERT_TRUE(after.hausdorffFromRef && after.hausdorffToRef);
    EXPECT_LT(*after.hausdorffFromRef, 0.1 * kL);
    EXPECT_LT(*after.hausdorffToRef, 0.1 * kL);
    EXPECT_EQ(facesTurnedOver(m), 0u);
}

// Two vertices on a crease a tenth of an edge length apart (an edge of the cube split next to its end, as two
// scans' samples on the same crease): the short edge between them is collapsed onto one of them, which gives
// the cube's own triangulation back (every angle 45° or 90°).
TEST(CreaseSnap, CollapsesAShortEdgeBetweenTwoVerticesOnACrease) {
    const fss::Mesh cube = fss::shapes::cube(kN, kSide);
    fss::Mesh m = cube;
    const fss::VertexIndex a = vertexAt(m, Eigen::Vector3d(0.0, 0.5, 0.5));
    const fss::VertexIndex b = vertexAt(m, Eigen::Vector3d(kL, 0.5, 0.5));
    ASSERT_NE(a, fss::Mesh::null_vertex());
    ASSERT_NE(b, fss::Mesh::null_vertex());
    const auto [h, found] = CGAL::halfedge(a, b, m);
    ASSERT_TRUE(found);
    // Split the edge (a, b) at 0.1 L from a, and each of its two faces from the new vertex.
    const fss::HalfedgeIndex hn = CGAL::Euler::split_edge(h, m); // the new vertex is target(hn)
    const fss::VertexIndex v = m.target(hn);
    m.point(v) = fss::Point3(0.1 * kL, 0.5, 0.5);
    CGAL::Euler::split_face(hn, m.next(m.next(hn)), m);
    const fss::HalfedgeIndex og = m.opposite(h);
    CGAL::Euler::split_face(og, m.next(m.next(og)), m);
    ASSERT_EQ(m.number_of_vertices(), cube.number_of_vertices() + 1);
    const fss::Metrics before = metricsAgainst(m, cube);
    ASSERT_LT(before.minAngleDeg, 10.0);

    const fss::detail::CreaseSnapReport r = fss::detail::snapToCreases(m, cube, options());
    EXPECT_GE(r.repairs, 1u);
    EXPECT_EQ(m.number_of_vertices(), cube.number_of_vertices());
    for (fss::VertexIndex w : m.vertices())
        EXPECT_LT(distanceToCube(fss::test::position(m, w)), 1e-12);
    const fss::Metrics after = metricsAgainst(m, cube);
    fss::test::expectClosedValidMesh(after);
    EXPECT_NEAR(after.minAngleDeg, 45.0, 1e-9);
    EXPECT_NEAR(after.area, 6.0 * kSide * kSide, 1e-9);
}

// knownFree (CreaseSnapOptions, SeamRelaxOptions) only skips the whole-mesh entry test: on a cube remeshed by
// `auto` without the crease recovery and the relaxation (free of self-intersections, CGAL says), both give
// the same mesh to the last bit with and without it, and report their result free (freeAfter), which CGAL
// confirms. With a vertex pushed through the cube (the mesh intersects itself on entry) nothing is known
// after.
TEST(CreaseSnap, KnownFreeSkipsOnlyTheEntryTestAndFreeAfterHolds) {
    namespace PMP = CGAL::Polygon_mesh_processing;
    const fss::Mesh cube = fss::shapes::cube(8, 1.0);
    const fss::AutoResult plain = fss::test::cubeBeforeRelaxation(cube);
    ASSERT_FALSE(PMP::does_self_intersect(plain.mesh));
    fss::detail::CreaseSnapOptions co;
    co.edgeLength = plain.edgeLength;
    fss::detail::SeamRelaxOptions ro;
    ro.edgeLength = plain.edgeLength;
    std::vector<std::string> results;
    for (bool known : {false, true}) {
        SCOPED_TRACE(known ? "known free" : "tested");
        fss::Mesh m = plain.mesh;
        co.knownFree = known;
        const fss::detail::CreaseSnapReport cr = fss::detail::snapToCreases(m, cube, co);
        EXPECT_GT(cr.snaps, 0u);
        EXPECT_TRUE(cr.freeAfter);
        EXPECT_FALSE(PMP::does_self_intersect(m));
        ro.knownFree = known && cr.freeAfter;
        const fss::detail::SeamRelaxReport rr = fss::detail::relaxSeams(m, cube, ro);
        EXPECT_GT(rr.moves + rr.flips, 0u);
        EXPECT_TRUE(rr.freeAfter);
        EXPECT_FALSE(PMP::does_self_intersect(m));
        results.push_back(fss::test::exactMeshText(m));
    }
    EXPECT_EQ(results[0], results[1]);

    fss::Mesh pierced = plain.mesh;
    fss::VertexIndex top = *pierced.vertices().begin();
    for (fss::VertexIndex v : pierced.vertices())
        if (pierced.point(v).z() > pierced.point(top).z()) top = v;
    const fss::Point3 p = pierced.point(top);
    pierced.point(top) = fss::Point3(p.x(), p.y(), -1.0); // through the bottom side (z = -1/2)
    ASSERT_TRUE(PMP::does_self_intersect(pierced));
    fss::Mesh relaxed = pierced;
    EXPECT_FALSE(fss::detail::snapToCreases(pierced, cube, options()).freeAfter);
    ro.knownFree = false;
    EXPECT_FALSE(fss::detail::relaxSeams(relaxed, cube, ro).freeAfter);
}
