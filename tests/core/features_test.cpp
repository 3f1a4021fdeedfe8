// The sharp edges and crease chains of a mesh (internal: core/src/mesh/features.h) on analytic shapes whose
// creases are known exactly, and on CGAL's meshes against the four predicates they replace (auto's feature
// chains, the crease recovery's crease index, the fishbone cache's crease edges, the seam relaxation's
// feature edges), which must classify every edge alike at the angles FSS uses.
#include "mesh/features.h"
#include "test_math.h"

#include "fss/mesh_io.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace {

using fss::detail::creaseChains;
using fss::detail::creaseCorners;
using fss::detail::sharpEdges;

std::size_t count(const std::vector<char>& flags) {
    return std::size_t(std::count(flags.begin(), flags.end(), 1));
}

TEST(Features, CubeHasTwelveSharpEdgesAndEightCorners) {
    for (int n : {1, 4}) {
        const fss::Mesh cube = fss::shapes::cube(n, 2.0);
        const std::vector<char> sharp = sharpEdges(cube, 60.0);
        EXPECT_EQ(count(sharp), std::size_t(12 * n)) << "n = " << n;
        EXPECT_EQ(creaseCorners(cube, sharp).size(), 8u);
        // A right angle is sharp at any bound below 90°, never at or above it.
        EXPECT_EQ(count(sharpEdges(cube, 89.0)), std::size_t(12 * n));
        EXPECT_EQ(count(sharpEdges(cube, 91.0)), 0u);
    }
}

TEST(Features, CubeChainsAreItsTwelveEdges) {
    const fss::Mesh cube = fss::shapes::cube(4, 2.0);
    const auto chains = creaseChains(cube, sharpEdges(cube, 60.0), 40.0);
    ASSERT_EQ(chains.size(), 12u);
    for (const auto& c : chains) {
        EXPECT_NEAR(c.length, 2.0, 1e-12);
        ASSERT_EQ(c.points.size(), 5u);
        // Both ends are corners of the cube, and the bisector points out of the cube along a face diagonal
        // of the edge's cross-section.
        for (const Eigen::Vector3d& p : {c.points.front(), c.points.back()})
            EXPECT_NEAR(p.cwiseAbs().minCoeff(), 1.0, 1e-12);
        EXPECT_NEAR(c.bisector.norm(), 1.0, 1e-12);
        const Eigen::Vector3d mid = 0.5 * (c.points.front() + c.points.back());
        EXPECT_GT(c.bisector.dot(mid), 1.0);
    }
}

TEST(Features, CylinderRimsAreClosedLoops) {
    const int nu = 24;
    const fss::Mesh cylinder = fss::shapes::cylinder(nu, 3, 1.0, 2.0, true);
    const std::vector<char> sharp = sharpEdges(cylinder, 60.0);
    EXPECT_EQ(count(sharp), std::size_t(2 * nu)); // the sides meet at 15°, the rims at 90°
    EXPECT_TRUE(creaseCorners(cylinder, sharp).empty());
    // Without a limit on the bisector's turn, each rim is one closed loop.
    const auto loops = creaseChains(cylinder, sharp, 180.0);
    ASSERT_EQ(loops.size(), 2u);
    const double perimeter = 2.0 * nu * std::sin(std::numbers::pi / nu);
    for (const auto& c : loops) {
        EXPECT_NEAR(c.length, perimeter, 1e-12);
        EXPECT_EQ(c.points.size(), std::size_t(nu + 1));
        EXPECT_EQ(c.points.front(), c.points.back());
    }
    // With a limit of 40°, a rim (whose bisector turns all the way round) falls into pieces that each turn
    // less, and every rim edge is in exactly one piece.
    const auto pieces = creaseChains(cylinder, sharp, 40.0);
    EXPECT_GT(pieces.size(), 2u);
    double total = 0;
    std::size_t edges = 0;
    for (const auto& c : pieces)
        total += c.length, edges += c.points.size() - 1;
    EXPECT_NEAR(total, 2 * perimeter, 1e-12);
    EXPECT_EQ(edges, std::size_t(2 * nu));
}

TEST(Features, BorderEdgesAreNotSharp) {
    const fss::Mesh open = fss::shapes::cylinder(16, 2, 1.0, 2.0, false);
    EXPECT_EQ(count(sharpEdges(open, 30.0)), 0u);
}

// ---------------------------------------------------------------------------------------------------------
// The predicates the features unit replaces, as they were written (issue 18).

Eigen::Vector3d unit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d(0, 0, 0);
}
Eigen::Vector3d faceUnit(const fss::Mesh& m, fss::FaceIndex f) {
    const auto h = m.halfedge(f);
    return unit(fss::test::position(m, m.source(h)), fss::test::position(m, m.target(h)),
                fss::test::position(m, m.target(m.next(h))));
}

// auto_remesh.cpp featureChains
bool autoChains(const fss::Mesh& m, fss::EdgeIndex e, double deg) {
    const auto h = m.halfedge(e);
    return faceUnit(m, m.face(h)).dot(faceUnit(m, m.face(m.opposite(h)))) <
           std::cos(deg * std::numbers::pi / 180.0);
}
// crease_snap.cpp CreaseIndex
bool creaseSnap(const fss::Mesh& m, fss::EdgeIndex e, double deg) {
    const auto h = m.halfedge(e), o = m.opposite(h);
    const Eigen::Vector3d a = fss::test::position(m, m.source(h)), b = fss::test::position(m, m.target(h));
    const Eigen::Vector3d n1 = unit(a, b, fss::test::position(m, m.target(m.next(h))));
    const Eigen::Vector3d n2 = unit(b, a, fss::test::position(m, m.target(m.next(o))));
    return !(n1.isZero() || n2.isZero() || n1.dot(n2) >= std::cos(deg * std::numbers::pi / 180.0));
}
// fishbone_scan.cpp FishboneCache::creaseEdges
bool fishboneCache(const fss::Mesh& m, fss::EdgeIndex e, double deg) {
    auto normal = [&](fss::FaceIndex f) {
        const auto h = m.halfedge(f);
        const Eigen::Vector3d a = fss::test::position(m, m.source(h));
        return Eigen::Vector3d(
            (fss::test::position(m, m.target(h)) - a).cross(fss::test::position(m, m.target(m.next(h))) - a));
    };
    const auto h = m.halfedge(e);
    const Eigen::Vector3d n0 = normal(m.face(h)), n1 = normal(m.face(m.opposite(h)));
    const double l = n0.norm() * n1.norm();
    return l > 0 && n0.dot(n1) < std::cos(deg * std::numbers::pi / 180.0) * l;
}
// seam_relax.cpp markFeaturesAndZone
bool seamRelax(const fss::Mesh& m, fss::EdgeIndex e, double deg) {
    const auto h = m.halfedge(e);
    const Eigen::Vector3d u = faceUnit(m, m.face(h)), v = faceUnit(m, m.face(m.opposite(h)));
    return std::atan2(u.cross(v).norm(), u.dot(v)) > deg * std::numbers::pi / 180.0;
}

TEST(Features, AgreesWithTheFormerPredicatesOnCgalMeshes) {
    for (const char* name : {"fandisk.off", "bunny00.off", "elephant.off", "couplingdown.off"}) {
        const fss::Mesh mesh = fss::readMesh(fss::test::meshPath(name));
        for (double deg : {30.0, 35.0}) {
            const std::vector<char> sharp = sharpEdges(mesh, deg);
            std::size_t differ[4] = {0, 0, 0, 0};
            for (fss::EdgeIndex e : mesh.edges()) {
                if (mesh.is_border(e)) {
                    EXPECT_FALSE(sharp[e.idx()]);
                    continue;
                }
                const bool s = sharp[e.idx()] != 0;
                differ[0] += autoChains(mesh, e, deg) != s;
                differ[1] += creaseSnap(mesh, e, deg) != s;
                differ[2] += fishboneCache(mesh, e, deg) != s;
                differ[3] += seamRelax(mesh, e, deg) != s;
            }
            std::printf("%s at %g deg: %zu sharp of %zu edges; differing from auto %zu, crease_snap %zu, "
                        "fishbone %zu, seam_relax %zu\n",
                        name, deg, count(sharp), std::size_t(mesh.number_of_edges()), differ[0], differ[1],
                        differ[2], differ[3]);
            for (std::size_t d : differ)
                EXPECT_EQ(d, 0u) << name << " at " << deg << "°";
        }
    }
}

} // namespace
