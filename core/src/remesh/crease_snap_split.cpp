#include "remesh/crease_snapper.h"

#include "mesh/local_ops.h"

#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>

namespace fss::detail::creases {

VertexIndex CreaseSnapper::mendedSplit(HalfedgeIndex h, const Vec& q, double gain) {
    const HalfedgeIndex o = m_.opposite(h);
    const VertexIndex a = m_.source(h), b = m_.target(h);
    const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
    const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
    const Before before = measure({{pa, pb, pc}, {pb, pa, pd}});
    if (!closeEnough(before, {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, gain))
        return Mesh::null_vertex();
    std::vector<VertexIndex> region = {a, b, c, d};
    const std::vector<Tri> regionBefore = facesAround(region);
    const Mesh saved = m_;
    const VertexIndex v = splitAt(h, q);
    if (v == Mesh::null_vertex()) return v;
    region.push_back(v);
    if (mendAround(v, region, regionBefore, gain * before.maxError)) return v;
    m_ = saved;
    return Mesh::null_vertex();
}

std::size_t CreaseSnapper::splitSweep() {
    std::vector<EdgeIndex> edges(m_.edges().begin(), m_.edges().end());
    std::size_t splits = 0;
    for (EdgeIndex e : edges) {
        if (m_.is_removed(e) || m_.is_border(e)) continue;
        const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
        // The crease point closest to the edge.
        double best = std::numeric_limits<double>::infinity(), along = 0;
        Vec q;
        for (int s : creases_.near(0.5 * (pa + pb))) {
            double u, t;
            closestSegmentParameters(pa, pb, creases_.a(s), creases_.b(s), u, t);
            const Vec x = pa + u * (pb - pa), y = creases_.a(s) + t * (creases_.b(s) - creases_.a(s));
            if ((x - y).norm() < best) best = (x - y).norm(), q = y, along = u;
        }
        // The edge passes the crease between its ends, at a bevel of a tenth to most of an edge length.
        if (!std::isfinite(best) || best < 0.1 * L_ || best > L_ || along <= 0.1 || along >= 0.9) continue;
        const double radius = o_.snapRadius * L_;
        if ((q - pa).norm() < radius || (q - pb).norm() < radius) continue;
        // Faces (a, b, c), (b, a, d) become (a, q, c), (q, b, c), (b, q, d), (q, a, d).
        const VertexIndex v = better({{pa, pb, pc}, {pb, pa, pd}},
                                     {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, false, 0.99)
                                  ? splitAt(h, q)
                                  : mendedSplit(h, q, 0.9);
        if (v == Mesh::null_vertex()) continue;
        onCrease_[v.idx()] = 1;
        ++splits;
    }
    return splits;
}

VertexIndex CreaseSnapper::splitAt(HalfedgeIndex h, const Vec& q) {
    const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
    const FaceIndex f = m_.face(h), g = m_.face(m_.opposite(h));
    const VertexIndex a = m_.source(h), b = m_.target(h);
    const std::int32_t idF = haveIds ? ids[f] : -1, idG = haveIds ? ids[g] : -1;
    const float qualityF = haveQuality ? quality[f] : 0.f, qualityG = haveQuality ? quality[g] : 0.f;
    const EdgeSplit split = splitEdge(m_, h, Point3(q.x(), q.y(), q.z()));
    const VertexIndex v = split.vertex;
    const HalfedgeIndex h3 = split.first, h4 = split.second;
    for (FaceIndex nf : {m_.face(h3), m_.face(m_.opposite(h3)), m_.face(h4), m_.face(m_.opposite(h4))}) {
        const bool sideF = nf == m_.face(h3) || nf == m_.face(m_.opposite(h3));
        if (haveIds) ids[nf] = sideF ? idF : idG;
        if (haveQuality) quality[nf] = sideF ? qualityF : qualityG;
    }
    if (intersectsAround({v, a, b})) {
        undoSplitEdge(m_, h, split);
        return Mesh::null_vertex();
    }
    frozen_.resize(m_.number_of_vertices() + m_.number_of_removed_vertices(), 0);
    onCrease_.resize(frozen_.size(), 0);
    frozen_[v.idx()] = 0;
    onCrease_[v.idx()] = 0;
    return v;
}

std::size_t CreaseSnapper::errorSplitSweep() {
    prefetchFaces();
    std::vector<FaceIndex> faces(m_.faces().begin(), m_.faces().end());
    std::size_t splits = 0;
    for (FaceIndex f : faces) {
        if (m_.is_removed(f)) continue;
        HalfedgeIndex h = m_.halfedge(f);
        const Tri t = triangle(f);
        const SurfacePoint sp = closest_((t.a + t.b + t.c) / 3.0);
        if (!sp || !far(t, sp.distance)) continue;
        for (HalfedgeIndex k : CGAL::halfedges_around_face(m_.halfedge(f), m_))
            if ((pos(m_, m_.source(k)) - pos(m_, m_.target(k))).squaredNorm() >
                (pos(m_, m_.source(h)) - pos(m_, m_.target(h))).squaredNorm())
                h = k;
        if (m_.is_border(m_.opposite(h))) continue;
        const HalfedgeIndex o = m_.opposite(h);
        const Vec pa = pos(m_, m_.source(h)), pb = pos(m_, m_.target(h));
        const Vec pc = pos(m_, m_.target(m_.next(h))), pd = pos(m_, m_.target(m_.next(o)));
        const Vec mid = 0.5 * (pa + pb);
        Vec q;
        double d;
        bool crease = creases_.closest(mid, q, d) && d < o_.snapRadius * L_;
        if (!crease) {
            const SurfacePoint sp = closest_(mid);
            if (!sp) continue;
            q = sp.point;
        }
        const VertexIndex v = better({{pa, pb, pc}, {pb, pa, pd}},
                                     {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, false, 0.99)
                                  ? splitAt(h, q)
                                  : mendedSplit(h, q, 0.8);
        if (v == Mesh::null_vertex()) continue;
        onCrease_[v.idx()] = crease;
        ++splits;
    }
    return splits;
}

std::size_t CreaseSnapper::flipSweep() {
    const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
    std::size_t flips = 0;
    for (EdgeIndex e : m_.edges()) {
        if (m_.is_border(e)) continue;
        const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
        if (isInput(m_.face(h)) != isInput(m_.face(o))) continue; // the scanned area stays
        if (!canFlip(m_, h)) continue;
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
        Vec q;
        double dist;
        if (!creases_.closest(0.25 * (pa + pb + pc + pd), q, dist) || dist > L_) continue;
        // Faces (a, b, c), (b, a, d) become (a, d, c), (d, b, c).
        if (!better({{pa, pb, pc}, {pb, pa, pd}}, {{pa, pd, pc}, {pd, pb, pc}}, false, 0.8, 0.02 * L_))
            continue;
        const FaceIndex f = m_.face(h), g = m_.face(o);
        const std::int32_t idF = haveIds ? ids[f] : -1, idG = haveIds ? ids[g] : -1;
        const float qualityF = haveQuality ? quality[f] : 0.f, qualityG = haveQuality ? quality[g] : 0.f;
        CGAL::Euler::flip_edge(h, m_);
        if (intersectsAround({a, b, c, d})) { // undo: the second flip rotates the edge back to (a, b)
            CGAL::Euler::flip_edge(h, m_);
            // The faces may have swapped sides: the one with corner c is (a, b, c) again.
            for (FaceIndex k : {m_.face(h), m_.face(m_.opposite(h))}) {
                bool hasC = false;
                for (VertexIndex w : CGAL::vertices_around_face(m_.halfedge(k), m_))
                    hasC = hasC || w == c;
                if (haveIds) ids[k] = hasC ? idF : idG;
                if (haveQuality) quality[k] = hasC ? qualityF : qualityG;
            }
            continue;
        }
        ++flips;
    }
    return flips;
}

} // namespace fss::detail::creases
