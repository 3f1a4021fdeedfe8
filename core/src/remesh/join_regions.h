#pragma once
// Internal (not installed): the one-pass join of auto v2 (auto_v2.cpp, step 3) and the flood fill over faces
// that auto v1's follow-up views and auto v2's extra views share.
#include "fss/mesh.h"
#include "fss/raycast.h"
#include "fss/scan.h"

#include <CGAL/boost/graph/iterator.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace fss::detail {

/// A vertex's position as an Eigen vector (auto v2 and its join).
inline Eigen::Vector3d at(const Mesh& m, VertexIndex v) {
    const Point3& p = m.point(v);
    return {p.x(), p.y(), p.z()};
}

/// Points in a uniform grid of cell \p reach: which lie within \p reach of a query point.
class PointGrid {
public:
    explicit PointGrid(double reach) : reach_(reach) {}
    void add(const Eigen::Vector3d& p) { cells_[key(p)].push_back(p); }
    bool near(const Eigen::Vector3d& c) const {
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const auto it = cells_.find(key(c + reach_ * Eigen::Vector3d(dx, dy, dz)));
                    if (it == cells_.end()) continue;
                    for (const Eigen::Vector3d& p : it->second)
                        if ((p - c).squaredNorm() <= reach_ * reach_) return true;
                }
        return false;
    }

private:
    std::int64_t key(const Eigen::Vector3d& p) const {
        const Eigen::Vector3i c((p / reach_).array().floor().cast<int>());
        return (std::int64_t(c.x() & 0x1FFFFF) << 42) | (std::int64_t(c.y() & 0x1FFFFF) << 21) |
               std::int64_t(c.z() & 0x1FFFFF);
    }
    double reach_;
    std::unordered_map<std::int64_t, std::vector<Eigen::Vector3d>> cells_;
};

/// The unit normal of face \p f (zero for a degenerate face).
inline Eigen::Vector3d faceNormal(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    const Eigen::Vector3d a = at(m, m.source(h)), b = at(m, m.target(h)), c = at(m, m.target(m.next(h)));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
}

/// The area of face \p f.
inline double faceArea(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    const Eigen::Vector3d a = at(m, m.source(h)), b = at(m, m.target(h)), c = at(m, m.target(m.next(h)));
    return 0.5 * (b - a).cross(c - a).norm();
}

/// The connected pieces (through edges) of the faces of \p mesh for which \p member(f) is true, in the order
/// of mesh.faces() of their first face; each piece's faces in the order a depth-first fill reaches them.
template <class Member>
std::vector<std::vector<FaceIndex>> faceComponents(const Mesh& mesh, Member&& member) {
    std::vector<std::vector<FaceIndex>> out;
    std::vector<char> seen(mesh.number_of_faces() + mesh.number_of_removed_faces(), 0);
    for (FaceIndex f : mesh.faces()) {
        if (seen[f.idx()] || !member(f)) continue;
        std::vector<FaceIndex> piece;
        std::vector<FaceIndex> stack{f};
        seen[f.idx()] = 1;
        while (!stack.empty()) {
            const FaceIndex g = stack.back();
            stack.pop_back();
            piece.push_back(g);
            for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(g), mesh)) {
                const FaceIndex o = mesh.face(mesh.opposite(h));
                if (o != Mesh::null_face() && !seen[o.idx()] && member(o))
                    seen[o.idx()] = 1, stack.push_back(o);
            }
        }
        out.push_back(std::move(piece));
    }
    return out;
}

/// The simple loops of the boundary cycle \p cycle (its vertices in order) that passes some vertices more
/// than once (a pinched cycle, where two fans of faces meet at one vertex): cut at each repeated vertex,
/// every loop in the cycle's order, loops of fewer than three vertices left out. The hole filling fills a
/// pinched cycle loop by loop: CGAL's hole triangulation returns no face for it.
std::vector<std::vector<VertexIndex>> pinchedCycleLoops(const std::vector<VertexIndex>& cycle);

/// Adds the faces of \p patch to \p out (scan id and quality kept).
void appendPatch(Mesh& out, const Mesh& patch);

/// Flags the faces of \p reference whose centroid lies farther than \p reach from every vertex of \p patches:
/// the parts of the surface no region sampled (thin pieces the opening removed, regions whose patch failed,
/// faces no view sees).
std::vector<char> unsampledFaces(const Mesh& reference, const std::vector<Patch>& patches, double reach);

/// The boundary of an open reference, sampled: a boundary cycle of the join that runs along it is the
/// reference's own border, which the hole filling leaves open (none on a closed reference).
struct ReferenceBorder {
    std::vector<Eigen::Vector3d> samples; ///< points on the reference's boundary edges, at most reach/2 apart
    double reach = 0;                     ///< a join edge whose midpoint lies this close is on the border
};

/// The samples of \p reference's boundary edges for ReferenceBorder with \p reach.
ReferenceBorder referenceBorder(const Mesh& reference, double reach);

/// Whether the boundary cycle of \p mesh through border halfedge \p h runs along \p border: at least half
/// of its edges have their midpoint within border.reach of it.
bool cycleOnBorder(const Mesh& mesh, HalfedgeIndex h, const ReferenceBorder& border);

/// Fills every boundary cycle of \p mesh that does not run along \p border (cycleOnBorder) with CGAL's hole
/// triangulation and refinement (a pinched cycle loop by loop, pinchedCycleLoops); the new faces take the
/// scan id and quality of a face next to them.
/// With \p closeInlets, a cycle along the border has its inlets closed (closeBorderInlets: a gap between two
/// patches that reaches the border); off in the join (measured on blade: it cost a border loop).
void fillJoinHoles(Mesh& mesh, const ReferenceBorder& border, bool closeInlets = false);

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

/// Closes the gaps between the patches already in \p mesh (auto_v2.cpp, step 3) and repairs the result: the
/// faces that intersect another, are degenerate, touch a pinched vertex or (\p closed) an unclosed boundary
/// are removed with a ring around them and the holes filled again, up to \p repairRounds times.
/// \p unsampled: the reference's faces to add as input faces (JoinStyle::InputRegions).
/// \p border: the reference's boundary (its cycles stay open; empty when the reference is closed).
void joinRegions(Mesh& mesh, const Mesh& reference, const std::vector<char>* unsampled,
                 const RayCaster& caster, const ReferenceBorder& border, JoinStyle style, double L,
                 bool closed, bool debug, int repairRounds);

/// Repairs what the join left wrong: the faces that intersect another, are degenerate, touch a pinched vertex
/// (on an open reference also one with two boundary fans, where two gaps meet)
/// or (\p closed) an unclosed boundary are removed with a ring of faces around them and the holes filled
/// again, up to \p rounds times. Returns true when none is left.
bool repairJoin(Mesh& mesh, const ReferenceBorder& border, bool closed, int rounds, bool debug);

/// Removes the smallest connected pieces of \p mesh of at most \p maxFaces faces while it has more than
/// \p components pieces (an input face no patch reached, closed on itself by the hole filling); returns how
/// many were removed.
std::size_t dropSmallPieces(Mesh& mesh, std::size_t components, std::size_t maxFaces);

/// Flags in \p inputFaces the faces of \p reference whose centroid lies within \p reach of a face the join
/// \p joined left wrong (as joinRegions' repair finds them); returns how many were flagged.
std::size_t widenInputRegions(const Mesh& reference, const Mesh& joined, bool closed, double reach,
                              std::vector<char>& inputFaces);

/// Flags in \p inputFaces the faces of \p reference whose centroid lies farther than \p reach from \p joined
/// (parts of the input the join does not cover); returns how many were flagged.
std::size_t flagUncoveredFaces(const Mesh& reference, const Mesh& joined, double reach,
                               std::vector<char>& inputFaces);

/// Removes from \p mesh the faces with a vertex within \p reach of the centroid of a face of \p reference
/// flagged in \p faces (so that those faces are as far from the patches as unsampledFaces' are).
void removePatchFacesNear(Mesh& mesh, const Mesh& reference, const std::vector<char>& faces, double reach);

} // namespace fss::detail
