// Mesh building: the halfedge structure of a repaired triangle soup, assembled directly (linear time), and
// the flat, contiguously indexed form of a mesh that the writers and canonicalMesh use.
#include "mesh/io_detail.h"

#include <CGAL/boost/graph/iterator.h>

#include <numeric>

namespace fss::detail::io {

/// Builds the halfedge structure of a triangle soup that analyseTopology accepts (no repeated corners,
/// manifold, consistently oriented) directly: CGAL::Euler::add_face looks every new edge up around its
/// vertex, which is quadratic in the valence (a fan apex of a finely segmented cylinder cap). Vertices keep
/// the order of the used points and faces the order of the triangles. std::nullopt if the soup is not such.
std::optional<Mesh> buildTriangleMesh(const std::vector<Point3>& points, const std::vector<char>& used,
                                      const std::vector<Polygon>& triangles) {
    const std::size_t nf = triangles.size();
    Mesh mesh;
    mesh.reserve(Mesh::size_type(points.size()), Mesh::size_type(nf * 3 / 2 + 3), Mesh::size_type(nf));
    std::vector<VertexIndex> vertex(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        if (used[i]) vertex[i] = mesh.add_vertex(points[i]);

    // Corner c = 3f + j owns the halfedge from corner j to corner j + 1 of triangle f. Bucket the corners
    // by the smaller end of their edge (counting sort); an edge's two halfedges meet in one bucket.
    auto from = [&](std::size_t c) { return triangles[c / 3][c % 3]; };
    auto to = [&](std::size_t c) { return triangles[c / 3][(c % 3 + 1) % 3]; };
    std::vector<std::size_t> start(points.size() + 1, 0);
    for (std::size_t c = 0; c < 3 * nf; ++c)
        ++start[std::min(from(c), to(c)) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::size_t> bucket(3 * nf), fill(start.begin(), start.end() - 1);
    for (std::size_t c = 0; c < 3 * nf; ++c)
        bucket[fill[std::min(from(c), to(c))]++] = c;

    std::vector<HalfedgeIndex> halfedge(3 * nf);
    std::vector<HalfedgeIndex> borderFrom(points.size());       // the border halfedge leaving a point
    std::vector<std::pair<HalfedgeIndex, std::size_t>> borders; // border halfedge, the point it ends at
    for (std::size_t v = 0; v < points.size(); ++v) {
        const auto begin = bucket.begin() + std::ptrdiff_t(start[v]),
                   end = bucket.begin() + std::ptrdiff_t(start[v + 1]);
        auto other = [&](std::size_t c) { return std::max(from(c), to(c)); };
        std::sort(begin, end, [&](std::size_t a, std::size_t b) { return other(a) < other(b); });
        for (auto it = begin; it != end;) {
            const std::size_t c = *it;
            const HalfedgeIndex h = mesh.add_edge(), o = mesh.opposite(h);
            mesh.set_target(h, vertex[to(c)]);
            mesh.set_target(o, vertex[from(c)]);
            halfedge[c] = h;
            if (it + 1 != end && other(*(it + 1)) == other(c)) {
                const std::size_t d = *(it + 1);
                if (from(d) != to(c) || (it + 2 != end && other(*(it + 2)) == other(c))) return std::nullopt;
                halfedge[d] = o;
                it += 2;
            } else {
                if (borderFrom[to(c)] != HalfedgeIndex()) return std::nullopt;
                borderFrom[to(c)] = o;
                borders.emplace_back(o, from(c));
                ++it;
            }
        }
    }
    for (std::size_t f = 0; f < nf; ++f) {
        const FaceIndex face = mesh.add_face();
        mesh.set_halfedge(face, halfedge[3 * f]);
        for (std::size_t j = 0; j < 3; ++j) {
            mesh.set_face(halfedge[3 * f + j], face);
            mesh.set_next(halfedge[3 * f + j], halfedge[3 * f + (j + 1) % 3]);
            mesh.set_halfedge(vertex[triangles[f][(j + 1) % 3]], halfedge[3 * f + j]);
        }
    }
    // Border halfedges follow each other around holes; a border vertex points to its incoming one.
    for (const auto& [h, end] : borders) {
        if (borderFrom[end] == HalfedgeIndex()) return std::nullopt;
        mesh.set_next(h, borderFrom[end]);
        mesh.set_halfedge(vertex[end], h);
    }
    return mesh;
}

FlatMesh flatten(const Mesh& mesh) {
    FlatMesh flat;
    std::vector<std::size_t> index(mesh.num_vertices(), 0);
    flat.points.reserve(mesh.number_of_vertices());
    for (VertexIndex v : mesh.vertices()) {
        index[std::size_t(v)] = flat.points.size();
        flat.points.push_back(mesh.point(v));
    }
    const auto quality = mesh.property_map<FaceIndex, float>(props::faceQuality);
    const auto scanId = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    flat.hasQuality = quality.second;
    flat.hasScanId = scanId.second;
    const auto group = mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup);
    flat.hasGroups = group.second;
    if (flat.hasGroups) flat.groupNames = groupNames(mesh);
    flat.faceStart.reserve(mesh.number_of_faces() + 1);
    flat.corners.reserve(3 * mesh.number_of_faces());
    for (FaceIndex f : mesh.faces()) {
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            flat.corners.push_back(index[std::size_t(v)]);
        flat.faceStart.push_back(flat.corners.size());
        if (flat.hasQuality) flat.quality.push_back(quality.first[f]);
        if (flat.hasScanId) flat.scanId.push_back(scanId.first[f]);
        if (flat.hasGroups) flat.group.push_back(group.first[f]);
    }
    return flat;
}

} // namespace fss::detail::io
