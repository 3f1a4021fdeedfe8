#include "remesh/crease_snapper.h"

#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace fss::detail::creases {

std::size_t CreaseSnapper::cornerSweep() {
    const std::vector<Vec>& corners = creases_.corners();
    if (corners.empty()) return 0;
    const double radius = 2 * o_.snapRadius * L_;
    // The corners in a uniform grid of cells of the radius: the vertices within the radius of a corner
    // lie in the 27 cells around their own.
    auto cellOf = [&](const Vec& p) {
        return std::array<std::int64_t, 3>{std::int64_t(std::floor(p.x() / radius)),
                                           std::int64_t(std::floor(p.y() / radius)),
                                           std::int64_t(std::floor(p.z() / radius))};
    };
    std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> grid;
    for (std::size_t i = 0; i < corners.size(); ++i)
        grid[cellOf(corners[i])].push_back(i);
    std::vector<std::vector<std::pair<double, VertexIndex>>> near(corners.size());
    std::vector<char> taken(corners.size(), 0);
    for (VertexIndex v : m_.vertices()) {
        const Vec p = pos(m_, v);
        const auto c = cellOf(p);
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
                    if (it == grid.end()) continue;
                    for (std::size_t i : it->second) {
                        const double d = (p - corners[i]).norm();
                        if (d < 1e-9 * L_)
                            taken[i] = 1;
                        else if (d < radius && !frozen_[v.idx()])
                            near[i].emplace_back(d, v);
                    }
                }
    }
    std::size_t snaps = 0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        if (taken[i] || near[i].empty()) continue;
        std::sort(near[i].begin(), near[i].end());
        if (near[i].size() > 3) near[i].resize(3);
        for (const auto& [d, v] : near[i])
            if (!m_.is_removed(v) && (pos(m_, v) - corners[i]).norm() < radius && moveVertex(v, corners[i])) {
                onCrease_[v.idx()] = 1;
                ++snaps;
                break;
            }
    }
    return snaps;
}

bool CreaseSnapper::moveVertex(VertexIndex v, const Vec& target) {
    const Vec p = pos(m_, v);
    std::vector<Tri> before, after;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
        const HalfedgeIndex n1 = m_.next(h);
        const Vec q = pos(m_, m_.target(n1)), r = pos(m_, m_.target(m_.next(n1)));
        before.push_back({p, q, r});
        after.push_back({target, q, r});
    }
    return better(before, after, true, 0.99) && place(v, target);
}

bool CreaseSnapper::place(VertexIndex v, const Vec& target) {
    const Point3 old = m_.point(v);
    m_.point(v) = Point3(target.x(), target.y(), target.z());
    if (!intersectsAround({v})) return true;
    m_.point(v) = old;
    return false;
}

std::size_t CreaseSnapper::removeSweep() {
    const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
    std::vector<VertexIndex> candidates;
    for (VertexIndex v : m_.vertices())
        if (!frozen_[v.idx()] && m_.degree(v) == 3) candidates.push_back(v);
    std::size_t removals = 0;
    for (VertexIndex v : candidates) {
        if (m_.is_removed(v) || m_.degree(v) != 3) continue;
        std::vector<Tri> before;
        std::vector<VertexIndex> ring;
        std::vector<FaceIndex> faces;
        bool mixed = false, tooSmall = false;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const HalfedgeIndex n1 = m_.next(h);
            before.push_back({pos(m_, v), pos(m_, m_.target(n1)), pos(m_, m_.target(m_.next(n1)))});
            ring.push_back(m_.source(h));
            faces.push_back(m_.face(h));
            mixed = mixed || isInput(faces.front()) != isInput(faces.back());
            tooSmall = tooSmall || m_.degree(m_.source(h)) <= 3;
        }
        if (mixed || tooSmall) continue;
        // The ring (v's neighbours around it, in order) becomes one face with v's faces' orientation.
        const Tri merged{pos(m_, ring[2]), pos(m_, ring[1]), pos(m_, ring[0])};
        if (!better(before, {merged}, false, 0.99, 0.02 * L_)) continue;
        std::int32_t oldIds[3] = {-1, -1, -1};
        float oldQuality[3] = {0.f, 0.f, 0.f};
        for (std::size_t i = 0; i < 3; ++i) {
            if (haveIds) oldIds[i] = ids[faces[i]];
            if (haveQuality) oldQuality[i] = quality[faces[i]];
        }
        const Point3 old = m_.point(v);
        const HalfedgeIndex hv = m_.halfedge(v);
        const HalfedgeIndex border = CGAL::Euler::remove_center_vertex(hv, m_);
        const FaceIndex f = m_.face(border);
        if (haveIds) ids[f] = oldIds[0];
        if (haveQuality) quality[f] = oldQuality[0];
        if (intersectsAround({ring[0], ring[1], ring[2]})) { // undo: the vertex back in the face
            const HalfedgeIndex hn = CGAL::Euler::add_center_vertex(border, m_);
            m_.point(m_.target(hn)) = old;
            // Each new face has the halfedge (ring[i] → v) of the old face faces[i].
            for (HalfedgeIndex h : CGAL::halfedges_around_target(hn, m_)) {
                const std::size_t i =
                    std::size_t(std::find(ring.begin(), ring.end(), m_.source(h)) - ring.begin());
                if (haveIds) ids[m_.face(h)] = oldIds[i];
                if (haveQuality) quality[m_.face(h)] = oldQuality[i];
            }
            continue;
        }
        ++removals;
    }
    return removals;
}

std::size_t CreaseSnapper::snapSweep() {
    struct Candidate {
        double distance;
        VertexIndex v;
        Vec target;
        bool crease; // the target is on a crease (else the closest reference point)
    };
    std::vector<Candidate> candidates;
    for (VertexIndex v : m_.vertices()) {
        if (frozen_[v.idx()] || onCrease_[v.idx()]) continue;
        Vec q;
        double d;
        if (!creases_.closest(pos(m_, v), q, d)) continue; // no crease near
        if (d < o_.snapRadius * L_) {
            if (d > 1e-9 * L_) candidates.push_back({d, v, q, true});
            continue;
        }
        // Farther from the crease but off the reference (the stitches' collapses leave a few vertices
        // inside a bevel): onto the closest reference point.
        const SurfacePoint sp = closest_(pos(m_, v));
        if (sp && sp.distance > 0.1 * L_) candidates.push_back({sp.distance, v, sp.point, false});
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
    std::size_t snaps = 0;
    for (const Candidate& c : candidates) {
        const VertexIndex v = c.v;
        bool crowded = false;
        for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
            crowded = crowded || (onCrease_[w.idx()] && (pos(m_, w) - c.target).norm() < o_.snapRadius * L_);
        if (crowded || !moveVertex(v, c.target)) continue;
        onCrease_[v.idx()] = c.crease;
        ++snaps;
    }
    return snaps;
}

} // namespace fss::detail::creases
