// Stitch stage "cut" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

namespace fss::detail::stitching {

int ComponentStitcher::addLocal(LVert l) {
    cut_.L.push_back(l);
    return int(cut_.L.size()) - 1;
}

int ComponentStitcher::regionVertex(VertexIndex v) {
    auto [it, fresh] = cut_.lidOfCurrent.try_emplace(std::uint32_t(v), -1);
    if (fresh) {
        LVert l;
        l.kind = LVert::Region;
        l.cur = std::uint32_t(v);
        l.pos = toVec(M_.point(v));
        l.uv = vproj(v).uv;
        it->second = addLocal(l);
    }
    return it->second;
}

void ComponentStitcher::buildLocalVertices() {
    for (FaceIndex f : reg_.faces) {
        const HalfedgeIndex h0 = M_.halfedge(f);
        HalfedgeIndex h = h0;
        do {
            regionVertex(M_.target(h));
            h = M_.next(h);
        } while (h != h0);
    }
    for (FaceIndex f : reg_.faces) {
        const HalfedgeIndex h0 = M_.halfedge(f);
        HalfedgeIndex h = h0;
        do {
            const EdgeIndex e = M_.edge(h);
            if (!cut_.redgeIndex.count(std::uint32_t(e))) {
                const HalfedgeIndex he = M_.halfedge(e);
                cut_.redgeIndex[std::uint32_t(e)] = int(cut_.redges.size());
                cut_.redges.push_back({regionVertex(M_.source(he)), regionVertex(M_.target(he)), e, {}, {}});
            }
            h = M_.next(h);
        } while (h != h0);
    }
    std::vector<int> bverts(comp_.boundary.begin(), comp_.boundary.end());
    std::sort(bverts.begin(), bverts.end());
    for (int v : bverts) {
        LVert l;
        l.kind = LVert::PatchBoundary;
        l.patchA = v;
        l.chain = true;
        l.pos = P_.pos[std::size_t(v)];
        l.uv = P_.uv[std::size_t(v)];
        cut_.lidOfPatch[v] = addLocal(l);
    }
}

bool ComponentStitcher::patchStaysValid(int v, const Point2& uv) const {
    for (int f : comp_.vertexFaces.at(v)) {
        const auto& t = P_.tri[std::size_t(f)];
        Point2 q[3];
        for (int k = 0; k < 3; ++k)
            q[k] = t[std::size_t(k)] == v ? uv : L_uvOfPatch(t[std::size_t(k)]);
        if (!leftTurn(q[0], q[1], q[2])) return false;
    }
    return true;
}

Point2 ComponentStitcher::L_uvOfPatch(int v) const {
    auto it = cut_.lidOfPatch.find(v);
    return it == cut_.lidOfPatch.end() ? P_.uv[std::size_t(v)] : cut_.L[std::size_t(it->second)].uv;
}

const Vec3& ComponentStitcher::posOfPatch(int v) const {
    auto it = cut_.lidOfPatch.find(v);
    return it == cut_.lidOfPatch.end() ? P_.pos[std::size_t(v)] : cut_.L[std::size_t(it->second)].pos;
}

void ComponentStitcher::liftOnEdge(int re, double s, Vec3& pos, Point2& uv) {
    const int u = cut_.redges[std::size_t(re)].u, w = cut_.redges[std::size_t(re)].w;
    const VProj &pu = vproj(VertexIndex(cut_.L[std::size_t(u)].cur)),
                &pw = vproj(VertexIndex(cut_.L[std::size_t(w)].cur));
    const double t = View::perspectiveParam(s, pu.w, pw.w);
    pos = cut_.L[std::size_t(u)].pos + t * (cut_.L[std::size_t(w)].pos - cut_.L[std::size_t(u)].pos);
    double wq;
    if (!V_.project(pos, uv, wq))
        uv = Point2(pu.uv.x() + s * (pw.uv.x() - pu.uv.x()), pu.uv.y() + s * (pw.uv.y() - pu.uv.y()));
}

bool ComponentStitcher::splittable(int re) const {
    const HalfedgeIndex h = M_.halfedge(cut_.redges[std::size_t(re)].edge);
    for (HalfedgeIndex g : {h, M_.opposite(h)})
        if (M_.is_border(g) || !reg_.index.count(std::uint32_t(M_.face(g)))) return false;
    return true;
}

FaceIndex ComponentStitcher::outerFace(int re, const std::unordered_set<std::uint32_t>& interior) const {
    const HalfedgeIndex h = M_.halfedge(cut_.redges[std::size_t(re)].edge);
    FaceIndex outer;
    int inRegion = 0;
    for (HalfedgeIndex g : {h, M_.opposite(h)}) {
        if (M_.is_border(g)) return FaceIndex();
        const FaceIndex f = M_.face(g);
        if (reg_.index.count(std::uint32_t(f)))
            ++inRegion;
        else
            outer = f;
    }
    if (inRegion != 1 || interior.count(std::uint32_t(outer))) return FaceIndex();
    if (M_.next(M_.next(M_.next(M_.halfedge(outer)))) != M_.halfedge(outer)) return FaceIndex();
    return outer;
}

void ComponentStitcher::snap() {
    const double cell = 2.0 * comp_.h2;
    // Snapping distances are a fraction of the local edge lengths on both sides, so that snapped
    // points keep their order and no triangle folds.
    std::vector<double> regionEdgeMin(cut_.L.size(), std::numeric_limits<double>::infinity());
    for (const auto& re : cut_.redges) {
        const double l = std::sqrt(dist2(cut_.L[std::size_t(re.u)].uv, cut_.L[std::size_t(re.w)].uv));
        for (int v : {re.u, re.w})
            regionEdgeMin[std::size_t(v)] = std::min(regionEdgeMin[std::size_t(v)], l);
    }
    const double ratio = O_.collapseEdgeRatio;
    snapToMeshVertices(cell, ratio, regionEdgeMin);
    snapOntoMeshEdges(cell, ratio);
    splitPatchEdgesAtMeshVertices(cell, ratio);
}

// Rule 1: a patch boundary vertex close to a mesh vertex becomes that vertex.
void ComponentStitcher::snapToMeshVertices(double cell, double ratio,
                                           const std::vector<double>& regionEdgeMin) {
    BucketGrid grid(cell, cut_.L.size());
    for (std::size_t i = 0; i < cut_.L.size(); ++i)
        if (cut_.L[i].kind == LVert::Region) grid.insert(int(i), cut_.L[i].uv.bbox());
    struct Cand {
        double d;
        int patch, lid;
    };
    std::vector<Cand> cands;
    for (const auto& [v, lid] : cut_.lidOfPatch) {
        const double r = comp_.snapRadius.at(v);
        const Point2 uv = cut_.L[std::size_t(lid)].uv;
        grid.query(grown(uv.bbox(), r), [&](int i) {
            const double d = std::sqrt(dist2(uv, cut_.L[std::size_t(i)].uv));
            if (d < std::min(r, ratio * regionEdgeMin[std::size_t(i)])) cands.push_back({d, v, i});
        });
    }
    std::sort(cands.begin(), cands.end(), [](const Cand& x, const Cand& y) {
        return x.d != y.d ? x.d < y.d : (x.patch != y.patch ? x.patch < y.patch : x.lid < y.lid);
    });
    std::unordered_set<int> usedPatch, usedRegion;
    for (const Cand& c : cands) {
        if (usedPatch.count(c.patch) || usedRegion.count(c.lid)) continue;
        if (!patchStaysValid(c.patch, cut_.L[std::size_t(c.lid)].uv)) continue;
        usedPatch.insert(c.patch);
        usedRegion.insert(c.lid);
        const int old = cut_.lidOfPatch.at(c.patch);
        cut_.L[std::size_t(old)].alive = false;
        cut_.lidOfPatch[c.patch] = c.lid;
        cut_.L[std::size_t(c.lid)].patchA = c.patch;
        cut_.L[std::size_t(c.lid)].chain = true;
    }
}

// Rule 2: a patch boundary vertex close to a mesh edge moves onto it (an edge split). On an edge at
// the region's rim (typically a crease whose other face the view does not see) the other face is
// split along that edge too.
void ComponentStitcher::snapOntoMeshEdges(double cell, double ratio) {
    const std::unordered_set<std::uint32_t> interior = [&] {
        std::unordered_set<std::uint32_t> out;
        for (FaceIndex f : reg_.interior)
            out.insert(std::uint32_t(f));
        return out;
    }();
    BucketGrid grid(cell, cut_.redges.size());
    for (std::size_t i = 0; i < cut_.redges.size(); ++i)
        grid.insert(int(i), bboxOf(cut_.L[std::size_t(cut_.redges[i].u)].uv,
                                   cut_.L[std::size_t(cut_.redges[i].w)].uv));
    std::vector<int> verts;
    for (const auto& [v, lid] : cut_.lidOfPatch)
        if (cut_.L[std::size_t(lid)].kind == LVert::PatchBoundary) verts.push_back(v);
    std::sort(verts.begin(), verts.end());
    for (int v : verts) {
        const int lid = cut_.lidOfPatch.at(v);
        const double r = comp_.snapRadius.at(v);
        const Point2 uv = cut_.L[std::size_t(lid)].uv;
        int best = -1;
        double bestD = r, bestS = 0;
        grid.query(grown(uv.bbox(), r), [&](int i) {
            double s;
            const Point2 &U = cut_.L[std::size_t(cut_.redges[std::size_t(i)].u)].uv,
                         &W = cut_.L[std::size_t(cut_.redges[std::size_t(i)].w)].uv;
            const double d = segmentDistance(uv, U, W, s);
            if (d < bestD && d < ratio * std::sqrt(dist2(U, W)) && s > 1e-3 && s < 1 - 1e-3) {
                bestD = d;
                best = i;
                bestS = s;
            }
        });
        if (best < 0) continue;
        const FaceIndex outer = splittable(best) ? FaceIndex() : outerFace(best, interior);
        if (!splittable(best) && outer == FaceIndex()) continue;
        Vec3 pos;
        Point2 q;
        liftOnEdge(best, bestS, pos, q);
        if (!patchStaysValid(v, q)) continue;
        if (outer != FaceIndex()) {
            // Its two pieces must pass the stitch's angle floor (else the patch keeps its place) ...
            const auto ov = faceVertices(outer);
            const Vec3 A = toVec(M_.point(ov[0])), B = toVec(M_.point(ov[1])), C = toVec(M_.point(ov[2]));
            const REdge& r = cut_.redges[std::size_t(best)];
            const Vec3 D = A + B + C - cut_.L[std::size_t(r.u)].pos - cut_.L[std::size_t(r.w)].pos;
            // Its neighbours along the edge: the edge's ends or vertices snapped onto it before.
            const double sq = lineParam(q, cut_.L[std::size_t(r.u)].uv, cut_.L[std::size_t(r.w)].uv);
            double below = 0, above = 1;
            Vec3 U = cut_.L[std::size_t(r.u)].pos, W = cut_.L[std::size_t(r.w)].pos;
            for (const auto& [sp, other] : r.splits) {
                if (sp <= sq && sp >= below) {
                    below = sp;
                    U = cut_.L[std::size_t(other)].pos;
                }
                if (sp > sq && sp <= above) {
                    above = sp;
                    W = cut_.L[std::size_t(other)].pos;
                }
            }
            const double floor = std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                          0.999 * minAngle(A, B, C));
            // ... and be no worse than the sliver the snap avoids (up to the needle angle).
            const double fan = std::min(minAngle(U, pos, D), minAngle(pos, W, D));
            if (fan < floor || fan < std::min(minAngle(U, P_.pos[std::size_t(v)], W), kNeedleDeg * kDeg))
                continue;
            // At most one split edge per outer face (it becomes a fan from the opposite corner).
            auto [it, fresh] = cut_.outerSplits.try_emplace(std::uint32_t(outer), best);
            if (!fresh && it->second != best) continue;
            cut_.L[std::size_t(lid)].onOuterEdge = true;
        }
        LVert& l = cut_.L[std::size_t(lid)];
        l.pos = pos;
        l.uv = q;
        l.edgeU = cut_.redges[std::size_t(best)].u;
        l.edgeW = cut_.redges[std::size_t(best)].w;
        cut_.redges[std::size_t(best)].splits.push_back(
            {lineParam(q, cut_.L[std::size_t(cut_.redges[std::size_t(best)].u)].uv,
                       cut_.L[std::size_t(cut_.redges[std::size_t(best)].w)].uv),
             lid});
    }
}

// Rule 3: a mesh vertex close to a patch boundary edge splits that edge. The closest go first; a
// vertex is taken when the patch triangle on the edge stays a fan of counter-clockwise triangles.
void ComponentStitcher::splitPatchEdgesAtMeshVertices(double cell, double ratio) {
    BucketGrid grid(cell, comp_.pedges.size());
    for (std::size_t i = 0; i < comp_.pedges.size(); ++i)
        grid.insert(int(i), bboxOf(L_uvOfPatch(comp_.pedges[i].a), L_uvOfPatch(comp_.pedges[i].b)));
    struct Cand {
        double d, s;
        int lid;
    };
    std::vector<std::vector<Cand>> cands(comp_.pedges.size());
    for (std::size_t i = 0; i < cut_.L.size(); ++i) {
        const LVert& l = cut_.L[i];
        if (l.kind != LVert::Region || l.chain) continue;
        int best = -1;
        double bestRel = 1, bestS = 0, bestD = 0;
        grid.query(grown(l.uv.bbox(), comp_.margin), [&](int e) {
            const auto& pe = comp_.pedges[std::size_t(e)];
            const int la = cut_.lidOfPatch.at(pe.a), lb = cut_.lidOfPatch.at(pe.b);
            if (la == int(i) || lb == int(i)) return;
            const Point2 &A = cut_.L[std::size_t(la)].uv, &B = cut_.L[std::size_t(lb)].uv;
            double s;
            const double d = segmentDistance(l.uv, A, B, s);
            const double rel = d / (ratio * std::sqrt(dist2(A, B)));
            if (rel < bestRel && s > 1e-3 && s < 1 - 1e-3) {
                bestRel = rel;
                best = e;
                bestS = s;
                bestD = d;
            }
        });
        if (best >= 0) cands[std::size_t(best)].push_back({bestD, bestS, int(i)});
    }
    for (std::size_t e = 0; e < comp_.pedges.size(); ++e) {
        auto& cs = cands[e];
        if (cs.empty()) continue;
        std::sort(cs.begin(), cs.end(),
                  [](const Cand& x, const Cand& y) { return x.d != y.d ? x.d < y.d : x.lid < y.lid; });
        auto& pe = comp_.pedges[e];
        const Point2 A = L_uvOfPatch(pe.a), B = L_uvOfPatch(pe.b), C = L_uvOfPatch(pe.opposite);
        const Vec3 A3 = posOfPatch(pe.a), B3 = posOfPatch(pe.b), C3 = posOfPatch(pe.opposite);
        // The floor the final check applies to the pieces of this patch triangle.
        const double floor = std::min(O_.minAngleFloorDeg * kDeg,
                                      0.999 * minAngle(P_.pos[std::size_t(pe.a)], P_.pos[std::size_t(pe.b)],
                                                       P_.pos[std::size_t(pe.opposite)]));
        std::vector<std::pair<double, int>> taken; // sorted by s
        for (const Cand& c : cs) {
            const auto pos = std::lower_bound(taken.begin(), taken.end(), std::pair{c.s, -1});
            const Point2 prev = pos == taken.begin() ? A : cut_.L[std::size_t(std::prev(pos)->second)].uv;
            const Point2 next = pos == taken.end() ? B : cut_.L[std::size_t(pos->second)].uv;
            const Point2& v = cut_.L[std::size_t(c.lid)].uv;
            if (!leftTurn(prev, v, C) || !leftTurn(v, next, C)) continue;
            if (!(lineParam(v, prev, next) > 0 && lineParam(v, prev, next) < 1)) continue;
            // The fan's pieces must pass the final check's angle floor in 3D: a mesh vertex in line
            // with the patch triangle's other corners (a patch vertex snapped onto a mesh edge
            // through it) would leave a needle no triangulation of that triangle avoids.
            const Vec3& prev3 = pos == taken.begin() ? A3 : cut_.L[std::size_t(std::prev(pos)->second)].pos;
            const Vec3& next3 = pos == taken.end() ? B3 : cut_.L[std::size_t(pos->second)].pos;
            const Vec3& v3 = cut_.L[std::size_t(c.lid)].pos;
            if (minAngle(prev3, v3, C3) < floor || minAngle(v3, next3, C3) < floor) continue;
            taken.insert(pos, {c.s, c.lid});
        }
        for (const auto& [sp, lid] : taken) {
            pe.splits.push_back({sp, lid});
            LVert& l = cut_.L[std::size_t(lid)];
            l.chain = true;
            l.patchA = pe.a;
            l.patchB = pe.b;
        }
    }
}

std::vector<int> ComponentStitcher::polyline(int from, int to, std::vector<std::pair<double, int>> splits) {
    std::sort(splits.begin(), splits.end());
    std::vector<int> out{from};
    for (const auto& s : splits)
        if (s.second != out.back()) out.push_back(s.second);
    if (to != out.back()) out.push_back(to);
    return out;
}

bool ComponentStitcher::computeCrossings(Attempt& a) {
    struct Sub {
        int p, q, owner;
    };
    std::vector<Sub> rsubs, psubs;
    for (std::size_t i = 0; i < cut_.redges.size(); ++i) {
        const auto pl = polyline(cut_.redges[i].u, cut_.redges[i].w, cut_.redges[i].splits);
        for (std::size_t k = 0; k + 1 < pl.size(); ++k)
            rsubs.push_back({pl[k], pl[k + 1], int(i)});
    }
    for (std::size_t i = 0; i < comp_.pedges.size(); ++i) {
        const auto pl = polyline(cut_.lidOfPatch.at(comp_.pedges[i].a), cut_.lidOfPatch.at(comp_.pedges[i].b),
                                 comp_.pedges[i].splits);
        for (std::size_t k = 0; k + 1 < pl.size(); ++k)
            psubs.push_back({pl[k], pl[k + 1], int(i)});
    }
    BucketGrid grid(2.0 * comp_.h2, rsubs.size());
    for (std::size_t i = 0; i < rsubs.size(); ++i)
        grid.insert(int(i), bboxOf(cut_.L[std::size_t(rsubs[i].p)].uv, cut_.L[std::size_t(rsubs[i].q)].uv));
    std::vector<int> bad;
    for (const Sub& ps : psubs) {
        const Point2 P = cut_.L[std::size_t(ps.p)].uv, Q = cut_.L[std::size_t(ps.q)].uv;
        grid.query(bboxOf(P, Q), [&](int ri) {
            const Sub& rs = rsubs[std::size_t(ri)];
            if (rs.p == ps.p || rs.p == ps.q || rs.q == ps.p || rs.q == ps.q) return;
            const Point2 R = cut_.L[std::size_t(rs.p)].uv, S = cut_.L[std::size_t(rs.q)].uv;
            const auto o1 = CGAL::orientation(P, Q, R), o2 = CGAL::orientation(P, Q, S);
            const auto o3 = CGAL::orientation(R, S, P), o4 = CGAL::orientation(R, S, Q);
            if (o1 != CGAL::COLLINEAR && o2 != CGAL::COLLINEAR && o3 != CGAL::COLLINEAR &&
                o4 != CGAL::COLLINEAR) {
                if (o1 == o2 || o3 == o4) return; // no crossing
                // Proper crossing: intersection in the view, then lifted onto the 3D mesh edge.
                const double d = area2(Point2(0, 0), Point2(Q.x() - P.x(), Q.y() - P.y()),
                                       Point2(S.x() - R.x(), S.y() - R.y()));
                const double t = area2(Point2(0, 0), Point2(R.x() - P.x(), R.y() - P.y()),
                                       Point2(S.x() - R.x(), S.y() - R.y())) /
                                 d;
                const Point2 X(P.x() + t * (Q.x() - P.x()), P.y() + t * (Q.y() - P.y()));
                auto& re = cut_.redges[std::size_t(rs.owner)];
                const double s = std::clamp(
                    lineParam(X, cut_.L[std::size_t(re.u)].uv, cut_.L[std::size_t(re.w)].uv), 0.0, 1.0);
                LVert l;
                l.kind = LVert::Crossing;
                l.chain = true;
                auto& pe = comp_.pedges[std::size_t(ps.owner)];
                l.patchA = pe.a;
                l.patchB = pe.b;
                liftOnEdge(rs.owner, s, l.pos, l.uv);
                l.edgeU = re.u;
                l.edgeW = re.w;
                const int id = addLocal(l);
                re.splits.push_back(
                    {lineParam(l.uv, cut_.L[std::size_t(re.u)].uv, cut_.L[std::size_t(re.w)].uv), id});
                pe.splits.push_back({lineParam(l.uv, L_uvOfPatch(pe.a), L_uvOfPatch(pe.b)), id});
                return;
            }
            if (CGAL::do_intersect(Segment2(P, Q), Segment2(R, S))) {
                // A contact that snapping did not resolve: trim the patch there.
                bad.push_back(comp_.pedges[std::size_t(ps.owner)].a);
                bad.push_back(comp_.pedges[std::size_t(ps.owner)].b);
            }
        });
    }
    if (!bad.empty()) return fail(a, "its boundary touches mesh edges in a degenerate way", std::move(bad));
    for (auto& re : cut_.redges)
        re.line = polyline(re.u, re.w, re.splits);
    for (auto& pe : comp_.pedges)
        pe.line = polyline(cut_.lidOfPatch.at(pe.a), cut_.lidOfPatch.at(pe.b), pe.splits);
    return true;
}

} // namespace fss::detail::stitching
