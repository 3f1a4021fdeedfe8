#pragma once
// The helpers the metrics tests share (metrics_test.cpp, metrics_distances_test.cpp): a moved and scaled
// mesh, a mesh from triangles, the metrics against a reference and the radius ratio from three sides.
#include "fss/error.h"
#include "fss/metrics.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

using fss::Mesh;
using fss::Metrics;
using fss::MetricsOptions;
using fss::Point3;

namespace metrics_test_helpers {

constexpr double kPi = std::numbers::pi;

inline Mesh transformed(Mesh m, double scale, double dx = 0, double dy = 0, double dz = 0) {
    for (auto v : m.vertices()) {
        const Point3& p = m.point(v);
        m.point(v) = Point3(scale * p.x() + dx, scale * p.y() + dy, scale * p.z() + dz);
    }
    return m;
}

inline Mesh fromTriangles(const std::vector<Point3>& points,
                          const std::vector<std::array<int, 3>>& triangles) {
    Mesh m;
    std::vector<fss::VertexIndex> v;
    for (const Point3& p : points)
        v.push_back(m.add_vertex(p));
    for (const auto& t : triangles) {
        const auto f = m.add_face(v[t[0]], v[t[1]], v[t[2]]);
        EXPECT_NE(f, Mesh::null_face()) << "test mesh could not be built";
    }
    return m;
}

inline Metrics withReference(const Mesh& mesh, const Mesh& reference) {
    MetricsOptions options;
    options.reference = &reference;
    options.selfIntersections = false;
    return fss::computeMetrics(mesh, options);
}

// Radius ratio 2 r_in / r_circ of a triangle with sides a, b, c (Heron), for the expected values.
inline double radiusRatioOfSides(double a, double b, double c) {
    const double s = (a + b + c) / 2;
    const double area = std::sqrt(s * (s - a) * (s - b) * (s - c));
    return 2 * (area / s) / (a * b * c / (4 * area));
}

} // namespace metrics_test_helpers
