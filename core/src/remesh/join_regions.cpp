// The one-pass join of auto v2 (auto_v2.cpp's file comment, step 3): the patches and the faces no patch
// reaches put into one mesh, the gaps between them closed by an advancing front (GapCloser), what is left by
// CGAL's hole filling, faces that intersect or pinch removed and refilled (repairJoin).
#include "remesh/join_regions.h"

#include "fss/metrics.h"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/refine.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/intersections.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <queue>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace fss::detail {
namespace {

/// Adds the faces of \p reference flagged in \p keep to \p out as faces left from the input (scan id -1).
void appendInputFaces(Mesh& out, const Mesh& reference, const std::vector<char>& keep) {
    auto outIds = out.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    auto outQuality = out.add_property_map<FaceIndex, float>(props::faceQuality, 0.f).first;
    std::vector<VertexIndex> map(reference.number_of_vertices() + reference.number_of_removed_vertices());
    for (FaceIndex f : reference.faces()) {
        if (!keep[f.idx()]) continue;
        std::array<VertexIndex, 3> corners;
        int i = 0;
        for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference)) {
            if (map[v.idx()] == VertexIndex()) map[v.idx()] = out.add_vertex(reference.point(v));
            corners[std::size_t(i++)] = map[v.idx()];
        }
        const FaceIndex g = out.add_face(corners[0], corners[1], corners[2]);
        if (g == Mesh::null_face()) continue;
        outIds[g] = -1;
        outQuality[g] = 0.f;
    }
}

/// The advancing front that closes the gaps between the patches of \p mesh (auto_v2.cpp, step 3): border
/// edges take the border vertex within \p reach of them that sees them under the largest angle, when the
/// new face turns by less than \p maxFoldDeg against the faces next to it, has no angle below
/// \p minAngleDeg and crosses no face already there (tested against the faces in the grid cells its box
/// meets); the roundest such faces (largest smallest angle) are added first, ears (faces closing two border
/// edges) before the others. Returns the number of faces added.
class GapCloser {
public:
    /// With \p onSurface, a face whose centroid lies farther than \p maxGap from that surface is not added
    /// (an open reference: its own boundaries must stay open).
    GapCloser(Mesh& mesh, double reach, double maxFoldDeg, double minAngleDeg,
              const RayCaster* onSurface = nullptr, double maxGap = 0)
        : m_(mesh), onSurface_(onSurface), maxGap_(maxGap), reach_(reach),
          cosFold_(std::cos(maxFoldDeg * std::numbers::pi / 180.0)),
          minAngle_(minAngleDeg * std::numbers::pi / 180.0) {
        ids_ = m_.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
        quality_ = m_.add_property_map<FaceIndex, float>(props::faceQuality, 0.f).first;
        for (VertexIndex v : m_.vertices())
            if (m_.is_border(v, true)) cells_[key(at(m_, v))].push_back(v);
        for (FaceIndex f : m_.faces())
            addFaceCells(f);
    }

    std::size_t run() {
        for (HalfedgeIndex h : m_.halfedges())
            if (m_.is_border(h)) push(h);
        std::size_t added = 0;
        while (!queue_.empty()) {
            const Candidate c = queue_.top();
            queue_.pop();
            if (!m_.is_border(c.h)) continue;
            const Candidate now = best(c.h);
            if (now.p == Mesh::null_vertex()) continue;
            if (now.p != c.p || now.score < c.score - 1e-12) {
                queue_.push(now);
                continue;
            }
            const VertexIndex u = m_.source(c.h), w = m_.target(c.h);
            const FaceIndex f0 = m_.face(m_.opposite(c.h));
            if (onSurface_ &&
                onSurface_->closestPoint((at(m_, u) + at(m_, w) + at(m_, c.p)) / 3.0).distance > maxGap_)
                continue;
            // A face that would cross one already there (measured on couplingdown: 506 of the 509 face pairs
            // that intersected after the gap closing were its own) is refused; the edge looks for another.
            if (crosses(u, w, c.p)) {
                refused_.insert(pairKey(c.h, c.p));
                push(c.h);
                continue;
            }
            const FaceIndex f = m_.add_face(u, w, c.p);
            if (f == Mesh::null_face()) continue;
            addFaceCells(f);
            ids_[f] = ids_[f0];
            quality_[f] = quality_[f0];
            ++added;
            for (VertexIndex v : {u, w, c.p})
                for (HalfedgeIndex g : CGAL::halfedges_around_target(v, m_)) {
                    if (m_.is_border(g)) push(g);
                    if (m_.is_border(m_.opposite(g))) push(m_.opposite(g));
                }
        }
        return added;
    }

private:
    struct Candidate {
        double score = -1;
        HalfedgeIndex h;
        VertexIndex p = Mesh::null_vertex();
        bool operator<(const Candidate& o) const { return score < o.score; }
    };

    std::int64_t key(const Eigen::Vector3d& p) const { return key(cell(p)); }
    Eigen::Vector3i cell(const Eigen::Vector3d& p) const {
        return {int(std::floor(p.x() / reach_)), int(std::floor(p.y() / reach_)),
                int(std::floor(p.z() / reach_))};
    }
    static std::int64_t key(const Eigen::Vector3i& c) {
        return (std::int64_t(c.x() & 0x1FFFFF) << 42) | (std::int64_t(c.y() & 0x1FFFFF) << 21) |
               std::int64_t(c.z() & 0x1FFFFF);
    }

    Eigen::Vector3d vertexNormal(VertexIndex v) const {
        Eigen::Vector3d n(0, 0, 0);
        for (FaceIndex f : CGAL::faces_around_target(m_.halfedge(v), m_))
            if (f != Mesh::null_face()) n += faceArea(m_, f) * faceNormal(m_, f);
        return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
    }

    bool freeOrBorder(VertexIndex a, VertexIndex b) const {
        const HalfedgeIndex h = m_.halfedge(a, b);
        return h == Mesh::null_halfedge() || m_.is_border(h);
    }

    Candidate best(HalfedgeIndex h) const {
        Candidate out;
        out.h = h;
        const VertexIndex u = m_.source(h), w = m_.target(h);
        const Eigen::Vector3d a = at(m_, u), b = at(m_, w), mid = 0.5 * (a + b);
        const FaceIndex f0 = m_.face(m_.opposite(h));
        if (f0 == Mesh::null_face()) return out;
        const Eigen::Vector3d n0 = faceNormal(m_, f0);
        const Eigen::Vector3i c0 = cell(mid);
        double bestChoice = -1;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const auto it = cells_.find(key(Eigen::Vector3i(c0.x() + dx, c0.y() + dy, c0.z() + dz)));
                    if (it == cells_.end()) continue;
                    for (VertexIndex p : it->second) {
                        if (p == u || p == w || m_.is_removed(p) || !m_.is_border(p, true)) continue;
                        if (refused_.count(pairKey(h, p))) continue;
                        const Eigen::Vector3d c = at(m_, p);
                        if ((c - a).norm() > reach_ || (c - b).norm() > reach_) continue;
                        Eigen::Vector3d n = (b - a).cross(c - a);
                        if (n.norm() == 0) continue;
                        n.normalize();
                        if (n.dot(n0) < cosFold_ || n.dot(vertexNormal(p)) < cosFold_) continue;
                        const Eigen::Vector3d ca = a - c, cb = b - c, ab = b - a;
                        const double angP = std::atan2(ca.cross(cb).norm(), ca.dot(cb));
                        const double angA = std::atan2(ab.cross(c - a).norm(), ab.dot(c - a));
                        const double angB = std::numbers::pi - angP - angA;
                        const double smallest = std::min({angP, angA, angB});
                        if (smallest < minAngle_) continue;
                        if (!freeOrBorder(w, p) || !freeOrBorder(p, u)) continue;
                        // The Delaunay choice: the largest angle at p (ears first: they shorten the front).
                        const bool ear = m_.halfedge(w, p) != Mesh::null_halfedge() ||
                                         m_.halfedge(p, u) != Mesh::null_halfedge();
                        const double choice = angP + (ear ? 4.0 : 0.0);
                        if (choice > bestChoice)
                            bestChoice = choice, out.p = p, out.score = smallest + (ear ? 1.0 : 0.0);
                    }
                }
        return out;
    }

    static std::uint64_t pairKey(HalfedgeIndex h, VertexIndex p) {
        return (std::uint64_t(h.idx()) << 32) | std::uint64_t(p.idx());
    }

    /// Registers face \p f in every cell its bounding box meets.
    void addFaceCells(FaceIndex f) {
        Eigen::AlignedBox3d box;
        for (VertexIndex v : CGAL::vertices_around_face(m_.halfedge(f), m_))
            box.extend(at(m_, v));
        const Eigen::Vector3i lo = cell(box.min()), hi = cell(box.max());
        for (int x = lo.x(); x <= hi.x(); ++x)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int z = lo.z(); z <= hi.z(); ++z)
                    faceCells_[key(Eigen::Vector3i(x, y, z))].push_back(f);
    }

    /// Whether the triangle (u, w, p) meets a face of the mesh that has none of its corners.
    bool crosses(VertexIndex u, VertexIndex w, VertexIndex p) const {
        const Kernel::Triangle_3 t(m_.point(u), m_.point(w), m_.point(p));
        Eigen::AlignedBox3d box;
        for (VertexIndex v : {u, w, p})
            box.extend(at(m_, v));
        const Eigen::Vector3i lo = cell(box.min()), hi = cell(box.max());
        for (int x = lo.x(); x <= hi.x(); ++x)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int z = lo.z(); z <= hi.z(); ++z) {
                    const auto it = faceCells_.find(key(Eigen::Vector3i(x, y, z)));
                    if (it == faceCells_.end()) continue;
                    for (FaceIndex f : it->second) {
                        if (m_.is_removed(f)) continue;
                        const HalfedgeIndex g = m_.halfedge(f);
                        const VertexIndex a = m_.source(g), b = m_.target(g), c = m_.target(m_.next(g));
                        bool shares = false;
                        for (VertexIndex v : {a, b, c})
                            shares = shares || v == u || v == w || v == p;
                        if (shares) continue;
                        if (CGAL::do_intersect(t, Kernel::Triangle_3(m_.point(a), m_.point(b), m_.point(c))))
                            return true;
                    }
                }
        return false;
    }

    void push(HalfedgeIndex h) {
        const Candidate c = best(h);
        if (c.p != Mesh::null_vertex()) queue_.push(c);
    }

    Mesh& m_;
    const RayCaster* onSurface_;
    double maxGap_, reach_, cosFold_, minAngle_;
    Mesh::Property_map<FaceIndex, std::int32_t> ids_;
    Mesh::Property_map<FaceIndex, float> quality_;
    std::unordered_map<std::int64_t, std::vector<VertexIndex>> cells_;
    std::priority_queue<Candidate> queue_;
    std::unordered_map<std::int64_t, std::vector<FaceIndex>> faceCells_;
    std::unordered_set<std::uint64_t> refused_;
};

/// Refines the faces \p added (a fill) and returns them with the faces the refinement adds (those it
/// splits keep their index); \p newVertices receives the refinement's vertices.
std::vector<FaceIndex> refineAdded(Mesh& mesh, std::vector<FaceIndex> added,
                                   std::vector<VertexIndex>& newVertices) {
    std::vector<FaceIndex> refined;
    if (!added.empty())
        CGAL::Polygon_mesh_processing::refine(mesh, added, std::back_inserter(refined),
                                              std::back_inserter(newVertices));
    added.insert(added.end(), refined.begin(), refined.end());
    return added;
}

/// Fills the pinched boundary cycle through border halfedge \p h (CGAL's hole triangulation returns no face
/// for a cycle that passes a vertex twice: measured on couplingdown, 20 of its 105 cycles, all of them
/// pinched and no other) loop by loop: each simple loop is triangulated as a polyline (no new vertex) and
/// its triangles added in the loop's order, the orientation of the border halfedges, then refined as
/// triangulate_and_refine_hole refines a fill. Returns the new faces; \p newVertices receives the
/// refinement's.
std::vector<FaceIndex> fillPinchedCycle(Mesh& mesh, HalfedgeIndex h, std::vector<VertexIndex>& newVertices) {
    std::vector<VertexIndex> cycle;
    for (HalfedgeIndex g : CGAL::halfedges_around_face(h, mesh))
        cycle.push_back(mesh.source(g));
    std::vector<FaceIndex> added;
    for (const std::vector<VertexIndex>& loop : pinchedCycleLoops(cycle)) {
        std::vector<Point3> points;
        for (VertexIndex v : loop)
            points.push_back(mesh.point(v));
        std::vector<CGAL::Triple<int, int, int>> triangles;
        CGAL::Polygon_mesh_processing::triangulate_hole_polyline(points, std::back_inserter(triangles));
        for (const CGAL::Triple<int, int, int>& t : triangles) {
            const FaceIndex f = mesh.add_face(loop[std::size_t(t.first)], loop[std::size_t(t.second)],
                                              loop[std::size_t(t.third)]);
            if (f != Mesh::null_face()) added.push_back(f);
        }
    }
    return refineAdded(mesh, std::move(added), newVertices);
}

/// Closes the inlets of the boundary cycle through border halfedge \p h, which runs along the reference's
/// border: a run of its edges whose midpoints lie off the border (farther than border.reach), from vertex a
/// to vertex b, that goes into the surface and comes back (a gap between two patches that reaches the
/// border: its path at least kInletRatio times the chord a-b, the chord at most kInletChord reaches) is
/// triangulated as a polygon closed by the chord (no new vertex), then refined. Measured on
/// mech-holes-shark: such a gap merged with a hole's border cycle, which the hole filling then left open.
/// Returns the faces added; \p newVertices receives the refinement's.
std::vector<FaceIndex> closeBorderInlets(Mesh& mesh, HalfedgeIndex h, const PointGrid& near, double reach,
                                         std::vector<VertexIndex>& newVertices) {
    constexpr double kInletRatio = 2.5, kInletChord = 4.0;
    std::vector<VertexIndex> cycle;
    std::vector<char> off;
    for (HalfedgeIndex g : CGAL::halfedges_around_face(h, mesh)) {
        cycle.push_back(mesh.source(g));
        off.push_back(!near.near(0.5 * (at(mesh, mesh.source(g)) + at(mesh, mesh.target(g)))));
    }
    const std::size_t n = cycle.size();
    std::size_t start = n;
    for (std::size_t i = 0; i < n && start == n; ++i)
        if (!off[i]) start = i; // a run never wraps past an edge on the border
    if (start == n) return {};
    std::vector<std::vector<VertexIndex>> inlets;
    for (std::size_t k = 1; k <= n; ++k) {
        const std::size_t i = (start + k) % n;
        if (!off[i]) continue;
        std::vector<VertexIndex> run{cycle[i]};
        double path = 0;
        std::size_t j = i;
        while (off[j]) {
            const std::size_t next = (j + 1) % n;
            path += (at(mesh, cycle[next]) - at(mesh, cycle[j])).norm();
            run.push_back(cycle[next]);
            j = next;
            ++k;
        }
        const double chord = (at(mesh, run.back()) - at(mesh, run.front())).norm();
        std::vector<VertexIndex> sorted = run;
        std::sort(sorted.begin(), sorted.end());
        const bool simple = std::unique(sorted.begin(), sorted.end()) == sorted.end();
        const bool accept = run.size() >= 4 && simple && chord <= kInletChord * reach &&
                            path >= kInletRatio * chord &&
                            mesh.halfedge(run.back(), run.front()) == Mesh::null_halfedge();
        if (std::getenv("FSS_AUTO_V2_DEBUG") && run.size() >= 3)
            std::fprintf(stderr, "v2 inlet: %zu of %zu edges, chord %.2f reach, path %.2f chords, %s: %s\n",
                         run.size() - 1, n, chord / reach, path / std::max(chord, 1e-300),
                         simple ? "simple" : "not simple", accept ? "closed" : "left");
        if (accept) inlets.push_back(std::move(run));
    }
    std::vector<FaceIndex> added;
    for (const std::vector<VertexIndex>& loop : inlets) {
        std::vector<Point3> points;
        for (VertexIndex v : loop)
            points.push_back(mesh.point(v));
        std::vector<CGAL::Triple<int, int, int>> triangles;
        CGAL::Polygon_mesh_processing::triangulate_hole_polyline(points, std::back_inserter(triangles));
        std::vector<FaceIndex> faces;
        bool ok = !triangles.empty();
        for (const CGAL::Triple<int, int, int>& t : triangles) {
            const FaceIndex f = mesh.add_face(loop[std::size_t(t.first)], loop[std::size_t(t.second)],
                                              loop[std::size_t(t.third)]);
            if (f == Mesh::null_face()) {
                ok = false;
                break;
            }
            faces.push_back(f);
        }
        if (!ok) {
            for (FaceIndex f : faces)
                CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
            continue;
        }
        added.insert(added.end(), faces.begin(), faces.end());
    }
    return refineAdded(mesh, std::move(added), newVertices);
}

Eigen::Vector3d centroid(const Mesh& m, FaceIndex f) {
    Eigen::Vector3d c(0, 0, 0);
    for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
        c += at(m, v) / 3.0;
    return c;
}

} // namespace

ReferenceBorder referenceBorder(const Mesh& reference, double reach) {
    ReferenceBorder out;
    out.reach = reach;
    for (HalfedgeIndex h : reference.halfedges()) {
        if (!reference.is_border(h)) continue;
        const Eigen::Vector3d a = at(reference, reference.source(h)), b = at(reference, reference.target(h));
        const int steps = std::max(1, int(std::ceil(2.0 * (b - a).norm() / reach)));
        for (int i = 0; i < steps; ++i)
            out.samples.push_back(a + (b - a) * (double(i) / steps));
    }
    return out;
}

bool cycleOnBorder(const Mesh& mesh, HalfedgeIndex h, const ReferenceBorder& border) {
    if (border.samples.empty()) return false;
    PointGrid grid(border.reach);
    for (const Eigen::Vector3d& p : border.samples)
        grid.add(p);
    std::size_t edges = 0, near = 0;
    for (HalfedgeIndex g : CGAL::halfedges_around_face(h, mesh)) {
        ++edges;
        near += grid.near(0.5 * (at(mesh, mesh.source(g)) + at(mesh, mesh.target(g))));
    }
    return 2 * near >= edges;
}

void fillJoinHoles(Mesh& mesh, const ReferenceBorder& border, bool closeInlets) {
    auto ids = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    auto quality = mesh.add_property_map<FaceIndex, float>(props::faceQuality, 0.f).first;
    std::vector<HalfedgeIndex> cycles;
    CGAL::Polygon_mesh_processing::extract_boundary_cycles(mesh, std::back_inserter(cycles));
    PointGrid borderGrid(border.reach > 0 ? border.reach : 1.0);
    for (const Eigen::Vector3d& p : border.samples)
        borderGrid.add(p);
    for (HalfedgeIndex h : cycles) {
        if (!mesh.is_border(h)) continue;
        // A cycle along the reference's own boundary stays open (measured on mech-holes-shark: the repair's
        // refill closed two of its four holes; on blade it capped an end and bridged the two sides).
        if (cycleOnBorder(mesh, h, border)) {
            if (!closeInlets) continue;
            std::vector<VertexIndex> newVertices;
            const FaceIndex next = mesh.face(mesh.opposite(h));
            for (FaceIndex f : closeBorderInlets(mesh, h, borderGrid, border.reach, newVertices)) {
                ids[f] = next != Mesh::null_face() ? ids[next] : 0;
                quality[f] = next != Mesh::null_face() ? quality[next] : 0.f;
            }
            continue;
        }
        const FaceIndex next = mesh.face(mesh.opposite(h));
        // For FSS_AUTO_V2_DEBUG, the cycle before it is filled: its length, how many of its vertices it
        // passes more than once (a pinched cycle) and how many of its vertex pairs two apart are already
        // joined by an edge of the mesh (the triangulation may not create an edge twice).
        std::string cycleText;
        if (std::getenv("FSS_AUTO_V2_DEBUG")) {
            std::vector<VertexIndex> cycle;
            for (HalfedgeIndex g : CGAL::halfedges_around_face(h, mesh))
                cycle.push_back(mesh.target(g));
            std::vector<VertexIndex> sorted = cycle;
            std::sort(sorted.begin(), sorted.end());
            const std::size_t repeated =
                sorted.size() - std::size_t(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
            std::size_t chords = 0;
            for (std::size_t i = 0; i < cycle.size() && cycle.size() > 3; ++i)
                chords += mesh.halfedge(cycle[i], cycle[(i + 2) % cycle.size()]) != Mesh::null_halfedge();
            cycleText = std::to_string(cycle.size()) + " edges, " + std::to_string(repeated) +
                        " repeated vertices, " + std::to_string(chords) + " chords";
        }
        std::vector<FaceIndex> added;
        std::vector<VertexIndex> newVertices;
        // Refined (vertices inserted at the edge length of the hole's border), so that the seam relaxation
        // can move the fill onto the reference (it projects zone vertices that lie off it).
        CGAL::Polygon_mesh_processing::triangulate_and_refine_hole(mesh, h, std::back_inserter(added),
                                                                   std::back_inserter(newVertices));
        if (added.empty() && mesh.is_border(h)) added = fillPinchedCycle(mesh, h, newVertices);
        for (FaceIndex f : added) {
            ids[f] = next != Mesh::null_face() ? ids[next] : 0;
            quality[f] = next != Mesh::null_face() ? quality[next] : 0.f;
        }
        if (!cycleText.empty())
            std::fprintf(stderr, "v2 fill: cycle of %s -> %zu faces, %zu new vertices\n", cycleText.c_str(),
                         added.size(), newVertices.size());
    }
}

namespace {

/// The faces the join left wrong (joinDefects).
struct Defects {
    std::vector<char> bad;       ///< per face index
    std::size_t pairs = 0;       ///< intersecting face pairs
    std::size_t faces = 0;       ///< bad faces
    std::size_t borderEdges = 0; ///< boundary edges
};

/// The faces of \p mesh that intersect another, are degenerate, touch a pinched vertex (a vertex whose faces
/// form several fans; with \p twoFans also a vertex with two boundary fans, where two gaps meet) or
/// (\p closed) lie at a boundary the hole filling could not close.
Defects findDefects(const Mesh& mesh, bool closed, bool twoFans = false) {
    namespace PMP = CGAL::Polygon_mesh_processing;
    Defects out;
    out.bad.assign(mesh.number_of_faces() + mesh.number_of_removed_faces(), 0);
    std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
    PMP::self_intersections<CGAL::Parallel_if_available_tag>(faces(mesh), mesh, std::back_inserter(pairs));
    out.pairs = pairs.size();
    for (const auto& [f, g] : pairs)
        out.bad[f.idx()] = out.bad[g.idx()] = 1;
    for (FaceIndex f : mesh.faces())
        if (PMP::is_degenerate_triangle_face(f, mesh)) out.bad[f.idx()] = 1;
    std::vector<int> incoming(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);
    for (HalfedgeIndex h : mesh.halfedges())
        ++incoming[mesh.target(h).idx()];
    std::vector<char> pinched(incoming.size(), 0);
    for (VertexIndex v : mesh.vertices()) {
        int around = 0, borders = 0;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(v, mesh)) {
            ++around;
            borders += mesh.is_border(h);
        }
        // Two boundary fans at one vertex (two gaps meeting there) pinch it as well: computeMetrics counts
        // it (measured on mech-holes-shark: the only defect left after the repair, so validation failed).
        // Only where the caller asks (repairJoin on an open reference): on a closed one every face at a
        // boundary is bad anyway, and marking the whole fan there too changed elephant's repair for the
        // worse (Hausdorff from it 0.005 -> 0.026 of the diagonal); in the repair inside the join in two
        // passes it made blade's refill merge a gap with its border (1 boundary loop of 2).
        pinched[v.idx()] = around != incoming[v.idx()] || (twoFans && borders > 1);
    }
    for (HalfedgeIndex h : mesh.halfedges())
        out.borderEdges += mesh.is_border(h);
    // Faces at a pinched vertex, and (closed meshes) at a boundary the hole filling could not close.
    for (FaceIndex f : mesh.faces())
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
            if (pinched[mesh.target(h).idx()] || (closed && mesh.is_border(mesh.opposite(h))))
                out.bad[f.idx()] = 1;
    for (char b : out.bad)
        out.faces += b;
    return out;
}

/// Repairs what the gap closing left wrong (findDefects, \p twoFans passed on): the bad faces, with one ring
/// of faces around them, are removed and the holes (with those left open) are filled again (fillHoles); up to
/// \p rounds times. Returns true when the mesh is then free of defects.
bool repairDefects(Mesh& mesh, const ReferenceBorder& border, bool closed, int rounds, bool debug,
                   bool twoFans) {
    for (int round = 0;; ++round) {
        const Defects d = findDefects(mesh, closed, twoFans);
        if (debug)
            std::fprintf(stderr,
                         "v2 repair %d: %zu faces, %zu intersecting pairs, %zu bad faces, %zu border edges\n",
                         round, std::size_t(mesh.number_of_faces()), d.pairs, d.faces, d.borderEdges);
        if (d.faces == 0 && (!closed || d.borderEdges == 0)) return true;
        if (round == rounds) return false;
        // One ring of faces around the bad ones.
        std::vector<char> ring(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);
        for (FaceIndex f : mesh.faces())
            if (d.bad[f.idx()])
                for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
                    ring[v.idx()] = 1;
        std::vector<FaceIndex> remove;
        for (FaceIndex f : mesh.faces()) {
            bool near = d.bad[f.idx()];
            for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
                near = near || ring[v.idx()];
            if (near) remove.push_back(f);
        }
        for (FaceIndex f : remove)
            CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
        for (VertexIndex v : mesh.vertices())
            if (mesh.is_isolated(v)) mesh.remove_vertex(v);
        // Without this, the hole refinement's new vertices reuse removed ones and crashed on elephant (a
        // corrupt free list in Surface_mesh::add_vertex); the face marks above are rebuilt every round.
        mesh.collect_garbage();
        fillJoinHoles(mesh, border);
    }
}

} // namespace

std::vector<std::vector<VertexIndex>> pinchedCycleLoops(const std::vector<VertexIndex>& cycle) {
    std::vector<std::vector<VertexIndex>> out;
    std::vector<VertexIndex> path;
    std::unordered_map<std::uint32_t, std::size_t> position;
    for (VertexIndex v : cycle) {
        const auto it = position.find(v.idx());
        if (it == position.end()) {
            position[v.idx()] = path.size();
            path.push_back(v);
            continue;
        }
        // path[it->second] == v: the vertices after it up to here close a loop through v.
        std::vector<VertexIndex> loop(path.begin() + std::ptrdiff_t(it->second), path.end());
        for (std::size_t i = it->second + 1; i < path.size(); ++i)
            position.erase(path[i].idx());
        path.resize(it->second + 1);
        if (loop.size() >= 3) out.push_back(std::move(loop));
    }
    if (path.size() >= 3) out.push_back(std::move(path));
    return out;
}

/// Adds the faces of \p patch to \p out (scan id and quality kept).
void appendPatch(Mesh& out, const Mesh& patch) {
    auto outIds = out.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    auto outQuality = out.add_property_map<FaceIndex, float>(props::faceQuality, 0.f).first;
    const auto [ids, haveIds] = patch.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    const auto [quality, haveQuality] = patch.property_map<FaceIndex, float>(props::faceQuality);
    std::vector<VertexIndex> map(patch.number_of_vertices() + patch.number_of_removed_vertices());
    for (VertexIndex v : patch.vertices())
        map[v.idx()] = out.add_vertex(patch.point(v));
    for (FaceIndex f : patch.faces()) {
        const HalfedgeIndex h = patch.halfedge(f);
        const FaceIndex g = out.add_face(map[patch.source(h).idx()], map[patch.target(h).idx()],
                                         map[patch.target(patch.next(h)).idx()]);
        if (g == Mesh::null_face()) continue;
        outIds[g] = haveIds ? ids[f] : -1;
        outQuality[g] = haveQuality ? quality[f] : 0.f;
    }
}

/// Flags the faces of \p reference whose centroid lies farther than \p reach from every vertex of \p patches:
/// the parts of the surface no region sampled (thin pieces the opening removed, regions whose patch failed,
/// faces no view sees).
std::vector<char> unsampledFaces(const Mesh& reference, const std::vector<Patch>& patches, double reach) {
    PointGrid grid(reach);
    for (const Patch& patch : patches)
        for (VertexIndex v : patch.mesh.vertices())
            grid.add(at(patch.mesh, v));
    std::vector<char> out(reference.number_of_faces() + reference.number_of_removed_faces(), 0);
    for (FaceIndex f : reference.faces())
        out[f.idx()] = !grid.near(centroid(reference, f));
    return out;
}

std::size_t widenInputRegions(const Mesh& reference, const Mesh& joined, bool closed, double reach,
                              std::vector<char>& inputFaces) {
    const Defects d = findDefects(joined, closed);
    PointGrid grid(reach);
    for (FaceIndex f : joined.faces())
        if (d.bad[f.idx()]) grid.add(centroid(joined, f));
    std::size_t added = 0;
    for (FaceIndex f : reference.faces())
        if (!inputFaces[f.idx()] && grid.near(centroid(reference, f))) inputFaces[f.idx()] = 1, ++added;
    return added;
}

bool repairJoin(Mesh& mesh, const ReferenceBorder& border, bool closed, int rounds, bool debug) {
    return repairDefects(mesh, border, closed, rounds, debug, !closed);
}

std::size_t dropSmallPieces(Mesh& mesh, std::size_t components, std::size_t maxFaces) {
    std::vector<std::vector<FaceIndex>> pieces = faceComponents(mesh, [](FaceIndex) { return true; });
    std::stable_sort(pieces.begin(), pieces.end(),
                     [](const auto& a, const auto& b) { return a.size() < b.size(); });
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < pieces.size() && pieces.size() - dropped > components; ++i) {
        if (pieces[i].size() > maxFaces) break;
        for (FaceIndex f : pieces[i])
            CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
        ++dropped;
    }
    if (dropped == 0) return 0;
    for (VertexIndex v : mesh.vertices())
        if (mesh.is_isolated(v)) mesh.remove_vertex(v);
    mesh.collect_garbage();
    return dropped;
}

std::size_t flagUncoveredFaces(const Mesh& reference, const Mesh& joined, double reach,
                               std::vector<char>& inputFaces) {
    const RayCaster onJoin(joined);
    std::size_t added = 0;
    for (FaceIndex f : reference.faces())
        if (!inputFaces[f.idx()] && onJoin.closestPoint(centroid(reference, f)).distance > reach)
            inputFaces[f.idx()] = 1, ++added;
    return added;
}

void removePatchFacesNear(Mesh& mesh, const Mesh& reference, const std::vector<char>& faces, double reach) {
    // The distance to the flagged faces themselves, not to their centroids: a long face of a CAD part has
    // patch faces over its far ends (measured on mech-holes-shark: 49 intersecting face pairs at the input
    // faces of every round when the centroids were used).
    Mesh flagged;
    appendInputFaces(flagged, reference, faces);
    if (flagged.number_of_faces() == 0) return;
    const RayCaster onFlagged(flagged);
    std::vector<FaceIndex> remove;
    for (FaceIndex f : mesh.faces())
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            if (onFlagged.closestPoint(at(mesh, v)).distance <= reach) {
                remove.push_back(f);
                break;
            }
    for (FaceIndex f : remove)
        CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
    for (VertexIndex v : mesh.vertices())
        if (mesh.is_isolated(v)) mesh.remove_vertex(v);
    mesh.collect_garbage();
}

/// Closes the gaps between the patches already in \p mesh (auto_v2.cpp, step 3) and repairs the result
/// (repairJoin). \p unsampled: the reference's faces to add as input faces (JoinStyle::InputRegions).
void joinRegions(Mesh& mesh, const Mesh& reference, const std::vector<char>* unsampled,
                 const RayCaster& caster, const ReferenceBorder& border, JoinStyle style, double L,
                 bool closed, bool debug, int repairRounds) {
    const auto borderEdges = [&] {
        std::size_t n = 0;
        for (HalfedgeIndex h : mesh.halfedges())
            n += mesh.is_border(h);
        return n;
    };
    const auto pieces = [&](const char* when) {
        if (!debug) return;
        const auto ids = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId).first;
        const auto comps = faceComponents(mesh, [](FaceIndex) { return true; });
        std::fprintf(stderr, "v2: %zu components %s:", comps.size(), when);
        for (const std::vector<FaceIndex>& c : comps) {
            std::size_t input = 0, border = 0;
            std::vector<int> views;
            for (FaceIndex f : c) {
                input += ids[f] < 0;
                if (ids[f] >= 0 && std::find(views.begin(), views.end(), ids[f]) == views.end())
                    views.push_back(ids[f]);
                for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
                    border += mesh.is_border(mesh.opposite(h));
            }
            std::fprintf(stderr, " [%zu faces, %zu input, %zu views, %zu border]", c.size(), input,
                         views.size(), border);
        }
        std::fprintf(stderr, "\n");
    };
    if (style == JoinStyle::InputRegions) {
        if (unsampled) appendInputFaces(mesh, reference, *unsampled);
        if (debug)
            std::fprintf(stderr, "v2: %zu border edges, %zu vertices with the input regions\n", borderEdges(),
                         std::size_t(mesh.number_of_vertices()));
        if (debug)
            std::fprintf(stderr, "v2: %zu intersecting pairs before the gap closing\n",
                         findDefects(mesh, false).pairs);
        // Measured on elephant: a second pass with a reach of 6 L (TwoPasses) made most of the intersections
        // the repair then removes (103 intersecting face pairs after the first pass, 589 after the second).
        GapCloser(mesh, 2.5 * L, 80.0, 10.0, &caster, 0.25 * L).run();
    } else {
        const RayCaster* onSurface = closed ? nullptr : &caster;
        GapCloser(mesh, 2.5 * L, 80.0, 10.0, onSurface, 0.25 * L).run();
        if (debug) std::fprintf(stderr, "v2: %zu border edges after pass 1\n", borderEdges());
        GapCloser(mesh, 6.0 * L, 85.0, 0.5, onSurface, 0.25 * L).run();
    }
    if (debug) std::fprintf(stderr, "v2: %zu border edges after the gap closing\n", borderEdges());
    pieces("after the gap closing");
    if (debug)
        std::fprintf(stderr, "v2: %zu intersecting pairs before the hole filling\n",
                     findDefects(mesh, false).pairs);
    // On an open reference only the cycles off its boundary (gaps between patches) are filled.
    fillJoinHoles(mesh, border);
    if (debug) std::fprintf(stderr, "v2: %zu border edges after the hole filling\n", borderEdges());
    repairDefects(mesh, border, closed, repairRounds, debug, false);
    mesh.collect_garbage();
    pieces("after the repair");
}

} // namespace fss::detail
