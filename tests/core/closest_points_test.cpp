// The memoized closest-point queries of the crease recovery (internal: core/src/remesh/closest_points.h), and
// the crease recovery and the seam relaxation run with one and with two TBB threads: the answers are
// RayCaster's own (and the sphere's analytic closest points), and the meshes are the same bytes.
#include "remesh/closest_points.h"
#include "remesh/crease_snap.h"
#include "remesh/seam_relax.h"

#include "fss/auto_remesh.h"
#include "fss/raycast.h"
#include "fss/shapes.h"

#include "auto_cube.h"
#include "mesh_text.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <random>
#include <string>
#include <vector>

namespace {

std::vector<Eigen::Vector3d> randomPoints(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < n; ++i)
        points.emplace_back(u(rng), u(rng), u(rng));
    return points;
}

} // namespace

// Prefetched (in parallel, one or two threads) or asked one by one, the answers are RayCaster's, and on a
// fine sphere the closest point is the radial projection within the chord error.
TEST(ClosestPoints, AnswersAreTheRayCastersForAnyThreadCount) {
    const fss::Mesh sphere = fss::shapes::icosphere(4, 1.0);
    const fss::RayCaster caster(sphere);
    const std::vector<Eigen::Vector3d> points = randomPoints(2000, 3);
    for (int threads : {1, 2}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        const fss::detail::ClosestPoints closest(caster);
        closest.prefetch(std::vector<Eigen::Vector3d>(points.begin(), points.begin() + 1000));
        for (const Eigen::Vector3d& p : points) {
            const fss::SurfacePoint a = closest(p), b = caster.closestPoint(p);
            ASSERT_TRUE(a && b);
            EXPECT_EQ(a.face, b.face);
            EXPECT_EQ(a.point, b.point);
            EXPECT_EQ(a.distance, b.distance);
            // icosphere(4): edges of about 0.077, so the faces lie within 1e-3 of the unit sphere.
            if (p.norm() > 0.1) {
                EXPECT_NEAR(a.distance, std::abs(p.norm() - 1.0), 2e-3);
            }
        }
    }
}

// The seam relaxation and the crease recovery on a cube remeshed by `auto` without them (its seams and
// bevelled creases): the same mesh, to the last bit, with one and with two TBB threads; and each changes it.
TEST(ClosestPoints, RelaxationAndCreaseRecoveryAreTheSameForOneAndTwoThreads) {
    const fss::Mesh cube = fss::shapes::cube(8, 1.0);
    const fss::AutoResult plain = fss::test::cubeBeforeRelaxation(cube);
    fss::detail::SeamRelaxOptions ro;
    ro.edgeLength = plain.edgeLength;
    fss::detail::CreaseSnapOptions co;
    co.edgeLength = plain.edgeLength;
    std::vector<std::string> results;
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        fss::Mesh m = plain.mesh;
        const fss::detail::CreaseSnapReport cr = fss::detail::snapToCreases(m, cube, co);
        EXPECT_GT(cr.snaps, 0u);
        const fss::detail::SeamRelaxReport rr = fss::detail::relaxSeams(m, cube, ro);
        EXPECT_GT(rr.moves + rr.flips, 0u);
        results.push_back(fss::test::exactMeshText(m));
    }
    EXPECT_NE(results[0], fss::test::exactMeshText(plain.mesh));
    EXPECT_EQ(results[0], results[1]);
}
