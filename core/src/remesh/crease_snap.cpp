#include "remesh/crease_snap.h"

#include "remesh/crease_snapper.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <algorithm>
#include <vector>

namespace fss::detail {
namespace creases {

namespace PMP = CGAL::Polygon_mesh_processing;

void CreaseSnapper::round(CreaseSnapReport& r) {
    markFrozen();
    r.snaps += cornerSweep();
    r.snaps += snapSweep();
    r.removals += removeSweep();
    markFrozen();
    r.repairs += shortCreaseEdgeSweep();
    r.repairs += repairSweep();
    markFrozen();
    r.splits += splitSweep();
    markFrozen();
    r.splits += errorSplitSweep();
    markFrozen();
    for (int sweep = 0; sweep < 4; ++sweep) {
        const std::size_t f = flipSweep();
        r.flips += f;
        if (f == 0) break;
    }
}

bool CreaseSnapper::isInput(FaceIndex f) const {
    const auto [ids, have] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    return !have || ids[f] < 0;
}

void CreaseSnapper::markFrozen() {
    const std::size_t nv = m_.number_of_vertices() + m_.number_of_removed_vertices();
    frozen_.assign(nv, 0);
    onCrease_.resize(nv, 0);
    for (VertexIndex v : m_.vertices())
        frozen_[v.idx()] = m_.is_border(v);
}

bool CreaseSnapper::intersectsAround(std::initializer_list<VertexIndex> vertices) const {
    std::vector<VertexIndex> ring(vertices);
    for (VertexIndex v : vertices)
        for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
            ring.push_back(w);
    return PMP::does_self_intersect(faceIndicesAround(ring), m_);
}

std::vector<FaceIndex> CreaseSnapper::faceIndicesAround(const std::vector<VertexIndex>& vertices) const {
    std::vector<FaceIndex> faces;
    for (VertexIndex v : vertices)
        for (FaceIndex f : CGAL::faces_around_target(m_.halfedge(v), m_))
            if (f != Mesh::null_face()) faces.push_back(f);
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    return faces;
}

} // namespace creases

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using creases::CreaseSnapper;

/// Whether \p a and \p b are the same mesh: the same elements (removed ones too), points and connectivity.
bool sameMesh(const Mesh& a, const Mesh& b) {
    if (a.num_vertices() != b.num_vertices() || a.num_halfedges() != b.num_halfedges() ||
        a.num_faces() != b.num_faces())
        return false;
    for (VertexIndex v : a.vertices())
        if (b.is_removed(v) || a.point(v) != b.point(v) || a.halfedge(v) != b.halfedge(v)) return false;
    for (HalfedgeIndex h : a.halfedges())
        if (b.is_removed(h) || a.target(h) != b.target(h) || a.next(h) != b.next(h) || a.face(h) != b.face(h))
            return false;
    for (FaceIndex f : a.faces())
        if (b.is_removed(f) || a.halfedge(f) != b.halfedge(f)) return false;
    return a.number_of_vertices() == b.number_of_vertices() && a.number_of_faces() == b.number_of_faces();
}
} // namespace

CreaseSnapReport snapToCreases(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& options) {
    CreaseSnapReport report;
    if (options.rounds <= 0 || mesh.is_empty() || reference.is_empty()) {
        report.freeAfter = options.knownFree;
        return report;
    }
    CreaseSnapper snapper(mesh, reference, options);
    report.creaseEdges = snapper.creaseEdges();
    const bool intersectedBefore =
        !options.knownFree && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
    // Whether the mesh is the one tested last (or known free on entry): a round without operations is not
    // tested, so it counts only when it left the mesh exactly as it was.
    bool tested = !intersectedBefore;
    for (int round = 0; round < options.rounds; ++round) {
        const Mesh before = mesh;
        std::vector<char> marksBefore = snapper.creaseMarks();
        CreaseSnapReport r;
        snapper.round(r);
        if (r.snaps + r.splits + r.flips + r.removals + r.repairs == 0) {
            tested = tested && sameMesh(mesh, before);
            break;
        }
        if (!intersectedBefore && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) {
            mesh = before;
            snapper.setCreaseMarks(std::move(marksBefore));
            ++report.roundsReverted;
            break;
        }
        report.snaps += r.snaps;
        report.splits += r.splits;
        report.flips += r.flips;
        report.removals += r.removals;
        report.repairs += r.repairs;
    }
    snapper.markCreaseVertices();
    mesh.collect_garbage();
    report.freeAfter = tested;
    return report;
}

} // namespace fss::detail
