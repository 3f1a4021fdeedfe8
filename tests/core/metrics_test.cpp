// Quality metrics: exact values on analytic shapes and hand-made meshes. Distances, formatting and the
// brute-force cross-check on CGAL's sample meshes: metrics_distances_test.cpp.
#include "metrics_helpers.h"

using namespace metrics_test_helpers;

// ---- analytic shapes ------------------------------------------------------------------------------------

TEST(Metrics, GridCountsValenceAndShape) {
    const int n = 7, m = 5;
    const double h = 0.5;
    const Metrics x = fss::computeMetrics(fss::shapes::grid(n, m, h));
    EXPECT_EQ(x.vertices, std::size_t((n + 1) * (m + 1)));
    EXPECT_EQ(x.faces, std::size_t(2 * n * m));
    EXPECT_EQ(x.edges, std::size_t(3 * n * m + n + m));
    EXPECT_EQ(x.boundaryEdges, std::size_t(2 * (n + m)));
    EXPECT_EQ(x.boundaryLoops, 1u);
    EXPECT_EQ(x.components, 1u);
    EXPECT_FALSE(x.closed);
    EXPECT_EQ(x.nonManifoldVertices, 0u);
    EXPECT_EQ(x.degenerateFaces, 0u);
    ASSERT_TRUE(x.selfIntersections.has_value());
    EXPECT_EQ(*x.selfIntersections, 0u);
    EXPECT_EQ(x.valenceHistogram, (std::map<int, std::size_t>{{6, std::size_t((n - 1) * (m - 1))}}));
    EXPECT_EQ(x.interiorVertices, std::size_t((n - 1) * (m - 1)));
    EXPECT_DOUBLE_EQ(x.fracValence6Interior, 1.0);

    // Right isosceles triangles, legs h: angles 45, 45, 90.
    EXPECT_NEAR(x.minAngleDeg, 45, 1e-9);
    EXPECT_NEAR(x.maxAngleDeg, 90, 1e-9);
    EXPECT_NEAR(x.meanMinAngleDeg, 45, 1e-9);
    EXPECT_EQ(x.fracMinAngleBelow30, 0.0);
    EXPECT_EQ(x.fracMinAngleBelow10, 0.0);
    // Legs 1, hypotenuse sqrt2: r_in = (1 + 1 - sqrt2)/2, r_circ = sqrt2/2, so 2 r_in/r_circ = 2(sqrt2 - 1).
    const double rr = 2 * (std::sqrt(2.0) - 1);
    EXPECT_NEAR(rr, radiusRatioOfSides(1, 1, std::sqrt(2.0)), 1e-12);
    EXPECT_NEAR(x.radiusRatioMean, rr, 1e-12);
    EXPECT_NEAR(x.radiusRatioMin, rr, 1e-12);

    // Edges: n(m+1) horizontal + (n+1)m vertical of length h, nm diagonals of length h sqrt2.
    const double axis = n * (m + 1) + (n + 1) * m, diag = n * m, count = axis + diag;
    const double mean = h * (axis + diag * std::sqrt(2.0)) / count;
    const double meanSq = h * h * (axis + 2 * diag) / count;
    EXPECT_NEAR(x.edgeLengthMean, mean, 1e-12);
    EXPECT_NEAR(x.edgeLengthCv, std::sqrt(meanSq - mean * mean) / mean, 1e-12);
    EXPECT_NEAR(x.bboxDiagonal, std::hypot(n * h, m * h), 1e-12);
    EXPECT_NEAR(x.area, n * m * h * h, 1e-12);
    EXPECT_FALSE(x.hausdorffToRef || x.hausdorffFromRef || x.hausdorffToRefRel || x.hausdorffFromRefRel ||
                 x.rmsToRef);
}

TEST(Metrics, IcosahedronIsEquilateralAndClosed) {
    const double radius = 2.0;
    const Metrics x = fss::computeMetrics(fss::shapes::icosahedron(radius));
    EXPECT_EQ(x.vertices, 12u);
    EXPECT_EQ(x.faces, 20u);
    EXPECT_EQ(x.edges, 30u);
    EXPECT_TRUE(x.closed);
    EXPECT_EQ(x.boundaryEdges, 0u);
    EXPECT_EQ(x.boundaryLoops, 0u);
    EXPECT_EQ(x.components, 1u);
    EXPECT_EQ(x.valenceHistogram, (std::map<int, std::size_t>{{5, 12}}));
    EXPECT_EQ(x.interiorVertices, 12u);
    EXPECT_EQ(x.fracValence6Interior, 0.0);
    EXPECT_NEAR(x.minAngleDeg, 60, 1e-9);
    EXPECT_NEAR(x.maxAngleDeg, 60, 1e-9);
    EXPECT_NEAR(x.meanMinAngleDeg, 60, 1e-9);
    EXPECT_NEAR(x.radiusRatioMean, 1, 1e-12);
    EXPECT_NEAR(x.radiusRatioMin, 1, 1e-12);
    const double a = radius / std::sin(2 * kPi / 5); // edge of the icosahedron with circumradius `radius`
    EXPECT_NEAR(x.edgeLengthMean, a, 1e-12);
    EXPECT_NEAR(x.edgeLengthCv, 0, 1e-12);
    EXPECT_NEAR(x.area, 20 * std::sqrt(3.0) / 4 * a * a, 1e-12);
    EXPECT_EQ(*x.selfIntersections, 0u);
}

TEST(Metrics, TorusHasValenceSixEverywhere) {
    const Metrics x = fss::computeMetrics(fss::shapes::torus(24, 12));
    EXPECT_EQ(x.vertices, 24u * 12u);
    EXPECT_EQ(x.faces, 2u * 24u * 12u);
    EXPECT_EQ(x.edges, 3u * 24u * 12u);
    EXPECT_TRUE(x.closed);
    EXPECT_EQ(x.components, 1u);
    EXPECT_EQ(x.valenceHistogram, (std::map<int, std::size_t>{{6, 24 * 12}}));
    EXPECT_DOUBLE_EQ(x.fracValence6Interior, 1.0);
    EXPECT_EQ(*x.selfIntersections, 0u);
}

TEST(Metrics, CubeHasNoDegenerateFaces) {
    const Metrics x = fss::computeMetrics(fss::shapes::cube(3, 2.0));
    EXPECT_EQ(x.degenerateFaces, 0u);
    EXPECT_EQ(*x.selfIntersections, 0u);
    EXPECT_TRUE(x.closed);
    EXPECT_NEAR(x.area, 6 * 4.0, 1e-12);
    EXPECT_NEAR(x.bboxDiagonal, 2 * std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(x.minAngleDeg, 45, 1e-9);
    EXPECT_NEAR(x.maxAngleDeg, 90, 1e-9);
}

// ---- hand-made meshes ---------------------------------------------------------------------------------

TEST(Metrics, CollinearFaceIsDegenerate) {
    // a, b, c on the x axis; d below: (a, b, c) is degenerate, (b, a, d) is a proper triangle sharing ab.
    const Mesh m = fromTriangles({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0.5, -1, 0}}, {{0, 1, 2}, {1, 0, 3}});
    const Metrics x = fss::computeMetrics(m);
    EXPECT_EQ(x.faces, 2u);
    EXPECT_EQ(x.degenerateFaces, 1u);
    EXPECT_NEAR(x.minAngleDeg, 0, 1e-12);
    EXPECT_NEAR(x.maxAngleDeg, 180, 1e-12);
    EXPECT_EQ(x.radiusRatioMin, 0.0);
    EXPECT_EQ(x.fracMinAngleBelow10, 0.5);
    EXPECT_EQ(*x.selfIntersections, 0u); // degenerate faces are reported in degenerateFaces only
    EXPECT_NEAR(x.area, 0.5, 1e-12);
}

TEST(Metrics, DisjointShapesAreTwoComponents) {
    Mesh m = fss::shapes::icosphere(1);
    m.join(transformed(fss::shapes::torus(16, 8), 1.0, 5, 0, 0));
    const Metrics x = fss::computeMetrics(m);
    EXPECT_EQ(x.components, 2u);
    EXPECT_TRUE(x.closed);
    EXPECT_EQ(*x.selfIntersections, 0u);
}

TEST(Metrics, HoleInGridIsASecondBoundaryLoop) {
    Mesh m = fss::shapes::grid(4, 4);
    // Remove both triangles of the quad [1,2]x[1,2]: a square hole with 4 boundary edges.
    std::vector<fss::FaceIndex> hole;
    for (auto f : m.faces()) {
        double cx = 0, cy = 0;
        for (auto v : m.vertices_around_face(m.halfedge(f))) {
            cx += m.point(v).x() / 3;
            cy += m.point(v).y() / 3;
        }
        if (cx > 1 && cx < 2 && cy > 1 && cy < 2) hole.push_back(f);
    }
    ASSERT_EQ(hole.size(), 2u);
    for (auto f : hole)
        CGAL::Euler::remove_face(m.halfedge(f), m);
    ASSERT_TRUE(m.has_garbage());
    const Metrics x = fss::computeMetrics(m);
    EXPECT_EQ(x.faces, 30u);
    EXPECT_EQ(x.edges, 3u * 16u + 8u - 1u); // the hole's diagonal is gone
    EXPECT_EQ(x.boundaryEdges, 16u + 4u);
    EXPECT_EQ(x.boundaryLoops, 2u);
    EXPECT_EQ(x.components, 1u);
    EXPECT_FALSE(x.closed);
    EXPECT_EQ(x.interiorVertices, 9u - 4u);
    EXPECT_NEAR(x.area, 15.0, 1e-12);
}

TEST(Metrics, GarbageIsIgnored) {
    Mesh m = fss::shapes::icosphere(2);
    // Two faces far apart: two triangular holes.
    const auto f0 = *m.faces().begin();
    fss::FaceIndex far = f0;
    double best = 0;
    for (auto f : m.faces()) {
        const double d =
            CGAL::squared_distance(m.point(m.target(m.halfedge(f))), m.point(m.target(m.halfedge(f0))));
        if (d > best) best = d, far = f;
    }
    CGAL::Euler::remove_face(m.halfedge(f0), m);
    CGAL::Euler::remove_face(m.halfedge(far), m);
    ASSERT_TRUE(m.has_garbage());
    Mesh compact = m;
    compact.collect_garbage();

    const Metrics x = withReference(m, fss::shapes::icosphere(2));
    const Metrics y = withReference(compact, fss::shapes::icosphere(2));
    EXPECT_EQ(x.faces, 320u - 2u);
    EXPECT_EQ(x.boundaryLoops, 2u);
    EXPECT_EQ(x.boundaryEdges, 6u);
    EXPECT_EQ(fss::metricsToJson(x), fss::metricsToJson(y));
    const Metrics z = fss::computeMetrics(m);
    EXPECT_EQ(*z.selfIntersections, 0u);
}

// valenceAndMinAngle gives computeMetrics' two figures bit for bit, with garbage, borders, a pinched vertex
// and a degenerate face too (the brute-force comparison is in MetricsOnSampleMesh).
TEST(Metrics, ValenceAndMinAngleAreComputeMetricsFigures) {
    std::vector<Mesh> meshes = {fss::shapes::icosphere(3), fss::shapes::uvSphere(40, 21),
                                fss::shapes::torus(30, 12, 1.0, 0.3)};
    Mesh holed = fss::shapes::icosphere(2);
    CGAL::Euler::remove_face(holed.halfedge(*holed.faces().begin()), holed);
    ASSERT_TRUE(holed.has_garbage());
    meshes.push_back(holed);
    Mesh pinched; // two triangles sharing one vertex only, plus a collinear one
    const auto o = pinched.add_vertex({0, 0, 0}), a = pinched.add_vertex({1, 0, 0}),
               b = pinched.add_vertex({0, 1, 0}), c = pinched.add_vertex({-1, 0, 0}),
               d = pinched.add_vertex({0, -1, 0}), e = pinched.add_vertex({2, 0, 0}),
               f = pinched.add_vertex({3, 0, 0});
    pinched.add_face(o, a, b);
    pinched.add_face(o, c, d);
    pinched.add_face(a, e, f);
    meshes.push_back(pinched);
    meshes.push_back(Mesh{});
    for (const Mesh& m : meshes) {
        fss::MetricsOptions options;
        options.selfIntersections = false;
        const Metrics x = fss::computeMetrics(m, options);
        const fss::ValenceAndMinAngle y = fss::valenceAndMinAngle(m);
        EXPECT_EQ(y.fracValence6Interior, x.fracValence6Interior) << m.number_of_faces() << " faces";
        EXPECT_EQ(y.minAngleDeg, x.minAngleDeg) << m.number_of_faces() << " faces";
    }
    EXPECT_EQ(fss::valenceAndMinAngle(pinched).minAngleDeg, 0.0);                      // the collinear face
    EXPECT_EQ(fss::valenceAndMinAngle(meshes[0]).fracValence6Interior, 630.0 / 642.0); // 12 of valence 5
}

// valenceAndMinAngle reports every kFiguresProgressFaces faces of its angle loop and stops when its progress
// asks: a stop at the second report in the loop leaves it after exactly kFiguresProgressFaces faces; a
// progress that never stops changes no figure.
TEST(Metrics, ValenceAndMinAngleStopsWhenAsked) {
    const Mesh torus = fss::shapes::torus(200, 100, 1.0, 0.4); // 40000 faces: 10 reports in the angle loop
    const double faces = double(torus.number_of_faces());
    std::vector<std::pair<std::string, double>> seen;
    const fss::Progress all([&](double f, std::string_view stage) {
        seen.emplace_back(std::string(stage), f);
        return true;
    });
    const fss::ValenceAndMinAngle whole = fss::valenceAndMinAngle(torus, all);
    const fss::ValenceAndMinAngle plain = fss::valenceAndMinAngle(torus);
    EXPECT_EQ(whole.fracValence6Interior, plain.fracValence6Interior);
    EXPECT_EQ(whole.minAngleDeg, plain.minAngleDeg);
    // The valence count visits 120000 halfedges and 20000 vertices: 35 reports (0, 4096, … 139264 steps).
    const double steps = double(torus.number_of_halfedges() + torus.number_of_vertices());
    ASSERT_EQ(steps, 140000.0);
    ASSERT_EQ(seen.size(),
              35u + 10u + 1u); // 35 "valence", 10 in the angle loop (0, 4096, … 36864), the final 1
    for (std::size_t k = 0; k < 35; ++k) {
        EXPECT_EQ(seen[k].first, "valence") << k;
        EXPECT_EQ(seen[k].second, double(k * fss::kFiguresProgressFaces) / steps) << k;
    }
    for (std::size_t k = 0; k < 10; ++k)
        EXPECT_EQ(seen[35 + k].second, double(k * fss::kFiguresProgressFaces) / faces) << k;
    EXPECT_EQ(seen.back().second, 1.0);

    // A stop at the second report of the valence count leaves it after exactly kFiguresProgressFaces steps,
    // before any face's angle (session 17's count could not be stopped).
    std::size_t valenceReports = 0, angleReports = 0;
    const fss::Progress stopInValence([&](double, std::string_view stage) {
        if (stage != "valence") {
            ++angleReports;
            return true;
        }
        return ++valenceReports < 2;
    });
    EXPECT_THROW(fss::valenceAndMinAngle(torus, stopInValence), fss::CancelledError);
    EXPECT_EQ(valenceReports, 2u);
    EXPECT_EQ(angleReports, 0u);

    std::size_t loopReports = 0;
    double stoppedAt = -1;
    const fss::Progress stop([&](double f, std::string_view stage) {
        if (stage != "smallest angle") return true;
        stoppedAt = f;
        return ++loopReports < 2;
    });
    EXPECT_THROW(fss::valenceAndMinAngle(torus, stop), fss::CancelledError);
    EXPECT_EQ(loopReports, 2u);
    EXPECT_EQ(stoppedAt * faces, double(fss::kFiguresProgressFaces));
}

// valenceAndMinAngle measures a mesh holding garbage as it is (no dense copy, which could not be stopped):
// its figures and its step and face counts are those of the collected mesh, and computeMetrics' on it.
TEST(Metrics, ValenceAndMinAngleMeasuresAMeshWithGarbageInPlace) {
    Mesh holed = fss::shapes::torus(60, 30, 1.0, 0.4);
    std::size_t removed = 0;
    const std::vector<fss::FaceIndex> faces(holed.faces().begin(), holed.faces().end());
    for (fss::FaceIndex f : faces) // every 7th face (and the edges and vertices it leaves alone)
        if (std::size_t(f) % 7 == 3) {
            CGAL::Euler::remove_face(holed.halfedge(f), holed);
            ++removed;
        }
    ASSERT_GT(removed, 200u);
    ASSERT_TRUE(holed.has_garbage());
    Mesh dense = holed;
    dense.collect_garbage();
    ASSERT_EQ(holed.number_of_faces(), dense.number_of_faces());
    ASSERT_LT(holed.number_of_faces(), holed.num_faces()); // removed faces are still stored
    auto counted = [](const Mesh& m, std::size_t& valence, std::size_t& angle) {
        return fss::valenceAndMinAngle(m, fss::Progress([&](double, std::string_view stage) {
                                           ++(stage == "valence" ? valence : angle);
                                           return true;
                                       }));
    };
    std::size_t valenceHoled = 0, angleHoled = 0, valenceDense = 0, angleDense = 0;
    const fss::ValenceAndMinAngle inPlace = counted(holed, valenceHoled, angleHoled);
    const fss::ValenceAndMinAngle collected = counted(dense, valenceDense, angleDense);
    const fss::Metrics reference = fss::computeMetrics(dense);
    EXPECT_EQ(inPlace.fracValence6Interior, reference.fracValence6Interior);
    EXPECT_EQ(inPlace.minAngleDeg, reference.minAngleDeg);
    EXPECT_EQ(collected.fracValence6Interior, reference.fracValence6Interior);
    EXPECT_EQ(collected.minAngleDeg, reference.minAngleDeg);
    EXPECT_LT(reference.interiorVertices, std::size_t(60 * 30)); // the holes' corners are border vertices
    EXPECT_EQ(valenceHoled, valenceDense);
    EXPECT_EQ(angleHoled, angleDense);
}

TEST(Metrics, PinchedVertexIsNonManifold) {
    // Two open fans of two triangles each, above and below the apex, sharing only the apex: Surface_mesh
    // accepts this (the apex is on the border of both) and keeps one vertex with two umbrellas.
    const std::vector<Point3> pts = {{0, 0, 0},  {1, 0, 1},  {0, 1, 1},  {-1, 0, 1},
                                     {1, 0, -1}, {0, 1, -1}, {-1, 0, -1}};
    const Mesh m = fromTriangles(pts, {{0, 1, 2}, {0, 2, 3}, {0, 5, 4}, {0, 6, 5}});
    ASSERT_EQ(m.number_of_faces(), 4u);
    ASSERT_EQ(m.number_of_vertices(), 7u);
    const Metrics x = fss::computeMetrics(m);
    EXPECT_EQ(x.nonManifoldVertices, 1u);
    EXPECT_EQ(x.components, 2u);
    EXPECT_EQ(x.boundaryEdges, 8u);
    // Surface_mesh links both fans' borders through the apex: one figure-8 cycle of border halfedges.
    EXPECT_EQ(x.boundaryLoops, 1u);
    EXPECT_EQ(x.interiorVertices, 0u);
    EXPECT_FALSE(x.closed);

    const Metrics manifold = fss::computeMetrics(fss::shapes::icosphere(2));
    EXPECT_EQ(manifold.nonManifoldVertices, 0u);
}

TEST(Metrics, InterpenetratingSpheresSelfIntersect) {
    Mesh m = fss::shapes::icosphere(2);
    m.join(transformed(fss::shapes::icosphere(2), 1.0, 1.0, 0, 0));
    const Metrics x = fss::computeMetrics(m);
    ASSERT_TRUE(x.selfIntersections.has_value());
    EXPECT_GT(*x.selfIntersections, 0u);
    EXPECT_EQ(x.components, 2u);

    const Metrics clean = fss::computeMetrics(fss::shapes::icosphere(3));
    EXPECT_EQ(*clean.selfIntersections, 0u);

    MetricsOptions skip;
    skip.selfIntersectionMaxFaces = 100;
    EXPECT_FALSE(fss::computeMetrics(m, skip).selfIntersections.has_value());
    skip = {};
    skip.selfIntersections = false;
    EXPECT_FALSE(fss::computeMetrics(m, skip).selfIntersections.has_value());
}

TEST(Metrics, EmptyMeshAndBadInput) {
    const Mesh empty;
    const Metrics x = fss::computeMetrics(empty);
    EXPECT_EQ(x.vertices, 0u);
    EXPECT_EQ(x.faces, 0u);
    EXPECT_EQ(x.edges, 0u);
    EXPECT_EQ(x.components, 0u);
    EXPECT_EQ(x.boundaryLoops, 0u);
    EXPECT_EQ(x.interiorVertices, 0u);
    EXPECT_TRUE(x.valenceHistogram.empty());
    EXPECT_EQ(x.minAngleDeg, 0.0);
    EXPECT_EQ(x.maxAngleDeg, 0.0);
    EXPECT_EQ(x.meanMinAngleDeg, 0.0);
    EXPECT_EQ(x.radiusRatioMean, 0.0);
    EXPECT_EQ(x.edgeLengthMean, 0.0);
    EXPECT_EQ(x.bboxDiagonal, 0.0);
    EXPECT_EQ(x.area, 0.0);
    EXPECT_EQ(x.selfIntersections.value_or(99), 0u);
    EXPECT_FALSE(fss::metricsToText(x).empty());
    const nlohmann::json j = nlohmann::json::parse(fss::metricsToJson(x));
    EXPECT_EQ(j.at("faces").get<std::size_t>(), 0u);
    EXPECT_TRUE(j.at("valence_histogram").is_object() && j.at("valence_histogram").empty());

    // An empty mesh against a real reference: nothing to measure, no crash.
    const Metrics e = withReference(empty, fss::shapes::icosphere(1));
    EXPECT_FALSE(e.hausdorffToRef.has_value());
    EXPECT_FALSE(e.hausdorffFromRef.has_value());

    // An empty reference is an error, and so is a reference without a proper face.
    EXPECT_THROW(withReference(fss::shapes::icosphere(1), empty), fss::InvalidInputError);
    const Mesh flat = fromTriangles({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
    EXPECT_THROW(withReference(fss::shapes::icosphere(1), flat), fss::InvalidInputError);

    // Not a triangle mesh.
    Mesh quad;
    const auto a = quad.add_vertex({0, 0, 0}), b = quad.add_vertex({1, 0, 0}), c = quad.add_vertex({1, 1, 0}),
               d = quad.add_vertex({0, 1, 0});
    quad.add_face(a, b, c, d);
    EXPECT_THROW(fss::computeMetrics(quad), fss::InvalidInputError);
}
