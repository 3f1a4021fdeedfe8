// Guarded local operations: flip and collapse guards, edge split, vertex-move guard. See mesh/local_ops.h.
#include "mesh/local_ops.h"

#include "mesh/triangle_geometry.h"

#include <CGAL/Box_intersection_d/Box_with_info_d.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>

#include <numbers>

namespace fss::detail {

bool canFlip(const Mesh& mesh, HalfedgeIndex h) {
    if (mesh.is_border(mesh.edge(h))) return false;
    const HalfedgeIndex o = mesh.opposite(h);
    const VertexIndex c = mesh.target(mesh.next(h)), d = mesh.target(mesh.next(o));
    return c != d && mesh.degree(mesh.source(h)) > 3 && mesh.degree(mesh.target(h)) > 3 &&
           !CGAL::halfedge(c, d, mesh).second;
}

bool canCollapse(const Mesh& mesh, EdgeIndex e, bool keepOppositeValence) {
    if (keepOppositeValence) {
        const HalfedgeIndex h = mesh.halfedge(e), o = mesh.opposite(h);
        if (mesh.degree(mesh.target(mesh.next(h))) <= 3 || mesh.degree(mesh.target(mesh.next(o))) <= 3)
            return false;
    }
    return CGAL::Euler::does_satisfy_link_condition(e, mesh);
}

EdgeSplit splitEdge(Mesh& mesh, HalfedgeIndex h, const Point3& at) {
    EdgeSplit s;
    const HalfedgeIndex hn = CGAL::Euler::split_edge(h, mesh);
    s.vertex = mesh.target(hn);
    mesh.point(s.vertex) = at;
    s.first = CGAL::Euler::split_face(hn, mesh.next(mesh.next(hn)), mesh);
    const HalfedgeIndex og = mesh.opposite(h);
    s.second = CGAL::Euler::split_face(og, mesh.next(mesh.next(og)), mesh);
    return s;
}

void undoSplitEdge(Mesh& mesh, HalfedgeIndex h, const EdgeSplit& split) {
    // The two new edges, then the new vertex.
    CGAL::Euler::join_face(split.second, mesh);
    CGAL::Euler::join_face(split.first, mesh);
    CGAL::Euler::join_vertex(h, mesh); // removes the new vertex, the source of h
}

bool moveKeepsStar(const Mesh& mesh, VertexIndex v, const Eigen::Vector3d& to, double maxTurn, double floor) {
    const Eigen::Vector3d p = pos(mesh, v);
    double oldMin = std::numbers::pi, newMin = std::numbers::pi;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
        const HalfedgeIndex n1 = mesh.next(h);
        const Eigen::Vector3d s = pos(mesh, mesh.target(n1)), t = pos(mesh, mesh.target(mesh.next(n1)));
        oldMin = std::min(oldMin, minAngle(p, s, t));
        newMin = std::min(newMin, minAngle(to, s, t));
        const Eigen::Vector3d n0 = unitNormal(p, s, t), n = unitNormal(to, s, t);
        if (n0.isZero() || n.isZero() || angleBetween(n, n0) > maxTurn) return false;
    }
    return newMin >= std::min(oldMin, floor);
}

std::vector<std::pair<FaceIndex, FaceIndex>> intersectionsAround(const Mesh& mesh,
                                                                 const std::vector<VertexIndex>& touched) {
    std::vector<FaceIndex> near;
    for (VertexIndex v : touched)
        if (!mesh.is_removed(v))
            for (FaceIndex f : CGAL::faces_around_target(mesh.halfedge(v), mesh))
                if (f != Mesh::null_face()) near.push_back(f);
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    if (near.empty()) return {};
    using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, FaceIndex>;
    auto box = [&](FaceIndex f) {
        const HalfedgeIndex h = mesh.halfedge(f);
        return Box(mesh.point(mesh.source(h)).bbox() + mesh.point(mesh.target(h)).bbox() +
                       mesh.point(mesh.target(mesh.next(h))).bbox(),
                   f);
    };
    std::vector<Box> changed, all;
    changed.reserve(near.size());
    all.reserve(mesh.number_of_faces());
    for (FaceIndex f : near)
        changed.push_back(box(f));
    for (FaceIndex f : mesh.faces())
        all.push_back(box(f));
    CGAL::box_intersection_d(changed.begin(), changed.end(), all.begin(), all.end(),
                             [&](const Box&, const Box& other) { near.push_back(other.info()); });
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
    CGAL::Polygon_mesh_processing::self_intersections(near, mesh, std::back_inserter(pairs));
    return pairs;
}

std::vector<VertexIndex> cornersOf(const Mesh& mesh,
                                   const std::vector<std::pair<FaceIndex, FaceIndex>>& pairs) {
    std::vector<VertexIndex> out;
    for (const auto& [f, g] : pairs)
        for (FaceIndex h : {f, g})
            for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(h), mesh))
                out.push_back(v);
    return out;
}

} // namespace fss::detail
