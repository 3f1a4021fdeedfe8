#pragma once
// The helpers the mesh I/O tests share (mesh_io_test.cpp, mesh_io_errors_test.cpp): scratch files,
// the expected IoError, positions and face corners, the STL float, area and volume, a hand-made octahedron
// and the round trip of one format.
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

namespace mesh_io_test_helpers {

// ----------------------------------------------------------------------------------------- helpers

inline void writeFile(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

inline std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Expects readMesh(path) to throw fss::IoError whose message names the file and contains every part.
inline void expectIoError(const fs::path& path, std::initializer_list<std::string> parts,
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
inline void expectBadText(const std::string& name, const std::string& text,
                          std::initializer_list<std::string> parts, const fss::ReadOptions& options = {}) {
    const fs::path p = fss::test::tmpPath(name);
    writeFile(p, text);
    expectIoError(p, parts, options);
}

inline std::vector<Point3> positions(const Mesh& m) {
    std::vector<Point3> p;
    for (VertexIndex v : m.vertices())
        p.push_back(m.point(v));
    return p;
}

/// Corner positions of every face in face order, rotated so that the smallest point comes first (the
/// starting corner of a face is not part of its identity).
inline std::vector<std::array<Point3, 3>> faceCorners(const Mesh& m) {
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

inline double relativeError(double a, double b) {
    return std::abs(a - b) / std::max(1.0, std::max(std::abs(a), std::abs(b)));
}

inline double maxRelativeError(const Point3& a, const Point3& b) {
    return std::max({relativeError(a.x(), b.x()), relativeError(a.y(), b.y()), relativeError(a.z(), b.z())});
}

/// The point as binary STL stores it. The float goes through a volatile: GCC 12.2 at -O2 miscompiles
/// double(float(x)) on neighbouring coordinates (SLP vectorisation drops the rounding of two of them).
inline double toFloat(double v) {
    volatile float f = static_cast<float>(v);
    return f;
}
inline Point3 asFloat(const Point3& p) {
    return {toFloat(p.x()), toFloat(p.y()), toFloat(p.z())};
}

inline double area(const Mesh& m) {
    double a = 0;
    for (FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Point3 &p = m.point(m.source(h)), &q = m.point(m.target(h)), &r = m.point(m.target(m.next(h)));
        a += std::sqrt(CGAL::cross_product(q - p, r - p).squared_length()) / 2;
    }
    return a;
}

inline double signedVolume(const Mesh& m) {
    double v = 0;
    for (FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const Vector3 p = m.point(m.source(h)) - CGAL::ORIGIN, q = m.point(m.target(h)) - CGAL::ORIGIN,
                      r = m.point(m.target(m.next(h))) - CGAL::ORIGIN;
        v += CGAL::scalar_product(p, CGAL::cross_product(q, r)) / 6;
    }
    return v;
}

inline bool hasRepair(const ReadReport& r, const std::string& sentence) {
    return std::find(r.repairs.begin(), r.repairs.end(), sentence) != r.repairs.end();
}

inline std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v)
        s += "[" + x + "] ";
    return s;
}

/// An octahedron with coordinates that do not have short decimal forms, built with a removed vertex at
/// the front so that vertex indices are not dense (the writers must re-index).
inline Mesh makeOctahedron(bool withGarbage = true) {
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
inline std::string caseName(const FormatCase& c) {
    return c.ext.substr(1) + (c.binary ? "_binary" : "_ascii");
}

inline const std::vector<FormatCase> kAllFormats = {{".off", false}, {".obj", false}, {".ply", false},
                                                    {".ply", true},  {".stl", false}, {".stl", true}};

/// Writes `mesh` in the given format, reads it back and checks counts, coordinates and face order.
inline void checkRoundTrip(const Mesh& mesh, const FormatCase& fc, const std::string& stem) {
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

} // namespace mesh_io_test_helpers
