// Stitch v2, design B: the band's creases as polylines of the draft, and the operations on crease vertices
// that use them (band_remesher.h): splits of crease edges and slides of crease vertices put the vertex on
// the draft's crease line (the crease of the surface the band is remeshed on), not on a chord of it, so
// crease vertices may move along curved creases too; and the repair split of faces below the aim whose
// corners cannot move (faces between two creases or at a crease corner, DESIGN.md §6.2).
#include "stitch/band_remesher.h"

namespace fss::stitch::band {

bool BandRemesher::isCap(FaceIndex f) const {
    for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
        const V3 p = detail::pos(S_, S_.target(h));
        if (detail::angleBetween(detail::pos(S_, S_.source(h)) - p,
                                 detail::pos(S_, S_.target(S_.next(h))) - p) > 120.0 * kBandDeg)
            return true;
    }
    return false;
}

void BandRemesher::findCreases() {
    // Band edges between band faces whose normals differ by more than the crease angle, with two filters
    // against false creases (finely cut curved surfaces, where one tilted face or a short stub of a crease
    // would pin vertices that the band needs to move, DESIGN.md §6.2):
    //  - a face whose normal differs by more than the crease angle from every band neighbour with a known
    //    normal (at least two), or (a cap below the split floor: an angle above 120 deg) from at least two
    //    of them while they agree with each other (pairwise within the crease angle: one smooth surface
    //    around a tilted cap, a fold the cut left: its two tilted edges would make a crease turning back on
    //    itself that pins the cap's apex), is an outlier, not a feature: its normal counts as unknown;
    //  - a crease edge that hangs off a crease (one end on no other crease edge, the other on two or more)
    //    or stands alone is dropped unless its dihedral angle is at least twice the crease angle.
    const double creaseCos = std::cos(in_.creaseAngleDeg * kBandDeg);
    std::unordered_map<std::uint32_t, V3> normal;
    auto creaseNormal = [&](FaceIndex f) -> V3 {
        auto [it, fresh] = normal.try_emplace(std::uint32_t(f), V3(0, 0, 0));
        if (!fresh) return it->second;
        if (in_.creaseNormal) {
            it->second = in_.creaseNormal(f);
        } else {
            const HalfedgeIndex h = S_.halfedge(f);
            const V3 a = detail::pos(S_, S_.source(h)), b = detail::pos(S_, S_.target(h)),
                     c = detail::pos(S_, S_.target(S_.next(h)));
            if (detail::minAngle(a, b, c) >= kSliverDeg * kBandDeg) it->second = detail::unitNormal(a, b, c);
        }
        return it->second;
    };
    const bool filter = !stageOff("creasefilter");
    std::vector<FaceIndex> outliers;
    for (FaceIndex f : bandList_) {
        const V3 n = creaseNormal(f);
        if (!filter || !(n.squaredNorm() > 0)) continue;
        int known = 0, apart = 0;
        std::array<V3, 3> around;
        for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
            if (!interiorEdge(h)) continue;
            const V3 m = creaseNormal(S_.face(S_.opposite(h)));
            if (!(m.squaredNorm() > 0)) continue;
            around[std::size_t(known++)] = m;
            apart += n.dot(m) < creaseCos;
        }
        bool agree = true;
        for (int i = 0; i < known; ++i)
            for (int j = i + 1; j < known; ++j)
                agree = agree && around[std::size_t(i)].dot(around[std::size_t(j)]) >= creaseCos;
        const bool tilted = apart >= 2 && agree && faceMinAngle(f) < kSplitFloorDeg * kBandDeg && isCap(f);
        if (known >= 2 && (apart == known || tilted)) outliers.push_back(f);
    }
    for (FaceIndex f : outliers)
        normal[std::uint32_t(f)] = V3(0, 0, 0);
    std::unordered_map<std::uint64_t, double> cosine; // per crease edge: the cosine of its dihedral angle
    for (FaceIndex f : bandList_)
        for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
            if (!interiorEdge(h)) continue;
            const V3 n1 = creaseNormal(S_.face(h)), n2 = creaseNormal(S_.face(S_.opposite(h)));
            if (n1.squaredNorm() > 0 && n2.squaredNorm() > 0 && n1.dot(n2) < creaseCos) {
                addCrease(S_.source(h), S_.target(h));
                cosine[bandKey(S_.source(h), S_.target(h))] = n1.dot(n2);
            }
        }
    if (!filter) return;
    const double strongCos = std::cos(2 * in_.creaseAngleDeg * kBandDeg);
    std::vector<std::pair<VertexIndex, VertexIndex>> weak;
    for (const auto& [k, c] : cosine) {
        const VertexIndex a(std::uint32_t(k >> 32)), b(std::uint32_t(k & 0xffffffffu));
        const int da = creaseDegree(a), db = creaseDegree(b);
        const bool stub = (da == 1 && db != 2) || (db == 1 && da != 2);
        if (stub && c > strongCos) weak.push_back({a, b});
    }
    std::sort(weak.begin(), weak.end());
    for (const auto& [a, b] : weak)
        removeCrease(a, b);
    if (!stageOff("bridge")) bridgeCreases(normal);
}

void BandRemesher::bridgeCreases(const std::unordered_map<std::uint32_t, V3>& normal) {
    // A sliver of the draft across a crease has no reliable normal, so the crease stops on both sides of it:
    // two crease ends a short band edge apart, each held like a corner, and the short edge stays (its
    // collapse would move a held vertex: BandCrease.ShortEdgesAtAHeldCreaseVertexKeepTheCrease). Where the
    // two stubs continue one line (they turn by at most kStraightCreaseDeg and the gap's far end lies within
    // kCreaseChordDev of the line), the edge across the gap is a crease too, so neither end is held.
    auto unknownNormal = [&](FaceIndex f) {
        auto it = normal.find(std::uint32_t(f));
        return it == normal.end() || !(it->second.squaredNorm() > 0);
    };
    auto along = [&](VertexIndex v) { // v's other end on its one crease edge
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(v), S_))
            if (isCrease(v, w)) return w;
        return Mesh::null_vertex();
    };
    std::vector<std::pair<VertexIndex, VertexIndex>> bridges;
    std::vector<std::uint32_t> ends;
    for (const auto& [v, d] : creaseDeg_)
        if (d == 1) ends.push_back(v);
    std::sort(ends.begin(), ends.end());
    for (std::uint32_t ai : ends) {
        const VertexIndex a(ai), x = along(a);
        if (x == Mesh::null_vertex()) continue;
        const V3 pa = detail::pos(S_, a), px = detail::pos(S_, x);
        VertexIndex best = Mesh::null_vertex();
        double bestTurn = kStraightCreaseDeg * kBandDeg;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(a), S_)) {
            const VertexIndex b = S_.source(h);
            if (std::uint32_t(b) <= ai || creaseDegree(b) != 1 || isCrease(a, b) || !interiorEdge(h))
                continue;
            if (!unknownNormal(S_.face(h)) && !unknownNormal(S_.face(S_.opposite(h)))) continue;
            const VertexIndex y = along(b);
            if (y == Mesh::null_vertex() || y == x) continue;
            const V3 pb = detail::pos(S_, b), py = detail::pos(S_, y);
            const double turn = detail::angleBetween(pa - px, py - pb);
            const V3 d = (pa - px).normalized();
            const double off = ((pb - pa) - (pb - pa).dot(d) * d).norm();
            if (turn <= bestTurn && off <= kCreaseChordDev * (py - px).norm()) {
                bestTurn = turn;
                best = b;
            }
        }
        if (best != Mesh::null_vertex()) bridges.push_back({a, best});
    }
    for (const auto& [a, b] : bridges)
        if (creaseDegree(a) == 1 && creaseDegree(b) == 1) addCrease(a, b);
}

void BandRemesher::buildCreaseChains() {
    // Crease graph over S_'s vertices (at setup S_'s band is the draft, ref_ its copy).
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> adj;
    for (std::uint64_t k : crease_) {
        const auto a = std::uint32_t(k >> 32), b = std::uint32_t(k & 0xffffffffu);
        adj[a].push_back(b);
        adj[b].push_back(a);
    }
    std::vector<std::uint32_t> starts;
    for (auto& [v, n] : adj) {
        std::sort(n.begin(), n.end());
        starts.push_back(v);
    }
    std::sort(starts.begin(), starts.end()); // deterministic chains
    std::unordered_set<std::uint64_t> used;
    auto walk = [&](std::uint32_t from, std::uint32_t next) {
        const int chain = int(chainPts_.size());
        std::vector<V3> pts{detail::pos(S_, VertexIndex(from))};
        std::vector<double> arc{0.0};
        creasePos_[from].push_back({chain, 0.0});
        std::uint32_t prev = from, cur = next;
        used.insert(bandKey(VertexIndex(prev), VertexIndex(cur)));
        for (;;) {
            const V3 p = detail::pos(S_, VertexIndex(cur));
            arc.push_back(arc.back() + (p - pts.back()).norm());
            pts.push_back(p);
            creasePos_[cur].push_back({chain, arc.back()});
            const auto& n = adj[cur];
            if (n.size() != 2 || cur == from) break;
            const std::uint32_t after = n[0] == prev ? n[1] : n[0];
            if (!used.insert(bandKey(VertexIndex(cur), VertexIndex(after))).second) break;
            prev = cur;
            cur = after;
        }
        chainPts_.push_back(std::move(pts));
        chainArc_.push_back(std::move(arc));
    };
    // Open chains from their ends and corners (other than two crease edges), then the closed loops.
    for (int pass = 0; pass < 2; ++pass)
        for (std::uint32_t v : starts) {
            if (pass == 0 && adj[v].size() == 2) continue;
            for (std::uint32_t w : adj[v])
                if (!used.count(bandKey(VertexIndex(v), VertexIndex(w)))) walk(v, w);
        }
}

void BandRemesher::smoothNormals() {
    const double creaseCos = std::cos(in_.creaseAngleDeg * kBandDeg);
    cornerNormal_.assign(ref_.num_halfedges(), V3(0, 0, 0));
    // Each face's area vector and reliability once (every corner around a face reads them, ~18 times).
    std::vector<V3> areas(ref_.num_faces(), V3(0, 0, 0));
    std::vector<char> reliables(ref_.num_faces(), 0);
    for (FaceIndex g : ref_.faces()) {
        const HalfedgeIndex h = ref_.halfedge(g);
        const V3 a = detail::pos(ref_, ref_.source(h)), b = detail::pos(ref_, ref_.target(h)),
                 c = detail::pos(ref_, ref_.target(ref_.next(h)));
        areas[std::size_t(g)] = V3((b - a).cross(c - a));
        reliables[std::size_t(g)] = detail::minAngle(a, b, c) >= kSliverDeg * kBandDeg;
    }
    auto area = [&](FaceIndex g) { return areas[std::size_t(g)]; };
    auto reliable = [&](FaceIndex g) { return reliables[std::size_t(g)] != 0; };
    for (FaceIndex f : ref_.faces()) {
        const V3 nf = area(f).normalized();
        const bool fReliable = reliable(f);
        for (HalfedgeIndex h : CGAL::halfedges_around_face(ref_.halfedge(f), ref_)) {
            // The faces around the corner on f's side of any crease (a sliver's own normal says nothing:
            // then all faces around, unless they span a crease, when the corner keeps f's plane).
            V3 sum(0, 0, 0), all(0, 0, 0);
            bool spansCrease = false;
            V3 first(0, 0, 0);
            for (HalfedgeIndex g : CGAL::halfedges_around_target(h, ref_)) {
                if (ref_.is_border(g)) continue;
                const V3 ag = area(ref_.face(g));
                if (!(ag.squaredNorm() > 0)) continue;
                const V3 ng = ag.normalized();
                all += ag;
                if (reliable(ref_.face(g))) {
                    if (first.squaredNorm() == 0) first = ng;
                    spansCrease = spansCrease || ng.dot(first) < creaseCos;
                }
                if (fReliable && ng.dot(nf) >= creaseCos) sum += ag;
            }
            const V3 n = fReliable ? sum : (spansCrease ? nf : all);
            cornerNormal_[std::size_t(h)] = n.squaredNorm() > 0 ? V3(n.normalized()) : nf;
        }
    }
}

V3 BandRemesher::smoothPoint(FaceIndex refFace, const V3& p) const {
    if (stageOff("smooth") || refFace == Mesh::null_face()) return p;
    const HalfedgeIndex h0 = ref_.halfedge(refFace);
    const std::array<HalfedgeIndex, 3> h{h0, ref_.next(h0), ref_.next(ref_.next(h0))};
    std::array<V3, 3> x, n;
    for (std::size_t i = 0; i < 3; ++i) {
        x[i] = detail::pos(ref_, ref_.target(h[i]));
        n[i] = cornerNormal_[std::size_t(h[i])];
        if (!(n[i].squaredNorm() > 0)) return p;
    }
    // Barycentric coordinates of p (on the face) by sub-areas, clamped into the face.
    const V3 nf = (x[1] - x[0]).cross(x[2] - x[0]);
    const double A = nf.squaredNorm();
    if (!(A > 0)) return p;
    std::array<double, 3> w{(x[2] - x[1]).cross(p - x[1]).dot(nf) / A,
                            (x[0] - x[2]).cross(p - x[2]).dot(nf) / A, 0.0};
    w[0] = std::max(0.0, w[0]);
    w[1] = std::max(0.0, w[1]);
    w[2] = std::max(0.0, 1.0 - w[0] - w[1]);
    const double sum = w[0] + w[1] + w[2];
    V3 lin(0, 0, 0), star(0, 0, 0);
    for (std::size_t i = 0; i < 3; ++i)
        lin += w[i] / sum * x[i];
    for (std::size_t i = 0; i < 3; ++i)
        star += w[i] / sum * (lin - (lin - x[i]).dot(n[i]) * n[i]);
    return 0.5 * (lin + star);
}

void BandRemesher::findOrigins() {
    report_.origin.clear();
    for (FaceIndex f : report_.faces) {
        const HalfedgeIndex h = S_.halfedge(f);
        const V3 c = (detail::pos(S_, S_.source(h)) + detail::pos(S_, S_.target(h)) +
                      detail::pos(S_, S_.target(S_.next(h)))) /
                     3.0;
        std::size_t o = std::size_t(-1);
        for (VertexIndex v : CGAL::vertices_around_face(h, S_)) {
            const FaceIndex hint = at(hint_, std::size_t(v), Mesh::null_face());
            if (hint == Mesh::null_face()) continue;
            const SurfacePoint sp = near2_(c, hint);
            if (sp && std::size_t(sp.face) < refOrigin_.size()) o = refOrigin_[std::size_t(sp.face)];
            break;
        }
        report_.origin.push_back(o);
    }
}

void BandRemesher::liftRelaxed(const std::vector<VertexIndex>& verts, const std::vector<V3>& before) {
    for (std::size_t k = 0; k < verts.size(); ++k) { // (maxTurn_: in_.maxNormalTurnDeg in radians)
        const VertexIndex v = verts[k];
        const V3 p = detail::pos(S_, v);
        if (p == before[k]) continue;
        const V3 q = smoothPoint(hint_[std::size_t(v)], p);
        // Where the lift would turn or flatten the star (it moves the vertex along the normal by about the
        // chord's sag), the relaxed place on the draft stays.
        if (q == p || !starAcceptable(v, q, maxTurn_) ||
            starMinAngle(v, q) < starMinAngle(v, p) - 0.5 * kBandDeg)
            continue;
        S_.point(v) = Point3(q.x(), q.y(), q.z());
    }
}

V3 BandRemesher::creasePoint(int chain, double s) const {
    const auto& arc = chainArc_[std::size_t(chain)];
    const auto& pts = chainPts_[std::size_t(chain)];
    if (s <= 0) return pts.front();
    if (s >= arc.back()) return pts.back();
    const std::size_t i = std::size_t(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin());
    const double len = arc[i] - arc[i - 1];
    const double t = len > 0 ? (s - arc[i - 1]) / len : 0.0;
    return pts[i - 1] + t * (pts[i] - pts[i - 1]);
}

CreasePos BandRemesher::creaseBetween(VertexIndex a, VertexIndex b, double t, V3& q) const {
    const auto ia = creasePos_.find(std::uint32_t(a)), ib = creasePos_.find(std::uint32_t(b));
    if (ia == creasePos_.end() || ib == creasePos_.end()) return {};
    // Their common chain, the nearest pair of places (a corner or a loop's start has several).
    CreasePos best;
    double bestGap = std::numeric_limits<double>::infinity(), sa = 0, sb = 0;
    for (const CreasePos& x : ia->second)
        for (const CreasePos& y : ib->second)
            if (x.chain == y.chain && std::abs(x.s - y.s) < bestGap) {
                bestGap = std::abs(x.s - y.s);
                best.chain = x.chain;
                sa = x.s;
                sb = y.s;
            }
    if (best.chain < 0) return {};
    // The polyline between them must be about as long as the edge (the same stretch of crease, not the
    // way round a loop or along another crease).
    const double edge = (detail::pos(S_, a) - detail::pos(S_, b)).norm();
    if (!(bestGap <= 1.5 * edge + 1e-12)) return {};
    best.s = sa + t * (sb - sa);
    q = creasePoint(best.chain, best.s);
    return best;
}

bool BandRemesher::creaseCollapseKeepsLine(VertexIndex from, VertexIndex to, VertexIndex other) const {
    const V3 pf = detail::pos(S_, from), pt = detail::pos(S_, to), po = detail::pos(S_, other);
    if (!stageOff("lift")) {
        // On the draft's polyline: every point of it between `to` and `other` near the new edge.
        V3 dummy;
        const CreasePos x = creaseBetween(to, from, 0.0, dummy), y = creaseBetween(from, other, 1.0, dummy);
        if (x.chain >= 0 && x.chain == y.chain) {
            const auto& arc = chainArc_[std::size_t(x.chain)];
            const auto& pts = chainPts_[std::size_t(x.chain)];
            const double lo = std::min(x.s, y.s), hi = std::max(x.s, y.s);
            const V3 d = po - pt;
            const double len2 = d.squaredNorm();
            if (!(len2 > 0)) return false;
            double dev = 0;
            for (std::size_t i = 0; i < pts.size(); ++i) {
                if (arc[i] < lo || arc[i] > hi) continue;
                const double u = std::clamp((pts[i] - pt).dot(d) / len2, 0.0, 1.0);
                dev = std::max(dev, (pts[i] - (pt + u * d)).norm());
            }
            dev = std::max(dev, (pf - (pt + std::clamp((pf - pt).dot(d) / len2, 0.0, 1.0) * d)).norm());
            return dev <= kCreaseChordDev * std::sqrt(len2);
        }
    }
    return detail::angleBetween(pf - pt, po - pf) <= kStraightCreaseDeg * kBandDeg;
}

bool BandRemesher::repairSplit(FaceIndex f) {
    // Only where the face's corners cannot be moved by the other repairs: crease vertices or held ones.
    for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
        if (!isFixed(v) && creaseDegree(v) == 0 && wholeStarInBand(v)) return false;
    HalfedgeIndex bestH = Mesh::null_halfedge();
    double bestT = 0.5, bestMin = -1;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
        if (!interiorEdge(h)) continue;
        const double oldMin = std::min(faceMinAngle(f), faceMinAngle(S_.face(S_.opposite(h))));
        for (double t : {0.5, 1.0 / 3.0, 2.0 / 3.0, 0.25, 0.75}) {
            const SplitPoint sp = splitPoint(h, t);
            const double m = splitMinAngle(h, sp.q);
            if (m > oldMin + 0.5 * kBandDeg && m > bestMin) {
                bestMin = m;
                bestH = h;
                bestT = t;
            }
        }
    }
    if (bestH == Mesh::null_halfedge()) return false;
    minSplitGain_ = 1.0 + 1e-6;
    const bool ok = split(bestH, bestT);
    minSplitGain_ = 0;
    return ok;
}

void BandRemesher::slidePass() {
    const double aim = in_.minAngleDeg * kBandDeg, maxTurn = in_.maxNormalTurnDeg * kBandDeg;
    const std::vector<VertexIndex> verts = cornersOfFacesBelow(
        aim, [&](VertexIndex v) { return !isFixed(v) && creaseDegree(v) == 2 && wholeStarInBand(v); });
    for (VertexIndex v : verts) {
        std::vector<VertexIndex> ends;
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(v), S_))
            if (isCrease(v, w)) ends.push_back(w);
        if (ends.size() != 2) continue;
        const V3 p = detail::pos(S_, v), e0 = detail::pos(S_, ends[0]), e1 = detail::pos(S_, ends[1]);
        // Along the draft's crease polyline where v has a place on it (a curved crease too); else along a
        // nearly straight crease's chords.
        const bool straight = detail::angleBetween(p - e0, e1 - p) <= kSlideCreaseDeg * kBandDeg;
        slideTowards(v, ends, !stageOff("lift"), straight, maxTurn);
    }
}

void BandRemesher::slideTowards(VertexIndex v, const std::vector<VertexIndex>& ends, bool lift, bool chords,
                                double maxTurn) {
    const V3 p = detail::pos(S_, v);
    double best = starMinAngle(v, p);
    V3 bestP = p;
    CreasePos bestPos;
    for (VertexIndex e : ends)
        for (double t : {0.1, 0.2, 0.3, 0.4}) {
            V3 q = p + t * (detail::pos(S_, e) - p);
            const CreasePos cp = lift ? creaseBetween(v, e, t, q) : CreasePos{};
            if (cp.chain < 0 && !chords) continue;
            if (raisesStar(v, q, best, maxTurn)) {
                bestP = q;
                bestPos = cp;
            }
        }
    if (bestP != p) moveAlongCrease(v, bestP, bestPos);
}

void BandRemesher::moveAlongCrease(VertexIndex v, const V3& p, const CreasePos& pos) {
    S_.point(v) = Point3(p.x(), p.y(), p.z());
    if (pos.chain >= 0)
        creasePos_[std::uint32_t(v)] = {pos};
    else
        creasePos_.erase(std::uint32_t(v));
    const FaceIndex hint = at(hint_, std::size_t(v), Mesh::null_face());
    if (hint != Mesh::null_face()) {
        const SurfacePoint sp = near2_(p, hint);
        if (sp) hint_[std::size_t(v)] = sp.face;
    }
    touch(v);
    ++report_.moves;
}

} // namespace fss::stitch::band
