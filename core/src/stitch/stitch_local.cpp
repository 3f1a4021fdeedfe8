// Stitch stage "local" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

namespace fss::detail::stitching {

std::pair<std::uint32_t, std::uint32_t> ComponentStitcher::seamKey(VertexIndex a, VertexIndex b) {
    return std::minmax(std::uint32_t(a), std::uint32_t(b));
}

std::vector<std::size_t> ComponentStitcher::growthOrder(const std::vector<std::array<VertexIndex, 3>>& faces,
                                                        const Mesh& m) {
    IndexMap<std::size_t, std::uint64_t> byEdge;
    for (std::size_t i = 0; i < faces.size(); ++i)
        for (int k = 0; k < 3; ++k)
            byEdge[dirKey(std::uint32_t(faces[i][std::size_t(k)]),
                          std::uint32_t(faces[i][std::size_t((k + 1) % 3)]))] = i;
    std::vector<std::size_t> order;
    std::vector<char> done(faces.size(), 0);
    std::deque<std::size_t> queue;
    for (std::size_t i = 0; i < faces.size(); ++i)
        for (int k = 0; k < 3 && !done[i]; ++k) {
            const VertexIndex a = faces[i][std::size_t(k)], b = faces[i][std::size_t((k + 1) % 3)];
            if (!m.has_valid_index(a) || !m.has_valid_index(b) || m.is_removed(a) || m.is_removed(b))
                continue;
            const auto h = m.halfedge(a, b);
            if (h != Mesh::null_halfedge() && m.is_border(h)) {
                done[i] = 1;
                queue.push_back(i);
            }
        }
    auto drain = [&] {
        while (!queue.empty()) {
            const std::size_t i = queue.front();
            queue.pop_front();
            order.push_back(i);
            for (int k = 0; k < 3; ++k) {
                const std::size_t* j = byEdge.find(dirKey(std::uint32_t(faces[i][std::size_t((k + 1) % 3)]),
                                                          std::uint32_t(faces[i][std::size_t(k)])));
                if (j && !done[*j]) {
                    done[*j] = 1;
                    queue.push_back(*j);
                }
            }
        }
    };
    drain();
    for (std::size_t i = 0; i < faces.size(); ++i)
        if (!done[i]) {
            done[i] = 1;
            queue.push_back(i);
            drain();
        }
    return order;
}

std::vector<char> ComponentStitcher::findCore() {
    // Components smaller than this, or cores smaller than that, go whole through the local mesh.
    constexpr std::size_t kMinComponentFaces = 2048, kMinCoreFaces = 512;
    std::vector<char> core;
    cut_.coreFaces.clear();
    cut_.coreBorder.clear();
    cut_.coreChords.clear();
    cut_.coreArea = 0;
    if (!bypass_ || faces_.size() < kMinComponentFaces) return core;
    const std::size_t n = P_.pos.size();
    // The faces around every vertex of the component (compressed rows: positions in faces_).
    std::vector<std::uint32_t> start(n + 1, 0);
    for (int f : faces_)
        for (int v : P_.tri[std::size_t(f)])
            ++start[std::size_t(v) + 1];
    for (std::size_t v = 0; v < n; ++v)
        start[v + 1] += start[v];
    std::vector<std::uint32_t> around(start[n]), fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < faces_.size(); ++i)
        for (int v : P_.tri[std::size_t(faces_[i])])
            around[fill[std::size_t(v)]++] = std::uint32_t(i);
    // Rings from the boundary, breadth first, up to coreRings() − 1; unreached vertices lie deeper.
    const int rings = coreRings();
    std::vector<int> depth(n, -1);
    std::vector<int> queue(comp_.boundary.begin(), comp_.boundary.end());
    for (int v : queue)
        depth[std::size_t(v)] = 0;
    for (std::size_t q = 0; q < queue.size(); ++q) {
        const int v = queue[q];
        if (depth[std::size_t(v)] + 1 >= rings) continue;
        for (std::uint32_t j = start[std::size_t(v)]; j < start[std::size_t(v) + 1]; ++j)
            for (int w : P_.tri[std::size_t(faces_[around[j]])])
                if (depth[std::size_t(w)] < 0) {
                    depth[std::size_t(w)] = depth[std::size_t(v)] + 1;
                    queue.push_back(w);
                }
    }
    core.assign(faces_.size(), 0);
    std::size_t count = 0;
    for (std::size_t i = 0; i < faces_.size(); ++i) {
        const auto& t = P_.tri[std::size_t(faces_[i])];
        core[i] =
            depth[std::size_t(t[0])] < 0 && depth[std::size_t(t[1])] < 0 && depth[std::size_t(t[2])] < 0;
        count += std::size_t(core[i]);
    }
    if (count < kMinCoreFaces) return {};
    // A face degenerate in 3D (the view's rounding can hide it) would fail the checks: no bypass then.
    for (std::size_t i = 0; i < faces_.size(); ++i) {
        if (!core[i]) continue;
        const auto& t = P_.tri[std::size_t(faces_[i])];
        if (CGAL::collinear(toPoint(P_.pos[std::size_t(t[0])]), toPoint(P_.pos[std::size_t(t[1])]),
                            toPoint(P_.pos[std::size_t(t[2])])))
            return {};
    }
    // The core's border: edges whose other face (b → a, in the component: the core's vertices are not on
    // its boundary) is not a core face.
    for (std::size_t i = 0; i < faces_.size(); ++i) {
        if (!core[i]) continue;
        const int f = faces_[i];
        const auto& t = P_.tri[std::size_t(f)];
        std::uint8_t bits = 0;
        for (int k = 0; k < 3; ++k) {
            const int a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
            bool coreBeyond = false;
            for (std::uint32_t j = start[std::size_t(b)]; j < start[std::size_t(b) + 1] && !coreBeyond; ++j) {
                const auto& u = P_.tri[std::size_t(faces_[around[j]])];
                for (int m = 0; m < 3; ++m)
                    if (u[std::size_t(m)] == b && u[std::size_t((m + 1) % 3)] == a)
                        coreBeyond = core[around[j]] != 0;
            }
            if (!coreBeyond) bits |= std::uint8_t(1u << k);
        }
        cut_.coreFaces.push_back(f);
        cut_.coreBorder.push_back(bits);
        for (int k = 0; k < 3; ++k)
            if (bits & (1u << k))
                depth[std::size_t(t[std::size_t(k)])] = depth[std::size_t(t[std::size_t((k + 1) % 3)])] = -2;
        cut_.coreArea += area2(P_.uv[std::size_t(t[0])], P_.uv[std::size_t(t[1])], P_.uv[std::size_t(t[2])]);
    }
    // Inner edges of the core between two of its border vertices: S must not have them too (coreFits).
    for (std::size_t i = 0; i < cut_.coreFaces.size(); ++i) {
        const auto& t = P_.tri[std::size_t(cut_.coreFaces[i])];
        for (int k = 0; k < 3; ++k) {
            const int a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
            if (!(cut_.coreBorder[i] & (1u << k)) && a < b && depth[std::size_t(a)] == -2 &&
                depth[std::size_t(b)] == -2)
                cut_.coreChords.push_back({a, b});
        }
    }
    coreMask_ = core;
    return core;
}

void ComponentStitcher::dissolveCore() {
    for (int f : cut_.coreFaces) {
        const auto& t = P_.tri[std::size_t(f)];
        const double floor = std::min(O_.minAngleFloorDeg * kDeg,
                                      0.999 * minAngle(P_.pos[std::size_t(t[0])], P_.pos[std::size_t(t[1])],
                                                       P_.pos[std::size_t(t[2])]));
        cut_.newFaces.push_back({{localOfPatch(t[0]), localOfPatch(t[1]), localOfPatch(t[2])},
                                 P_.hasQuality ? P_.quality[std::size_t(f)] : kInputFaceQuality,
                                 P_.hasScanId ? P_.scanId[std::size_t(f)] : -1,
                                 true,
                                 Vec3(0, 0, 0),
                                 floor,
                                 false});
    }
    cut_.coreFaces.clear();
    cut_.coreBorder.clear();
    cut_.coreChords.clear();
    coreMask_.clear();
}

bool ComponentStitcher::retryWithoutCore(Attempt& a) {
    bypass_ = false;
    dissolveCore();
    a = Attempt{};
    return buildAndOptimise(a);
}

bool ComponentStitcher::coreFits(Local& loc) {
    const Mesh& S = loc.star.S;
    // Every core border edge a → b is a border halfedge of S ...
    std::vector<HalfedgeIndex> borders;
    for (const auto& [x, y] : loc.coreEdges) {
        if (S.is_removed(x) || S.is_removed(y)) return false;
        const HalfedgeIndex h = S.halfedge(x, y);
        if (h == Mesh::null_halfedge() || !S.is_border(h)) return false;
    }
    // ... and there is no other border halfedge at those vertices: the hole is exactly the core's.
    for (std::size_t i = 0; i < loc.coreEdges.size(); ++i) {
        const VertexIndex v = loc.coreEdges[i].first;
        if (S.halfedge(v) == Mesh::null_halfedge()) return false;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S))
            for (HalfedgeIndex g : {h, S.opposite(h)})
                if (S.is_border(g)) borders.push_back(g);
    }
    std::sort(borders.begin(), borders.end());
    borders.erase(std::unique(borders.begin(), borders.end()), borders.end());
    if (borders.size() != loc.coreEdges.size()) return false;
    // The core's inner edges between border vertices are not edges of S (no edge twice).
    for (const auto& [p, q] : cut_.coreChords) {
        const VertexIndex *x = loc.coreVertex.find(std::uint32_t(p)),
                          *y = loc.coreVertex.find(std::uint32_t(q));
        if (!x || !y || S.halfedge(*x, *y) != Mesh::null_halfedge()) return false;
    }
    // No kept face overlaps a core face in the view (disjoint in the view, disjoint in 3D: the
    // self-intersection test of the local mesh need not see the core).
    for (FaceIndex f : S.faces()) {
        if (!loc.star.kept[f]) continue;
        std::array<Point2, 3> q;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S)) {
            double w;
            if (k == 3 || !V_.project(pt(S, v), q[std::size_t(k)], w)) return false;
            ++k;
        }
        if (k != 3) return false;
        const CGAL::Bbox_2 box = bboxOf(q[0], q[1], q[2]);
        const bool flat = CGAL::collinear(q[0], q[1], q[2]);
        const Triangle2 kept = CGAL::orientation(q[0], q[1], q[2]) == CGAL::RIGHT_TURN
                                   ? Triangle2(q[0], q[2], q[1])
                                   : Triangle2(q[0], q[1], q[2]);
        bool overlap = false;
        comp_.grid.query(box, [&](int i) {
            if (overlap || !coreMask_[std::size_t(i)]) return;
            if (!CGAL::do_overlap(box, triBox(faces_[std::size_t(i)]))) return;
            overlap = flat || CGAL::do_intersect(kept, patchTriangle(faces_[std::size_t(i)]));
        });
        if (overlap) return false;
    }
    return true;
}

bool ComponentStitcher::buildAndOptimise(Attempt& a) {
    heldRim_.clear();
    bandMinAfterDeg_ = -1;
    Local loc;
    Mesh& S = loc.star.S;
    StageClock::lap("other");
    if (!buildStar(M_, cut_.replaced, loc.star)) return fail(a, "the mesh is not manifold near its seam");
    StageClock::lap("star");
    // A copy is cheaper than building the star again (the copied maps address the copy's arrays).
    loc.pristine = loc.star;
    StageClock::lap("star copy");
    loc.pristine.cur = loc.pristine.S.property_map<VertexIndex, std::uint32_t>("v:cur").first;
    loc.pristine.kept = loc.pristine.S.property_map<FaceIndex, bool>("f:kept").first;
    loc.lid = S.add_property_map<VertexIndex, int>("v:lid", -1).first;
    loc.uv = S.add_property_map<VertexIndex, Point2>("v:uv", Point2(0, 0)).first;
    loc.locked = S.add_property_map<VertexIndex, bool>("v:locked", false).first;
    loc.quality = S.add_property_map<FaceIndex, float>("f:q", kInputFaceQuality).first;
    loc.scanId = S.add_property_map<FaceIndex, std::int32_t>("f:s", -1).first;
    loc.patchSide = S.add_property_map<FaceIndex, bool>("f:patch", false).first;
    loc.planeNormal = S.add_property_map<FaceIndex, Vec3>("f:plane", Vec3(0, 0, 0)).first;
    loc.minAllowed = S.add_property_map<FaceIndex, double>("f:floor", 0.0).first;
    loc.offView = S.add_property_map<FaceIndex, bool>("f:offview", false).first;
    // Border edges around the replaced faces before (must be the same after: no new holes).
    const auto bordersBefore = bordersAround(loc);
    // Map local ids to S vertices.
    std::vector<VertexIndex> sv(cut_.L.size());
    std::unordered_set<std::uint32_t> reusedCur;
    for (const LFace& f : cut_.newFaces)
        for (int id : f.v)
            if (cut_.L[std::size_t(id)].kind == LVert::Region) reusedCur.insert(cut_.L[std::size_t(id)].cur);
    for (std::size_t i = 0; i < cut_.L.size(); ++i) {
        const LVert& l = cut_.L[i];
        if (!l.alive) continue;
        if (l.kind == LVert::Region) {
            const VertexIndex* it = loc.star.fromCurrent.find(l.cur);
            if (!it) continue; // a region vertex of no replaced face
            sv[i] = *it;
        }
    }
    // Fresh vertices are created on use, in order.
    std::vector<std::array<VertexIndex, 3>> faceVs;
    std::vector<Vec3> freshPos;
    for (const LFace& f : cut_.newFaces) {
        std::array<VertexIndex, 3> vs;
        for (int k = 0; k < 3; ++k) {
            const int id = f.v[std::size_t(k)];
            if (sv[std::size_t(id)] == VertexIndex()) {
                if (cut_.L[std::size_t(id)].kind == LVert::Region)
                    return fail(a, "internal error: a seam vertex is missing from the local mesh");
                sv[std::size_t(id)] = S.add_vertex(toPoint(cut_.L[std::size_t(id)].pos));
            }
            vs[std::size_t(k)] = sv[std::size_t(id)];
        }
        faceVs.push_back(vs);
    }
    for (VertexIndex v : S.vertices()) {
        // Vertices of the star only: their place in the view (vertices behind the eye keep the origin;
        // their faces are kept and always tested for intersections).
        double w;
        Point2 uv(0, 0);
        if (loc.star.cur[v] != kNone && V_.project(pt(S, v), uv, w)) loc.uv[v] = uv;
    }
    for (std::size_t i = 0; i < cut_.L.size(); ++i)
        if (sv[i] != VertexIndex()) {
            loc.lid[sv[i]] = int(i);
            loc.uv[sv[i]] = cut_.L[i].uv;
        }
    StageClock::lap("local:vertices");
    for (FaceIndex f : cut_.replaced)
        removeFaceKeeping(S, loc.star.faceFromCurrent.at(std::uint32_t(f)),
                          [&](VertexIndex v) { return reusedCur.count(loc.star.cur[v]) > 0; });
    StageClock::lap("local:remove");
    std::vector<int> bad;
    const auto order = growthOrder(faceVs, S);
    StageClock::lap("local:growthOrder");
    for (std::size_t i : order) {
        progress_.tick();
        const FaceIndex g = S.add_face(faceVs[i][0], faceVs[i][1], faceVs[i][2]);
        if (g == Mesh::null_face()) {
            for (int id : cut_.newFaces[i].v)
                addBad(bad, id);
            continue;
        }
        loc.star.kept[g] = false;
        loc.quality[g] = cut_.newFaces[i].quality;
        loc.scanId[g] = cut_.newFaces[i].scanId;
        loc.patchSide[g] = cut_.newFaces[i].patchSide;
        loc.planeNormal[g] = cut_.newFaces[i].planeNormal;
        loc.minAllowed[g] = cut_.newFaces[i].minAllowed;
        loc.offView[g] = cut_.newFaces[i].offView;
    }
    if (!bad.empty()) return fail(a, "its seam would not be manifold", std::move(bad));
    StageClock::lap("local:add_face");
    for (VertexIndex v : S.vertices()) {
        bool lockedV = S.is_border(v);
        for (FaceIndex f : CGAL::faces_around_target(S.halfedge(v), S))
            if (f == Mesh::null_face() || loc.star.kept[f]) lockedV = true;
        loc.locked[v] = lockedV || S.halfedge(v) == Mesh::null_halfedge();
    }
    for (const auto& pe : comp_.pedges)
        for (std::size_t j = 0; j + 1 < pe.line.size(); ++j)
            loc.seam.insert(seamKey(sv[std::size_t(pe.line[j])], sv[std::size_t(pe.line[j + 1])]));
    // The core's border in S (its vertices are border vertices of S, so locked above).
    for (std::size_t i = 0; i < cut_.coreFaces.size(); ++i) {
        const auto& t = P_.tri[std::size_t(cut_.coreFaces[i])];
        for (int k = 0; k < 3; ++k) {
            if (!(cut_.coreBorder[i] & (1u << k))) continue;
            VertexIndex ends[2];
            for (int e = 0; e < 2; ++e) {
                const int p = t[std::size_t((k + e) % 3)];
                const auto it = cut_.lidOfPatch.find(p);
                if (it == cut_.lidOfPatch.end() || sv[std::size_t(it->second)] == VertexIndex())
                    return retryWithoutCore(a);
                ends[e] = sv[std::size_t(it->second)];
                loc.coreVertex[std::uint32_t(p)] = ends[e];
                loc.coreVertexSet.insert(std::uint32_t(ends[e]));
            }
            loc.coreEdges.push_back({ends[0], ends[1]});
        }
    }

    StageClock::lap("local mesh");
    progress_.step(6, 8);
    if (O_.optimiseSeam) {
        const Refill refill = refill_ ? refillSeam(loc) : Refill::NotDone;
        if (refill == Refill::Broken) return retryWithoutRefill(a);
        if (refill == Refill::NotDone) optimise(loc, a.plan);
        if (remesh_ && refill != Refill::Applied && !remeshBand(loc, a.plan)) return retryWithoutRemesh(a);
    }
    StageClock::lap("optimise");
    progress_.step(7, 8);
    if (!validate(loc, bordersBefore, a)) {
        if (loc.coreBroken) return retryWithoutCore(a);
        if (loc.refilled) return retryWithoutRefill(a);
        if (loc.remeshed && stitch::bandDiagnostics())
            std::fprintf(stderr, "band: fails the checks (%s; v1 kept)\n", a.reason.c_str());
        if (loc.remeshed) return retryWithoutRemesh(a);
        return false;
    }
    StageClock::lap("validate:self-intersections");
    const bool ok = extractPlan(loc, a);
    StageClock::lap("plan:seam figures");
    return ok;
}

bool ComponentStitcher::retryWithoutRefill(Attempt& a) {
    refill_ = false;
    a = Attempt{};
    const bool ok = buildAndOptimise(a);
    refill_ = true;
    return ok;
}

bool ComponentStitcher::retryWithoutRemesh(Attempt& a) {
    remesh_ = false;
    a = Attempt{};
    const bool ok = buildAndOptimise(a);
    remesh_ = true;
    return ok;
}

bool ComponentStitcher::remeshBand(Local& loc, Plan& plan) {
    Mesh& S = loc.star.S;
    // The band: new faces the view sees with a vertex within kBandRings rings (over such faces) of the
    // seam line.
    constexpr int kBandRings = 2;
    auto usable = [&](FaceIndex f) { return f != Mesh::null_face() && !loc.star.kept[f] && !loc.offView[f]; };
    std::unordered_set<std::uint32_t> near;
    std::vector<VertexIndex> ring;
    for (const auto& [p, q] : loc.seam) {
        loc.seamLineLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
        for (std::uint32_t v : {p, q})
            if (near.insert(v).second) ring.push_back(VertexIndex(v));
    }
    loc.seamLineEdges = loc.seam.size();
    std::sort(ring.begin(), ring.end());
    for (int r = 0; r < kBandRings; ++r) {
        std::vector<VertexIndex> next;
        for (VertexIndex v : ring)
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S))
                if (usable(S.face(h)) && near.insert(std::uint32_t(S.source(h))).second)
                    next.push_back(S.source(h));
        std::sort(next.begin(), next.end());
        ring.swap(next);
    }
    stitch::BandRemeshInput in;
    in.mesh = &S;
    for (FaceIndex f : S.faces()) {
        if (!usable(f)) continue;
        for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
            if (near.count(std::uint32_t(v))) {
                in.band.push_back(f);
                break;
            }
    }
    // Built again past held rim vertices (growPastHeldRim): their whole stars join the band.
    for (std::uint32_t c : rimStars_) {
        const VertexIndex* v = loc.star.fromCurrent.find(c);
        if (!v || S.halfedge(*v) == Mesh::null_halfedge()) continue;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(*v), S))
            if (!S.is_border(h) && !loc.star.kept[S.face(h)] && !loc.patchSide[S.face(h)])
                in.band.push_back(S.face(h));
    }
    std::sort(in.band.begin(), in.band.end());
    in.band.erase(std::unique(in.band.begin(), in.band.end()), in.band.end());
    if (in.band.empty()) return true;
    in.camera = &V_.camera();
    in.fixed = [&](VertexIndex v) { return bool(loc.locked[v]); };
    in.vertexData = [&](VertexIndex to, VertexIndex from) {
        if (from == Mesh::null_vertex()) {
            loc.star.cur[to] = kNone;
            loc.lid[to] = -1;
            loc.locked[to] = false;
        } else {
            loc.star.cur[to] = loc.star.cur[from];
            loc.lid[to] = loc.lid[from];
            loc.uv[to] = loc.uv[from];
            loc.locked[to] = loc.locked[from];
        }
    };
    in.faceData = [&](FaceIndex to, FaceIndex from) {
        copyFace(loc, from, to);
        loc.star.kept[to] = false; // a face the band made is new
    };
    // Creases: pieces of old faces outside the patch carry their face's plane (reliable even for a
    // sliver piece); other faces their own normal unless they are slivers.
    in.creaseNormal = [&](FaceIndex f) -> Eigen::Vector3d {
        if (!loc.patchSide[f] && loc.planeNormal[f].squaredNorm() > 0) return loc.planeNormal[f].normalized();
        const HalfedgeIndex h = S.halfedge(f);
        const Vec3 a = pt(S, S.source(h)), b = pt(S, S.target(h)), c = pt(S, S.target(S.next(h)));
        return minAngle(a, b, c) >= 10.0 * kDeg ? Vec3(normalOf(a, b, c).normalized()) : Vec3(0, 0, 0);
    };
    in.edgeLength = comp_.h3;
    in.maxNormalTurnDeg = O_.maxNormalChangeDeg;
    // The band grows over new faces outside the patch only: moving the patch's samples beyond the first
    // rings puts them on its chords, up to a footprint off the reference (measured: fandisk, 80² scan).
    in.growable = [&](FaceIndex f) {
        return f != Mesh::null_face() && !loc.star.kept[f] && !loc.patchSide[f];
    };
    in.unseen = [&](FaceIndex f) { return !loc.star.kept[f] && loc.offView[f]; };
    in.growBelowDeg = 20.0;
    // The labels of where a face lies (the scan that made it, its quality) follow the surface: each band face
    // takes those of the draft face under its centroid, so the scanned area stays where the patch put it
    // whatever the splits, flips and moves did (Stitch.PatchInsideFlatGrid: the faces with the scan id cover
    // the patch's area within 0.5 %).
    std::vector<std::pair<float, std::int32_t>> draftLabels;
    in.draft = [&](const std::vector<FaceIndex>& faces) {
        for (FaceIndex f : faces)
            draftLabels.push_back({loc.quality[f], loc.scanId[f]});
    };
    const stitch::BandRemeshReport r = stitch::remeshBand(in);
    progress_.tick(in.band.size());
    const bool worse = r.minAngleAfterDeg < r.minAngleBeforeDeg &&
                       !(r.minAngleAfterDeg >= 20.0 && r.fracAbove30After >= r.fracAbove30Before);
    if (stitch::bandDiagnostics())
        std::fprintf(
            stderr,
            "band: %zu faces (+%zu grown), min %.2f -> %.2f%s; < 20 deg: %zu free, %zu held, %zu beyond, "
            "%zu unseen\n",
            in.band.size(), r.grown, r.minAngleBeforeDeg, r.minAngleAfterDeg, worse ? " WORSE (v1 kept)" : "",
            r.below20Free, r.below20Held, r.below20Beyond, r.below20Unseen);
    if (worse) return false;
    bandMinAfterDeg_ = r.minAngleAfterDeg;
    noteHeldRim(loc, r.faces);
    // Moved and new vertices: their place in the view; a mesh vertex that moved becomes a new vertex
    // (the old one goes with the replaced faces around it: its whole star is in the band).
    for (VertexIndex v : r.touched) {
        double w;
        Point2 uv;
        if (!V_.project(pt(S, v), uv, w)) return false;
        loc.uv[v] = uv;
        if (loc.star.cur[v] != kNone) {
            loc.star.cur[v] = kNone;
            loc.lid[v] = -1;
        }
    }
    for (std::size_t i = 0; i < r.faces.size(); ++i)
        if (r.origin[i] < draftLabels.size()) {
            loc.quality[r.faces[i]] = draftLabels[r.origin[i]].first;
            loc.scanId[r.faces[i]] = draftLabels[r.origin[i]].second;
        }
    loc.seam.clear();
    for (FaceIndex f : r.faces) {
        const HalfedgeIndex h = S.halfedge(f);
        const VertexIndex x = S.source(h), y = S.target(h), z = S.target(S.next(h));
        loc.seam.insert(seamKey(x, y));
        loc.seam.insert(seamKey(y, z));
        loc.seam.insert(seamKey(z, x));
    }
    loc.remeshed = true;
    plan.flips += r.flips;
    plan.collapses += r.collapses;
    return true;
}

auto ComponentStitcher::refillSeam(Local& loc) -> Refill {
    Mesh& S = loc.star.S;
    // The strip: new faces the view sees with a vertex on the seam or next to it (over new faces).
    std::unordered_set<std::uint32_t> near;
    for (const auto& [p, q] : loc.seam) {
        near.insert(p);
        near.insert(q);
        loc.seamLineLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
    }
    loc.seamLineEdges = loc.seam.size();
    std::vector<std::uint32_t> line(near.begin(), near.end());
    std::sort(line.begin(), line.end());
    for (std::uint32_t v : line)
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(VertexIndex(v)), S))
            if (!S.is_border(h) && !loc.star.kept[S.face(h)]) near.insert(std::uint32_t(S.source(h)));
    std::vector<FaceIndex> strip;
    for (FaceIndex f : S.faces()) {
        if (loc.star.kept[f] || loc.offView[f]) continue;
        for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
            if (near.count(std::uint32_t(v))) {
                strip.push_back(f);
                break;
            }
    }
    if (strip.empty()) return Refill::NotDone;
    stitch::StripRefillInput in;
    in.mesh = &S;
    in.strip = strip;
    in.uv = [&](VertexIndex v) { return Eigen::Vector2d(loc.uv[v].x(), loc.uv[v].y()); };
    in.keep = [&](VertexIndex v) { return bool(loc.locked[v]); };
    in.camera = &V_.camera();
    const stitch::StripRefill fill = stitch::refillStrip(in);
    progress_.tick(strip.size());
    if (!fill.ok) return Refill::NotDone;
    // Edit the local mesh: the strip goes, the fill comes (grown from the hole's border).
    struct Inherited {
        float quality;
        std::int32_t scanId;
        bool patchSide;
        Vec3 planeNormal;
        double minAllowed;
    };
    std::vector<Inherited> inherited;
    for (FaceIndex f : fill.parent)
        inherited.push_back(
            {loc.quality[f], loc.scanId[f], loc.patchSide[f], loc.planeNormal[f], loc.minAllowed[f]});
    std::unordered_set<std::uint32_t> keep;
    for (VertexIndex v : fill.kept)
        keep.insert(std::uint32_t(v));
    for (FaceIndex f : strip)
        removeFaceKeeping(S, f, [&](VertexIndex v) { return keep.count(std::uint32_t(v)) > 0; });
    std::vector<VertexIndex> vertexOf(fill.kept);
    for (std::size_t i = 0; i < fill.fresh.size(); ++i) {
        const VertexIndex v = S.add_vertex(toPoint(fill.fresh[i]));
        loc.uv[v] = Point2(fill.freshUv[i].x(), fill.freshUv[i].y());
        loc.lid[v] = -1;
        loc.locked[v] = false;
        loc.star.cur[v] = kNone;
        vertexOf.push_back(v);
    }
    std::vector<std::array<VertexIndex, 3>> faceVs;
    for (const auto& t : fill.triangles)
        faceVs.push_back(
            {vertexOf[std::size_t(t[0])], vertexOf[std::size_t(t[1])], vertexOf[std::size_t(t[2])]});
    loc.seam.clear();
    loc.refilled = true;
    for (std::size_t i : growthOrder(faceVs, S)) {
        const FaceIndex g = S.add_face(faceVs[i][0], faceVs[i][1], faceVs[i][2]);
        if (g == Mesh::null_face()) return Refill::Broken;
        loc.star.kept[g] = false;
        loc.quality[g] = inherited[i].quality;
        loc.scanId[g] = inherited[i].scanId;
        loc.patchSide[g] = inherited[i].patchSide;
        loc.planeNormal[g] = inherited[i].planeNormal;
        loc.minAllowed[g] = inherited[i].minAllowed;
        loc.offView[g] = false;
        for (int k = 0; k < 3; ++k)
            loc.seam.insert(seamKey(faceVs[i][std::size_t(k)], faceVs[i][std::size_t((k + 1) % 3)]));
    }
    return Refill::Applied;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> ComponentStitcher::bordersAround(Local& loc) const {
    std::set<std::pair<std::uint32_t, std::uint32_t>> out;
    const Mesh& S = loc.star.S;
    for (VertexIndex v : S.vertices()) {
        if (!loc.star.isFull(v) || S.halfedge(v) == Mesh::null_halfedge()) continue;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S))
            for (HalfedgeIndex g : {h, S.opposite(h)})
                if (S.is_border(g) && !(onCoreBorder(loc, S.source(g)) && onCoreBorder(loc, S.target(g))))
                    out.insert(std::minmax(loc.star.cur[S.source(g)], loc.star.cur[S.target(g)]));
    }
    return out;
}

VertexSet ComponentStitcher::seamNeighbourhood(Local& loc) const {
    const Mesh& S = loc.star.S;
    VertexSet inside(S.num_vertices());
    std::vector<VertexIndex> ring;
    for (const auto& [a, b] : loc.seam)
        for (std::uint32_t v : {a, b})
            if (inside.insert(v)) ring.push_back(VertexIndex(v));
    for (int r = 0; r < O_.seamRings; ++r) {
        std::vector<VertexIndex> next;
        for (VertexIndex v : ring)
            for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(v), S))
                if (inside.insert(std::uint32_t(w))) next.push_back(w);
        ring.swap(next);
    }
    return inside;
}

bool ComponentStitcher::oriented(const Local& loc, FaceIndex f, const Point2& ua, const Point2& ub,
                                 const Point2& uc, const Vec3& a, const Vec3& b, const Vec3& c) {
    if (loc.offView[f]) return normalOf(a, b, c).dot(loc.planeNormal[f]) > 0;
    return leftTurn(ua, ub, uc);
}

bool ComponentStitcher::oriented(const Local& loc, FaceIndex f, VertexIndex a, VertexIndex b,
                                 VertexIndex c) const {
    const Mesh& S = loc.star.S;
    return oriented(loc, f, loc.uv[a], loc.uv[b], loc.uv[c], pt(S, a), pt(S, b), pt(S, c));
}

std::vector<EdgeIndex> ComponentStitcher::edgesAround(const Mesh& S, const VertexSet& vertices) {
    // Not just the set of edges: an EdgeIndex keeps the halfedge it was made from (S.halfedge(e) returns
    // that one, and callers read directions from it), so which of an edge's two copies the sort leaves
    // first depends on the exact sequence std::sort is given. Keep it: the vertices in increasing order,
    // each one's halfedges in circulation order.
    std::vector<EdgeIndex> out;
    for (std::uint32_t v : vertices.sorted()) {
        const VertexIndex x(v);
        if (S.is_removed(x) || S.halfedge(x) == Mesh::null_halfedge()) continue;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(x), S))
            out.push_back(S.edge(h));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::vector<double> ComponentStitcher::seamDistance(const Local& loc, const VertexSet& within) const {
    const Mesh& S = loc.star.S;
    // By vertex index (infinity: not reached); `known` as the keys of a map would be.
    std::vector<double> dist(S.num_vertices(), std::numeric_limits<double>::infinity());
    std::vector<char> known(S.num_vertices(), 0);
    using Item = std::pair<double, std::uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    for (const auto& [a, b] : loc.seam)
        for (std::uint32_t v : {a, b})
            if (!std::exchange(known[v], char(1))) {
                dist[v] = 0.0;
                queue.push({0.0, v});
            }
    while (!queue.empty()) {
        const auto [d, v] = queue.top();
        queue.pop();
        if (d > dist[v]) continue;
        for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(VertexIndex(v)), S)) {
            if (!within.count(std::uint32_t(w))) continue;
            const double dw = d + (pt(S, VertexIndex(v)) - pt(S, w)).norm();
            if (!std::exchange(known[std::size_t(w)], char(1)) || dw < dist[std::size_t(w)]) {
                dist[std::size_t(w)] = dw;
                queue.push({dw, std::uint32_t(w)});
            }
        }
    }
    return dist;
}

} // namespace fss::detail::stitching
