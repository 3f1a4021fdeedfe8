// Stitch stage "cdt" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

namespace fss::detail::stitching {

bool ComponentStitcher::triangulate(Cdt& cdt, std::vector<CdtVertex>& vh, Attempt& a) {
    vh.assign(cut_.L.size(), CdtVertex());
    std::vector<int> order;
    for (std::size_t i = 0; i < cut_.L.size(); ++i)
        if (cut_.L[i].alive) order.push_back(int(i));
    std::vector<int> bad;
    CdtFace hint;
    std::size_t inserted = 0;
    for (int i : order) {
        progress_.tick();
        const CdtVertex v = cdt.insert(cut_.L[std::size_t(i)].uv, hint);
        if (v->info().id >= 0) {
            addBad(bad, i);
            addBad(bad, v->info().id);
            continue;
        }
        ++inserted;
        v->info().id = i;
        vh[std::size_t(i)] = v;
        hint = v->face();
    }
    if (!bad.empty())
        return fail(a, "some of its boundary vertices coincide with mesh vertices in the view",
                    std::move(bad));
    auto constrain = [&](const std::vector<int>& line) {
        for (std::size_t k = 0; k + 1 < line.size(); ++k) {
            const std::size_t p = std::size_t(line[k]), q = std::size_t(line[k + 1]);
            progress_.tick();
            cut_.subEdges.push_back({line[k], line[k + 1]});
            cdt.insert_constraint(vh[p], vh[q]);
        }
    };
    for (const auto& re : cut_.redges)
        constrain(re.line);
    const std::size_t regionSubs = cut_.subEdges.size();
    for (const auto& pe : comp_.pedges)
        constrain(pe.line);
    if (cdt.number_of_vertices() != inserted) {
        for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
            if (v->info().id < 0) {
                addNear(bad, v->point());
            }
        return fail(a, "it or the mesh under it overlaps itself in the scan's view", std::move(bad));
    }
    for (std::size_t k = 0; k < cut_.subEdges.size(); ++k) {
        const auto [p, q] = cut_.subEdges[k];
        CdtFace f;
        int i;
        if (!cdt.is_edge(vh[std::size_t(p)], vh[std::size_t(q)], f, i)) {
            addBad(bad, p);
            addBad(bad, q);
            continue;
        }
        (k < regionSubs ? cut_.regionSub : cut_.patchSub).insert(edgeKey(std::uint32_t(p), std::uint32_t(q)));
    }
    if (!bad.empty())
        return fail(a, "its boundary passes exactly through mesh vertices in the view", std::move(bad));
    return true;
}

CdtFace ComponentStitcher::leftOf(const Cdt& cdt, CdtVertex p, CdtVertex q) {
    CdtFace f;
    int i;
    cdt.is_edge(p, q, f, i);
    return f->vertex(f->ccw(i)) == p ? f : f->neighbor(i);
}

std::uint64_t ComponentStitcher::keyOf(CdtFace f, int i) const {
    return edgeKey(std::uint32_t(f->vertex(f->ccw(i))->info().id),
                   std::uint32_t(f->vertex(f->cw(i))->info().id));
}

bool ComponentStitcher::classify(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a) {
    std::vector<int> bad;
    std::vector<CdtFace> stack;
    for (std::size_t r = 0; r < reg_.faces.size(); ++r) {
        const auto vs = faceVertices(reg_.faces[r]);
        double covered = 0;
        for (int k = 0; k < 3; ++k) {
            const int u = cut_.lidOfCurrent.at(std::uint32_t(vs[std::size_t(k)]));
            const HalfedgeIndex he = M_.halfedge(vs[std::size_t(k)], vs[std::size_t((k + 1) % 3)]);
            const auto& re = cut_.redges[std::size_t(cut_.redgeIndex.at(std::uint32_t(M_.edge(he))))];
            std::vector<int> line = re.line;
            if (line.front() != u) std::reverse(line.begin(), line.end());
            for (std::size_t j = 0; j + 1 < line.size(); ++j) {
                const CdtFace f = leftOf(cdt, vh[std::size_t(line[j])], vh[std::size_t(line[j + 1])]);
                if (f->info().region == int(r)) continue;
                if (f->info().region >= 0 || cdt.is_infinite(f)) {
                    addNear(bad, cut_.L[std::size_t(line[j])].uv);
                    continue;
                }
                stack.push_back(f);
                while (!stack.empty()) {
                    const CdtFace g = stack.back();
                    stack.pop_back();
                    if (g->info().region == int(r)) continue;
                    if (g->info().region >= 0 || cdt.is_infinite(g)) {
                        addNear(bad, cut_.L[std::size_t(line[j])].uv);
                        stack.clear();
                        break;
                    }
                    g->info().region = int(r);
                    covered += area2(g->vertex(0)->point(), g->vertex(1)->point(), g->vertex(2)->point());
                    for (int e = 0; e < 3; ++e)
                        if (!cut_.regionSub.count(keyOf(g, e))) stack.push_back(g->neighbor(e));
                }
            }
        }
        const Triangle2 t = faceTriangle(reg_.faces[r]);
        const double full = area2(t[0], t[1], t[2]);
        if (std::abs(covered - full) > 1e-7 * full) addNear(bad, CGAL::centroid(t));
    }
    if (!bad.empty()) return fail(a, "the mesh under it overlaps itself in the scan's view", std::move(bad));
    // Inside / outside of the patch: the interior lies to the left of every boundary edge.
    std::vector<std::pair<CdtFace, std::int8_t>> fill;
    for (const auto& pe : comp_.pedges)
        for (std::size_t j = 0; j + 1 < pe.line.size(); ++j) {
            const CdtVertex s = vh[std::size_t(pe.line[j])], t = vh[std::size_t(pe.line[j + 1])];
            fill.emplace_back(leftOf(cdt, s, t), std::int8_t(1));
            fill.emplace_back(leftOf(cdt, t, s), std::int8_t(0));
        }
    while (!fill.empty()) {
        const auto [f, side] = fill.back();
        fill.pop_back();
        if (f->info().inside == side) continue;
        if (f->info().inside >= 0) {
            if (!cdt.is_infinite(f))
                addNear(bad, CGAL::centroid(cdt.triangle(f)));
            else
                bad.push_back(-1);
            continue;
        }
        f->info().inside = side;
        for (int e = 0; e < 3; ++e)
            if (!cut_.patchSub.count(keyOf(f, e))) fill.emplace_back(f->neighbor(e), side);
    }
    if (!bad.empty()) return fail(a, "it overlaps itself in the scan's view", std::move(bad));
    return true;
}

bool ComponentStitcher::checkCoverage(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a) {
    std::vector<int> bad;
    for (std::size_t i = 0; i < cut_.L.size(); ++i) {
        const LVert& l = cut_.L[i];
        if (!l.alive || !l.chain) continue;
        const CdtVertex v = vh[i];
        bool uncovered = false;
        CdtFace under;
        auto fc = cdt.incident_faces(v), end = fc;
        do {
            // On an edge at the region's rim, the side beyond it is not the patch's (split separately).
            if (cdt.is_infinite(fc) || fc->info().region < 0) {
                if (!l.onOuterEdge || fc->info().inside != 0) uncovered = true;
            } else {
                under = fc;
            }
        } while (++fc != end);
        if (under == CdtFace()) uncovered = true;
        // Around a seam vertex inside mesh faces or on mesh edges, the seam faces must surround it.
        if (uncovered && l.kind != LVert::Region) addBad(bad, int(i));
        if (l.kind == LVert::PatchBoundary && !uncovered) {
            // The patch must lie on the surface under it (not on an occluder or another sheet).
            const FaceIndex f = reg_.faces[std::size_t(under->info().region)];
            if (gapTo(l.pos, f) > gapTolerance(f)) addBad(bad, int(i));
        }
    }
    if (!bad.empty())
        return fail(a, "it reaches past the visible, stitchable part of the mesh", std::move(bad));
    return true;
}

bool ComponentStitcher::triangulatePolygon(const std::vector<int>& poly, const std::vector<unsigned>& edges,
                                           float q, std::int32_t sid, double floor) {
    const std::size_t n = poly.size();
    auto P = [&](std::size_t i) -> const Point2& { return cut_.L[std::size_t(poly[i])].uv; };
    auto X = [&](std::size_t i) -> const Vec3& { return cut_.L[std::size_t(poly[i])].pos; };
    if (n == 3) {
        if (!leftTurn(P(0), P(1), P(2))) return false;
        cut_.newFaces.push_back({{poly[0], poly[1], poly[2]}, q, sid, true, Vec3(0, 0, 0), floor, false});
        return true;
    }
    // diagonal[i][j]: the segment i–j lies inside the polygon and does not run along a triangle edge.
    std::vector<char> diagonal(n * n, 0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            if (j == i + 1 || (i == 0 && j == n - 1)) {
                diagonal[i * n + j] = diagonal[j * n + i] = 1;
                continue;
            }
            if (edges[i] & edges[j]) continue;
            // Inside the cone of the polygon's corner at i.
            const Point2 &pi = P(i), &prev = P((i + n - 1) % n), &next = P((i + 1) % n), &pj = P(j);
            const bool convex = CGAL::orientation(prev, pi, next) != CGAL::RIGHT_TURN;
            const bool inCone = convex ? (leftTurn(pi, next, pj) && leftTurn(prev, pi, pj))
                                       : !(CGAL::orientation(pi, next, pj) != CGAL::LEFT_TURN &&
                                           CGAL::orientation(prev, pi, pj) != CGAL::LEFT_TURN);
            if (!inCone) continue;
            bool clear = true;
            const Segment2 d(pi, pj);
            for (std::size_t e = 0; e < n && clear; ++e) {
                const std::size_t f = (e + 1) % n;
                if (e == i || e == j || f == i || f == j) continue;
                if (CGAL::do_intersect(d, Segment2(P(e), P(f)))) clear = false;
            }
            if (clear) diagonal[i * n + j] = diagonal[j * n + i] = 1;
        }
    // best[i][j]: best smallest angle triangulating the chain i..j closed by i–j (i < j).
    const double none = -1;
    std::vector<double> best(n * n, none);
    std::vector<std::size_t> split(n * n, 0);
    for (std::size_t i = 0; i + 1 < n; ++i)
        best[i * n + i + 1] = 4; // an edge: nothing to do
    for (std::size_t len = 2; len < n; ++len)
        for (std::size_t i = 0; i + len < n; ++i) {
            const std::size_t j = i + len;
            if (!diagonal[i * n + j]) continue;
            for (std::size_t k = i + 1; k < j; ++k) {
                const double left = best[i * n + k], right = best[k * n + j];
                if (left < 0 || right < 0 || !leftTurn(P(i), P(k), P(j))) continue;
                const double v = std::min({left, right, minAngle(X(i), X(k), X(j))});
                if (v > best[i * n + j]) {
                    best[i * n + j] = v;
                    split[i * n + j] = k;
                }
            }
        }
    if (best[n - 1] < 0) return false;
    std::vector<std::pair<std::size_t, std::size_t>> stack{{0, n - 1}};
    while (!stack.empty()) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        if (j == i + 1) continue;
        const std::size_t k = split[i * n + j];
        cut_.newFaces.push_back({{poly[i], poly[k], poly[j]}, q, sid, true, Vec3(0, 0, 0), floor, false});
        stack.push_back({i, k});
        stack.push_back({k, j});
    }
    return true;
}

bool ComponentStitcher::assemble(Cdt& cdt, Attempt& a) {
    cut_.replaced = reg_.interior;
    // Region faces: unchanged when they are exactly one outside triangle, else replaced by their
    // outside triangles.
    std::vector<std::vector<CdtFace>> pieces(reg_.faces.size());
    double insideArea = 0;
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (f->info().region >= 0) pieces[std::size_t(f->info().region)].push_back(f);
        if (f->info().inside == 1)
            insideArea += area2(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point());
    }
    for (std::size_t r = 0; r < reg_.faces.size(); ++r) {
        const auto vs = faceVertices(reg_.faces[r]);
        bool changed = pieces[r].size() != 1 || pieces[r][0]->info().inside != 0;
        if (!changed)
            for (int k = 0; k < 3; ++k) {
                const int lid = pieces[r][0]->vertex(k)->info().id;
                if (cut_.L[std::size_t(lid)].kind != LVert::Region ||
                    std::find(vs.begin(), vs.end(), VertexIndex(cut_.L[std::size_t(lid)].cur)) == vs.end())
                    changed = true;
            }
        if (!changed) continue;
        cut_.replaced.push_back(reg_.faces[r]);
        const float q = curHasQuality_ ? curQuality_[reg_.faces[r]] : kInputFaceQuality;
        const std::int32_t sid = curHasScanId_ ? curScanId_[reg_.faces[r]] : -1;
        const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
        const Vec3 n = normalOf(A, B, C).normalized();
        const double floor = std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                      0.999 * minAngle(A, B, C));
        for (CdtFace f : pieces[r])
            if (f->info().inside == 0)
                cut_.newFaces.push_back(
                    {{f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id},
                     q,
                     sid,
                     false,
                     n,
                     floor,
                     false});
    }
    // Mesh faces outside the region whose edge got seam vertices (a patch boundary along a crease, the
    // face beyond it unseen): split along that edge in 3D, a fan from the opposite corner in the face's
    // own plane, so the patch boundary meets the crease without a sliver in front of it.
    for (const auto& [fi, re] : cut_.outerSplits) {
        const FaceIndex face(fi);
        const REdge& r = cut_.redges[std::size_t(re)];
        if (r.line.size() <= 2) continue;
        const HalfedgeIndex he = M_.halfedge(r.edge);
        const bool forward = M_.face(he) == face;
        std::vector<int> line = r.line; // from the source to the target of `he`
        if (!forward) std::reverse(line.begin(), line.end());
        const int apex = regionVertex(M_.target(M_.next(forward ? he : M_.opposite(he))));
        const auto vs = faceVertices(face);
        const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
        const double floor = std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                      0.999 * minAngle(A, B, C));
        cut_.replaced.push_back(face);
        for (std::size_t k = 0; k + 1 < line.size(); ++k)
            cut_.newFaces.push_back({{line[k], line[k + 1], apex},
                                     curHasQuality_ ? curQuality_[face] : kInputFaceQuality,
                                     curHasScanId_ ? curScanId_[face] : -1,
                                     false,
                                     normalOf(A, B, C).normalized(),
                                     floor,
                                     !acceptable(face)});
    }
    // Their other neighbours open to the seam optimisation too (flips in their planes), as themselves.
    {
        std::unordered_set<std::uint32_t> taken;
        for (FaceIndex f : cut_.replaced)
            taken.insert(std::uint32_t(f));
        for (FaceIndex f : reg_.interior)
            taken.insert(std::uint32_t(f));
        for (const auto& [fi, re] : cut_.outerSplits) {
            if (cut_.redges[std::size_t(re)].line.size() <= 2) continue;
            for (HalfedgeIndex h : CGAL::halfedges_around_face(M_.halfedge(FaceIndex(fi)), M_)) {
                const FaceIndex g = M_.face(M_.opposite(h));
                if (g == Mesh::null_face() || reg_.index.count(std::uint32_t(g)) ||
                    !taken.insert(std::uint32_t(g)).second)
                    continue;
                if (M_.next(M_.next(M_.next(M_.halfedge(g)))) != M_.halfedge(g)) continue;
                openAsItself(g, !acceptable(g));
            }
        }
    }
    // The seam optimisation may also change the faces around the re-triangulated ones (seamRings):
    // they join the faces replaced (by themselves, to begin with).
    {
        std::unordered_set<std::uint32_t> taken;
        for (FaceIndex f : cut_.replaced)
            taken.insert(std::uint32_t(f));
        std::vector<FaceIndex> ring;
        for (FaceIndex f : cut_.replaced)
            if (reg_.index.count(std::uint32_t(f))) ring.push_back(f);
        for (int k = 1; k < O_.seamRings; ++k) {
            std::vector<FaceIndex> next;
            for (FaceIndex f : ring)
                for (VertexIndex v : faceVertices(f))
                    for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_)) {
                        if (g == Mesh::null_face() || taken.count(std::uint32_t(g)) || !acceptable(g))
                            continue;
                        taken.insert(std::uint32_t(g));
                        next.push_back(g);
                        openAsItself(g, false);
                    }
            ring.swap(next);
        }
        // The faces the view does not see around the mesh vertices on the seam (behind a crease the
        // patch boundary runs along): flips among them (in their plane) bring those vertices' valence
        // down, where the patch's faces in front have raised it.
        std::vector<FaceIndex> unseen;
        for (const auto& pe : comp_.pedges)
            for (int id : pe.line) {
                const LVert& l = cut_.L[std::size_t(id)];
                if (l.kind != LVert::Region) continue;
                const VertexIndex v(l.cur);
                for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_))
                    if (g != Mesh::null_face() && !taken.count(std::uint32_t(g)) && !acceptable(g) &&
                        M_.next(M_.next(M_.next(M_.halfedge(g)))) == M_.halfedge(g)) {
                        taken.insert(std::uint32_t(g));
                        unseen.push_back(g);
                    }
            }
        for (FaceIndex g : unseen)
            openAsItself(g, true);
    }
    // Patch faces, the boundary ones re-triangulated over the seam vertices of their edges; the core's
    // (findCore) go straight into the mesh after the others (Plan::coreFaces).
    const std::vector<char> core = findCore();
    StageClock::lap("assemble:core");
    double patchArea = cut_.coreArea;
    std::vector<int> bad;
    for (std::size_t i = 0; i < faces_.size(); ++i) {
        if (!core.empty() && core[i]) continue;
        const int f = faces_[i];
        progress_.tick();
        const auto& t = P_.tri[std::size_t(f)];
        std::vector<int> poly;
        std::vector<unsigned> edges;
        for (int k = 0; k < 3; ++k) {
            const int p = t[std::size_t(k)], q = t[std::size_t((k + 1) % 3)];
            poly.push_back(localOfPatch(p));
            edges.push_back((1u << k) | (1u << ((k + 2) % 3)));
            auto it = comp_.pedgeIndex.find(dirKey(std::uint32_t(p), std::uint32_t(q)));
            if (it != comp_.pedgeIndex.end()) {
                const auto& line = comp_.pedges[std::size_t(it->second)].line;
                poly.insert(poly.end(), line.begin() + 1, line.end() - 1);
                edges.insert(edges.end(), line.size() - 2, 1u << k);
            }
        }
        const float q = P_.hasQuality ? P_.quality[std::size_t(f)] : kInputFaceQuality;
        const std::int32_t sid = P_.hasScanId ? P_.scanId[std::size_t(f)] : -1;
        const std::size_t before = cut_.newFaces.size();
        const double floor = std::min(O_.minAngleFloorDeg * kDeg,
                                      0.999 * minAngle(P_.pos[std::size_t(t[0])], P_.pos[std::size_t(t[1])],
                                                       P_.pos[std::size_t(t[2])]));
        if (!triangulatePolygon(poly, edges, q, sid, floor)) {
            for (int v : t)
                bad.push_back(v);
            continue;
        }
        for (std::size_t i = before; i < cut_.newFaces.size(); ++i) {
            const auto& nf = cut_.newFaces[i].v;
            patchArea += area2(cut_.L[std::size_t(nf[0])].uv, cut_.L[std::size_t(nf[1])].uv,
                               cut_.L[std::size_t(nf[2])].uv);
        }
    }
    if (!bad.empty())
        return fail(a, "some of its boundary triangles cannot be joined to the seam", std::move(bad));
    if (std::abs(patchArea - insideArea) > 1e-6 * insideArea)
        return fail(a, "it overlaps itself in the scan's view");
    return true;
}

void ComponentStitcher::openAsItself(FaceIndex g, bool offView) {
    const auto vs = faceVertices(g);
    const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
    cut_.replaced.push_back(g);
    cut_.newFaces.push_back({{regionVertex(vs[0]), regionVertex(vs[1]), regionVertex(vs[2])},
                             curHasQuality_ ? curQuality_[g] : kInputFaceQuality,
                             curHasScanId_ ? curScanId_[g] : -1,
                             false,
                             normalOf(A, B, C).normalized(),
                             std::min(O_.minAngleFloorDeg * kDeg, 0.999 * minAngle(A, B, C)),
                             offView});
}

int ComponentStitcher::localOfPatch(int p) {
    auto it = cut_.lidOfPatch.find(p);
    if (it != cut_.lidOfPatch.end()) return it->second;
    LVert l;
    l.kind = LVert::PatchInterior;
    l.patchA = p;
    l.pos = P_.pos[std::size_t(p)];
    l.uv = P_.uv[std::size_t(p)];
    const int id = addLocal(l);
    cut_.lidOfPatch[p] = id;
    return id;
}

} // namespace fss::detail::stitching
