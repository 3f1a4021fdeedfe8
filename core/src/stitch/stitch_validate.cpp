// Stitch stage "validate" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

namespace fss::detail::stitching {

std::vector<FaceIndex> ComponentStitcher::intersectionCandidates(Local& loc) {
    Mesh& S = loc.star.S;
    std::unordered_set<std::uint32_t> near;
    {
        const int rings = O_.seamRings + 2;
        std::vector<VertexIndex> ring;
        for (const auto& [a, b] : loc.seam)
            for (std::uint32_t v : {a, b})
                if (near.insert(v).second) ring.push_back(VertexIndex(v));
        for (int r = 0; r < rings; ++r) {
            std::vector<VertexIndex> next;
            for (VertexIndex v : ring)
                for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(v), S))
                    if (near.insert(std::uint32_t(w)).second) next.push_back(w);
            ring.swap(next);
        }
    }
    auto faceBox = [&](FaceIndex f) {
        CGAL::Bbox_2 b;
        for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
            b += loc.uv[v].bbox();
        return b;
    };
    std::vector<FaceIndex> out, kept;
    for (FaceIndex f : S.faces())
        if (loc.star.kept[f]) kept.push_back(f);
    BucketGrid keptGrid(4.0 * comp_.h2, S.num_faces());
    for (FaceIndex f : kept)
        keptGrid.insert(int(std::uint32_t(f)), faceBox(f));
    for (FaceIndex f : S.faces()) {
        bool take = loc.star.kept[f];
        if (!take)
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                if (near.count(std::uint32_t(v))) take = true;
        if (!take) {
            const CGAL::Bbox_2 b = faceBox(f);
            keptGrid.query(b, [&](int g) {
                if (!take && CGAL::do_overlap(b, faceBox(FaceIndex(std::uint32_t(g))))) take = true;
            });
        }
        if (take) out.push_back(f);
    }
    return out;
}

bool ComponentStitcher::validate(Local& loc,
                                 const std::set<std::pair<std::uint32_t, std::uint32_t>>& bordersBefore,
                                 Attempt& a) {
    Mesh& S = loc.star.S;
    if (!loc.coreEdges.empty() && !coreFits(loc)) {
        loc.coreBroken = true;
        return fail(a, "internal: the core does not fit its hole");
    }
    StageClock::lap("validate:core");
    std::vector<int> bad;
    auto badFace = [&](FaceIndex f) {
        Point2 c(0, 0);
        double x = 0, y = 0;
        for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S)) {
            x += loc.uv[v].x() / 3.0;
            y += loc.uv[v].y() / 3.0;
        }
        c = Point2(x, y);
        addNear(bad, c);
    };
    // Faces: not degenerate, facing the camera, no needles.
    bool needles = false;
    for (FaceIndex f : S.faces()) {
        progress_.tick();
        if (loc.star.kept[f]) continue;
        const HalfedgeIndex h = S.halfedge(f);
        const VertexIndex p = S.source(h), q = S.target(h), r = S.target(S.next(h));
        if (CGAL::collinear(S.point(p), S.point(q), S.point(r)) || !oriented(loc, f, p, q, r)) {
            badFace(f);
        } else if (minAngle(pt(S, p), pt(S, q), pt(S, r)) < loc.minAllowed[f]) {
            badFace(f);
            needles = true;
        }
    }
    if (!bad.empty() && !needles)
        return fail(a, "it would create degenerate or back-facing faces", std::move(bad));
    if (!bad.empty()) return fail(a, "it would create needle-like faces at its seam", std::move(bad));
    // Vertices: manifold (one umbrella) and no new border.
    std::vector<int> incoming(S.num_vertices(), 0);
    for (HalfedgeIndex h : S.halfedges())
        ++incoming[std::uint32_t(S.target(h))];
    for (VertexIndex v : S.vertices()) {
        if (S.halfedge(v) == Mesh::null_halfedge() || !loc.star.isFull(v)) continue;
        int n = 0, borders = 0;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S)) {
            ++n;
            borders += S.is_border(h);
        }
        // (A vertex on the core's border has a border gap per core fan: the core fills them, coreFits.)
        if (n != incoming[std::uint32_t(v)] || (borders > 1 && !onCoreBorder(loc, v))) {
            addNear(bad, loc.uv[v]);
        }
    }
    if (!bad.empty()) return fail(a, "it would create a non-manifold vertex", std::move(bad));
    for (FaceIndex f : S.faces())
        if (!loc.star.kept[f])
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                if (loc.star.cur[v] == kNone && S.is_border(v) && !onCoreBorder(loc, v)) badFace(f);
    const auto bordersAfter = bordersAround(loc);
    if (bordersAfter != bordersBefore) {
        // Locate the difference (a hole of the mesh under the patch, an edge left dangling).
        for (const auto* set : {&bordersAfter, &bordersBefore})
            for (const auto& e : *set)
                if (!(set == &bordersAfter ? bordersBefore : bordersAfter).count(e)) {
                    Point2 uv;
                    double w;
                    if (e.first != kNone && e.second != kNone &&
                        V_.project(0.5 * (toVec(M_.point(VertexIndex(e.first))) +
                                          toVec(M_.point(VertexIndex(e.second)))),
                                   uv, w))
                        addNear(bad, uv);
                }
    }
    if (!bad.empty() || bordersAfter != bordersBefore)
        return fail(a, "it would open or close a hole in the mesh", std::move(bad));
    // No new self-intersections among the local faces.
    StageClock::lap("validate:faces+vertices");
    std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
    const auto candidates = intersectionCandidates(loc);
    StageClock::lap("validate:candidates");
    progress_.tick(candidates.size());
    PMP::self_intersections(candidates, S, std::back_inserter(pairs));
    for (const auto& [f, g] : pairs) {
        if (!loc.star.kept[f]) badFace(f);
        if (!loc.star.kept[g]) badFace(g);
    }
    if (!bad.empty()) return fail(a, "it would make the mesh intersect itself", std::move(bad));
    if (O_.failValidationForTesting) return fail(a, "its final check was forced to fail for testing");
    return true;
}

std::vector<std::size_t> ComponentStitcher::growthOrderIn(const Mesh& S, const std::vector<FaceIndex>& sfaces,
                                                          const Local& loc) {
    // Position of each face of S in sfaces (kAbsent: not there).
    constexpr std::size_t kAbsent = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> index(S.num_faces(), kAbsent);
    for (std::size_t i = 0; i < sfaces.size(); ++i)
        index[std::size_t(sfaces[i])] = i;
    std::vector<char> done(sfaces.size(), 0);
    std::vector<std::size_t> order;
    order.reserve(sfaces.size());
    std::deque<std::size_t> queue;
    for (std::size_t i = 0; i < sfaces.size(); ++i)
        for (HalfedgeIndex h : CGAL::halfedges_around_face(S.halfedge(sfaces[i]), S)) {
            const FaceIndex g = S.face(S.opposite(h));
            // Next to a face that exists before the additions (kept, or left unchanged).
            if (!done[i] &&
                (g == Mesh::null_face() || loc.star.kept[g] || index[std::size_t(g)] == kAbsent)) {
                done[i] = 1;
                queue.push_back(i);
            }
        }
    auto drain = [&] {
        while (!queue.empty()) {
            const std::size_t i = queue.front();
            queue.pop_front();
            order.push_back(i);
            for (HalfedgeIndex h : CGAL::halfedges_around_face(S.halfedge(sfaces[i]), S)) {
                const FaceIndex g = S.face(S.opposite(h));
                if (g == Mesh::null_face() || loc.star.kept[g]) continue;
                const std::size_t j = index[std::size_t(g)];
                if (j != kAbsent && !done[j]) {
                    done[j] = 1;
                    queue.push_back(j);
                }
            }
        }
    };
    drain();
    for (std::size_t i = 0; i < sfaces.size(); ++i)
        if (!done[i]) {
            done[i] = 1;
            queue.push_back(i);
            drain();
        }
    return order;
}

bool ComponentStitcher::extractPlan(Local& loc, Attempt& a) {
    Mesh& S = loc.star.S;
    Plan& plan = a.plan;
    // Faces that come out exactly as they were stay in the mesh untouched (same index).
    std::map<std::array<std::uint32_t, 3>, FaceIndex> byCorners;
    auto corners = [](std::array<std::uint32_t, 3> c) {
        std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
        return c;
    };
    for (FaceIndex f : cut_.replaced) {
        const auto vs = faceVertices(f);
        byCorners[corners({std::uint32_t(vs[0]), std::uint32_t(vs[1]), std::uint32_t(vs[2])})] = f;
    }
    std::unordered_set<std::uint32_t> unchanged;
    // Vertices: current ones stay themselves, new ones are numbered in order of use.
    std::unordered_map<std::uint32_t, std::uint32_t> freshIndex;
    std::vector<std::array<VertexIndex, 3>> faces;
    std::vector<FaceIndex> sfaces;
    for (FaceIndex f : S.faces())
        if (!loc.star.kept[f]) {
            const HalfedgeIndex h = S.halfedge(f);
            const std::array<VertexIndex, 3> fv{S.source(h), S.target(h), S.target(S.next(h))};
            const std::array<std::uint32_t, 3> c{loc.star.cur[fv[0]], loc.star.cur[fv[1]],
                                                 loc.star.cur[fv[2]]};
            if (c[0] != kNone && c[1] != kNone && c[2] != kNone) {
                auto it = byCorners.find(corners(c));
                if (it != byCorners.end()) {
                    unchanged.insert(std::uint32_t(it->second));
                    continue;
                }
            }
            faces.push_back(fv);
            sfaces.push_back(f);
        }
    for (FaceIndex f : cut_.replaced)
        if (!unchanged.count(std::uint32_t(f))) plan.removed.push_back(f);
    std::unordered_set<std::uint32_t> reused;
    // Order faces for growth in the rehearsal mesh: the star as copied (same star, same removals).
    Star& rehearsal = loc.pristine;
    for (const auto& fv : faces)
        for (VertexIndex v : fv) {
            const std::uint32_t c = loc.star.cur[v];
            if (c != kNone) {
                if (reused.insert(c).second) plan.reused.push_back(VertexIndex(c));
            } else if (!freshIndex.count(std::uint32_t(v))) {
                freshIndex[std::uint32_t(v)] = std::uint32_t(plan.freshPositions.size());
                plan.freshPositions.push_back(pt(S, v));
            }
        }
    // Face order: growth order over the faces expressed in the rehearsal mesh after the removals.
    std::vector<std::array<PlanVertex, 3>> pf;
    for (const auto& fv : faces) {
        std::array<PlanVertex, 3> p;
        for (int k = 0; k < 3; ++k) {
            const VertexIndex v = fv[std::size_t(k)];
            const std::uint32_t c = loc.star.cur[v];
            p[std::size_t(k)] =
                c != kNone ? PlanVertex{c, false} : PlanVertex{freshIndex.at(std::uint32_t(v)), true};
        }
        pf.push_back(p);
    }
    StageClock::lap("plan");
    // Rehearse: add fresh vertices, remove the replaced faces, add the faces in growth order.
    std::vector<VertexIndex> fresh;
    for (const Vec3& p : plan.freshPositions)
        fresh.push_back(rehearsal.S.add_vertex(toPoint(p)));
    std::unordered_set<std::uint32_t> keep;
    for (VertexIndex v : plan.reused)
        keep.insert(std::uint32_t(rehearsal.fromCurrent.at(std::uint32_t(v))));
    for (FaceIndex f : plan.removed)
        removeFaceKeeping(rehearsal.S, rehearsal.faceFromCurrent.at(std::uint32_t(f)),
                          [&](VertexIndex v) { return keep.count(std::uint32_t(v)) > 0; });
    std::vector<std::array<VertexIndex, 3>> rf;
    for (const auto& p : pf) {
        std::array<VertexIndex, 3> r;
        for (int k = 0; k < 3; ++k)
            r[std::size_t(k)] = p[std::size_t(k)].fresh ? fresh[p[std::size_t(k)].index]
                                                        : rehearsal.fromCurrent.at(p[std::size_t(k)].index);
        rf.push_back(r);
    }
    const auto order = growthOrderIn(S, sfaces, loc);
    StageClock::lap("rehearsal:prepare");
    progress_.step(8, 8);
    for (std::size_t i : order) {
        progress_.tick();
        if (rehearsal.S.add_face(rf[i][0], rf[i][1], rf[i][2]) == Mesh::null_face())
            return fail(a, "internal error: the stitch could not be rehearsed");
    }
    StageClock::lap("rehearsal:add_face");
    for (std::size_t i : order) {
        plan.faces.push_back(pf[i]);
        plan.quality.push_back(loc.quality[sfaces[i]]);
        plan.scanId.push_back(loc.scanId[sfaces[i]]);
    }
    // Seam figures (after a refill, the seam's faces and vertices are the fill's).
    plan.seamEdges = loc.seam.size();
    std::unordered_set<std::uint32_t> seamVerts;
    for (const auto& [p, q] : loc.seam) {
        plan.seamLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
        seamVerts.insert(p);
        seamVerts.insert(q);
    }
    if (loc.refilled || loc.remeshed) {
        plan.seamEdges = loc.seamLineEdges;
        plan.seamLength = loc.seamLineLength;
    }
    for (std::uint32_t v : seamVerts)
        if (loc.star.isFull(VertexIndex(v))) plan.seamValences.push_back(S.degree(VertexIndex(v)));
    // The core: its vertices on its border are fresh vertices of the plan, the others come after them.
    IndexMap<std::uint32_t> planOf; // patch vertex → index among the plan's fresh vertices
    for (std::size_t i = 0; i < cut_.coreFaces.size(); ++i) {
        const int f = cut_.coreFaces[i];
        const auto& t = P_.tri[std::size_t(f)];
        std::array<PlanVertex, 3> p;
        for (int k = 0; k < 3; ++k) {
            const int v = t[std::size_t(k)];
            auto [slot, isNew] = planOf.try_emplace(std::uint32_t(v));
            if (isNew) {
                if (const VertexIndex* s = loc.coreVertex.find(std::uint32_t(v))) {
                    const auto it = freshIndex.find(std::uint32_t(*s));
                    if (it == freshIndex.end())
                        return fail(a, "internal error: a core vertex is not in the plan");
                    *slot = it->second;
                } else {
                    *slot = std::uint32_t(plan.freshPositions.size());
                    plan.freshPositions.push_back(P_.pos[std::size_t(v)]);
                }
            }
            p[std::size_t(k)] = PlanVertex{*slot, true};
        }
        plan.coreFaces.push_back(p);
        plan.coreBorder.push_back(cut_.coreBorder[i]);
        plan.coreQuality.push_back(P_.hasQuality ? P_.quality[std::size_t(f)] : kInputFaceQuality);
        plan.coreScanId.push_back(P_.hasScanId ? P_.scanId[std::size_t(f)] : -1);
    }
    StageClock::lap("plan:core");
    for (std::size_t i = 0; i < faces.size(); ++i) {
        const auto& fv = faces[i];
        if (!seamVerts.count(std::uint32_t(fv[0])) && !seamVerts.count(std::uint32_t(fv[1])) &&
            !seamVerts.count(std::uint32_t(fv[2])))
            continue;
        plan.seamFaceMinAngles.push_back(minAngle(pt(S, fv[0]), pt(S, fv[1]), pt(S, fv[2])) / kDeg);
    }
    return true;
}

} // namespace fss::detail::stitching
