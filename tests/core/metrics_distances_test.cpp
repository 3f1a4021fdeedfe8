// Quality metrics: distances against analytic values, the JSON and text forms, and an independent
// brute-force cross-check on CGAL's sample meshes.
#include "metrics_helpers.h"

using namespace metrics_test_helpers;

// ---- distances -------------------------------------------------------------------------------------------

TEST(Metrics, ScaledSphereHausdorffIsOnePercentOfRadius) {
    const double r = 2.0;
    const Mesh inner = fss::shapes::icosphere(4, r);
    const Mesh outer = transformed(inner, 1.01);
    const Metrics x = withReference(outer, inner);
    ASSERT_TRUE(x.hausdorffToRef && x.hausdorffFromRef && x.rmsToRef);
    EXPECT_NEAR(*x.hausdorffToRef, 0.01 * r, 0.05 * 0.01 * r);
    EXPECT_NEAR(*x.hausdorffFromRef, 0.01 * r, 0.05 * 0.01 * r);
    EXPECT_NEAR(*x.rmsToRef, 0.01 * r, 0.05 * 0.01 * r);
    const double refDiagonal = 2 * r * std::sqrt(3.0); // the icosphere has vertices at (+-r, 0, 0) etc.
    EXPECT_NEAR(*x.hausdorffToRefRel, *x.hausdorffToRef / refDiagonal, 1e-12);
    EXPECT_NEAR(*x.hausdorffFromRefRel, *x.hausdorffFromRef / refDiagonal, 1e-12);
    std::cout << "[ figures  ] icosphere(4) x1.01, r = " << r << ": hausdorff to " << *x.hausdorffToRef
              << " from " << *x.hausdorffFromRef << " rms " << *x.rmsToRef << " (0.01 r = " << 0.01 * r
              << ")\n";
    // Outer vertices are exactly 0.01 r away from the convex inner polyhedron (closest point: its vertex).
    EXPECT_NEAR(*x.hausdorffToRef, 0.01 * r, 1e-9);

    // Symmetric: swapping the roles swaps the one-sided distances.
    const Metrics y = withReference(inner, outer);
    EXPECT_NEAR(*y.hausdorffToRef, *x.hausdorffFromRef, 0.05 * 0.01 * r);
    EXPECT_NEAR(*y.hausdorffFromRef, *x.hausdorffToRef, 0.05 * 0.01 * r);
}

TEST(Metrics, MeshAgainstItselfIsAtDistanceZero) {
    const Mesh m = fss::shapes::torus(32, 16);
    const Metrics x = withReference(m, m);
    EXPECT_LT(*x.hausdorffToRef, 1e-9);
    EXPECT_LT(*x.hausdorffFromRef, 1e-9);
    EXPECT_LT(*x.rmsToRef, 1e-9);
}

TEST(Metrics, TranslatedGridIsAtDistanceD) {
    const double d = 0.3;
    const Mesh g = fss::shapes::grid(10, 8, 0.25);
    const Metrics x = withReference(transformed(g, 1.0, 0, 0, d), g);
    EXPECT_NEAR(*x.hausdorffToRef, d, 1e-12);
    EXPECT_NEAR(*x.hausdorffFromRef, d, 1e-12);
    EXPECT_NEAR(*x.rmsToRef, d, 1e-12);
    EXPECT_NEAR(*x.hausdorffToRefRel, d / std::hypot(2.5, 2.0), 1e-12);
}

TEST(Metrics, PatchAgainstGridIsAsymmetric) {
    // The reference is the grid [0,10]^2; the patch [4,6]^2 lies on it. Every patch point is on the grid;
    // the grid point farthest from the patch is a corner, e.g. (0,0) -> (4,4): 4 sqrt2.
    const Mesh full = fss::shapes::grid(10, 10, 1.0);
    const Mesh patch = transformed(fss::shapes::grid(2, 2, 1.0), 1.0, 4, 4, 0);
    const Metrics x = withReference(patch, full);
    EXPECT_LT(*x.hausdorffToRef, 1e-12);
    EXPECT_LT(*x.rmsToRef, 1e-12);
    EXPECT_NEAR(*x.hausdorffFromRef, 4 * std::sqrt(2.0), 0.05 * 4 * std::sqrt(2.0));
    EXPECT_NEAR(*x.hausdorffFromRefRel, 4 * std::sqrt(2.0) / (10 * std::sqrt(2.0)), 1e-9);
}

TEST(Metrics, HausdorffAwayFromVerticesIsFoundBySampling) {
    // A flat square [0,2]^2 (two triangles, diagonal (0,0)-(2,2)) against a tent with apex (1,1,h).
    // Square -> tent: the farthest point is the square's centre, on its diagonal edge, not a vertex:
    // distance h / sqrt(1 + h^2) to each tent face. Tent -> square: the apex, distance h.
    const double h = 1.0;
    const Mesh square = fss::shapes::grid(1, 1, 2.0);
    const Mesh tent = fromTriangles({{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {1, 1, h}},
                                    {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
    const Metrics x = withReference(square, tent);
    const double exact = h / std::sqrt(1 + h * h);
    EXPECT_NEAR(*x.hausdorffToRef, exact, 0.01 * exact);
    EXPECT_LE(*x.hausdorffToRef, exact + 1e-12); // sampling gives a lower bound
    std::cout << "[ figures  ] square -> tent: hausdorff " << *x.hausdorffToRef << " (exact " << exact
              << "), rms " << *x.rmsToRef << " (exact " << exact * std::sqrt(1.0 / 6.0) << ")\n";
    EXPECT_NEAR(*x.hausdorffFromRef, h, 1e-12);
    // RMS over the square of the distance to the tent: by symmetry, the mean of (y h/sqrt(1+h^2))^2 over
    // the triangle (0,0),(2,0),(1,1), where y is uniform on the triangle with density 2(1-y): E[y^2] = 1/6.
    EXPECT_NEAR(*x.rmsToRef, exact * std::sqrt(1.0 / 6.0), 0.01 * exact);

    // A sparse explicit density still measures (vertices are always sampled).
    MetricsOptions sparse;
    sparse.reference = &tent;
    sparse.distanceSamplesPerArea = 10;
    const Metrics s = fss::computeMetrics(square, sparse);
    EXPECT_LE(*s.hausdorffToRef, exact + 1e-12);
    EXPECT_NEAR(*s.hausdorffFromRef, h, 1e-12);
}

TEST(Metrics, DistancesAreDeterministic) {
    const Mesh a = fss::shapes::icosphere(3);
    const Mesh b = fss::shapes::uvSphere(32, 16);
    EXPECT_EQ(fss::metricsToJson(withReference(a, b)), fss::metricsToJson(withReference(a, b)));
}

TEST(Metrics, ProgressIsReportedAndCancels) {
    const Mesh a = fss::shapes::icosphere(3);
    const Mesh b = transformed(a, 1.01);
    MetricsOptions options;
    options.reference = &b;
    std::vector<double> fractions;
    std::set<std::string> stages;
    const fss::Progress progress([&](double f, std::string_view stage) {
        fractions.push_back(f);
        stages.emplace(stage);
        return true;
    });
    (void)fss::computeMetrics(a, options, progress);
    ASSERT_FALSE(fractions.empty());
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_EQ(fractions.front(), 0.0);
    EXPECT_EQ(fractions.back(), 1.0);
    EXPECT_TRUE(stages.count("self-intersections"));
    EXPECT_TRUE(stages.count("distance to reference"));
    EXPECT_TRUE(stages.count("distance from reference"));

    int calls = 0;
    const fss::Progress cancelInDistances([&](double f, std::string_view) { return ++calls < 5 || f < 0.5; });
    EXPECT_THROW((void)fss::computeMetrics(a, options, cancelInDistances), fss::CancelledError);
}

// ---- formatting ---------------------------------------------------------------------------------------

TEST(Metrics, JsonHasTheDocumentedKeysAndValues) {
    const Mesh g = fss::shapes::grid(6, 4, 0.5);
    const Metrics x = withReference(g, transformed(g, 1.0, 0, 0, 0.1));
    const nlohmann::json j = nlohmann::json::parse(fss::metricsToJson(x));
    ASSERT_TRUE(j.is_object());
    EXPECT_EQ(j.size(), 33u); // 29 + the quality measures of issue 22 (aspect ratio, scaled Jacobian)
    EXPECT_EQ(j.at("vertices").get<std::size_t>(), x.vertices);
    EXPECT_EQ(j.at("faces").get<std::size_t>(), x.faces);
    EXPECT_EQ(j.at("edges").get<std::size_t>(), x.edges);
    EXPECT_EQ(j.at("boundary_edges").get<std::size_t>(), x.boundaryEdges);
    EXPECT_EQ(j.at("boundary_loops").get<std::size_t>(), x.boundaryLoops);
    EXPECT_EQ(j.at("components").get<std::size_t>(), x.components);
    EXPECT_EQ(j.at("closed").get<bool>(), x.closed);
    EXPECT_EQ(j.at("non_manifold_vertices").get<std::size_t>(), x.nonManifoldVertices);
    EXPECT_EQ(j.at("degenerate_faces").get<std::size_t>(), x.degenerateFaces);
    EXPECT_TRUE(j.at("self_intersections").is_null()); // withReference skips them
    EXPECT_EQ(j.at("valence_histogram"), nlohmann::json({{"6", 15}}));
    EXPECT_EQ(j.at("interior_vertices").get<std::size_t>(), x.interiorVertices);
    const std::map<std::string, double> doubles = {
        {"frac_valence6_interior", x.fracValence6Interior},
        {"min_angle_deg", x.minAngleDeg},
        {"max_angle_deg", x.maxAngleDeg},
        {"mean_min_angle_deg", x.meanMinAngleDeg},
        {"frac_min_angle_below_30", x.fracMinAngleBelow30},
        {"frac_min_angle_below_10", x.fracMinAngleBelow10},
        {"radius_ratio_mean", x.radiusRatioMean},
        {"radius_ratio_min", x.radiusRatioMin},
        {"aspect_ratio_mean", x.aspectRatioMean},
        {"aspect_ratio_max", x.aspectRatioMax},
        {"scaled_jacobian_min", x.scaledJacobianMin},
        {"scaled_jacobian_mean", x.scaledJacobianMean},
        {"edge_length_mean", x.edgeLengthMean},
        {"edge_length_cv", x.edgeLengthCv},
        {"bbox_diagonal", x.bboxDiagonal},
        {"area", x.area},
        {"hausdorff_to_ref", *x.hausdorffToRef},
        {"hausdorff_from_ref", *x.hausdorffFromRef},
        {"hausdorff_to_ref_rel", *x.hausdorffToRefRel},
        {"hausdorff_from_ref_rel", *x.hausdorffFromRefRel},
        {"rms_to_ref", *x.rmsToRef},
    };
    for (const auto& [key, value] : doubles)
        EXPECT_EQ(j.at(key).get<double>(), value) << key;
    EXPECT_NEAR(j.at("hausdorff_to_ref").get<double>(), 0.1, 1e-12);

    const Metrics plain = fss::computeMetrics(g);
    const nlohmann::json k = nlohmann::json::parse(fss::metricsToJson(plain, -1));
    EXPECT_EQ(k.at("self_intersections").get<std::size_t>(), 0u);
    for (const char* key : {"hausdorff_to_ref", "hausdorff_from_ref", "hausdorff_to_ref_rel",
                            "hausdorff_from_ref_rel", "rms_to_ref"})
        EXPECT_TRUE(k.at(key).is_null()) << key;
    EXPECT_EQ(fss::metricsToJson(plain, -1).find('\n'), std::string::npos);
}

TEST(Metrics, TextSummaryIsReadable) {
    const Mesh g = fss::shapes::grid(4, 3);
    const std::string text = fss::metricsToText(withReference(g, transformed(g, 1.0, 0, 0, 0.5)));
    for (const char* label :
         {"vertices / faces / edges", "components", "boundary edges / loops", "non-manifold vertices",
          "degenerate faces", "self-intersections", "valence histogram", "angle min / max", "radius ratio",
          "edge length", "area", "Hausdorff to ref", "Hausdorff from ref", "RMS"})
        EXPECT_NE(text.find(label), std::string::npos) << label << "\n" << text;
    EXPECT_NE(text.find("20 / 24 / 43"), std::string::npos) << text;
    EXPECT_NE(text.find("6:6"), std::string::npos) << text;
    EXPECT_NE(text.find("45.00 / 90.00 deg"), std::string::npos) << text;
    // Aligned: every value starts in the same column.
    std::istringstream lines(text);
    std::string line;
    std::set<std::size_t> columns;
    while (std::getline(lines, line)) {
        const std::size_t gap = line.find("  ", 2);
        ASSERT_NE(gap, std::string::npos) << line;
        columns.insert(line.find_first_not_of(' ', gap));
    }
    EXPECT_EQ(columns.size(), 1u) << text;
}

// ---- independent cross-check on CGAL's sample meshes ----------------------------------------------------

namespace brute {

// A deliberately separate implementation: raw OFF parsing, std::set of undirected edges, plain doubles.
struct Soup {
    std::vector<std::array<double, 3>> points;
    std::vector<std::array<std::size_t, 3>> triangles;
};

Soup readOff(const std::string& path) {
    std::ifstream in(path);
    EXPECT_TRUE(in.good()) << path;
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) {
        if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
        if (line.find_first_not_of(" \t\r") != std::string::npos) lines.push_back(line);
    }
    std::size_t at = 0;
    std::istringstream header(lines.at(at++));
    std::string magic;
    header >> magic;
    EXPECT_EQ(magic, "OFF") << path;
    std::size_t nv = 0, nf = 0;
    if (!(header >> nv >> nf)) std::istringstream(lines.at(at++)) >> nv >> nf;
    Soup s;
    for (std::size_t i = 0; i < nv; ++i) {
        std::istringstream l(lines.at(at++));
        std::array<double, 3> p{};
        l >> p[0] >> p[1] >> p[2];
        s.points.push_back(p);
    }
    for (std::size_t i = 0; i < nf; ++i) {
        std::istringstream l(lines.at(at++));
        std::size_t k = 0;
        std::array<std::size_t, 3> t{};
        l >> k >> t[0] >> t[1] >> t[2];
        EXPECT_EQ(k, 3u) << path << " face " << i;
        s.triangles.push_back(t);
    }
    return s;
}

struct Expected {
    std::size_t vertices = 0, faces = 0, edges = 0, boundaryEdges = 0, boundaryLoops = 0, components = 0;
    std::size_t interior = 0, interior6 = 0;
    double minAngle = 360, maxAngle = 0, meanMinAngle = 0, area = 0, edgeMean = 0;
};

std::size_t root(std::vector<std::size_t>& parent, std::size_t x) {
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

Expected compute(const Soup& s) {
    Expected e;
    std::map<std::pair<std::size_t, std::size_t>, std::vector<std::size_t>> edgeFaces;
    std::set<std::size_t> used;
    for (std::size_t f = 0; f < s.triangles.size(); ++f)
        for (int i = 0; i < 3; ++i) {
            const std::size_t a = s.triangles[f][i], b = s.triangles[f][(i + 1) % 3];
            edgeFaces[{std::min(a, b), std::max(a, b)}].push_back(f);
            used.insert(a);
        }
    e.vertices = used.size();
    e.faces = s.triangles.size();
    e.edges = edgeFaces.size();

    std::map<std::size_t, int> valence;
    std::set<std::size_t> onBoundary;
    std::vector<std::size_t> faceParent(e.faces), vertexParent(s.points.size());
    std::iota(faceParent.begin(), faceParent.end(), 0);
    std::iota(vertexParent.begin(), vertexParent.end(), 0);
    double lengthSum = 0;
    for (const auto& [edge, faces] : edgeFaces) {
        ++valence[edge.first];
        ++valence[edge.second];
        const auto& p = s.points[edge.first];
        const auto& q = s.points[edge.second];
        lengthSum += std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                               (p[2] - q[2]) * (p[2] - q[2]));
        if (faces.size() == 1) {
            ++e.boundaryEdges;
            onBoundary.insert(edge.first);
            onBoundary.insert(edge.second);
            vertexParent[root(vertexParent, edge.first)] = root(vertexParent, edge.second);
        }
        for (std::size_t f : faces)
            faceParent[root(faceParent, f)] = root(faceParent, faces[0]);
    }
    e.edgeMean = lengthSum / double(e.edges);
    for (std::size_t f = 0; f < e.faces; ++f)
        if (root(faceParent, f) == f) ++e.components;
    std::set<std::size_t> loops;
    for (std::size_t v : onBoundary)
        loops.insert(root(vertexParent, v));
    e.boundaryLoops = loops.size();
    for (const auto& [v, n] : valence)
        if (!onBoundary.count(v)) {
            ++e.interior;
            if (n == 6) ++e.interior6;
        }

    for (const auto& t : s.triangles) {
        double smallest = 360;
        for (int i = 0; i < 3; ++i) {
            const auto& o = s.points[t[i]];
            const auto& p = s.points[t[(i + 1) % 3]];
            const auto& q = s.points[t[(i + 2) % 3]];
            const double u[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
            const double v[3] = {q[0] - o[0], q[1] - o[1], q[2] - o[2]};
            const double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            const double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            const double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            const double angle = std::acos(std::clamp(dot / (nu * nv), -1.0, 1.0)) * 180 / kPi;
            smallest = std::min(smallest, angle);
            e.minAngle = std::min(e.minAngle, angle);
            e.maxAngle = std::max(e.maxAngle, angle);
            if (i == 0) {
                const double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                     u[0] * v[1] - u[1] * v[0]};
                e.area += 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            }
        }
        e.meanMinAngle += smallest / double(s.triangles.size());
    }
    return e;
}

} // namespace brute

class MetricsOnSampleMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(MetricsOnSampleMesh, AgreesWithBruteForce) {
    const std::string path = fss::test::meshPath(GetParam()).string();
    Mesh mesh;
    ASSERT_TRUE(CGAL::IO::read_polygon_mesh(path, mesh)) << path;
    const Metrics x = fss::computeMetrics(mesh);
    const brute::Expected e = brute::compute(brute::readOff(path));

    EXPECT_EQ(x.vertices, e.vertices);
    EXPECT_EQ(x.faces, e.faces);
    EXPECT_EQ(x.edges, e.edges);
    EXPECT_EQ(x.boundaryEdges, e.boundaryEdges);
    EXPECT_EQ(x.boundaryLoops, e.boundaryLoops);
    EXPECT_EQ(x.components, e.components);
    EXPECT_EQ(x.closed, e.boundaryEdges == 0);
    EXPECT_EQ(x.nonManifoldVertices, 0u);
    EXPECT_EQ(x.interiorVertices, e.interior);
    EXPECT_NEAR(x.fracValence6Interior, double(e.interior6) / double(e.interior), 0.001);
    EXPECT_NEAR(x.minAngleDeg, e.minAngle, 0.05);
    EXPECT_NEAR(x.maxAngleDeg, e.maxAngle, 0.05);
    // The lean figures (the widget's accept): against the brute force, and the same doubles as above.
    const fss::ValenceAndMinAngle lean = fss::valenceAndMinAngle(mesh);
    EXPECT_NEAR(lean.fracValence6Interior, double(e.interior6) / double(e.interior), 0.001);
    EXPECT_NEAR(lean.minAngleDeg, e.minAngle, 0.05);
    EXPECT_EQ(lean.fracValence6Interior, x.fracValence6Interior);
    EXPECT_EQ(lean.minAngleDeg, x.minAngleDeg);
    EXPECT_NEAR(x.meanMinAngleDeg, e.meanMinAngle, 0.05);
    EXPECT_NEAR(x.area, e.area, 1e-9 * e.area);
    EXPECT_NEAR(x.edgeLengthMean, e.edgeMean, 1e-9 * e.edgeMean);
    ASSERT_TRUE(x.selfIntersections.has_value());

    const nlohmann::json j = nlohmann::json::parse(fss::metricsToJson(x));
    EXPECT_EQ(j.at("vertices").get<std::size_t>(), e.vertices);
    EXPECT_EQ(j.at("edges").get<std::size_t>(), e.edges);
    EXPECT_EQ(j.at("boundary_loops").get<std::size_t>(), e.boundaryLoops);
    EXPECT_EQ(j.at("self_intersections").get<std::size_t>(), *x.selfIntersections);
    EXPECT_EQ(j.at("min_angle_deg").get<double>(), x.minAngleDeg);
    std::size_t histogramTotal = 0;
    for (const auto& [valence, count] : j.at("valence_histogram").items())
        histogramTotal += count.get<std::size_t>();
    EXPECT_EQ(histogramTotal, e.interior);

    std::cout << "[ figures  ] " << GetParam() << ": V " << x.vertices << " F " << x.faces
              << " boundary loops " << x.boundaryLoops << " components " << x.components
              << " self-intersections " << *x.selfIntersections << " degenerate " << x.degenerateFaces
              << " frac6 " << x.fracValence6Interior << " angles " << x.minAngleDeg << ".." << x.maxAngleDeg
              << " mean min " << x.meanMinAngleDeg << "\n";
}

INSTANTIATE_TEST_SUITE_P(CgalData, MetricsOnSampleMesh,
                         ::testing::Values("fandisk.off", "blade.off", "couplingdown.off",
                                           "mech-holes-shark.off", "bunny00.off"),
                         [](const auto& info) {
                             std::string name = info.param;
                             name = name.substr(0, name.find('.'));
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// The distances depend only on the geometry: the same surfaces with their vertices and faces in another
// order (and each face starting at another corner) give exactly the same Hausdorff distances (the RMS to
// rounding), so a mesh measured in
// memory and the file written from it agree.
TEST(Metrics, DistancesDoNotDependOnTheOrderOfVerticesAndFaces) {
    auto permuted = [](const Mesh& m) {
        std::vector<fss::VertexIndex> order(m.vertices().begin(), m.vertices().end());
        std::reverse(order.begin(), order.end());
        std::rotate(order.begin(), order.begin() + std::ptrdiff_t(order.size() / 3), order.end());
        Mesh out;
        std::map<fss::VertexIndex, fss::VertexIndex> to;
        for (fss::VertexIndex v : order)
            to[v] = out.add_vertex(m.point(v));
        std::vector<fss::FaceIndex> faces(m.faces().begin(), m.faces().end());
        std::reverse(faces.begin(), faces.end());
        std::size_t k = 0;
        for (fss::FaceIndex f : faces) {
            std::vector<fss::VertexIndex> c;
            for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
                c.push_back(to[v]);
            std::rotate(c.begin(), c.begin() + std::ptrdiff_t(k++ % 3), c.end());
            EXPECT_NE(out.add_face(c), Mesh::null_face());
        }
        return out;
    };
    const Mesh a = fss::shapes::uvSphere(24, 12), b = fss::shapes::icosphere(3);
    const Metrics x = withReference(a, b), y = withReference(permuted(a), permuted(b));
    ASSERT_TRUE(x.hausdorffToRef && y.hausdorffToRef && x.hausdorffFromRef && y.hausdorffFromRef);
    EXPECT_GT(*x.hausdorffToRef, 0.0);
    EXPECT_EQ(*x.hausdorffToRef, *y.hausdorffToRef);
    EXPECT_EQ(*x.hausdorffFromRef, *y.hausdorffFromRef);
    EXPECT_NEAR(*x.rmsToRef, *y.rmsToRef, 1e-12 * *x.rmsToRef); // the same points, summed in another order
}
