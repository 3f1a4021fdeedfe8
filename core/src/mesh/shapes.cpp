#include "fss/shapes.h"

#include "fss/error.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace fss::shapes {
namespace {

constexpr double kPi = std::numbers::pi;

void require(bool ok, const std::string& sentence) {
    if (!ok) throw InvalidInputError(sentence);
}

void addTriangle(Mesh& m, VertexIndex a, VertexIndex b, VertexIndex c) {
    if (m.add_face(a, b, c) == Mesh::null_face())
        throw Error("Internal error: an analytic shape produced a non-manifold triangle.");
}

// Builds a mesh from an index list (outward orientation assumed).
Mesh fromTriangles(const std::vector<Point3>& pts, const std::vector<std::array<int, 3>>& tris) {
    Mesh m;
    std::vector<VertexIndex> v;
    v.reserve(pts.size());
    for (const Point3& p : pts)
        v.push_back(m.add_vertex(p));
    for (const auto& t : tris)
        addTriangle(m, v[t[0]], v[t[1]], v[t[2]]);
    return m;
}

struct IcoData {
    std::vector<Point3> points;
    std::vector<std::array<int, 3>> triangles;
};

IcoData icosahedronData() {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    IcoData d;
    const double raw[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                               {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    const double n = std::sqrt(1 + t * t);
    for (const auto& r : raw)
        d.points.emplace_back(r[0] / n, r[1] / n, r[2] / n);
    d.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    return d;
}

Point3 scaled(const Point3& p, double radius) {
    const double n = std::sqrt(p.x() * p.x() + p.y() * p.y() + p.z() * p.z());
    return {p.x() / n * radius, p.y() / n * radius, p.z() / n * radius};
}

} // namespace

Mesh grid(int nx, int ny, double h) {
    require(nx >= 1 && ny >= 1 && h > 0, "A grid needs at least one quad per side and a positive spacing.");
    std::vector<Point3> pts;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            pts.emplace_back(i * h, j * h, 0.0);
    std::vector<std::array<int, 3>> tris;
    auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            // Same diagonal (lower-left to upper-right) everywhere: interior valence exactly 6.
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return fromTriangles(pts, tris);
}

Mesh icosahedron(double radius) {
    return icosphere(0, radius);
}

Mesh icosphere(int levels, double radius) {
    require(levels >= 0 && levels <= 10, "The icosphere subdivision level must be between 0 and 10.");
    require(radius > 0, "The sphere radius must be positive.");
    IcoData d = icosahedronData();
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<int, int>, int> mid;
        auto midpoint = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            const Point3 m = CGAL::midpoint(d.points[a], d.points[b]);
            d.points.push_back(scaled(m, 1.0));
            return mid[key] = int(d.points.size()) - 1;
        };
        std::vector<std::array<int, 3>> next;
        next.reserve(d.triangles.size() * 4);
        for (const auto& t : d.triangles) {
            const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
            next.push_back({t[0], ab, ca});
            next.push_back({t[1], bc, ab});
            next.push_back({t[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        d.triangles = std::move(next);
    }
    for (Point3& p : d.points)
        p = scaled(p, radius);
    return fromTriangles(d.points, d.triangles);
}

Mesh uvSphere(int nu, int nv, double radius) {
    require(nu >= 3 && nv >= 2 && radius > 0, "A UV sphere needs nu >= 3, nv >= 2 and a positive radius.");
    std::vector<Point3> pts;
    pts.emplace_back(0, 0, radius); // north pole
    for (int j = 1; j < nv; ++j) {
        const double theta = kPi * j / nv;
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * kPi * i / nu;
            pts.emplace_back(radius * std::sin(theta) * std::cos(phi),
                             radius * std::sin(theta) * std::sin(phi), radius * std::cos(theta));
        }
    }
    pts.emplace_back(0, 0, -radius); // south pole
    const int south = int(pts.size()) - 1;
    auto id = [nu](int ring, int i) { return 1 + (ring - 1) * nu + ((i % nu) + nu) % nu; };
    std::vector<std::array<int, 3>> tris;
    for (int i = 0; i < nu; ++i)
        tris.push_back({0, id(1, i), id(1, i + 1)});
    for (int j = 1; j < nv - 1; ++j)
        for (int i = 0; i < nu; ++i) {
            tris.push_back({id(j, i), id(j + 1, i), id(j + 1, i + 1)});
            tris.push_back({id(j, i), id(j + 1, i + 1), id(j, i + 1)});
        }
    for (int i = 0; i < nu; ++i)
        tris.push_back({south, id(nv - 1, i + 1), id(nv - 1, i)});
    return fromTriangles(pts, tris);
}

Mesh cylinder(int nu, int nv, double radius, double height, bool capped) {
    require(nu >= 3 && nv >= 1 && radius > 0 && height > 0,
            "A cylinder needs nu >= 3, nv >= 1, a positive radius and a positive height.");
    std::vector<Point3> pts;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double phi = 2 * kPi * i / nu;
            pts.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * j / nv);
        }
    auto id = [nu](int j, int i) { return j * nu + ((i % nu) + nu) % nu; };
    std::vector<std::array<int, 3>> tris;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            tris.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
            tris.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
        }
    if (capped) {
        pts.emplace_back(0, 0, 0);
        const int bottom = int(pts.size()) - 1;
        pts.emplace_back(0, 0, height);
        const int top = int(pts.size()) - 1;
        for (int i = 0; i < nu; ++i) {
            tris.push_back({bottom, id(0, i + 1), id(0, i)});
            tris.push_back({top, id(nv, i), id(nv, i + 1)});
        }
    }
    return fromTriangles(pts, tris);
}

Mesh torus(int nu, int nv, double majorRadius, double minorRadius) {
    require(nu >= 3 && nv >= 3 && minorRadius > 0 && majorRadius > minorRadius,
            "A torus needs nu, nv >= 3 and radii with 0 < minor < major.");
    std::vector<Point3> pts;
    for (int i = 0; i < nu; ++i) {
        const double u = 2 * kPi * i / nu;
        for (int j = 0; j < nv; ++j) {
            const double v = 2 * kPi * j / nv;
            const double rr = majorRadius + minorRadius * std::cos(v);
            pts.emplace_back(rr * std::cos(u), rr * std::sin(u), minorRadius * std::sin(v));
        }
    }
    auto id = [nu, nv](int i, int j) { return ((i % nu) + nu) % nu * nv + ((j % nv) + nv) % nv; };
    std::vector<std::array<int, 3>> tris;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return fromTriangles(pts, tris);
}

Mesh cube(int n, double side) {
    require(n >= 1 && side > 0, "A cube needs at least one quad per side and a positive side length.");
    std::vector<Point3> pts;
    std::map<std::array<int, 3>, int> index; // integer lattice coordinates → vertex
    auto vertex = [&](int a, int b, int c) {
        const std::array<int, 3> key{a, b, c};
        auto it = index.find(key);
        if (it != index.end()) return it->second;
        pts.emplace_back(side * (double(a) / n - 0.5), side * (double(b) / n - 0.5),
                         side * (double(c) / n - 0.5));
        return index[key] = int(pts.size()) - 1;
    };
    std::vector<std::array<int, 3>> tris;
    // For each axis and side, a grid of quads; orientation chosen so the normal points outward.
    for (int axis = 0; axis < 3; ++axis)
        for (int sideSign = 0; sideSign < 2; ++sideSign) {
            const int fixed = sideSign ? n : 0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    auto lattice = [&](int u, int v) {
                        std::array<int, 3> c{};
                        c[axis] = fixed;
                        c[(axis + 1) % 3] = u;
                        c[(axis + 2) % 3] = v;
                        return vertex(c[0], c[1], c[2]);
                    };
                    const int a = lattice(i, j), b = lattice(i + 1, j), c = lattice(i + 1, j + 1),
                              d = lattice(i, j + 1);
                    // (u, v) = (axis+1, axis+2) is right-handed with the axis: u × v = +axis.
                    if (sideSign) {
                        tris.push_back({a, b, c});
                        tris.push_back({a, c, d});
                    } else {
                        tris.push_back({a, c, b});
                        tris.push_back({a, d, c});
                    }
                }
        }
    return fromTriangles(pts, tris);
}

} // namespace fss::shapes
