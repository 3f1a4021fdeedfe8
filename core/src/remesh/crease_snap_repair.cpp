#include "remesh/crease_snapper.h"

#include "mesh/local_ops.h"

#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>

namespace fss::detail::creases {

template <typename Op> bool CreaseSnapper::applyOrUndo(Op op, std::initializer_list<VertexIndex> around) {
    const Mesh saved = m_;
    const std::vector<char> frozen = frozen_, onCrease = onCrease_;
    op();
    if (!intersectsAround(around)) return true;
    m_ = saved;
    frozen_ = frozen;
    onCrease_ = onCrease;
    return false;
}

std::size_t CreaseSnapper::shortCreaseEdgeSweep() {
    std::vector<EdgeIndex> edges;
    for (EdgeIndex e : m_.edges()) {
        const HalfedgeIndex h = m_.halfedge(e);
        if (onACrease(m_.source(h)) && onACrease(m_.target(h)) &&
            (pos(m_, m_.source(h)) - pos(m_, m_.target(h))).norm() < L_ / 3)
            edges.push_back(e);
    }
    std::size_t collapses = 0;
    for (EdgeIndex e : edges)
        if (!m_.is_removed(e) && tryCollapse(m_.halfedge(e), 1.0)) ++collapses;
    return collapses;
}

std::size_t CreaseSnapper::repairSweep() {
    // Turned over: the gain 1 (no farther from the reference); far from it (only faces near a crease,
    // where the scans leave such faces): the gain 0.8.
    auto bad = [&](FaceIndex f) {
        const Tri t = triangle(f);
        const SurfacePoint sp = closest_((t.a + t.b + t.c) / 3.0);
        if (!sp) return 0.0;
        const Vec n = unitNormal(t.a, t.b, t.c);
        if (n.isZero() || n.dot(referenceNormalOf(sp.face)) < 0) return 1.0;
        return far(t, sp.distance) ? 0.8 : 0.0;
    };
    prefetchFaces();
    std::vector<FaceIndex> folded;
    for (FaceIndex f : m_.faces())
        if (bad(f) > 0) folded.push_back(f);
    std::size_t repaired = 0;
    for (FaceIndex f : folded) {
        if (m_.is_removed(f)) continue;
        const double gain = bad(f);
        if (gain == 0) continue;
        // The three edges, taken before any of them changes the face.
        const HalfedgeIndex h0 = m_.halfedge(f);
        const std::array<HalfedgeIndex, 3> edges = {h0, m_.next(h0), m_.prev(h0)};
        bool done = false;
        for (std::size_t i = 0; i < 3 && !done; ++i)
            done = tryFlip(edges[i], gain);
        for (std::size_t i = 0; i < 3 && !done; ++i)
            done = tryMoveToCrease(m_.target(edges[i]), gain);
        for (std::size_t i = 0; i < 3 && !done; ++i)
            done = tryCollapse(edges[i], gain);
        repaired += done;
    }
    return repaired;
}

bool CreaseSnapper::tryFlip(HalfedgeIndex h, double gain) {
    const HalfedgeIndex o = m_.opposite(h);
    if (m_.is_border(m_.edge(h)) || !sameKind(h) || !canFlip(m_, h)) return false;
    const VertexIndex a = m_.source(h), b = m_.target(h);
    const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
    const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
    if (!repairs(measure({{pa, pb, pc}, {pb, pa, pd}}), {{pa, pd, pc}, {pd, pb, pc}}, gain)) return false;
    return applyOrUndo([&] { CGAL::Euler::flip_edge(h, m_); }, {a, b, c, d});
}

bool CreaseSnapper::tryMoveToCrease(VertexIndex v, double gain) {
    if (frozen_[v.idx()] || onCrease_[v.idx()]) return false;
    Vec q;
    double dist;
    if (!creases_.closest(pos(m_, v), q, dist) || dist > L_) return false;
    for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
        if (onCrease_[w.idx()] && (pos(m_, w) - q).norm() < o_.snapRadius * L_) return false; // crowded
    const Vec p = pos(m_, v);
    std::vector<Tri> before, moved;
    std::vector<HalfedgeIndex> caps; // the edges opposite v in the faces with an angle above 160° at q
    for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
        const HalfedgeIndex opposite = m_.prev(h); // from target(next(h)) to source(h)
        const Vec x = pos(m_, m_.source(opposite)), y = pos(m_, m_.target(opposite));
        before.push_back({p, x, y});
        moved.push_back({q, x, y});
        if (angleBetween(x - q, y - q) > 160.0 * std::numbers::pi / 180.0) caps.push_back(opposite);
    }
    const Before measured = measure(before);
    if (caps.empty() && repairs(measured, moved, gain)) { // the move alone
        if (!place(v, q)) return false;
        onCrease_[v.idx()] = 1;
        return true;
    }
    // The move alone does not repair: with the caps flipped, then edges around v flipped where that
    // raises the smaller angle of their two faces (the edges opposite v, the edges from v), it may. Only
    // worth trying when the move brings the faces close enough and turns none over (its angles are what
    // the flips mend). The faces compared are those around v and its neighbours, before and after.
    if (!caps.empty() || closeEnough(measured, moved, gain)) {
        std::vector<VertexIndex> region{v};
        for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
            region.push_back(w);
        const std::vector<Tri> regionBefore = facesAround(region);
        const Mesh saved = m_;
        auto restore = [&] {
            m_ = saved;
            return false;
        };
        m_.point(v) = Point3(q.x(), q.y(), q.z());
        for (HalfedgeIndex c : caps)
            if (!flipIfValid(c)) return restore();
        if (!mendAround(v, region, regionBefore, gain * measured.maxError)) return restore();
        onCrease_[v.idx()] = 1;
        return true;
    }
    return false;
}

bool CreaseSnapper::mendAround(VertexIndex v, const std::vector<VertexIndex>& region,
                               const std::vector<Tri>& regionBefore, double maxError) {
    for (int flips = 0; flips < 8; ++flips) {
        HalfedgeIndex best;
        double bestGain = 1e-3;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_))
            for (HalfedgeIndex c : {m_.prev(h), h}) {
                const double g = flipAngleGain(c);
                if (g > bestGain) bestGain = g, best = c;
            }
        if (best == Mesh::null_halfedge() || !flipIfValid(best)) break;
    }
    Before limits = measure(regionBefore);
    limits.maxError = maxError;
    return repairs(limits, facesAround(region), 1.0) && !intersectsAround({v});
}

double CreaseSnapper::flipAngleGain(HalfedgeIndex c) const {
    const HalfedgeIndex o = m_.opposite(c);
    if (m_.is_border(m_.edge(c))) return 0;
    const Vec x = pos(m_, m_.source(c)), y = pos(m_, m_.target(c));
    const Vec a = pos(m_, m_.target(m_.next(c))), b = pos(m_, m_.target(m_.next(o)));
    // Faces (x, y, a), (y, x, b) become (x, b, a), (b, y, a).
    if (unitNormal(x, b, a).dot(unitNormal(b, y, a)) < 0.5) return 0;
    return std::min(minAngle(x, b, a), minAngle(b, y, a)) - std::min(minAngle(x, y, a), minAngle(y, x, b));
}

bool CreaseSnapper::flipIfValid(HalfedgeIndex c) {
    if (m_.is_border(m_.edge(c)) || !sameKind(c) || !canFlip(m_, c)) return false;
    CGAL::Euler::flip_edge(c, m_);
    return true;
}

bool CreaseSnapper::tryCollapse(HalfedgeIndex h, double gain) {
    const HalfedgeIndex o = m_.opposite(h);
    const EdgeIndex e = m_.edge(h);
    if (m_.is_border(e) || !sameKind(h)) return false;
    const VertexIndex a = m_.source(h), b = m_.target(h);
    const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
    if (frozen_[a.idx()] || frozen_[b.idx()]) return false;
    const bool onA = onACrease(a), onB = onACrease(b);
    if (!canCollapse(m_, e)) return false;
    const Vec pa = pos(m_, a), pb = pos(m_, b);
    // Where the merged vertex goes, and whether that is on a crease.
    std::vector<std::pair<Vec, bool>> targets;
    if (onA && onB)
        targets = {{pa, true}, {pb, true}};
    else if (onA)
        targets = {{pa, true}};
    else if (onB)
        targets = {{pb, true}};
    else {
        targets = {{pa, false}, {pb, false}};
        Vec q;
        double dist;
        const Vec mid = 0.5 * (pa + pb);
        if (creases_.closest(mid, q, dist) && dist < L_) targets.emplace_back(q, true);
        if (const SurfacePoint sp = closest_(mid)) targets.emplace_back(sp.point, false);
    }
    std::vector<Tri> before;
    std::vector<std::array<VertexIndex, 3>> ring; // the faces that stay, by their corners
    for (VertexIndex v : {a, b})
        for (FaceIndex g : CGAL::faces_around_target(m_.halfedge(v), m_)) {
            if (g == m_.face(h) || g == m_.face(o)) continue;
            if (isInput(g) != isInput(m_.face(h))) return false; // a border of the scanned area would move
            const HalfedgeIndex k = m_.halfedge(g);
            ring.push_back({m_.source(k), m_.target(k), m_.target(m_.next(k))});
            before.push_back(triangle(g));
        }
    for (FaceIndex g : {m_.face(h), m_.face(o)})
        before.push_back(triangle(g));
    const Before measured = measure(before);
    // The targets that repair, the one with the largest smallest angle first.
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t i = 0; i < targets.size(); ++i) {
        std::vector<Tri> after;
        double smallest = std::numbers::pi;
        for (const auto& r : ring) {
            Vec corner[3];
            for (int k = 0; k < 3; ++k)
                corner[k] = r[std::size_t(k)] == a || r[std::size_t(k)] == b ? targets[i].first
                                                                             : pos(m_, r[std::size_t(k)]);
            after.push_back({corner[0], corner[1], corner[2]});
            smallest = std::min(smallest, minAngle(corner[0], corner[1], corner[2]));
        }
        if (repairs(measured, after, gain)) order.emplace_back(-smallest, i);
    }
    std::sort(order.begin(), order.end());
    for (const auto& [negAngle, i] : order) {
        const auto& [t, marked] = targets[i];
        if (applyOrUndo(
                [&] {
                    const VertexIndex kept = CGAL::Euler::collapse_edge(e, m_);
                    m_.point(kept) = Point3(t.x(), t.y(), t.z());
                    onCrease_[kept.idx()] = marked;
                },
                {c, d}))
            return true;
    }
    return false;
}

} // namespace fss::detail::creases
