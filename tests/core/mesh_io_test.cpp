// Mesh I/O: round trips of every format on a hand-made mesh and on fandisk, PLY face properties,
// triangulation, orientation and manifold repair with their reports, and the canonical mesh. Bad files,
// writing and the fuzzed files: mesh_io_errors_test.cpp.

#include "mesh_io_helpers.h"

using namespace mesh_io_test_helpers;

// ----------------------------------------------------------------------------------------- reading

TEST(MeshIo, ReadsFandisk) {
    ReadReport report;
    const Mesh m = fss::readMesh(fss::test::meshPath("fandisk.off"), &report);
    EXPECT_EQ(m.number_of_vertices(), 6475u);
    EXPECT_EQ(m.number_of_faces(), 12946u);
    EXPECT_EQ(report.format, "off");
    EXPECT_FALSE(report.binary);
    EXPECT_FALSE(report.repaired()) << joined(report.repairs);
    EXPECT_EQ(report.soup.points, 6475u);
    EXPECT_EQ(report.soup.polygons, 12946u);
    EXPECT_EQ(report.soup.nonTriangles, 0u);
    EXPECT_EQ(report.soup.nonManifoldEdges, 0u);
    EXPECT_EQ(report.soup.nonManifoldVertices, 0u);
    EXPECT_EQ(report.soup.duplicatePoints, 0u);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_TRUE(CGAL::is_closed(m));
    EXPECT_FALSE(report.hasFaceQuality);
    EXPECT_FALSE((m.property_map<FaceIndex, float>(fss::props::faceQuality).second));
    // The first vertex as written in the file.
    EXPECT_EQ(m.point(*m.vertices().begin()), Point3(0.1696, 0.04095, -0.0471));
}

TEST(MeshIo, RoundTripsHandMadeMeshInEveryFormat) {
    const Mesh mesh = makeOctahedron();
    ASSERT_TRUE(mesh.has_garbage());
    ASSERT_EQ(mesh.number_of_vertices(), 6u);
    for (const FormatCase& fc : kAllFormats)
        checkRoundTrip(mesh, fc, "octahedron");
}

TEST(MeshIo, RoundTripsFandiskInEveryFormat) {
    const Mesh mesh = fss::readMesh(fss::test::meshPath("fandisk.off"));
    for (const FormatCase& fc : kAllFormats)
        checkRoundTrip(mesh, fc, "fandisk");
}

TEST(MeshIo, AsciiFilesUseSeventeenSignificantDigits) {
    Mesh m;
    m.add_face(m.add_vertex(Point3(0.1, 0, 0)), m.add_vertex(Point3(1, 0, 0)), m.add_vertex(Point3(0, 1, 0)));
    const fs::path p = fss::test::tmpPath("digits.obj");
    fss::writeMesh(m, p);
    EXPECT_NE(readFile(p).find("v 0.10000000000000001 0 0\n"), std::string::npos) << readFile(p);
    fss::writeMesh(m, p, {.precision = 6});
    EXPECT_NE(readFile(p).find("v 0.1 0 0\n"), std::string::npos) << readFile(p);
}

TEST(MeshIo, RoundTripsPlyFaceQualityAndScanId) {
    Mesh mesh = makeOctahedron();
    auto quality =
        mesh.add_property_map<FaceIndex, float>(fss::props::faceQuality, fss::kInputFaceQuality).first;
    auto scan = mesh.add_property_map<FaceIndex, std::int32_t>(fss::props::faceScanId, -1).first;
    const float qs[8] = {0.1f, fss::kInputFaceQuality, -3.5f, 1e-20f, 7.0f, 0.333333343f, 2.5e9f, 0.0f};
    const std::int32_t ids[8] = {
        -1, 0, 7, std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::min(),
        3,  3, 12};
    std::size_t i = 0;
    for (FaceIndex f : mesh.faces()) {
        quality[f] = qs[i];
        scan[f] = ids[i++];
    }
    // Remove one face properly (Euler) so that face indices have a gap too.
    CGAL::Euler::remove_face(mesh.halfedge(*std::next(mesh.faces().begin(), 2)), mesh);
    ASSERT_EQ(mesh.number_of_faces(), 7u);
    std::vector<float> expectedQ;
    std::vector<std::int32_t> expectedId;
    for (FaceIndex f : mesh.faces()) {
        expectedQ.push_back(quality[f]);
        expectedId.push_back(scan[f]);
    }

    for (bool binary : {false, true}) {
        SCOPED_TRACE(binary ? "binary" : "ascii");
        const fs::path p = fss::test::tmpPath(std::string("props_") + (binary ? "bin" : "ascii") + ".ply");
        fss::writeMesh(mesh, p, {.binary = binary});
        ReadReport report;
        const Mesh back = fss::readMesh(p, &report);
        EXPECT_TRUE(report.hasFaceQuality);
        EXPECT_TRUE(report.hasScanId);
        ASSERT_EQ(back.number_of_faces(), 7u);
        EXPECT_EQ(back.number_of_vertices(), mesh.number_of_vertices());
        const auto q = back.property_map<FaceIndex, float>(fss::props::faceQuality);
        const auto s = back.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId);
        ASSERT_TRUE(q.second);
        ASSERT_TRUE(s.second);
        std::size_t k = 0;
        for (FaceIndex f : back.faces()) {
            EXPECT_EQ(q.first[f], expectedQ[k]) << "face " << k;
            EXPECT_EQ(s.first[f], expectedId[k]) << "face " << k;
            ++k;
        }
        EXPECT_EQ(faceCorners(back), faceCorners(mesh));
    }

    // Formats without face properties do not invent them.
    const fs::path off = fss::test::tmpPath("props.off");
    fss::writeMesh(mesh, off);
    ReadReport report;
    const Mesh back = fss::readMesh(off, &report);
    EXPECT_FALSE(report.hasFaceQuality);
    EXPECT_FALSE(report.hasScanId);
    EXPECT_FALSE((back.property_map<FaceIndex, float>(fss::props::faceQuality).second));
}

TEST(MeshIo, PlyPropertiesFollowTheirFacesThroughTriangulation) {
    const std::string ply = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                            "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                            "property float quality\nproperty int scan_id\nend_header\n"
                            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 -1\n"
                            "4 0 1 2 3 0.25 4\n3 1 0 4 0.5 9\n";
    const fs::path p = fss::test::tmpPath("props_quad.ply");
    writeFile(p, ply);
    ReadReport report;
    const Mesh m = fss::readMesh(p, &report);
    ASSERT_EQ(m.number_of_faces(), 3u);
    EXPECT_TRUE(hasRepair(report, "triangulated 1 polygon with more than three corners into 2 triangles"))
        << joined(report.repairs);
    const auto q = m.property_map<FaceIndex, float>(fss::props::faceQuality).first;
    const auto s = m.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId).first;
    std::vector<float> qs;
    std::vector<std::int32_t> ss;
    for (FaceIndex f : m.faces()) {
        qs.push_back(q[f]);
        ss.push_back(s[f]);
    }
    EXPECT_EQ(qs, (std::vector<float>{0.25f, 0.25f, 0.5f}));
    EXPECT_EQ(ss, (std::vector<std::int32_t>{4, 4, 9}));
}

TEST(MeshIo, ReadsBigEndianPlyAndSkipsUnknownElementsAndProperties) {
    auto be = [](auto v) {
        auto b = std::bit_cast<std::array<char, sizeof(v)>>(v);
        if (std::endian::native == std::endian::little) std::reverse(b.begin(), b.end());
        return std::string(b.data(), b.size());
    };
    std::string ply = "ply\r\nformat binary_big_endian 1.0\r\ncomment hand made\r\nelement vertex 4\r\n"
                      "property double x\r\nproperty double y\r\nproperty double z\r\nproperty uchar red\r\n"
                      "element material 1\r\nproperty list uchar float values\r\n"
                      "element face 2\r\nproperty list uchar uint vertex_indices\r\n"
                      "property list uchar float texcoord\r\nproperty float quality\r\nend_header\n";
    const double xyz[4][3] = {{0, 0, 0}, {1.0 / 3, 0, 0}, {0, 1e-300, 0}, {0, 0, -7.25}};
    for (const auto& p : xyz)
        ply += be(p[0]) + be(p[1]) + be(p[2]) + be(std::uint8_t(200));
    ply += be(std::uint8_t(2)) + be(1.5f) + be(2.5f);
    const std::uint32_t faces[2][3] = {{0, 2, 1}, {0, 1, 3}};
    for (const auto& f : faces) {
        ply += be(std::uint8_t(3)) + be(f[0]) + be(f[1]) + be(f[2]);
        ply += be(std::uint8_t(2)) + be(0.5f) + be(0.25f);
        ply += be(0.75f);
    }
    const fs::path p = fss::test::tmpPath("big_endian.ply");
    writeFile(p, ply);
    ReadReport report;
    const Mesh m = fss::readMesh(p, &report);
    EXPECT_TRUE(report.binary);
    EXPECT_TRUE(report.hasFaceQuality);
    EXPECT_FALSE(report.hasScanId);
    ASSERT_EQ(m.number_of_vertices(), 4u);
    ASSERT_EQ(m.number_of_faces(), 2u);
    const auto pts = positions(m);
    EXPECT_EQ(pts[1], Point3(1.0 / 3, 0, 0));
    EXPECT_EQ(pts[2], Point3(0, 1e-300, 0));
    EXPECT_EQ(pts[3], Point3(0, 0, -7.25));
}

TEST(MeshIo, ReadsOffAndObjVariants) {
    // Counts on the header line, comments, CRLF, colours after vertices and faces.
    const fs::path off = fss::test::tmpPath("variants.off");
    writeFile(off, "# a comment\r\nCOFF 4 2 0 # counts\r\n0 0 0 255 0 0 255\r\n1 0 0 0 255 0 255\r\n"
                   "\r\n1 1 0 0 0 255 255\r\n0 1 +0 1 1 1 1\r\n3 0 1 2 0.5 0.5 0.5\r\n3 0 2 3\r\n");
    Mesh m = fss::readMesh(off);
    EXPECT_EQ(m.number_of_vertices(), 4u);
    EXPECT_EQ(m.number_of_faces(), 2u);

    // Slashes, relative indices, groups and materials.
    const fs::path obj = fss::test::tmpPath("variants.obj");
    writeFile(obj, "mtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                   "g group\nusemtl red\ns off\nf 1/1/1 2/1/1 3/1/1\nf -4//1 -2//1 -1//1\n");
    ReadReport report;
    m = fss::readMesh(obj, &report);
    EXPECT_EQ(report.format, "obj");
    EXPECT_EQ(m.number_of_vertices(), 4u);
    EXPECT_EQ(m.number_of_faces(), 2u);
    EXPECT_NEAR(area(m), 1.0, 1e-15);
}

TEST(MeshIo, TriangulatesQuadsAndNonConvexPolygons) {
    // A 3x3 grid of unit quads.
    std::string off = "OFF\n16 9 0\n";
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            off += std::to_string(i) + " " + std::to_string(j) + " 0\n";
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            const int a = 4 * j + i;
            off += "4 " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + 5) +
                   " " + std::to_string(a + 4) + "\n";
        }
    const fs::path p = fss::test::tmpPath("quads.off");
    writeFile(p, off);
    ReadReport report;
    Mesh m = fss::readMesh(p, &report);
    EXPECT_EQ(m.number_of_faces(), 18u);
    EXPECT_EQ(m.number_of_vertices(), 16u);
    EXPECT_EQ(report.soup.nonTriangles, 9u);
    EXPECT_EQ(report.repairs, std::vector<std::string>{
                                  "triangulated 9 polygons with more than three corners into 18 triangles"});
    EXPECT_NEAR(area(m), 9.0, 1e-12);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));

    // A non-convex L-shaped hexagon (area 3) in a tilted plane, clockwise as seen from +z, plus an
    // octagon with a collinear corner: fans from the first corner would overlap or leave the polygon.
    const fs::path obj = fss::test::tmpPath("lshape.obj");
    auto v = [](double x, double y) {
        return "v " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(0.5 * x + 0.25 * y) +
               "\n";
    };
    std::string text = v(0, 0) + v(0, 2) + v(1, 2) + v(1, 1) + v(2, 1) + v(2, 0) + "f 4 5 6 1 2 3\n";
    // Octagon: a U shape, 10 units^2: (10,0) (13,0) (13,3) (12,3) (12,1) (11,1) (11,3) (10,3) with a
    // collinear extra corner at (11.5, 0).
    text +=
        v(10, 0) + v(11.5, 0) + v(13, 0) + v(13, 3) + v(12, 3) + v(12, 1) + v(11, 1) + v(11, 3) + v(10, 3);
    text += "f 15 14 13 12 11 10 9 8 7\n"; // clockwise too
    writeFile(obj, text);
    m = fss::readMesh(obj, &report);
    EXPECT_EQ(report.soup.nonTriangles, 2u);
    EXPECT_EQ(m.number_of_faces(), 4u + 7u);
    const double tilt = std::sqrt(1 + 0.25 + 0.0625); // area scale of the plane z = x/2 + y/4
    EXPECT_NEAR(area(m), (3.0 + 7.0) * tilt, 1e-12);
    // Every triangle keeps the polygon's orientation (normal towards -z after the clockwise input).
    for (FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Vector3 n = CGAL::cross_product(m.point(m.target(h)) - m.point(m.source(h)),
                                              m.point(m.target(m.next(h))) - m.point(m.source(h)));
        EXPECT_LT(n.z(), 0.0);
    }
}

TEST(MeshIo, OrientsInconsistentSoupAndReportsIt) {
    // A tetrahedron with outward faces except one; try the flipped face first and last (the repair keeps
    // the majority's orientation either way).
    const std::string points = "4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    for (const std::string faces :
         {"3 0 1 2\n3 0 1 3\n3 1 2 3\n3 0 3 2\n", "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 2 3\n"}) {
        const fs::path p = fss::test::tmpPath("flipped.off");
        writeFile(p, "OFF\n" + points + faces);
        ReadReport report;
        const Mesh m = fss::readMesh(p, &report);
        EXPECT_EQ(report.repairs, std::vector<std::string>{
                                      "reoriented 1 polygon to match the orientation of their neighbours"});
        EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
        EXPECT_TRUE(CGAL::is_closed(m));
        EXPECT_EQ(m.number_of_vertices(), 4u);
        EXPECT_EQ(m.number_of_faces(), 4u);
        EXPECT_EQ(report.soup.nonManifoldEdges, 0u);
        EXPECT_NEAR(signedVolume(m), 1.0 / 6, 1e-15); // the three outward faces win
        expectIoError(p, {"not a valid oriented manifold mesh", "repair is disabled"}, {.repair = false});
    }
}

TEST(MeshIo, CountsAndRepairsNonManifoldEdge) {
    // Three triangles on the edge 0-1.
    const fs::path p = fss::test::tmpPath("fin.off");
    writeFile(p, "OFF\n5 3 0\n0 0 0\n1 0 0\n0.5 1 0\n0.5 -1 0\n0.5 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
    ReadReport report;
    const Mesh m = fss::readMesh(p, &report);
    EXPECT_EQ(report.soup.nonManifoldEdges, 1u);
    EXPECT_EQ(report.soup.nonManifoldVertices, 0u);
    EXPECT_TRUE(report.repaired());
    EXPECT_TRUE(hasRepair(report, "separated the polygons around 1 edge shared by more than two polygons"))
        << joined(report.repairs);
    EXPECT_TRUE(hasRepair(report, "duplicated 4 non-manifold vertices to make the mesh manifold"))
        << joined(report.repairs);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(m.number_of_faces(), 3u);
    EXPECT_EQ(m.number_of_vertices(), 9u);
    expectIoError(p, {"1 non-manifold edge", "repair is disabled"}, {.repair = false});
}

TEST(MeshIo, CountsAndRepairsBowTieVertex) {
    const fs::path p = fss::test::tmpPath("bowtie.obj");
    writeFile(p, "v 0 0 0\nv 1 1 0\nv -1 1 0\nv 1 -1 0\nv -1 -1 0\nf 1 2 3\nf 1 5 4\n");
    ReadReport report;
    const Mesh m = fss::readMesh(p, &report);
    EXPECT_EQ(report.soup.nonManifoldVertices, 1u);
    EXPECT_EQ(report.soup.nonManifoldEdges, 0u);
    EXPECT_EQ(report.repairs,
              std::vector<std::string>{"duplicated 1 non-manifold vertex to make the mesh manifold"});
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(m.number_of_faces(), 2u);
    EXPECT_EQ(m.number_of_vertices(), 6u);
    expectIoError(p, {"1 non-manifold vertex", "repair is disabled"}, {.repair = false});
}

TEST(MeshIo, MergesDuplicatesAndRemovesDegenerateAndIsolatedElements) {
    // A unit square as two triangles whose shared corners are stored twice, a triangle with a repeated
    // corner, a zero-area (collinear) triangle attached to the square's edge, a duplicate triangle, and an
    // unused point.
    const fs::path p = fss::test::tmpPath("dirty.off");
    writeFile(p, "OFF\n9 6 0\n0 0 0\n1 0 0\n1 1 0\n0 0 0\n1 1 0\n0 1 0\n7 7 7\n2 0 0\n0.5 0 0\n"
                 "3 0 1 2\n3 3 4 5\n3 0 0 1\n3 1 0 8\n3 1 7 2\n3 2 1 0\n");
    ReadReport report;
    const Mesh m = fss::readMesh(p, &report);
    EXPECT_EQ(report.soup.points, 9u);
    EXPECT_EQ(report.soup.polygons, 6u);
    EXPECT_EQ(report.soup.duplicatePoints, 2u);
    EXPECT_EQ(report.soup.degeneratePolygons, 2u); // repeated corner + zero area
    EXPECT_TRUE(hasRepair(report, "merged 2 duplicate points")) << joined(report.repairs);
    EXPECT_TRUE(hasRepair(report, "removed 1 degenerate polygon with repeated corners"))
        << joined(report.repairs);
    EXPECT_TRUE(hasRepair(report, "removed 1 duplicate triangle")) << joined(report.repairs);
    EXPECT_TRUE(hasRepair(report, "removed 1 isolated point that no polygon uses")) << joined(report.repairs);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(m.number_of_faces(), 4u);    // the square, the zero-area sliver (kept) and 1-7-2
    EXPECT_EQ(m.number_of_vertices(), 6u); // 0 1 2 5 7 8
}

TEST(MeshIo, DetectsFormatByContentAndCaseInsensitiveExtension) {
    const std::string fandisk = readFile(fss::test::meshPath("fandisk.off"));
    for (const std::string name : {"fandisk_copy.mesh", "fandisk_copy", "FANDISK_COPY.OFF"}) {
        writeFile(fss::test::tmpPath(name), fandisk);
        ReadReport report;
        const Mesh m = fss::readMesh(fss::test::tmpPath(name), &report);
        EXPECT_EQ(report.format, "off") << name;
        EXPECT_EQ(m.number_of_faces(), 12946u) << name;
    }
    const Mesh octa = makeOctahedron();
    const std::vector<std::pair<FormatCase, std::string>> sniffed = {{{".ply", false}, "ply"},
                                                                     {{".ply", true}, "ply"},
                                                                     {{".stl", false}, "stl"},
                                                                     {{".stl", true}, "stl"},
                                                                     {{".obj", false}, "obj"}};
    for (const auto& [fc, format] : sniffed) {
        const fs::path real = fss::test::tmpPath("sniff" + fc.ext),
                       disguised = fss::test::tmpPath("sniff_" + caseName(fc) + ".dat");
        fss::writeMesh(octa, real, {.binary = fc.binary});
        writeFile(disguised, readFile(real));
        ReadReport report;
        const Mesh m = fss::readMesh(disguised, &report);
        EXPECT_EQ(report.format, format) << caseName(fc);
        EXPECT_EQ(report.binary, fc.binary) << caseName(fc);
        EXPECT_EQ(m.number_of_faces(), 8u) << caseName(fc);
    }

    // Binary STL whose 80-byte header starts with "solid", as many exporters write it.
    const fs::path stl = fss::test::tmpPath("solid_header.stl");
    fss::writeMesh(octa, stl, {.binary = true});
    std::string bytes = readFile(stl);
    std::memcpy(bytes.data(), "solid exported by some CAD tool", 31);
    writeFile(stl, bytes);
    ReadReport report;
    const Mesh m = fss::readMesh(stl, &report);
    EXPECT_TRUE(report.binary);
    EXPECT_EQ(m.number_of_faces(), 8u);
    EXPECT_EQ(m.number_of_vertices(), 6u);

    EXPECT_TRUE(fss::isSupportedMeshFile("a/b.OFF"));
    EXPECT_TRUE(fss::isSupportedMeshFile("x.Ply"));
    EXPECT_TRUE(fss::isSupportedMeshFile("x.stl"));
    EXPECT_TRUE(fss::isSupportedMeshFile("x.obj"));
    EXPECT_FALSE(fss::isSupportedMeshFile("x.vtp"));
    EXPECT_FALSE(fss::isSupportedMeshFile("off"));
}

// canonicalMesh is what a file of the mesh reads back as: same points, same faces and the same halfedge
// layout (what makes a session started from memory replay exactly from its saved input file).
TEST(MeshIo, CanonicalMeshIsTheMeshAsReadBackFromItsFile) {
    for (const char* name : {"fandisk.off", "mech-holes-shark.off"}) {
        fss::Mesh m = fss::readMesh(fss::test::meshPath(name));
        // Disturb the layout: a mesh built in memory need not be in the reader's order.
        CGAL::Euler::flip_edge(m.halfedge(*std::next(m.edges().begin(), 10)), m);
        const fss::Mesh canonical = fss::canonicalMesh(m);
        for (const bool binary : {true, false}) {
            const auto path =
                fss::test::tmpPath(std::string("canonical_") + name + (binary ? ".ply" : ".off"));
            fss::WriteOptions o;
            o.binary = binary;
            fss::writeMesh(m, path, o);
            const fss::Mesh read = fss::readMesh(path);
            ASSERT_EQ(read.number_of_halfedges(), canonical.number_of_halfedges()) << name;
            ASSERT_EQ(read.number_of_faces(), canonical.number_of_faces()) << name;
            for (fss::VertexIndex v : read.vertices()) {
                ASSERT_EQ(read.point(v), canonical.point(v));
                ASSERT_EQ(read.halfedge(v), canonical.halfedge(v)) << name << " vertex " << v;
            }
            for (fss::HalfedgeIndex h : read.halfedges()) {
                ASSERT_EQ(read.next(h), canonical.next(h)) << name;
                ASSERT_EQ(read.target(h), canonical.target(h)) << name;
                ASSERT_EQ(read.face(h), canonical.face(h)) << name;
            }
            for (fss::FaceIndex f : read.faces())
                ASSERT_EQ(read.halfedge(f), canonical.halfedge(f)) << name;
        }
    }
    EXPECT_THROW(fss::canonicalMesh(fss::Mesh()), fss::IoError);
}
