// Sharp edges (CGAL's detect_sharp_edges) and the crease chains they form. See mesh/features.h.
#include "mesh/features.h"

#include "mesh/triangle_geometry.h"

#include <CGAL/Polygon_mesh_processing/detect_features.h>

#include <boost/property_map/property_map.hpp>

#include <cmath>
#include <numbers>

namespace fss::detail {
namespace {

/// A read-write edge property map over a vector of flags by edge index.
struct EdgeFlags {
    using key_type = EdgeIndex;
    using value_type = bool;
    using reference = bool;
    using category = boost::read_write_property_map_tag;
    std::vector<char>* flags;
    friend bool get(const EdgeFlags& m, EdgeIndex e) { return (*m.flags)[e.idx()] != 0; }
    friend void put(const EdgeFlags& m, EdgeIndex e, bool v) { (*m.flags)[e.idx()] = v ? 1 : 0; }
};

/// The face's unit normal from its halfedge's corners on (zero when degenerate).
Eigen::Vector3d faceNormal(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    return unitNormal(pos(mesh, mesh.source(h)), pos(mesh, mesh.target(h)),
                      pos(mesh, mesh.target(mesh.next(h))));
}

bool isDegenerate(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    const Point3 &a = mesh.point(mesh.source(h)), &b = mesh.point(mesh.target(h)),
                 &c = mesh.point(mesh.target(mesh.next(h)));
    return CGAL::cross_product(b - a, c - a) == CGAL::NULL_VECTOR;
}

} // namespace

std::vector<char> sharpEdges(const Mesh& mesh, double angleDeg) {
    std::vector<char> sharp(mesh.number_of_edges() + mesh.number_of_removed_edges(), 0);
    CGAL::Polygon_mesh_processing::detect_sharp_edges(mesh, angleDeg, EdgeFlags{&sharp});
    for (EdgeIndex e : mesh.edges()) {
        if (!sharp[e.idx()]) continue;
        const HalfedgeIndex h = mesh.halfedge(e);
        if (mesh.is_border(e) || isDegenerate(mesh, mesh.face(h)) ||
            isDegenerate(mesh, mesh.face(mesh.opposite(h))))
            sharp[e.idx()] = 0;
    }
    return sharp;
}

std::vector<int> sharpDegrees(const Mesh& mesh, const std::vector<char>& sharp) {
    std::vector<int> degree(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);
    for (EdgeIndex e : mesh.edges())
        if (sharp[e.idx()]) {
            ++degree[mesh.vertex(e, 0).idx()];
            ++degree[mesh.vertex(e, 1).idx()];
        }
    return degree;
}

std::vector<VertexIndex> creaseCorners(const Mesh& mesh, const std::vector<char>& sharp) {
    const std::vector<int> degree = sharpDegrees(mesh, sharp);
    std::vector<VertexIndex> corners;
    for (VertexIndex v : mesh.vertices())
        if (degree[v.idx()] != 0 && degree[v.idx()] != 2) corners.push_back(v);
    return corners;
}

std::vector<CreaseChain> creaseChains(const Mesh& mesh, const std::vector<char>& sharp,
                                      double maxBisectorTurnDeg) {
    const double cosTurn = std::cos(maxBisectorTurnDeg * std::numbers::pi / 180.0);
    const std::vector<int> degree = sharpDegrees(mesh, sharp);
    auto bisectorOf = [&](HalfedgeIndex h) {
        const Eigen::Vector3d b =
            faceNormal(mesh, mesh.face(h)) + faceNormal(mesh, mesh.face(mesh.opposite(h)));
        return b.norm() > 1e-12 ? Eigen::Vector3d(b.normalized()) : Eigen::Vector3d(0, 0, 0);
    };
    std::vector<char> used(sharp.size(), 0);
    std::vector<CreaseChain> chains;
    auto walk = [&](HalfedgeIndex start) {
        CreaseChain chain;
        chain.points.push_back(pos(mesh, mesh.source(start)));
        Eigen::Vector3d sum(0, 0, 0);
        HalfedgeIndex h = start;
        while (true) {
            used[mesh.edge(h).idx()] = 1;
            const Eigen::Vector3d p = pos(mesh, mesh.target(h));
            const double len = (p - chain.points.back()).norm();
            sum += bisectorOf(h) * len;
            chain.length += len;
            chain.points.push_back(p);
            const VertexIndex v = mesh.target(h);
            if (degree[v.idx()] != 2) break;
            HalfedgeIndex next;
            for (HalfedgeIndex o : CGAL::halfedges_around_source(v, mesh))
                if (sharp[mesh.edge(o).idx()] && !used[mesh.edge(o).idx()]) next = o;
            if (next == Mesh::null_halfedge()) break;
            const Eigen::Vector3d b = bisectorOf(next);
            if (sum.norm() > 0 && b.dot(sum.normalized()) < cosTurn) break; // the next piece faces elsewhere
            h = next;
        }
        if (sum.norm() > 0) chain.bisector = sum.normalized();
        chains.push_back(std::move(chain));
    };
    // Chains from their ends first (vertices of degree ≠ 2), then the closed loops.
    for (int pass = 0; pass < 2; ++pass)
        for (HalfedgeIndex h : mesh.halfedges()) {
            const EdgeIndex e = mesh.edge(h);
            if (!sharp[e.idx()] || used[e.idx()]) continue;
            if (pass == 0 && degree[mesh.source(h).idx()] == 2) continue;
            walk(h);
        }
    // A chain that stopped at a turn of the bisector continues as a new chain from where it stopped: the
    // walk above leaves the remaining edges unused, and the second pass starts them from a degree-2 vertex.
    return chains;
}

} // namespace fss::detail
