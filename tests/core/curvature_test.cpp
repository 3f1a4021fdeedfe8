// Curvature by jet fitting against analytic surfaces: torus (regular and irregularly sampled), open
// cylinder, sphere; degenerate neighbourhoods, bad options and cancellation.
#include "fss/curvature.h"
#include "fss/error.h"
#include "fss/shapes.h"
#include "test_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

using fss::CurvatureField;
using fss::Mesh;
using fss::VertexIndex;

namespace {

using fss::test::kDeg;
using fss::test::kPi;
using fss::test::median;

// Angle between two lines (direction sign ignored), degrees.
double lineAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const double c = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
    return std::acos(c) * kDeg;
}

double quantile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, std::size_t(q * double(v.size())))];
}

// Exact principal frame of the torus (major radius R around z, minor radius r) at a point on it:
// d1 (k1 = 1/r) along the tube's small circle (meridian), d2 (k2 = cos v / (R + r cos v)) around the axis.
// 1/r > cos v / (R + r cos v) everywhere when R > r, so the meridian is the maximal direction on the
// outer (k2 > 0) and the inner (k2 < 0) side alike.
struct TorusFrame {
    Eigen::Vector3d d1, d2;
    double k1, k2;
};
TorusFrame torusFrame(const Eigen::Vector3d& p, double R, double r) {
    const double u = std::atan2(p.y(), p.x());
    const double v = std::atan2(p.z(), std::hypot(p.x(), p.y()) - R);
    TorusFrame f;
    f.d1 = Eigen::Vector3d(-std::sin(v) * std::cos(u), -std::sin(v) * std::sin(u), std::cos(v));
    f.d2 = Eigen::Vector3d(-std::sin(u), std::cos(u), 0);
    f.k1 = 1.0 / r;
    f.k2 = std::cos(v) / (R + r * std::cos(v));
    return f;
}

struct Errors {
    std::vector<double> d1Deg, d2Deg, k1Rel, k2Abs;
};

Errors torusErrors(const Mesh& m, const CurvatureField& c, double R, double r) {
    Errors e;
    for (VertexIndex v : m.vertices()) {
        EXPECT_TRUE(c.isDefined(v));
        const TorusFrame f = torusFrame(fss::test::position(m, v), R, r);
        e.d1Deg.push_back(lineAngleDeg(c.d1[v.idx()], f.d1));
        e.d2Deg.push_back(lineAngleDeg(c.d2[v.idx()], f.d2));
        e.k1Rel.push_back(std::abs(c.k1[v.idx()] - f.k1) / f.k1);
        e.k2Abs.push_back(std::abs(c.k2[v.idx()] - f.k2) * r); // relative to the scale 1/r
    }
    return e;
}

void printErrors(const char* name, const Errors& e) {
    std::printf("[ %s ] median d1 %.4f deg, d2 %.4f deg; p95 d1 %.4f deg; max d1 %.4f deg; "
                "median |k1-1/r|/k1 %.2e; median |k2 err|*r %.2e\n",
                name, median(e.d1Deg), median(e.d2Deg), quantile(e.d1Deg, 0.95),
                *std::max_element(e.d1Deg.begin(), e.d1Deg.end()), median(e.k1Rel), median(e.k2Abs));
}

} // namespace

TEST(Curvature, TorusPrincipalDirectionsAndCurvatures) {
    const double R = 1.0, r = 0.3;
    const Mesh m = fss::shapes::torus(200, 100, R, r);
    ASSERT_EQ(m.number_of_vertices(), 20000u);
    const CurvatureField c = fss::estimateCurvature(m);
    ASSERT_EQ(c.size(), 20000u);
    const Errors e = torusErrors(m, c, R, r);
    printErrors("torus 200x100", e);
    EXPECT_LE(median(e.d1Deg), 5.0);
    EXPECT_LE(median(e.d2Deg), 5.0);
    EXPECT_LE(quantile(e.d1Deg, 0.95), 5.0);
    EXPECT_LE(median(e.k1Rel), 0.02);
    EXPECT_LE(median(e.k2Abs), 0.02);
    for (VertexIndex v : m.vertices()) {
        // k1 ≥ k2, orthonormal tangent frame.
        EXPECT_GE(c.k1[v.idx()], c.k2[v.idx()]);
        EXPECT_NEAR(c.d1[v.idx()].dot(c.d2[v.idx()]), 0.0, 1e-9);
        EXPECT_NEAR(c.d1[v.idx()].dot(c.normal[v.idx()]), 0.0, 0.05);
        // Outward normal: away from the tube's centre circle.
        const Eigen::Vector3d p = fss::test::position(m, v);
        const Eigen::Vector3d centre = Eigen::Vector3d(p.x(), p.y(), 0).normalized() * R;
        EXPECT_GT(c.normal[v.idx()].dot(p - centre), 0.0);
    }
}

TEST(Curvature, TorusOuterAndInnerRegions) {
    // Outer equator: both curvatures positive (convex); inner equator: k2 = -1/(R - r) < 0 (saddle).
    const double R = 1.0, r = 0.3;
    const Mesh m = fss::shapes::torus(200, 100, R, r);
    const CurvatureField c = fss::estimateCurvature(m);
    for (VertexIndex v : m.vertices()) {
        const Eigen::Vector3d p = fss::test::position(m, v);
        if (std::abs(p.z()) > 1e-9) continue;
        const double rho = std::hypot(p.x(), p.y());
        const double k2Exact = rho > R ? 1.0 / (R + r) : -1.0 / (R - r);
        EXPECT_NEAR(c.k1[v.idx()], 1.0 / r, 0.02 / r);
        EXPECT_NEAR(c.k2[v.idx()], k2Exact, 0.02 / r);
        const TorusFrame f = torusFrame(p, R, r);
        EXPECT_LE(lineAngleDeg(c.d1[v.idx()], f.d1), 1.0);
        // Anisotropy (k1 - k2) / (|k1| + |k2|): R/(R + 2r) outside, 1 inside (opposite signs).
        const double aExact = rho > R ? R / (R + 2 * r) : 1.0;
        EXPECT_NEAR(c.anisotropy[v.idx()], aExact, 0.02);
    }
}

TEST(Curvature, IrregularlySampledTorusStaysAccurate) {
    // Same torus, every vertex moved within the surface by up to ±0.35 of a grid cell in (u, v):
    // irregular triangles, exact positions on the analytic surface.
    const double R = 1.0, r = 0.3;
    const int nu = 200, nv = 100;
    Mesh m = fss::shapes::torus(nu, nv, R, r);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.35, 0.35);
    for (VertexIndex v : m.vertices()) {
        const Eigen::Vector3d p = fss::test::position(m, v);
        const double u = std::atan2(p.y(), p.x()) + jitter(rng) * 2 * kPi / nu;
        const double w = std::atan2(p.z(), std::hypot(p.x(), p.y()) - R) + jitter(rng) * 2 * kPi / nv;
        const double rho = R + r * std::cos(w);
        m.point(v) = fss::Point3(rho * std::cos(u), rho * std::sin(u), r * std::sin(w));
    }
    const CurvatureField c = fss::estimateCurvature(m);
    const Errors e = torusErrors(m, c, R, r);
    printErrors("irregular torus", e);
    EXPECT_LE(median(e.d1Deg), 5.0);
    EXPECT_LE(median(e.d2Deg), 5.0);
    EXPECT_LE(median(e.k1Rel), 0.05);

    fss::CurvatureOptions cubic;
    cubic.jetDegree = 3;
    cubic.minPoints = 19;
    const Errors e3 = torusErrors(m, fss::estimateCurvature(m, cubic), R, r);
    printErrors("irregular torus, degree 3", e3);
    EXPECT_LE(median(e3.d1Deg), 5.0);
}

TEST(Curvature, OpenCylinder) {
    const double radius = 1.0;
    const Mesh m = fss::shapes::cylinder(128, 64, radius, 4.0, /*capped=*/false);
    const CurvatureField c = fss::estimateCurvature(m);
    std::vector<double> d1Err, d2Err, k1Err, k2Err, boundaryD1Err;
    for (VertexIndex v : m.vertices()) {
        ASSERT_TRUE(c.isDefined(v));
        const Eigen::Vector3d p = fss::test::position(m, v);
        const Eigen::Vector3d around(-p.y(), p.x(), 0), axis(0, 0, 1);
        d1Err.push_back(lineAngleDeg(c.d1[v.idx()], around));
        d2Err.push_back(lineAngleDeg(c.d2[v.idx()], axis));
        k1Err.push_back(std::abs(c.k1[v.idx()] - 1.0 / radius));
        k2Err.push_back(std::abs(c.k2[v.idx()]));
        if (m.is_border(v)) boundaryD1Err.push_back(d1Err.back());
        EXPECT_GT(c.normal[v.idx()].dot(Eigen::Vector3d(p.x(), p.y(), 0)), 0.99);
    }
    std::printf("[ cylinder ] median d1 %.4f deg, d2 %.4f deg, max d1 %.4f deg, boundary median d1 %.4f "
                "deg; median |k1-1/r| %.2e, median |k2| %.2e\n",
                median(d1Err), median(d2Err), *std::max_element(d1Err.begin(), d1Err.end()),
                median(boundaryD1Err), median(k1Err), median(k2Err));
    EXPECT_LE(median(d1Err), 5.0);
    EXPECT_LE(median(d2Err), 5.0);
    EXPECT_LE(median(boundaryD1Err), 5.0);
    EXPECT_LE(median(k1Err), 0.01);
    EXPECT_LE(median(k2Err), 0.01);
}

TEST(Curvature, SphereIsUmbilicWithLowAnisotropy) {
    const double radius = 2.0;
    const Mesh m = fss::shapes::icosphere(5, radius);
    const CurvatureField c = fss::estimateCurvature(m);
    std::vector<double> aniso, k1Err, k2Err;
    for (VertexIndex v : m.vertices()) {
        ASSERT_TRUE(c.isDefined(v));
        aniso.push_back(c.anisotropy[v.idx()]);
        k1Err.push_back(std::abs(c.k1[v.idx()] - 1 / radius) * radius);
        k2Err.push_back(std::abs(c.k2[v.idx()] - 1 / radius) * radius);
    }
    std::printf("[ sphere ] median anisotropy %.2e, p95 %.2e, max %.2e; median rel k1 err %.2e, k2 %.2e\n",
                median(aniso), quantile(aniso, 0.95), *std::max_element(aniso.begin(), aniso.end()),
                median(k1Err), median(k2Err));
    EXPECT_LE(median(aniso), 0.02);
    EXPECT_LE(quantile(aniso, 0.95), 0.05);
    EXPECT_LE(median(k1Err), 0.01);
    EXPECT_LE(median(k2Err), 0.01);
}

TEST(Curvature, PlaneHasZeroCurvatureAndAnisotropy) {
    const Mesh m = fss::shapes::grid(20, 20, 0.1);
    const CurvatureField c = fss::estimateCurvature(m);
    for (VertexIndex v : m.vertices()) {
        ASSERT_TRUE(c.isDefined(v));
        EXPECT_NEAR(c.k1[v.idx()], 0.0, 1e-9);
        EXPECT_NEAR(c.k2[v.idx()], 0.0, 1e-9);
        EXPECT_LT(c.anisotropy[v.idx()], 1e-6);
        EXPECT_NEAR(c.normal[v.idx()].z(), 1.0, 1e-12);
    }
}

TEST(Curvature, DegenerateNeighbourhoodsAreUndefined) {
    // A lone triangle (3 points < 6 unknowns) and an isolated vertex: undefined, anisotropy 0.
    Mesh m;
    const auto a = m.add_vertex({0, 0, 0}), b = m.add_vertex({1, 0, 0}), d = m.add_vertex({0, 1, 0});
    m.add_face(a, b, d);
    const auto lonely = m.add_vertex({5, 5, 5});
    const CurvatureField c = fss::estimateCurvature(m);
    ASSERT_EQ(c.size(), 4u);
    for (VertexIndex v : {a, b, d, lonely}) {
        EXPECT_FALSE(c.isDefined(v));
        EXPECT_EQ(c.anisotropy[v.idx()], 0.0);
        EXPECT_TRUE(c.d1[v.idx()].isZero());
    }
    // Degree 3 on a 2-ring of 19 points works; on a tiny neighbourhood it falls back to degree 2.
    fss::CurvatureOptions cubic;
    cubic.jetDegree = 3;
    cubic.minPoints = 6;
    cubic.maxRings = 1; // 1-ring of a regular grid: 7 points < 10 unknowns → degree 2
    const Mesh g = fss::shapes::grid(6, 6, 1.0);
    const CurvatureField cg = fss::estimateCurvature(g, cubic);
    std::size_t defined = 0;
    for (VertexIndex v : g.vertices())
        defined += cg.isDefined(v);
    EXPECT_GT(defined, 0u);
}

TEST(Curvature, EmptyMeshGivesEmptyField) {
    EXPECT_EQ(fss::estimateCurvature(Mesh()).size(), 0u);
}

TEST(Curvature, BadOptionsThrow) {
    const Mesh m = fss::shapes::icosphere(1);
    fss::CurvatureOptions o;
    o.jetDegree = 4;
    EXPECT_THROW(fss::estimateCurvature(m, o), fss::InvalidInputError);
    o = {};
    o.minPoints = 5;
    EXPECT_THROW(fss::estimateCurvature(m, o), fss::InvalidInputError);
    o = {};
    o.maxRings = 0;
    EXPECT_THROW(fss::estimateCurvature(m, o), fss::InvalidInputError);
    o = {};
    o.anisotropyEpsilon = 0;
    EXPECT_THROW(fss::estimateCurvature(m, o), fss::InvalidInputError);
    Mesh bad = m;
    bad.point(*bad.vertices().begin()) = fss::Point3(std::nan(""), 0, 0);
    EXPECT_THROW(fss::estimateCurvature(bad), fss::InvalidInputError);
}

TEST(Curvature, ProgressReportsAndCancels) {
    const Mesh m = fss::shapes::torus(200, 100);
    std::vector<double> fractions;
    fss::Progress recording([&](double f, std::string_view stage) {
        EXPECT_EQ(stage, "curvature");
        fractions.push_back(f);
        return true;
    });
    fss::estimateCurvature(m, {}, recording);
    ASSERT_GE(fractions.size(), 3u);
    EXPECT_EQ(fractions.front(), 0.0);
    EXPECT_EQ(fractions.back(), 1.0);
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));

    int calls = 0;
    fss::Progress cancelling([&](double, std::string_view) { return ++calls < 2; });
    EXPECT_THROW(fss::estimateCurvature(m, {}, cancelling), fss::CancelledError);
}
