// Ray casting: the CPU rasterizer against independent analytic answers (a convex polyhedron clipped by
// its face planes, the circumscribed / inscribed spheres by a quadratic), hinted queries against the AABB
// tree, closest points against hand-computed values.
#include "fss/error.h"
#include "fss/raycast.h"
#include "fss/shapes.h"

#include "mesh/local_closest_point.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

using fss::Camera;
using fss::FrameBuffers;
using fss::Mesh;
using fss::RayCaster;
using fss::SurfacePoint;

namespace {

Eigen::Vector3d toEigen(const fss::Point3& p) {
    return {p.x(), p.y(), p.z()};
}

struct Plane {
    Eigen::Vector3d n; // outward unit normal
    double d;          // n·x = d on the plane
};

std::vector<Plane> facePlanes(const Mesh& m) {
    std::vector<Plane> planes(m.num_faces());
    for (auto f : m.faces()) {
        auto h = m.halfedge(f);
        const Eigen::Vector3d a = toEigen(m.point(m.source(h))), b = toEigen(m.point(m.target(h))),
                              c = toEigen(m.point(m.target(m.next(h))));
        const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
        planes[f.idx()] = {n, n.dot(a)};
    }
    return planes;
}

// Cyrus–Beck: the ray (t ≥ 0) against the convex polyhedron given by its outward face planes. Returns the
// entry parameter and the entering face, or t = +inf on a miss.
std::pair<double, int> clipConvex(const std::vector<Plane>& planes, const fss::Ray& ray) {
    double tIn = 0, tOut = std::numeric_limits<double>::infinity();
    int enter = -1;
    for (std::size_t i = 0; i < planes.size(); ++i) {
        const double denom = planes[i].n.dot(ray.direction);
        const double dist = planes[i].d - planes[i].n.dot(ray.origin); // > 0: origin inside this half-space
        if (denom < 0) {
            const double t = dist / denom;
            if (t > tIn) tIn = t, enter = int(i);
        } else if (denom > 0) {
            tOut = std::min(tOut, dist / denom);
        } else if (dist < 0) {
            return {std::numeric_limits<double>::infinity(), -1};
        }
    }
    if (enter < 0 || tIn > tOut) return {std::numeric_limits<double>::infinity(), -1};
    return {tIn, enter};
}

// Does the ray hit the sphere |x| = r (origin outside)? Solved as a quadratic in t.
bool hitsSphere(const fss::Ray& ray, double r) {
    const double b = ray.origin.dot(ray.direction), c = ray.origin.squaredNorm() - r * r;
    const double disc = b * b - c;
    return disc >= 0 && (-b + std::sqrt(disc)) >= 0;
}

Camera sphereCamera(bool parallel) {
    Camera c;
    c.eye = {0.7, -0.4, 4.0};
    c.focal = {0.05, 0.02, 0};
    c.up = {0, 1, 0};
    c.parallel = parallel;
    c.viewAngleDeg = 35;
    c.parallelScale = 1.3;
    c.width = 200;
    c.height = 160;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
    return c;
}

} // namespace

TEST(RayCast, CpuRasterOfSphereMatchesAnalyticCounts) {
    const double R = 1.0;
    const Mesh sphere = fss::shapes::icosphere(3, R);
    const auto planes = facePlanes(sphere);
    double rIn = R;
    for (const Plane& p : planes)
        rIn = std::min(rIn, p.d);
    ASSERT_GT(rIn, 0.99);
    for (bool parallel : {false, true}) {
        SCOPED_TRACE(parallel ? "parallel" : "perspective");
        const Camera cam = sphereCamera(parallel);
        const FrameBuffers fb = fss::rasterizeOnCpu(sphere, cam);
        ASSERT_EQ(fb.depth.size(), std::size_t(cam.width * cam.height));
        std::size_t polyhedronCount = 0, outerCount = 0, innerCount = 0, wrongFace = 0;
        for (int y = 0; y < cam.height; ++y) {
            for (int x = 0; x < cam.width; ++x) {
                fss::Ray ray = cam.ray(x + 0.5, y + 0.5);
                ray.origin = cam.unproject(x + 0.5, y + 0.5, 0.0);
                const auto [t, face] = clipConvex(planes, ray);
                const bool inPoly = std::isfinite(t);
                const bool inOuter = hitsSphere(ray, R), inInner = hitsSphere(ray, rIn);
                polyhedronCount += inPoly;
                outerCount += inOuter;
                innerCount += inInner;
                ASSERT_EQ(fb.covered(x, y), inPoly) << x << "," << y;
                // The polyhedron lies between its inscribed and circumscribed spheres.
                if (inInner) {
                    ASSERT_TRUE(fb.covered(x, y));
                }
                if (!inOuter) {
                    ASSERT_FALSE(fb.covered(x, y));
                }
                if (!inPoly) {
                    EXPECT_EQ(fb.depthAt(x, y), 1.0f);
                    continue;
                }
                // Face ids: the entering face of the clipping (ties at edges: same entry parameter).
                const int reported = int(fb.faceAt(x, y));
                if (reported != face) {
                    const Plane& p = planes[reported];
                    const double tr = (p.d - p.n.dot(ray.origin)) / p.n.dot(ray.direction);
                    if (std::abs(tr - t) > 1e-9) ++wrongFace;
                }
                const Eigen::Vector3d hit = ray.origin + t * ray.direction;
                EXPECT_NEAR(fb.depthAt(x, y), cam.project(hit).z(), 1e-6);
            }
        }
        EXPECT_EQ(wrongFace, 0u);
        EXPECT_EQ(fb.coveredCount(), polyhedronCount);
        EXPECT_LE(innerCount, fb.coveredCount());
        EXPECT_GE(outerCount, fb.coveredCount());
        // The sphere fills a good part of the image (the test is not vacuous).
        EXPECT_GT(innerCount, std::size_t(0.2 * cam.width * cam.height));
    }
}

TEST(RayCast, HintedIntersectionAgreesWithTree) {
    const Mesh sphere = fss::shapes::icosphere(4, 2.0);
    const RayCaster caster(sphere);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int hits = 0;
    for (int i = 0; i < 500; ++i) {
        fss::Ray ray;
        ray.origin = Eigen::Vector3d(u(rng), u(rng), 5.0);
        ray.direction = Eigen::Vector3d(0.1 * u(rng), 0.1 * u(rng), -1.0).normalized();
        const SurfacePoint ref = caster.intersect(ray);
        ASSERT_TRUE(ref);
        ++hits;
        EXPECT_NEAR((ref.point - ray.origin).norm(), ref.distance, 1e-9);
        EXPECT_NEAR(ref.point.norm(), 2.0, 0.01);
        // The right hint, no hint, and a hint on the equator that no ray of this bundle can hit within two
        // rings (the local search fails and the tree answers).
        const fss::FaceIndex equator = caster.closestPoint(Eigen::Vector3d(2.0, 0.0, 0.0)).face;
        for (fss::FaceIndex hint : {ref.face, equator, Mesh::null_face()}) {
            for (bool verify : {false, true}) {
                const SurfacePoint h = caster.intersect(ray, hint, {.rings = 2, .verifyUnoccluded = verify});
                ASSERT_TRUE(h);
                EXPECT_NEAR(h.distance, ref.distance, 1e-9);
            }
        }
    }
    EXPECT_EQ(hits, 500);
    // Ray pointing away misses.
    EXPECT_FALSE(caster.intersect(fss::Ray{{0, 0, 5}, {0, 0, 1}}));
    EXPECT_FALSE(caster.intersect(fss::Ray{{0, 0, 5}, {0, 0, 1}}, *sphere.faces().begin()));
}

TEST(RayCast, HintedIntersectionOnFarSideIsCaughtByVerification) {
    // The hint is a face of the back of the sphere: the local search hits the back, verification finds
    // the front face in the way and answers the true first hit.
    const Mesh sphere = fss::shapes::icosphere(3, 1.0);
    const RayCaster caster(sphere);
    const fss::Ray ray{{0.1, 0.05, 5.0}, {0, 0, -1}};
    const SurfacePoint front = caster.intersect(ray);
    ASSERT_TRUE(front);
    const fss::FaceIndex backFace = caster.closestPoint({0.1, 0.05, -1.0}).face;
    const SurfacePoint local = caster.intersect(ray, backFace, {.rings = 1, .verifyUnoccluded = false});
    ASSERT_TRUE(local);
    EXPECT_LT(local.point.z(), -0.9);
    const SurfacePoint verified = caster.intersect(ray, backFace, {.rings = 1, .verifyUnoccluded = true});
    EXPECT_EQ(verified.face, front.face);
    EXPECT_GT(verified.point.z(), 0.9);
}

TEST(RayCast, ClosestPointOnTriangleRegions) {
    const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    auto cp = [&](double x, double y, double z) { return fss::closestPointOnTriangle({x, y, z}, a, b, c); };
    EXPECT_TRUE(cp(0.5, 0.5, 3).isApprox(Eigen::Vector3d(0.5, 0.5, 0))); // interior
    EXPECT_TRUE(cp(-1, -1, 1).isApprox(a));                              // corner a
    EXPECT_TRUE(cp(3, -1, 0).isApprox(b));                               // corner b
    EXPECT_TRUE(cp(-1, 5, 0).isApprox(c));                               // corner c
    EXPECT_TRUE(cp(1, -3, 0).isApprox(Eigen::Vector3d(1, 0, 0)));        // edge ab
    EXPECT_TRUE(cp(-4, 1, 2).isApprox(Eigen::Vector3d(0, 1, 0)));        // edge ca
    EXPECT_TRUE(cp(2, 2, 0).isApprox(Eigen::Vector3d(1, 1, 0)));         // edge bc
    // Degenerate (collinear) triangle.
    const Eigen::Vector3d q = fss::closestPointOnTriangle({1, 1, 0}, a, b, Eigen::Vector3d(1, 0, 0));
    EXPECT_TRUE(q.isApprox(Eigen::Vector3d(1, 0, 0)));
}

TEST(RayCast, LocalClosestPointWalksToTheTreeAnswer) {
    const Mesh torus = fss::shapes::torus(48, 24, 2.0, 0.5);
    const RayCaster caster(torus);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 2 * 3.14159265358979);
    for (int i = 0; i < 200; ++i) {
        const double phi = u(rng), theta = u(rng);
        const Eigen::Vector3d p((2.0 + 0.55 * std::cos(theta)) * std::cos(phi),
                                (2.0 + 0.55 * std::cos(theta)) * std::sin(phi), 0.55 * std::sin(theta));
        const SurfacePoint ref = caster.closestPoint(p);
        // Start from the face closest to a point a bit around the tube: the walk must get there.
        const double phi2 = phi + 0.3;
        const Eigen::Vector3d q((2.0 + 0.5 * std::cos(theta)) * std::cos(phi2),
                                (2.0 + 0.5 * std::cos(theta)) * std::sin(phi2), 0.5 * std::sin(theta));
        const fss::FaceIndex hint = caster.closestPoint(q).face;
        const SurfacePoint local = fss::closestPointNear(torus, p, hint, {.rings = 2});
        ASSERT_TRUE(local);
        EXPECT_NEAR(local.distance, ref.distance, 1e-12);
        EXPECT_NEAR(ref.distance, 0.05, 0.02);
    }
    EXPECT_THROW(fss::closestPointNear(torus, {0, 0, 0}, fss::FaceIndex(999999)), fss::InvalidInputError);
}

TEST(RayCast, CachedLocalClosestPointGivesTheSameAnswers) {
    // LocalClosestPoint caches rings and skips faces already measured: every answer must be
    // closestPointNear's face for face (also where the walk ends in a local minimum short of the tree's
    // answer), and on the tree's answer where the walk reaches it.
    const Mesh torus = fss::shapes::torus(48, 24, 2.0, 0.5);
    const RayCaster caster(torus);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 2 * 3.14159265358979), r(0.2, 0.9);
    std::uniform_int_distribution<std::uint32_t> face(0, std::uint32_t(torus.num_faces() - 1));
    for (int rings : {0, 1, 2}) {
        fss::detail::LocalClosestPoint cached(torus, {.rings = rings});
        int sameAsTree = 0;
        for (int i = 0; i < 400; ++i) {
            const double phi = u(rng), theta = u(rng), rho = r(rng);
            const Eigen::Vector3d p((2.0 + rho * std::cos(theta)) * std::cos(phi),
                                    (2.0 + rho * std::cos(theta)) * std::sin(phi), rho * std::sin(theta));
            // Hints near the answer (the walk's use) and anywhere (long walks, local minima).
            const fss::FaceIndex hint =
                i % 2 ? caster.closestPoint(p + Eigen::Vector3d(0.1, 0, 0)).face : fss::FaceIndex(face(rng));
            const SurfacePoint walk = fss::closestPointNear(torus, p, hint, {.rings = rings});
            const SurfacePoint got = cached(p, hint);
            ASSERT_TRUE(got);
            EXPECT_EQ(got.face, walk.face);
            EXPECT_EQ(got.point, walk.point);
            EXPECT_EQ(got.distance, walk.distance);
            sameAsTree += std::abs(got.distance - caster.closestPoint(p).distance) < 1e-12;
        }
        if (rings > 0) {
            EXPECT_GT(sameAsTree, 150) << rings; // the walk gets there from the near hints
        }
    }
    fss::detail::LocalClosestPoint cached(torus, {.rings = 2});
    EXPECT_THROW(cached({0, 0, 0}, fss::FaceIndex(999999)), fss::InvalidInputError);
}

TEST(RayCast, RejectsPolygonsAndHandlesEmptyMeshes) {
    Mesh quad;
    auto v0 = quad.add_vertex({0, 0, 0}), v1 = quad.add_vertex({1, 0, 0}), v2 = quad.add_vertex({1, 1, 0}),
         v3 = quad.add_vertex({0, 1, 0});
    quad.add_face(v0, v1, v2, v3);
    EXPECT_THROW(RayCaster{quad}, fss::InvalidInputError);

    const Mesh empty;
    const RayCaster caster(empty);
    EXPECT_FALSE(caster.intersect(fss::Ray{{0, 0, 1}, {0, 0, -1}}));
    EXPECT_FALSE(caster.closestPoint({0, 0, 0}));
    Camera cam;
    cam.width = 8;
    cam.height = 4;
    const FrameBuffers fb = fss::rasterizeOnCpu(empty, cam);
    EXPECT_EQ(fb.coveredCount(), 0u);
    EXPECT_EQ(fb.faceId.size(), 32u);

    Camera bad;
    bad.width = 0;
    EXPECT_THROW(fss::rasterizeOnCpu(empty, bad), fss::InvalidInputError);
}

TEST(RayCast, NearPlaneClipsLikeGl) {
    // A grid at z = 0 seen from z = 1 with the near plane beyond it: nothing is drawn.
    const Mesh plane = fss::shapes::grid(4, 4, 0.5);
    Camera cam;
    cam.eye = {1, 1, 1};
    cam.focal = {1, 1, 0};
    cam.width = cam.height = 16;
    cam.nearPlane = 1.5;
    cam.farPlane = 10;
    EXPECT_EQ(fss::rasterizeOnCpu(plane, cam).coveredCount(), 0u);
    cam.nearPlane = 0.5;
    cam.farPlane = 0.9; // and the far plane before it: nothing either
    EXPECT_EQ(fss::rasterizeOnCpu(plane, cam).coveredCount(), 0u);
    cam.farPlane = 1.1;
    EXPECT_EQ(fss::rasterizeOnCpu(plane, cam).coveredCount(), 256u);
}
