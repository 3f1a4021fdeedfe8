// Mesh I/O: round trips of every format on a hand-made mesh and on fandisk, PLY face properties,
// triangulation, orientation and manifold repair with their reports, every kind of bad file, and a few
// hundred randomly corrupted files that must either load into a valid mesh or throw fss::IoError.
#include "fss/error.h"
#include "fss/mesh_io.h"

#include "test_data.h"

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using fss::FaceIndex;
using fss::IoError;
using fss::Mesh;
using fss::Point3;
using fss::ReadReport;
using fss::Vector3;
using fss::VertexIndex;

namespace {

// ----------------------------------------------------------------------------------------- helpers

void writeFile(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Expects readMesh(path) to throw fss::IoError whose message names the file and contains every part.
void expectIoError(const fs::path& path, std::initializer_list<std::string> parts,
                   const fss::ReadOptions& options = {}) {
    SCOPED_TRACE(path.filename().string());
    try {
        fss::readMesh(path, nullptr, options);
        ADD_FAILURE() << "no exception for " << path;
    } catch (const IoError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
        for (const std::string& part : parts)
            EXPECT_NE(what.find(part), std::string::npos) << what << "\n  lacks: " << part;
        EXPECT_EQ(what.back(), '.') << what;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "wrong exception type: " << e.what();
    }
}

/// Writes `text` into a scratch file and expects an IoError containing `parts`.
void expectBadText(const std::string& name, const std::string& text, std::initializer_list<std::string> parts,
                   const fss::ReadOptions& options = {}) {
    const fs::path p = fss::test::tmpPath(name);
    writeFile(p, text);
    expectIoError(p, parts, options);
}

std::vector<Point3> positions(const Mesh& m) {
    std::vector<Point3> p;
    for (VertexIndex v : m.vertices())
        p.push_back(m.point(v));
    return p;
}

/// Corner positions of every face in face order, rotated so that the smallest point comes first (the
/// starting corner of a face is not part of its identity).
std::vector<std::array<Point3, 3>> faceCorners(const Mesh& m) {
    std::vector<std::array<Point3, 3>> faces;
    for (FaceIndex f : m.faces()) {
        std::array<Point3, 3> c;
        std::size_t i = 0;
        for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
            c[i++ % 3] = m.point(v);
        EXPECT_EQ(i, 3u);
        std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
        faces.push_back(c);
    }
    return faces;
}

double relativeError(double a, double b) {
    return std::abs(a - b) / std::max(1.0, std::max(std::abs(a), std::abs(b)));
}

double maxRelativeError(const Point3& a, const Point3& b) {
    return std::max({relativeError(a.x(), b.x()), relativeError(a.y(), b.y()), relativeError(a.z(), b.z())});
}

/// The point as binary STL stores it. The float goes through a volatile: GCC 12.2 at -O2 miscompiles
/// double(float(x)) on neighbouring coordinates (SLP vectorisation drops the rounding of two of them).
double toFloat(double v) {
    volatile float f = static_cast<float>(v);
    return f;
}
Point3 asFloat(const Point3& p) {
    return {toFloat(p.x()), toFloat(p.y()), toFloat(p.z())};
}

double area(const Mesh& m) {
    double a = 0;
    for (FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Point3 &p = m.point(m.source(h)), &q = m.point(m.target(h)), &r = m.point(m.target(m.next(h)));
        a += std::sqrt(CGAL::cross_product(q - p, r - p).squared_length()) / 2;
    }
    return a;
}

double signedVolume(const Mesh& m) {
    double v = 0;
    for (FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Vector3 p = m.point(m.source(h)) - CGAL::ORIGIN, q = m.point(m.target(h)) - CGAL::ORIGIN,
                      r = m.point(m.target(m.next(h))) - CGAL::ORIGIN;
        v += CGAL::scalar_product(p, CGAL::cross_product(q, r)) / 6;
    }
    return v;
}

bool hasRepair(const ReadReport& r, const std::string& sentence) {
    return std::find(r.repairs.begin(), r.repairs.end(), sentence) != r.repairs.end();
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v)
        s += "[" + x + "] ";
    return s;
}

/// An octahedron with coordinates that do not have short decimal forms, built with a removed vertex at
/// the front so that vertex indices are not dense (the writers must re-index).
Mesh makeOctahedron(bool withGarbage = true) {
    Mesh m;
    VertexIndex dummy;
    if (withGarbage) dummy = m.add_vertex(Point3(9, 9, 9));
    const double a = 1.0 / 3.0, b = std::sqrt(2.0), c = 12345.678901234567;
    const std::array<VertexIndex, 6> v = {m.add_vertex(Point3(a, 0.1, -1e-7)),
                                          m.add_vertex(Point3(-b, 0.2, 0.3)),
                                          m.add_vertex(Point3(0.15, c / 1e4, 0.25)),
                                          m.add_vertex(Point3(0.1, -std::exp(1.0), 0.2)),
                                          m.add_vertex(Point3(0.05, 0.1, 2.0 / 7.0 + 1)),
                                          m.add_vertex(Point3(-0.1, 0.1, -1e3 * std::acos(-1.0)))};
    // +x, -x, +y, -y, +z, -z: faces oriented outwards.
    const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                             {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (const auto& f : faces)
        m.add_face(v[std::size_t(f[0])], v[std::size_t(f[1])], v[std::size_t(f[2])]);
    if (withGarbage) m.remove_vertex(dummy);
    return m;
}

struct FormatCase {
    std::string ext;
    bool binary;
};
std::string caseName(const FormatCase& c) {
    return c.ext.substr(1) + (c.binary ? "_binary" : "_ascii");
}

const std::vector<FormatCase> kAllFormats = {{".off", false}, {".obj", false}, {".ply", false},
                                             {".ply", true},  {".stl", false}, {".stl", true}};

/// Writes `mesh` in the given format, reads it back and checks counts, coordinates and face order.
void checkRoundTrip(const Mesh& mesh, const FormatCase& fc, const std::string& stem) {
    SCOPED_TRACE(stem + " " + caseName(fc));
    const fs::path path = fss::test::tmpPath(stem + "_" + caseName(fc) + fc.ext);
    fss::writeMesh(mesh, path, {.binary = fc.binary});
    ReadReport report;
    const Mesh back = fss::readMesh(path, &report);

    EXPECT_EQ(report.format, fc.ext.substr(1));
    EXPECT_EQ(report.binary, fc.binary);
    EXPECT_TRUE(report.repairs.empty()) << joined(report.repairs);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(back));
    ASSERT_EQ(back.number_of_vertices(), mesh.number_of_vertices()); // STL: corners merged back
    ASSERT_EQ(back.number_of_faces(), mesh.number_of_faces());
    EXPECT_EQ(report.soup.points, mesh.number_of_vertices());
    EXPECT_EQ(report.soup.polygons, mesh.number_of_faces());

    const bool stl = fc.ext == ".stl";
    if (!stl) { // vertex order is kept
        const auto a = positions(mesh), b = positions(back);
        for (std::size_t i = 0; i < a.size(); ++i) {
            if (fc.binary)
                ASSERT_EQ(a[i], b[i]) << "vertex " << i;
            else
                ASSERT_LE(maxRelativeError(a[i], b[i]), 1e-12) << "vertex " << i;
        }
    }
    // Face order and corners are kept in every format.
    auto fa = faceCorners(mesh);
    const auto fb = faceCorners(back);
    if (stl && fc.binary) // STL stores floats: compare with the float-rounded corners, exactly
        for (auto& c : fa) {
            for (Point3& p : c)
                p = asFloat(p);
            std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
        }
    for (std::size_t f = 0; f < fa.size(); ++f)
        for (std::size_t j = 0; j < 3; ++j) {
            if (fc.binary)
                ASSERT_EQ(fa[f][j], fb[f][j]) << "face " << f;
            else
                ASSERT_LE(maxRelativeError(fa[f][j], fb[f][j]), 1e-12) << "face " << f;
        }
}

} // namespace

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

// ----------------------------------------------------------------------------------------- bad files

TEST(MeshIoErrors, MissingUnreadableAndEmptyFiles) {
    expectIoError(fss::test::tmpPath("does_not_exist.off"), {"does not exist"});
    const fs::path folder = fss::test::tmpPath("a_folder.off");
    fs::create_directories(folder);
    expectIoError(folder, {"folder"});
    expectBadText("empty.off", "", {"empty"});
    expectBadText("blank.ply", " \n\t\r\n", {"only white space"});

    const fs::path locked = fss::test::tmpPath("locked.off");
    fs::copy_file(fss::test::meshPath("tetrahedron.off"), locked, fs::copy_options::overwrite_existing);
    fs::permissions(locked, fs::perms::none);
    if (!std::ifstream(locked)) { // root can read anything: only check where permissions apply
        expectIoError(locked, {"cannot be opened"});
    }
    fs::permissions(locked, fs::perms::owner_all);
}

TEST(MeshIoErrors, TruncatedFiles) {
    expectBadText("short_vertices.off", "OFF\n8 1 0\n0 0 0\n1 0 0\n0 1 0\n",
                  {"announces 8 vertices but the file ends after 3", "truncated"});
    expectBadText("short_faces.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                  {"announces 2 faces but the file ends after 1", "truncated"});
    expectBadText("short_face_line.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                  {"line 6", "face 0 announces 3 corners but lists 2"});
    expectBadText("short_vertex.obj", "v 0 0 0\nv 1 0\n",
                  {"line 2", "expected 3 coordinates for vertex 1 but found 2"});
    expectBadText("short.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0\n1 0 0\n",
                  {"truncated"});
    expectBadText("no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", {"end_header"});
    expectBadText("short.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
                  {"truncated"});
    expectBadText("no_endsolid.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
                  "0\nendloop\nendfacet\n",
                  {"endsolid", "truncated"});

    const Mesh octa = makeOctahedron();
    for (const FormatCase& fc : {FormatCase{".ply", true}, FormatCase{".stl", true}}) {
        const fs::path p = fss::test::tmpPath("cut_" + caseName(fc) + fc.ext);
        fss::writeMesh(octa, p, {.binary = true});
        const std::string bytes = readFile(p);
        writeFile(p, bytes.substr(0, bytes.size() - 7));
        expectIoError(p, {"truncated"});
    }
}

TEST(MeshIoErrors, HugeHeaderCountsFailFastWithoutAllocating) {
    expectBadText("huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n", {"2000000000 vertices", "truncated"});
    expectBadText("huge.ply",
                  "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\n"
                  "property double x\nproperty double y\nproperty double z\nelement face 1\n"
                  "property list uchar int vertex_indices\nend_header\n" +
                      std::string(100, '\0'),
                  {"4000000000000 vertex elements", "truncated"});
    std::string stl(84, ' ');
    const std::uint32_t n = 0xffffffffu;
    std::memcpy(stl.data() + 80, &n, 4); // little endian on our platforms
    expectBadText("huge.stl", stl, {"4294967295 triangles", "truncated"});
    expectBadText("huge_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n",
                  {"face 0 announces 1000000000 corners but lists 3"});
    // A binary PLY face list announcing more indices than the file holds.
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n";
    const std::int32_t big = 2000000000;
    ply.append(reinterpret_cast<const char*>(&big), 4);
    ply += std::string(8, '\0');
    expectBadText("huge_list.ply", ply, {"truncated"});
}

TEST(MeshIoErrors, UnknownFormatAndGarbage) {
    expectBadText("mystery.xyz", "hello world\nthis is not a mesh\n", {"not recognised", "'.xyz'"});
    expectBadText("mystery", "12 34 56\n", {"not recognised", "no extension"});
    std::mt19937 rng(7);
    std::string junk(3000, '\0');
    for (char& c : junk)
        c = static_cast<char>(rng());
    expectBadText("junk.bin", junk, {"not recognised"});
    expectBadText("junk.off", junk, {"OFF header"});
    expectBadText("junk.obj", junk, {"line "});
    expectBadText("junk.ply", junk, {"'ply'"});
    expectBadText("junk.stl", junk, {"binary STL"});
    expectBadText("words.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nhello 1 2 3\nf 1 2 3\n",
                  {"line 4", "unknown OBJ statement 'hello'"});
    expectBadText("words.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",
                  {"line 4", "expected a coordinate of vertex 1 but found 'zero'"});
    expectBadText("trailing.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n",
                  {"line 7", "unexpected data after the 1 face the header announces"});
    expectBadText("words.stl", "solid x\nfacet normal 0 0 1\nouter ring\n", {"line 3", "expected 'loop'"});
    expectBadText("binary.off", "OFF BINARY\n", {"binary OFF"});
    expectBadText("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", {"contains no faces"});
    expectBadText("nofaces.obj", "v 0 0 0\nv 1 0 0\n", {"contains no faces"});
    expectBadText("noface.ply",
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0\n",
                  {"no 'face' element"});
}

TEST(MeshIoErrors, NanAndInfiniteCoordinates) {
    expectBadText("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
                  {"line 4", "vertex 1", "NaN or infinite"});
    expectBadText("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n",
                  {"line 3", "vertex 2", "NaN or infinite"});
    expectBadText("overflow.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n", {"line 2", "NaN or infinite"});
    expectBadText("nan.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex NaN 0 0\nvertex 0 1 0\n"
                  "endloop\nendfacet\nendsolid x\n",
                  {"line 5", "NaN or infinite"});
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float coords[9] = {0, 0, 0, 1, 0, std::numeric_limits<float>::quiet_NaN(), 0, 1, 0};
    ply.append(reinterpret_cast<const char*>(coords), sizeof coords);
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {0, 1, 2};
    ply.append(reinterpret_cast<const char*>(&three), 1);
    ply.append(reinterpret_cast<const char*>(idx), sizeof idx);
    expectBadText("nan.ply", ply, {"vertex 1 has a NaN or infinite coordinate"});

    const fs::path stl = fss::test::tmpPath("inf.stl");
    fss::writeMesh(makeOctahedron(), stl, {.binary = true});
    std::string bytes = readFile(stl);
    const float inf = std::numeric_limits<float>::infinity();
    std::memcpy(bytes.data() + 84 + 50 * 3 + 12 + 4, &inf, 4); // triangle 3, first corner, y
    writeFile(stl, bytes);
    expectIoError(stl, {"triangle 3 has a NaN or infinite coordinate"});
}

TEST(MeshIoErrors, FacesIndexingMissingVerticesOrWithTooFewCorners) {
    const std::string pts = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    expectBadText("bad_index.off", "OFF\n4 2 0\n" + pts + "3 0 1 2\n3 0 1 9\n",
                  {"line 8", "face 1 uses vertex index 9", "only 4 vertices"});
    expectBadText("negative_index.off", "OFF\n4 1 0\n" + pts + "3 0 -1 2\n", {"face 0 uses vertex index -1"});
    expectBadText("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n",
                  {"line 5", "face 1 uses vertex 7", "only 3 vertices"});
    expectBadText("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", {"face 0 uses vertex index 0"});
    expectBadText("bad_relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
                  {"relative vertex index -4"});
    const std::string plyHeader =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    expectBadText("bad_index.ply", plyHeader + pts + "3 0 1 2\n3 2 1 4\n",
                  {"line 15", "face 1 uses vertex index 4"});
    expectBadText("two_corners.off", "OFF\n4 1 0\n" + pts + "2 0 1\n",
                  {"face 0 has 2 corners", "at least 3"});
    expectBadText("two_corners.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", {"face 0 has 2 corners"});
    expectBadText("two_corners.ply", plyHeader + pts + "3 0 1 2\n2 1 3\n", {"face 1 has 2 corners"});
    expectBadText("too_many_values.ply", plyHeader + pts + "3 0 1 2 7\n3 0 1 3\n",
                  {"more values than the header"});
}

TEST(MeshIoErrors, NothingLeftAfterRepair) {
    expectBadText("all_degenerate.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 0 1\n3 2 2 2\n",
                  {"nothing is left after repair", "all 2 polygons are degenerate"});
    // Distinct indices, identical points: degenerate only once duplicates are merged.
    expectBadText("same_points.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 1 1\nvertex 1 1 1\nvertex 1 1 1\n"
                  "endloop\nendfacet\nendsolid x\n",
                  {"nothing is left after repair"});
}

// ----------------------------------------------------------------------------------------- writing

TEST(MeshIoWrite, ReplacesAtomicallyAndReportsFailures) {
    const Mesh octa = makeOctahedron();
    const fs::path folder = fss::test::tmpPath("write_folder");
    fs::remove_all(folder);
    fs::create_directories(folder);
    auto entries = [&] {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(folder))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    };

    // Overwriting an existing file leaves no temporary behind.
    const fs::path target = folder / "mesh.off";
    writeFile(target, "old content");
    fss::writeMesh(octa, target);
    EXPECT_EQ(fss::readMesh(target).number_of_faces(), 8u);
    EXPECT_EQ(entries(), std::vector<std::string>{"mesh.off"});

    // Failures name the file, and leave what existed untouched.
    auto expectWriteError = [&](const fs::path& p, const std::string& part) {
        try {
            fss::writeMesh(octa, p);
            ADD_FAILURE() << "no exception for " << p;
        } catch (const IoError& e) {
            EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    const std::string before = readFile(target);
    expectWriteError(folder / "mesh.vtk", "'.vtk'");
    expectWriteError(folder / "missing" / "mesh.off", "temporary file");
    fs::create_directories(folder / "dir.ply");
    expectWriteError(folder / "dir.ply", "folder");
    EXPECT_EQ(readFile(target), before);
    EXPECT_EQ(entries(), (std::vector<std::string>{"dir.ply", "mesh.off"}));
}

TEST(MeshIoWrite, WritesPolygonFacesAsFansInStl) {
    Mesh quad;
    const auto a = quad.add_vertex(Point3(0, 0, 0)), b = quad.add_vertex(Point3(1, 0, 0)),
               c = quad.add_vertex(Point3(1, 1, 0)), d = quad.add_vertex(Point3(0, 1, 0));
    quad.add_face(a, b, c, d);
    for (bool binary : {false, true}) {
        const fs::path p = fss::test::tmpPath(binary ? "quad_bin.stl" : "quad_ascii.stl");
        fss::writeMesh(quad, p, {.binary = binary});
        const Mesh m = fss::readMesh(p);
        EXPECT_EQ(m.number_of_faces(), 2u);
        EXPECT_EQ(m.number_of_vertices(), 4u);
        EXPECT_NEAR(area(m), 1.0, 1e-15);
    }
}

// ----------------------------------------------------------------------------------------- robustness

TEST(MeshIoFuzz, CorruptedFilesLoadValidMeshesOrThrowIoError) {
    // A small mesh with face properties, in every format; then mutations of each file.
    Mesh mesh = makeOctahedron();
    auto q = mesh.add_property_map<FaceIndex, float>(fss::props::faceQuality, 0.5f).first;
    auto s = mesh.add_property_map<FaceIndex, std::int32_t>(fss::props::faceScanId, 3).first;
    (void)q;
    (void)s;
    std::vector<std::pair<std::string, std::string>> originals; // extension, bytes
    for (const FormatCase& fc : kAllFormats) {
        const fs::path p = fss::test::tmpPath("fuzz_source_" + caseName(fc) + fc.ext);
        fss::writeMesh(mesh, p, {.binary = fc.binary});
        originals.emplace_back(fc.ext, readFile(p));
    }

    std::mt19937 rng(20240611);
    auto uniform = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
    const std::vector<std::string> interesting = {
        "0", "9", "-", "\n", " ", "nan", "1e308", "/", "#", std::string(1, '\0'), "\xff", "e", "4294967295"};
    std::size_t loaded = 0, rejected = 0;
    constexpr int kCasesPerFormat = 60;
    for (const auto& [ext, original] : originals) {
        for (int round = 0; round < kCasesPerFormat; ++round) {
            std::string bytes = original;
            const int mutations = 1 + int(uniform(3));
            for (int k = 0; k < mutations && !bytes.empty(); ++k) {
                const std::size_t at = uniform(bytes.size());
                switch (uniform(6)) {
                case 0:
                    bytes.resize(at);
                    break; // truncate
                case 1:
                    bytes[at] = static_cast<char>(uniform(256));
                    break; // flip a byte
                case 2:
                    bytes.insert(at, 1, static_cast<char>(uniform(256)));
                    break; // insert a byte
                case 3:
                    bytes.erase(at, 1 + uniform(16));
                    break; // delete a run
                case 4:
                    bytes.insert(at, interesting[uniform(interesting.size())]);
                    break; // plausible token
                case 5:
                    bytes.insert(at, bytes.substr(at, 1 + uniform(40)));
                    break; // repeat a run
                }
            }
            const fs::path p = fss::test::tmpPath("fuzz" + ext);
            writeFile(p, bytes);
            try {
                ReadReport report;
                const Mesh m = fss::readMesh(p, &report);
                ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m)) << ext << " round " << round;
                ASSERT_TRUE(CGAL::is_triangle_mesh(m)) << ext << " round " << round;
                ASSERT_GT(m.number_of_faces(), 0u) << ext << " round " << round;
                ++loaded;
            } catch (const IoError& e) {
                ASSERT_NE(std::string(e.what()).find("fuzz" + ext), std::string::npos) << e.what();
                ++rejected;
            } catch (const std::exception& e) {
                FAIL() << ext << " round " << round << ": unexpected exception " << e.what();
            }
        }
    }
    EXPECT_EQ(loaded + rejected, originals.size() * kCasesPerFormat);
    EXPECT_GT(rejected, 0u);
    EXPECT_GT(loaded, 0u);
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
