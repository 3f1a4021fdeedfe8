// auto v2 (issue 23, auto_remesh.h AutoEngine::V2): the regions of the partition are sampled once each with
// the triangular lattice and joined in one pass, so that the cost does not grow as views × stitch.
//
//  1. Views: auto v1's greedy Gauss-map plan (planViews) and its partition of the surface (partitionSurface,
//     most frontal unoccluded view, Potts-smoothed), plus views aimed at the faces no view owns (their mean
//     normal), after which the partition is recomputed with all views.
//  2. Each region is sampled with the triangular lattice (sampleLattice) at a world spacing chosen so that
//     every region gets the vertex density of a regular triangulation at the target edge length (a region
//     seen at a mean cos θ is sampled at L·sqrt(cos θ)); only the samples on the region's own faces are kept
//     (no margin), triangulated on the lattice. The regions are independent: they are sampled in parallel
//     (parallelItems) from buffers rendered beforehand on one thread, and merged in view order, so the
//     result is the same for any thread count.
//  3. One join: the patches are put into one mesh, with the faces of the reference no patch reaches (centroid
//     farther than L from every patch vertex: thin pieces the opening removed, regions whose patch failed,
//     faces no view sees) as a region of their own, left from the input (scan id -1; the coverage says how
//     much). The gaps between them (about one lattice spacing wide, along the partition borders) are closed
//     by an advancing front over the boundary edges, a zipper in the manner of Turk & Levoy's zippering of
//     range images: each boundary edge takes as third corner the boundary vertex in front of it that sees it
//     under the largest angle (the Delaunay choice), best triangles first, only faces whose centroid lies
//     within L/4 of the reference; Surface_mesh::add_face refuses whatever would make the mesh non-manifold.
//     On a closed reference CGAL's hole filling closes what is left (junctions of three regions).
//  4. Seam relaxation and crease recovery once, as v1 ends (seam_relax.h, crease_snap.h).
//  5. Validation (validateJoin): as many boundary loops and connected components as the reference, a vertex
//     count within 10 % of the target (else parts went unsampled), closed when the reference is, no pinched
//     vertex, no degenerate face, no self-intersection.
// FSS_AUTO_V2_DEBUG=1 in the environment prints the stages' figures to stderr. A result that fails is dropped
// and v1 runs instead (AutoResult::engineNote). The advancing front is our own: CGAL's hole filling works on
// one boundary cycle at a time, and the gaps between patches are one multiply-connected region bounded by
// many cycles.
#include "remesh/auto_v2.h"

#include "base/parallel_rows.h"
#include "remesh/crease_snap.h"
#include "remesh/seam_relax.h"

#include "fss/error.h"
#include "fss/mask_triangulate.h"
#include "fss/metrics.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/scan_workspace.h"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <queue>
#include <string>
#include <unordered_map>

namespace fss::detail {
namespace {
namespace v2 {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

Eigen::Vector3d at(const Mesh& m, VertexIndex v) {
    const Point3& p = m.point(v);
    return {p.x(), p.y(), p.z()};
}

Eigen::Vector3d faceNormal(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    const Eigen::Vector3d a = at(m, m.source(h)), b = at(m, m.target(h)), c = at(m, m.target(m.next(h)));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
}

double faceArea(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    const Eigen::Vector3d a = at(m, m.source(h)), b = at(m, m.target(h)), c = at(m, m.target(m.next(h)));
    return 0.5 * (b - a).cross(c - a).norm();
}

/// The lattice spacing is this fraction of the spacing that gives a regular triangulation's vertex density:
/// the join adds no vertex and the seam relaxation collapses a few (measured: fandisk, bunny00 4-6 % short
/// of the target at 1).
constexpr double kDensity = 0.97;

/// The patch of region \p view: the triangular lattice at \p spacing world units, only the samples on the
/// faces the view owns, triangulated.
Patch regionPatch(const Mesh& reference, const FrameBuffers& buffers, const std::vector<int>& owner, int view,
                  double spacing, std::string* debug = nullptr) {
    ScanOptions so;
    so.scanId = view;
    so.lattice = Lattice::Triangular;
    so.spacingWorld = spacing;
    so.minLatticeAngleDeg = 0; // the partition already gave each face its most frontal view
    ScanWorkspace workspace;
    SampleGrid grid = sampleLattice(buffers, reference, workspace, so);
    std::size_t hits = 0, admissible = 0, own = 0;
    for (Sample& s : grid.samples) {
        hits += s.hit;
        admissible += s.admissible;
        if (s.admissible && (s.face == Sample::kNoFace || owner[s.face] != view))
            s.admissible = s.valid = false;
        own += s.admissible;
    }
    MaskStages stages;
    // The opening (radius 1) removes single samples and one-sample spikes, which the join cannot close
    // cleanly (measured on elephant: without it 1168 intersecting face pairs after the join, 79 with it).
    stages.morphology = {.radius = 1, .dilateRadius = 1};
    stages.atQuality = stages.atMorphology = stages.atTriangulate = {};
    stages.nothingBetter = stages.nothingLeft = "The view owns no part of the surface.";
    MaskedPatch out = maskAndTriangulate(grid, stages, workspace);
    if (debug)
        *debug = "hits " + std::to_string(hits) + " admissible " + std::to_string(admissible) + " own " +
                 std::to_string(own) + " morph " + std::to_string(out.counts.afterMorphology) + " verts " +
                 std::to_string(out.patch.mesh.number_of_vertices()) + " long " +
                 std::to_string(out.patch.report.longEdges) + " graz " +
                 std::to_string(out.patch.report.grazing) + " back " +
                 std::to_string(out.patch.report.backFacing) + " flip " +
                 std::to_string(out.patch.report.flipped);
    return std::move(out.patch);
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
    const auto key = [reach](const Eigen::Vector3d& p) {
        const Eigen::Vector3i c((p / reach).array().floor().cast<int>());
        return (std::int64_t(c.x() & 0x1FFFFF) << 42) | (std::int64_t(c.y() & 0x1FFFFF) << 21) |
               std::int64_t(c.z() & 0x1FFFFF);
    };
    std::unordered_map<std::int64_t, std::vector<Eigen::Vector3d>> cells;
    for (const Patch& patch : patches)
        for (VertexIndex v : patch.mesh.vertices())
            cells[key(at(patch.mesh, v))].push_back(at(patch.mesh, v));
    std::vector<char> out(reference.number_of_faces() + reference.number_of_removed_faces(), 0);
    for (FaceIndex f : reference.faces()) {
        Eigen::Vector3d c(0, 0, 0);
        for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
            c += at(reference, v) / 3.0;
        bool near = false;
        for (int dx = -1; dx <= 1 && !near; ++dx)
            for (int dy = -1; dy <= 1 && !near; ++dy)
                for (int dz = -1; dz <= 1 && !near; ++dz) {
                    const auto it = cells.find(key(c + reach * Eigen::Vector3d(dx, dy, dz)));
                    if (it == cells.end()) continue;
                    for (const Eigen::Vector3d& p : it->second)
                        if ((p - c).squaredNorm() <= reach * reach) {
                            near = true;
                            break;
                        }
                }
        out[f.idx()] = !near;
    }
    return out;
}

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

/// The advancing front that closes the gaps between the patches of \p mesh (file comment, step 3): border
/// edges take the border vertex within \p reach of them that sees them under the largest angle, when the
/// new face turns by less than \p maxFoldDeg against the faces next to it and has no angle below
/// \p minAngleDeg; the roundest such faces (largest smallest angle) are added first, ears (faces closing two
/// border edges) before the others. Returns the number of faces added.
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
            const FaceIndex f = m_.add_face(u, w, c.p);
            if (f == Mesh::null_face()) continue;
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
};

/// Fills every boundary cycle of \p mesh left by the gap closing with CGAL's hole triangulation and
/// refinement; the new faces take the scan id and quality of a face next to them.
void fillHoles(Mesh& mesh) {
    auto ids = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    auto quality = mesh.add_property_map<FaceIndex, float>(props::faceQuality, 0.f).first;
    std::vector<HalfedgeIndex> cycles;
    CGAL::Polygon_mesh_processing::extract_boundary_cycles(mesh, std::back_inserter(cycles));
    for (HalfedgeIndex h : cycles) {
        if (!mesh.is_border(h)) continue;
        const FaceIndex next = mesh.face(mesh.opposite(h));
        std::vector<FaceIndex> added;
        std::vector<VertexIndex> newVertices;
        // Refined (vertices inserted at the edge length of the hole's border), so that the seam relaxation
        // can move the fill onto the reference (it projects zone vertices that lie off it).
        CGAL::Polygon_mesh_processing::triangulate_and_refine_hole(mesh, h, std::back_inserter(added),
                                                                   std::back_inserter(newVertices));
        for (FaceIndex f : added) {
            ids[f] = next != Mesh::null_face() ? ids[next] : 0;
            quality[f] = next != Mesh::null_face() ? quality[next] : 0.f;
        }
    }
}

/// Repairs what the gap closing left wrong: the faces that intersect another, are degenerate or touch a
/// pinched vertex (a vertex whose faces form several fans), with one ring of faces around them, are removed
/// and the holes (with those left open) are filled again (fillHoles); up to \p rounds times. Returns true
/// when the mesh is then free of all three (and closed when \p closed).
bool repairJoin(Mesh& mesh, bool closed, int rounds, bool debug) {
    namespace PMP = CGAL::Polygon_mesh_processing;
    for (int round = 0;; ++round) {
        std::vector<char> bad(mesh.number_of_faces() + mesh.number_of_removed_faces(), 0);
        std::size_t nBad = 0;
        std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
        PMP::self_intersections<CGAL::Parallel_if_available_tag>(faces(mesh), mesh,
                                                                 std::back_inserter(pairs));
        for (const auto& [f, g] : pairs)
            bad[f.idx()] = bad[g.idx()] = 1;
        for (FaceIndex f : mesh.faces())
            if (PMP::is_degenerate_triangle_face(f, mesh)) bad[f.idx()] = 1;
        std::vector<int> incoming(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);
        for (HalfedgeIndex h : mesh.halfedges())
            ++incoming[mesh.target(h).idx()];
        std::vector<char> pinched(incoming.size(), 0);
        for (VertexIndex v : mesh.vertices()) {
            int around = 0;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(v, mesh)) {
                (void)h;
                ++around;
            }
            pinched[v.idx()] = around != incoming[v.idx()];
        }
        std::size_t border = 0;
        for (HalfedgeIndex h : mesh.halfedges())
            border += mesh.is_border(h);
        // Faces at a pinched vertex, and (closed meshes) at a boundary the hole filling could not close: the
        // larger hole left by removing them is filled again.
        for (FaceIndex f : mesh.faces())
            for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
                if (pinched[mesh.target(h).idx()] || (closed && mesh.is_border(mesh.opposite(h))))
                    bad[f.idx()] = 1;
        for (char b : bad)
            nBad += b;
        if (debug)
            std::fprintf(stderr, "v2 repair %d: %zu intersecting pairs, %zu bad faces, %zu border edges\n",
                         round, pairs.size(), nBad, border);
        if (nBad == 0 && (!closed || border == 0)) return true;
        if (round == rounds) return false;
        // One ring of faces around the bad ones.
        std::vector<char> ring(incoming.size(), 0);
        for (FaceIndex f : mesh.faces())
            if (bad[f.idx()])
                for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
                    ring[v.idx()] = 1;
        std::vector<FaceIndex> remove;
        for (FaceIndex f : mesh.faces()) {
            bool near = bad[f.idx()];
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
        fillHoles(mesh);
    }
}

/// How joinRegions closes the gaps between the regions.
enum class JoinStyle {
    /// The faces of the reference no patch reaches are added as a region left from the input; one pass of
    /// the gap closing, every new face within L/4 of the reference (no face bridges the two sides of a thin
    /// part); on a closed reference CGAL's hole filling closes what is left.
    InputRegions,
    /// Session 15's join: two passes of the gap closing (the second with a reach of 6 L), faces kept near
    /// the reference only on an open one; the hole filling bridges the parts no patch reaches.
    TwoPasses,
};

/// Closes the gaps between the patches already in \p mesh (file comment, step 3) and repairs the result
/// (repairJoin). \p unsampled: the reference's faces to add as input faces (JoinStyle::InputRegions).
void joinRegions(Mesh& mesh, const Mesh& reference, const std::vector<char>* unsampled,
                 const RayCaster& caster, JoinStyle style, double L, bool closed, bool debug) {
    const auto borderEdges = [&] {
        std::size_t n = 0;
        for (HalfedgeIndex h : mesh.halfedges())
            n += mesh.is_border(h);
        return n;
    };
    if (style == JoinStyle::InputRegions) {
        if (unsampled) appendInputFaces(mesh, reference, *unsampled);
        if (debug)
            std::fprintf(stderr, "v2: %zu border edges, %zu vertices with the input regions\n", borderEdges(),
                         std::size_t(mesh.number_of_vertices()));
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
    if (closed) fillHoles(mesh);
    if (debug) std::fprintf(stderr, "v2: %zu border edges after the hole filling\n", borderEdges());
    repairJoin(mesh, closed, 4, debug);
    mesh.collect_garbage();
}

/// Faces of \p reference no view owns, in connected pieces (through edges), largest area first.
struct Unowned {
    std::vector<FaceIndex> faces;
    double area = 0;
    Eigen::Vector3d normalSum{0, 0, 0};
};

std::vector<Unowned> unownedPieces(const Mesh& reference, const std::vector<int>& owner) {
    std::vector<Unowned> out;
    std::vector<char> seen(owner.size(), 0);
    for (FaceIndex f : reference.faces()) {
        if (owner[f.idx()] >= 0 || seen[f.idx()]) continue;
        Unowned piece;
        std::vector<FaceIndex> stack{f};
        seen[f.idx()] = 1;
        while (!stack.empty()) {
            const FaceIndex g = stack.back();
            stack.pop_back();
            piece.faces.push_back(g);
            const double a = faceArea(reference, g);
            piece.area += a;
            piece.normalSum += a * faceNormal(reference, g);
            for (HalfedgeIndex h : CGAL::halfedges_around_face(reference.halfedge(g), reference)) {
                const FaceIndex o = reference.face(reference.opposite(h));
                if (o != Mesh::null_face() && owner[o.idx()] < 0 && !seen[o.idx()])
                    seen[o.idx()] = 1, stack.push_back(o);
            }
        }
        out.push_back(std::move(piece));
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const Unowned& a, const Unowned& b) { return a.area > b.area; });
    return out;
}

} // namespace v2
} // namespace

std::string validateJoin(const Mesh& mesh, const JoinTarget& target) {
    MetricsOptions mo;
    const Metrics m = computeMetrics(mesh, mo);
    if (mesh.number_of_faces() == 0) return "the joined mesh has no face";
    if (m.boundaryLoops != target.boundaryLoops)
        return "the joined mesh has " + std::to_string(m.boundaryLoops) + " boundary loops, the input " +
               std::to_string(target.boundaryLoops);
    if (m.components != target.components)
        return "the joined mesh has " + std::to_string(m.components) + " connected components, the input " +
               std::to_string(target.components);
    // Parts of the surface no region sampled are bridged by the hole filling: far fewer vertices than a
    // regular triangulation of the whole surface means parts of it were cut off.
    if (std::abs(double(m.vertices) - target.vertices) > 0.1 * target.vertices)
        return "the joined mesh has " + std::to_string(m.vertices) + " vertices against the " +
               std::to_string(std::llround(target.vertices)) +
               " of the target: parts of the surface were not sampled";
    if (target.closed && !m.closed)
        return "the joined mesh has " + std::to_string(m.boundaryEdges) + " boundary edges left";
    if (m.nonManifoldVertices > 0)
        return "the joined mesh has " + std::to_string(m.nonManifoldVertices) + " pinched vertices";
    if (m.degenerateFaces > 0)
        return "the joined mesh has " + std::to_string(m.degenerateFaces) + " degenerate faces";
    if (m.selfIntersections.value_or(0) > 0)
        return "the joined mesh intersects itself (" + std::to_string(*m.selfIntersections) + " face pairs)";
    return {};
}

AutoResult autoRemeshV2(const Mesh& reference, const AutoOptions& options, const Progress& progress) {
    using namespace v2;
    const auto start = Clock::now();
    AutoResult result;
    result.engineUsed = AutoEngine::V2;
    std::vector<Eigen::Vector3d> corners;
    for (FaceIndex f : reference.faces())
        result.area += faceArea(reference, f);
    if (!(result.area > 0)) throw InvalidInputError("The mesh to remesh has no area.");
    const Eigen::AlignedBox3d box = boundingBox(reference);
    for (int i = 0; i < 8; ++i)
        corners.push_back(box.corner(Eigen::AlignedBox3d::CornerType(i)));
    result.edgeLength = detail::targetEdgeLength(result.area, options, reference.number_of_vertices());
    const double L = result.edgeLength;
    // Pixels finer than the lattice: the ID buffer then places the lattice's samples and decides the
    // partition's visibility at a fraction of an edge length.
    const double footprint = 0.5 * L;
    bool closedInput = true;
    for (HalfedgeIndex h : reference.halfedges())
        if (reference.is_border(h)) closedInput = false;

    // 1. Views and the partition.
    progress.report(0.0, "plan");
    auto t = Clock::now();
    std::unique_ptr<MeshRenderer> renderer =
        options.renderer ? options.renderer() : std::make_unique<CpuMeshRenderer>();
    renderer->setMesh(reference);
    std::vector<FrameBuffers> buffers;
    for (const Eigen::Vector3d& d :
         planViews(reference, options.servedAngleDeg, options.minViewAreaFraction, options.maxViews)) {
        progress.report(0.05, "plan");
        buffers.push_back(renderer->render(frameParallelView(d, corners, footprint, 2 * L)));
    }
    const double beta = options.partitionSmoothing * L, minIsland = options.minRegionArea * L * L;
    std::vector<int> owner =
        partitionSurface(reference, buffers, options.maxSamplingAngleDeg, beta, minIsland, 30);
    for (int round = 0; round < 2 && int(buffers.size()) < options.maxViews; ++round) {
        const std::vector<Unowned> pieces = unownedPieces(reference, owner);
        std::size_t added = 0;
        for (const Unowned& piece : pieces) {
            if (piece.area < 0.5 * L * L || int(buffers.size()) >= options.maxViews || added >= 12) break;
            if (piece.normalSum.norm() < 1e-3 * piece.area) continue;
            std::vector<Eigen::Vector3d> pts;
            for (FaceIndex f : piece.faces)
                for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
                    pts.push_back(at(reference, v));
            progress.report(0.1, "plan");
            buffers.push_back(
                renderer->render(frameParallelView(piece.normalSum.normalized(), pts, footprint, 4 * L)));
            ++added;
        }
        if (added == 0) break;
        owner =
            partitionSurface(reference, buffers, options.followUpMaxSamplingAngleDeg, beta, minIsland, 30);
    }
    result.planSeconds = since(t);

    // 2. The regions, sampled in parallel. Spacing per region: the vertex density of a regular
    // triangulation at L on the surface (a lattice cell seen at angle θ covers 1/cos θ of its screen area).
    t = Clock::now();
    const std::size_t nv = buffers.size();
    std::vector<double> cosArea(nv, 0), regionArea(nv, 0);
    for (FaceIndex f : reference.faces()) {
        const int o = owner[f.idx()];
        if (o < 0) continue;
        const double a = faceArea(reference, f);
        regionArea[std::size_t(o)] += a;
        cosArea[std::size_t(o)] +=
            a * std::max(0.0, -faceNormal(reference, f).dot(buffers[std::size_t(o)].camera.viewDirection()));
    }
    std::vector<Patch> patches(nv);
    std::vector<std::string> notes(nv), dbg(nv);
    progress.report(0.2, "scan");
    parallelItems(nv, 1, [&](std::size_t i) {
        if (regionArea[i] <= 0) {
            notes[i] = "The view owns no part of the surface.";
            return;
        }
        const double c = std::clamp(cosArea[i] / regionArea[i], 0.5, 1.0);
        try {
            patches[i] =
                regionPatch(reference, buffers[i], owner, int(i), kDensity * L * std::sqrt(c), &dbg[i]);
        } catch (const Error& e) {
            notes[i] = e.what();
        }
    });
    result.scanSeconds = since(t);
    if (std::getenv("FSS_AUTO_V2_DEBUG"))
        for (std::size_t i = 0; i < nv; ++i)
            std::fprintf(stderr, "v2 region %zu: area %.4f expected %.0f verts, cos %.2f: %s\n", i,
                         regionArea[i], regionArea[i] / (std::sqrt(3.0) / 2 * L * L),
                         regionArea[i] > 0 ? cosArea[i] / regionArea[i] : 0.0, dbg[i].c_str());

    // 3. One join.
    progress.report(0.5, "join");
    t = Clock::now();
    Mesh current;
    for (std::size_t i = 0; i < nv; ++i) {
        AutoStep step;
        step.kind = AutoStep::Kind::Initial;
        step.camera = buffers[i].camera;
        step.scanId = std::int32_t(i);
        step.patchFaces = patches[i].mesh.number_of_faces();
        step.facesAdded = step.patchFaces;
        step.stitched = step.patchFaces > 0;
        step.note = notes[i];
        if (step.stitched) appendPatch(current, patches[i].mesh);
        (step.stitched ? result.scansStitched : result.scansSkipped)++;
        result.steps.push_back(std::move(step));
    }
    if (current.number_of_faces() == 0) throw InvalidInputError("No view of auto v2 sees the surface.");
    const bool debug = std::getenv("FSS_AUTO_V2_DEBUG") != nullptr;
    // Two ways to join; the first whose result passes validateJoin is kept (else the first): the faces no
    // region sampled kept as a region of their own, joined in one pass (JoinStyle::InputRegions), then
    // session 15's join (JoinStyle::TwoPasses), which bridges those parts with the hole filling.
    const std::vector<char> unsampled = unsampledFaces(reference, patches, L);
    patches.clear();
    const RayCaster caster(reference);
    MetricsOptions referenceTopology;
    referenceTopology.selfIntersections = false;
    const Metrics referenceMetrics = computeMetrics(reference, referenceTopology);
    const JoinTarget target{.closed = closedInput,
                            .components = referenceMetrics.components,
                            .boundaryLoops = referenceMetrics.boundaryLoops,
                            .vertices = result.area / (std::sqrt(3.0) / 2.0 * L * L)};
    {
        Mesh joined = current;
        joinRegions(joined, reference, &unsampled, caster, JoinStyle::InputRegions, L, closedInput, debug);
        std::string why = validateJoin(joined, target);
        if (debug)
            std::fprintf(stderr, "v2: join with input regions: %s\n", why.empty() ? "valid" : why.c_str());
        if (why.empty()) {
            current = std::move(joined);
        } else {
            joinRegions(current, reference, nullptr, caster, JoinStyle::TwoPasses, L, closedInput, debug);
            const std::string other = validateJoin(current, target);
            if (debug)
                std::fprintf(stderr, "v2: join in two passes: %s\n", other.empty() ? "valid" : other.c_str());
            if (!other.empty()) current = std::move(joined);
        }
    }
    if (debug)
        std::fprintf(stderr, "v2: join %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));
    result.stitchSeconds = result.joinSeconds = since(t);

    // 4. Seam relaxation and crease recovery, once.
    progress.report(0.7, "relax");
    t = Clock::now();
    auto relax = [&] {
        if (options.seamRelaxRounds <= 0) return;
        const auto t0 = Clock::now();
        SeamRelaxOptions ro;
        ro.rounds = options.seamRelaxRounds;
        ro.edgeLength = L;
        ro.minAngleDeg = options.seamRelaxMinAngleDeg;
        ro.maxNormalChangeDeg = options.stitch.maxNormalChangeDeg;
        ro.featureAngleDeg = options.featureAngleDeg;
        ro.collapses = options.seamRelaxCollapses;
        const SeamRelaxReport rr = relaxSeams(current, reference, ro);
        result.seamFlips += rr.flips;
        result.seamCollapses += rr.collapses;
        result.seamMoves += rr.moves;
        result.seamRelaxDiscarded = result.seamRelaxDiscarded || rr.reverted;
        result.relaxSeconds += since(t0);
    };
    if (options.flipSliversBelowDeg > 0)
        result.sliverFlips = flipSliverFaces(current, options.flipSliversBelowDeg, 20.0, 8);
    result.relaxSeconds = since(t);
    relax();
    if (debug)
        std::fprintf(stderr, "v2: relax %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));
    if (options.creaseSnapRounds > 0) {
        const auto t0 = Clock::now();
        CreaseSnapOptions co;
        co.edgeLength = L;
        co.creaseAngleDeg = options.featureAngleDeg;
        co.minAngleDeg = options.stitch.minAngleFloorDeg;
        co.rounds = options.creaseSnapRounds;
        const CreaseSnapReport cr = snapToCreases(current, reference, co);
        result.creaseSnaps = cr.snaps;
        result.creaseSplits = cr.splits;
        result.creaseFlips = cr.flips;
        result.creaseRemovals = cr.removals;
        result.creaseRepairs = cr.repairs;
        result.creaseSeconds = since(t0);
        if (cr.snaps + cr.splits + cr.flips + cr.removals + cr.repairs > 0) relax();
        if (auto [onCrease, have] = current.property_map<VertexIndex, bool>(kOnCreaseProperty); have)
            current.remove_property_map(onCrease);
    }
    result.stitchSeconds += since(t);
    if (debug)
        std::fprintf(stderr, "v2: relax + creases %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));

    // 5. Validation; v1 when it fails.
    progress.report(0.95, "validate");
    t = Clock::now();
    const std::string why = validateJoin(current, target);
    if (debug) std::fprintf(stderr, "v2: validation %.2f s\n", since(t));
    if (!why.empty() && !options.fallbackToV1) {
        result.engineNote = "auto v2 failed (" + why + ").";
    } else if (!why.empty()) {
        AutoOptions o1 = options;
        o1.engine = AutoEngine::V1;
        AutoResult r = autoRemesh(reference, o1, progress);
        r.engineNote = "auto v2 failed (" + why + "); auto v1 ran instead.";
        r.seconds = since(start);
        return r;
    }
    // Coverage: the share of the reference's area in regions whose patch was made (sampled by a view); the
    // rest is bridged by the join (no face is left from the input in v2).
    {
        const auto [ids, haveIds] = current.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        double scanned = 0, total = 0;
        for (FaceIndex f : current.faces()) {
            const double a = faceArea(current, f);
            total += a;
            if (haveIds && ids[f] >= 0)
                scanned += a;
            else
                ++result.inputFacesLeft;
        }
        // The faces no patch reached are either left from the input (JoinStyle::InputRegions) or bridged by
        // the hole filling (TwoPasses, whose new faces take a neighbour's scan id): not sampled either way.
        double unsampledArea = 0;
        for (FaceIndex f : reference.faces())
            if (unsampled[f.idx()]) unsampledArea += faceArea(reference, f);
        result.coverage = std::min(total > 0 ? scanned / total : 0.0, 1.0 - unsampledArea / result.area);
        result.inputAreaLeft = total - scanned;
    }
    for (AutoStep& s : result.steps)
        s.coverageAfter = result.coverage;
    progress.report(1.0, "done");
    result.mesh = std::move(current);
    result.seconds = since(start);
    return result;
}

} // namespace fss::detail
