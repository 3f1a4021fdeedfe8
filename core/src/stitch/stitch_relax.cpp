// Stitch stage "relax" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

#include <boost/container/small_vector.hpp>

namespace fss::detail::stitching {

namespace {
// FSS_STITCH_V1_OFF=collapse,refine,collapse+flip,smooth,needles,valence,search skips those passes of the
// seam optimisation where the band remesh follows (to measure what each changes after it; the retry without
// the band runs them all).
bool v1Off(const char* name) {
    static const std::string off = [] {
        const char* e = std::getenv("FSS_STITCH_V1_OFF");
        return e ? std::string(",") + e + "," : std::string();
    }();
    return off.find(std::string(",") + name + ",") != std::string::npos;
}
} // namespace

void ComponentStitcher::optimise(Local& loc, Plan& plan) {
    Mesh& S = loc.star.S;
    const bool bandFollows = remesh_ && !refill_;
    auto skip = [&](const char* name) { return bandFollows && v1Off(name); };
    const double maxTurn = O_.maxNormalChangeDeg * kDeg;
    const double shortEdge = O_.collapseEdgeRatio * comp_.h3;
    auto isNewFace = [&](FaceIndex f) { return f != Mesh::null_face() && !loc.star.kept[f]; };
    auto removable = [&](VertexIndex v) {
        const int id = loc.lid[v];
        // Mesh vertices stay (they carry the old surface's shape); crossings, patch and Steiner vertices
        // may go.
        return !loc.locked[v] && (id < 0 || cut_.L[std::size_t(id)].kind != LVert::Region);
    };
    // -- collapses: remove a into b
    auto tryCollapse = [&](VertexIndex a, VertexIndex b, double& score) -> bool {
        if (!removable(a)) return false;
        const bool seamA = seamVertex(loc, a), seamB = seamVertex(loc, b);
        if (seamA && seamB && !loc.seam.count(seamKey(a, b))) return false;
        const HalfedgeIndex h = S.halfedge(a, b);
        if (h == Mesh::null_halfedge() || !isNewFace(S.face(h)) || !isNewFace(S.face(S.opposite(h))))
            return false;
        if (!detail::canCollapse(S, S.edge(h), false)) return false;
        double oldMin = std::numbers::pi, newMin = std::numbers::pi;
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(a), S)) {
            const FaceIndex f = S.face(g);
            if (!isNewFace(f)) return false;
            // g ends at a, so the face is (a, target(next(g)), source(g)) counter-clockwise.
            const VertexIndex p = S.target(S.next(g)), q = S.source(g);
            oldMin = std::min(oldMin, minAngle(pt(S, a), pt(S, p), pt(S, q)));
            if (p == b || q == b) continue;
            if (!oriented(loc, f, b, p, q)) return false;
            if (CGAL::collinear(S.point(b), S.point(p), S.point(q))) return false;
            const Vec3 n0 = normalOf(pt(S, a), pt(S, p), pt(S, q)),
                       n1 = normalOf(pt(S, b), pt(S, p), pt(S, q));
            if (loc.patchSide[f]) {
                if (angleBetween(n0, n1) > maxTurn) return false;
            } else {
                // A piece of a mesh face outside the patch may not leave that face's plane (any more
                // than it already does at a patch vertex).
                const Vec3& n = loc.planeNormal[f];
                if (angleBetween(n1, n) > std::max(angleBetween(n0, n), kCoplanar)) return false;
            }
            newMin = std::min(newMin, minAngle(pt(S, b), pt(S, p), pt(S, q)));
        }
        if (newMin < oldMin) return false;
        score = newMin;
        return true;
    };
    // Collapses the candidate edges (a, b), by increasing key, each in the direction that leaves the
    // larger smallest angle around (edges gone or changed by earlier collapses are skipped).
    using Candidates = std::vector<std::pair<double, std::pair<VertexIndex, VertexIndex>>>;
    auto collapseEach = [&](Candidates& cands) {
        std::sort(cands.begin(), cands.end());
        std::size_t done = 0;
        for (const auto& c : cands) {
            progress_.tick();
            const auto [a, b] = c.second;
            if (S.is_removed(a) || S.is_removed(b) || S.halfedge(a, b) == Mesh::null_halfedge()) continue;
            double s1 = -1, s2 = -1;
            const bool ok1 = tryCollapse(a, b, s1), ok2 = tryCollapse(b, a, s2);
            if (!ok1 && !ok2) continue;
            const VertexIndex from = (ok1 && (!ok2 || s1 >= s2)) ? a : b, to = from == a ? b : a;
            collapse(loc, from, to);
            ++done;
        }
        plan.collapses += done;
        return done;
    };
    auto collapsePass = [&] {
        for (int pass = 0; pass < 4; ++pass) {
            const auto near = seamNeighbourhood(loc);
            Candidates cands;
            for (EdgeIndex e : edgesAround(S, near)) {
                const HalfedgeIndex h = S.halfedge(e);
                const VertexIndex a = S.source(h), b = S.target(h);
                const double len = (pt(S, a) - pt(S, b)).norm();
                if (len < shortEdge) cands.push_back({len, {a, b}});
            }
            if (collapseEach(cands) == 0) break;
        }
    };
    StageClock::lap("optimise:other");
    if (!skip("collapse")) collapsePass();
    StageClock::lap("optimise:collapse");
    // -- refinement outside the patch: split long edges of the pieces around the seam (the new vertices
    // lie on the old surface: in a face's plane or on a mesh edge), graded from the patch's edge length
    // at the seam outwards, then flip within the faces' planes.
    for (int round = 0; round < 4 && O_.seamGrading > 0 && !skip("refine"); ++round) {
        if (refineOutside(loc) == 0) break;
        flipPass(loc, plan);
    }
    StageClock::lap("optimise:refine");
    if (!skip("collapse+flip")) {
        collapsePass();
        flipPass(loc, plan);
    }
    StageClock::lap("optimise:collapse+flip");
    // -- smoothing: the vertices added outside the patch move within their face's plane towards the
    // centre of their neighbours where that raises the smallest angle around them.
    for (int pass = 0; pass < 3 && !skip("smooth"); ++pass) {
        if (smoothOutside(loc) == 0) break;
        flipPass(loc, plan);
    }
    StageClock::lap("optimise:smooth");
    // -- needles: a face near the seam with a small angle loses its shortest edge when collapsing it
    // (either way, with every check of tryCollapse: no fold, no flip in the view, pieces outside stay
    // in their planes) raises the smallest angle around; then flip again.
    for (int pass = 0; pass < 3 && !skip("needles"); ++pass) {
        const auto near = seamNeighbourhood(loc);
        Candidates cands;
        for (const auto& [ang, f] : thinFaces(loc, near)) {
            const HalfedgeIndex h0 = S.halfedge(f);
            const VertexIndex v[3] = {S.source(h0), S.target(h0), S.target(S.next(h0))};
            int best = 0;
            double bestLen = std::numeric_limits<double>::infinity();
            for (int k = 0; k < 3; ++k) {
                const double len = (pt(S, v[k]) - pt(S, v[(k + 1) % 3])).norm();
                if (len < bestLen) {
                    bestLen = len;
                    best = k;
                }
            }
            cands.push_back({ang, {v[best], v[(best + 1) % 3]}});
        }
        if (collapseEach(cands) == 0) break;
        flipPass(loc, plan);
    }
    StageClock::lap("optimise:needles");
    if (!skip("valence")) valencePass(loc, plan);
    StageClock::lap("optimise:valence");
    // -- last smoothing: the free vertices near the seam whose smallest angle around is still small
    // search for a better place (smoothOutside with search; no flips after it, so the valences stay).
    for (int pass = 0; pass < 2 && !skip("search"); ++pass)
        if (smoothOutside(loc, true) == 0) break;
    StageClock::lap("optimise:search");
}

double ComponentStitcher::ringScore(const Local& loc,
                                    const std::vector<std::pair<VertexIndex, VertexIndex>>& ring,
                                    const std::vector<FaceIndex>& faces, const Vec3& p0, const Vec3& p1,
                                    bool floors, Point2& uv, double mustBeat, std::size_t* first) const {
    const Mesh& S = loc.star.S;
    // Each face's smallest angle at p1 once: the early test and the score below read the same doubles.
    const std::size_t n = ring.size();
    boost::container::small_vector<double, 16> after(n, 0.0);
    const std::size_t start = first && *first < n ? *first : 0;
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t i = (start + j) % n;
        after[i] = minAngle(p1, pt(S, ring[i].first), pt(S, ring[i].second));
        if (after[i] <= mustBeat) {
            if (first) *first = i;
            return -1.0;
        }
    }
    double w;
    if (!V_.project(p1, uv, w)) return -1.0;
    double m = std::numbers::pi;
    for (std::size_t i = 0; i < ring.size(); ++i) {
        const auto [p, q] = ring[i];
        if (!oriented(loc, faces[i], uv, loc.uv[p], loc.uv[q], p1, pt(S, p), pt(S, q)) ||
            CGAL::collinear(toPoint(p1), S.point(p), S.point(q)))
            return -1.0;
        if (loc.patchSide[faces[i]] &&
            angleBetween(normalOf(p0, pt(S, p), pt(S, q)), normalOf(p1, pt(S, p), pt(S, q))) >
                O_.maxNormalChangeDeg * kDeg)
            return -1.0;
        if (floors && after[i] < loc.minAllowed[faces[i]]) return -1.0;
        m = std::min(m, after[i]);
    }
    return m;
}

int ComponentStitcher::slideAlongEdge(Local& loc, VertexIndex v, bool search) {
    Mesh& S = loc.star.S;
    const LVert& l = cut_.L[std::size_t(loc.lid[v])];
    if (l.edgeU < 0) return 0;
    const Vec3 U = cut_.L[std::size_t(l.edgeU)].pos, W = cut_.L[std::size_t(l.edgeW)].pos;
    Vec3 centre(0, 0, 0);
    std::vector<std::pair<VertexIndex, VertexIndex>> ring;
    std::vector<FaceIndex> faces;
    for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
        const FaceIndex f = S.face(g);
        if (f == Mesh::null_face() || loc.star.kept[f]) return 0;
        ring.push_back({S.target(S.next(g)), S.source(g)});
        faces.push_back(f);
        centre += pt(S, S.source(g));
    }
    if (ring.size() < 3) return 0;
    centre /= double(ring.size());
    const double len2 = (W - U).squaredNorm();
    if (!(len2 > 0)) return 0;
    const Vec3 p0 = pt(S, v);
    double oldMin = std::numbers::pi;
    for (const auto& [p, q] : ring)
        oldMin = std::min(oldMin, minAngle(p0, pt(S, p), pt(S, q)));
    // The smallest angle around v moved to U + t (W - U), or -1 where a check fails.
    double bestMin = oldMin, bestT = -1;
    std::size_t firstFace = 0; // ringScore's first face to test
    auto score = [&](double t, Point2& uv) {
        return ringScore(loc, ring, faces, p0, U + t * (W - U), true, uv, bestMin, &firstFace);
    };
    Point2 bestUv;
    auto consider = [&](double t) {
        Point2 uv;
        const double m = score(t, uv);
        if (!(m > bestMin)) return;
        bestMin = m;
        bestT = t;
        bestUv = uv;
    };
    consider(std::clamp((centre - U).dot(W - U) / len2, kSlideEnd, 1.0 - kSlideEnd));
    if (search && bestMin < kSearchBelowDeg * kDeg)
        for (int k = 0; k <= kSlideSamples; ++k)
            consider(kSlideEnd + (1.0 - 2.0 * kSlideEnd) * double(k) / double(kSlideSamples));
    if (bestT < 0) return 0;
    S.point(v) = toPoint(U + bestT * (W - U));
    loc.uv[v] = bestUv;
    return 1;
}

std::size_t ComponentStitcher::smoothOutside(Local& loc, bool search) {
    Mesh& S = loc.star.S;
    const double maxTurn = O_.maxNormalChangeDeg * kDeg;
    const auto near = seamNeighbourhood(loc);
    const std::vector<std::uint32_t> order = near.sorted();
    std::size_t moved = 0;
    // Per vertex below (declared once: their storage is reused from vertex to vertex).
    std::vector<Vec3> planes, dirs;
    std::vector<std::pair<VertexIndex, VertexIndex>> ring; // (p, q): faces (v, p, q)
    std::vector<FaceIndex> ringFaces;
    std::vector<Triangle3> before;
    for (std::uint32_t vi : order) {
        progress_.tick();
        const VertexIndex v(vi);
        if (S.is_removed(v) || loc.locked[v] || loc.star.cur[v] != kNone) continue;
        if (S.halfedge(v) == Mesh::null_halfedge()) continue;
        // A seam vertex on a mesh edge slides along it; with `search`, one inside a mesh face (a patch
        // boundary vertex) moves like the points added outside, its patch side included.
        const bool onEdge = loc.lid[v] >= 0 && cut_.L[std::size_t(loc.lid[v])].edgeU >= 0;
        if (onEdge || (loc.lid[v] >= 0 && !search)) {
            moved += slideAlongEdge(loc, v, search);
            continue;
        }
        const bool withPatch = loc.lid[v] >= 0;
        // All faces around: pieces of one mesh face (a Steiner point inside it, not on a mesh edge), or
        // of two (a point on the mesh edge between them: it moves along that edge's line).
        planes.clear();
        bool outside = true;
        ring.clear();
        ringFaces.clear();
        Vec3 centre(0, 0, 0);
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
            const FaceIndex f = S.face(g);
            if (f == Mesh::null_face() || loc.star.kept[f] || (loc.patchSide[f] && !withPatch)) {
                outside = false;
                break;
            }
            const Vec3 n = loc.patchSide[f]
                               ? normalOf(pt(S, v), pt(S, S.target(S.next(g))), pt(S, S.source(g)))
                               : loc.planeNormal[f];
            if (std::none_of(planes.begin(), planes.end(),
                             [&](const Vec3& m) { return angleBetween(n, m) <= kCoplanar; }))
                planes.push_back(n);
            ring.push_back({S.target(S.next(g)), S.source(g)});
            ringFaces.push_back(f);
            centre += pt(S, S.source(g));
        }
        // Without `search` only a point inside one mesh face moves (to its neighbours' centre).
        if (!outside || ring.size() < 3 || (!search && planes.size() != 1)) continue;
        centre /= double(ring.size());
        const Vec3 p0 = pt(S, v);
        // The directions v may move in: the plane's (the mean plane where the pieces' planes differ by
        // little: a smoothly curved part of the mesh) and, between two planes, the line where they meet.
        Vec3 mean(0, 0, 0);
        double spread = 0;
        for (const Vec3& n : planes) {
            mean += n.normalized();
            for (const Vec3& m : planes)
                spread = std::max(spread, angleBetween(n, m));
        }
        mean.normalize();
        dirs.clear();
        if (planes.size() == 1 || spread <= maxTurn) {
            const Vec3 e1 = mean.unitOrthogonal(), e2 = mean.cross(e1);
            for (int k = 0; k < 8; ++k) {
                const double t = double(k) * std::numbers::pi / 4.0;
                dirs.push_back(std::cos(t) * e1 + std::sin(t) * e2);
            }
        }
        if (planes.size() == 2 && !withPatch) { // (the patch's planes are not exact: no line between them)
            const Vec3 d = planes[0].cross(planes[1]).normalized();
            if (d.allFinite()) {
                dirs.push_back(d);
                dirs.push_back(-d);
            }
        }
        if (dirs.empty()) continue;
        const Vec3 target = centre - mean * mean.dot(centre - p0);
        // How far a point moved to lies from the surface around v before (zero in one plane).
        before.clear();
        for (const auto& [p, q] : ring)
            before.emplace_back(toPoint(p0), S.point(p), S.point(q));
        const double maxGap = kNearPlanarFlipGap * comp_.h3;
        auto offSurface = [&](const Vec3& p1) {
            if (planes.size() == 1 && !withPatch) return false;
            double d2 = std::numeric_limits<double>::infinity();
            for (const Triangle3& t : before)
                d2 = std::min(d2, CGAL::to_double(CGAL::squared_distance(toPoint(p1), t)));
            return !(d2 <= maxGap * maxGap);
        };
        double oldMin = std::numbers::pi, nearest = std::numeric_limits<double>::infinity();
        for (const auto& [p, q] : ring) {
            oldMin = std::min(oldMin, minAngle(p0, pt(S, p), pt(S, q)));
            nearest = std::min(nearest, (pt(S, p) - p0).norm());
        }
        Vec3 best = p0;
        Point2 bestUv = loc.uv[v];
        double bestMin = oldMin;
        // The smallest angle around v moved to p1, or -1 where a face would turn over in the view (or,
        // unseen, against its plane) or degenerate, or where p1 cannot beat the best so far (the point-to-
        // triangle distances of offSurface last: they cost most).
        std::size_t firstFace = 0; // ringScore's first face to test
        auto score = [&](const Vec3& p1, Point2& uv) {
            const double m = ringScore(loc, ring, ringFaces, p0, p1, withPatch, uv, bestMin, &firstFace);
            return m < 0 || offSurface(p1) ? -1.0 : m;
        };
        // Keeps p1 when it beats the best so far.
        auto consider = [&](const Vec3& p1) {
            Point2 uv;
            const double m = score(p1, uv);
            if (!(m > bestMin)) return false;
            best = p1;
            bestUv = uv;
            bestMin = m;
            return true;
        };
        consider(target);
        // With `search`, where the smallest angle around stays below kSearchBelowDeg: a compass search
        // (the step halved when no direction helps) for the position with the largest smallest angle.
        if (search && bestMin < kSearchBelowDeg * kDeg) {
            double step = 0.25 * nearest;
            for (int level = 0, round = 0; level < kSearchLevels && round < kSearchRounds; ++round) {
                bool improved = false;
                const Vec3 from = best;
                for (const Vec3& d : dirs)
                    improved = consider(from + step * d) || improved;
                if (!improved) {
                    step *= 0.5;
                    ++level;
                }
            }
        }
        if (!(bestMin > oldMin)) continue;
        S.point(v) = toPoint(best);
        loc.uv[v] = bestUv;
        ++moved;
    }
    return moved;
}

std::size_t ComponentStitcher::refineOutside(Local& loc) {
    Mesh& S = loc.star.S;
    const auto near = seamNeighbourhood(loc);
    auto within = near;
    const std::vector<EdgeIndex> edges = edgesAround(S, near); // (S does not change until the splits)
    for (EdgeIndex e : edges)
        for (VertexIndex v : {S.source(S.halfedge(e)), S.target(S.halfedge(e))})
            within.insert(std::uint32_t(v));
    const auto dist = seamDistance(loc, within);
    auto distance = [&](VertexIndex v) {
        return std::size_t(v) < dist.size() ? dist[std::size_t(v)] : std::numeric_limits<double>::infinity();
    };
    std::vector<std::pair<double, EdgeIndex>> cands;
    for (EdgeIndex e : edges) {
        const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
        const FaceIndex f = S.face(h), g = S.face(o);
        if (f == Mesh::null_face() || g == Mesh::null_face() || loc.star.kept[f] || loc.star.kept[g])
            continue;
        if (loc.patchSide[f] || loc.patchSide[g]) continue;
        const Vec3 a = pt(S, S.source(h)), b = pt(S, S.target(h));
        const double len = (a - b).norm();
        const double target =
            comp_.h3 + O_.seamGrading * 0.5 * (distance(S.source(h)) + distance(S.target(h)));
        if (len > 4.0 / 3.0 * target) cands.push_back({len, e});
    }
    std::sort(cands.begin(), cands.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    std::size_t splits = 0;
    for (const auto& [len, e] : cands) {
        progress_.tick();
        if (S.is_removed(e)) continue;
        const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
        const FaceIndex f = S.face(h), g = S.face(o);
        const VertexIndex x = S.source(h), y = S.target(h);
        const Vec3 mid = 0.5 * (pt(S, x) + pt(S, y));
        Point2 uv;
        double w;
        if (!V_.project(mid, uv, w)) continue;
        // The split must leave all four triangles counter-clockwise in the view (pieces of a face the
        // view does not see: oriented like it) ...
        const VertexIndex z = S.target(S.next(h)), u = S.target(S.next(o));
        const Vec3 X = pt(S, x), Y = pt(S, y), Z = pt(S, z), U = pt(S, u);
        if (!oriented(loc, f, loc.uv[x], uv, loc.uv[z], X, mid, Z) ||
            !oriented(loc, f, uv, loc.uv[y], loc.uv[z], mid, Y, Z) ||
            !oriented(loc, g, loc.uv[y], uv, loc.uv[u], Y, mid, U) ||
            !oriented(loc, g, uv, loc.uv[x], loc.uv[u], mid, X, U))
            continue;
        // ... not put the new vertex nearer than a short seam edge to a neighbour of the edge's ends (two
        // vertices that close leave a thin piece no collapse can remove outside the patch) ...
        const double shortEdge = O_.collapseEdgeRatio * comp_.h3;
        bool crowded = false;
        for (VertexIndex end : {x, y})
            for (VertexIndex n : CGAL::vertices_around_target(S.halfedge(end), S))
                crowded = crowded || (n != x && n != y && (mid - pt(S, n)).norm() < shortEdge);
        if (crowded) continue;
        // ... and not make the smallest angle there worse.
        if (std::min({minAngle(X, mid, Z), minAngle(mid, Y, Z), minAngle(Y, mid, U), minAngle(mid, X, U)}) <
            0.99 * std::min(minAngle(X, Y, Z), minAngle(Y, X, U)))
            continue;
        const detail::EdgeSplit split = detail::splitEdge(S, h, toPoint(mid));
        const VertexIndex v = split.vertex;
        loc.uv[v] = uv;
        loc.lid[v] = -1;
        loc.locked[v] = false;
        loc.star.cur[v] = kNone;
        copyFace(loc, f, S.face(split.first));
        copyFace(loc, f, S.face(S.opposite(split.first)));
        copyFace(loc, g, S.face(split.second));
        copyFace(loc, g, S.face(S.opposite(split.second)));
        ++splits;
    }
    return splits;
}

void ComponentStitcher::copyFace(Local& loc, FaceIndex from, FaceIndex to) {
    if (from == to) return;
    loc.star.kept[to] = loc.star.kept[from];
    loc.quality[to] = loc.quality[from];
    loc.scanId[to] = loc.scanId[from];
    loc.patchSide[to] = loc.patchSide[from];
    loc.planeNormal[to] = loc.planeNormal[from];
    loc.minAllowed[to] = loc.minAllowed[from];
    loc.offView[to] = loc.offView[from];
}

bool ComponentStitcher::flipAllowed(const Local& loc, HalfedgeIndex h, const VertexSet& near, double& oldMin,
                                    double& newMin, bool& nearPlanar) const {
    const Mesh& S = loc.star.S;
    const double maxTurn = O_.maxNormalChangeDeg * kDeg;
    auto isNewFace = [&](FaceIndex f) { return f != Mesh::null_face() && !loc.star.kept[f]; };
    const HalfedgeIndex o = S.opposite(h);
    if (!isNewFace(S.face(h)) || !isNewFace(S.face(o))) return false;
    const VertexIndex x = S.source(h), y = S.target(h), z1 = S.target(S.next(h)), z2 = S.target(S.next(o));
    if (!near.count(std::uint32_t(x)) || !near.count(std::uint32_t(y))) return false;
    if (loc.seam.count(seamKey(x, y)) || !detail::canFlip(S, h)) return false;
    // New faces (x, z2, z1) and (z2, y, z1).
    if (loc.offView[S.face(h)] != loc.offView[S.face(o)] || !oriented(loc, S.face(h), x, z2, z1) ||
        !oriented(loc, S.face(o), z2, y, z1))
        return false;
    if (CGAL::collinear(S.point(x), S.point(z2), S.point(z1)) ||
        CGAL::collinear(S.point(z2), S.point(y), S.point(z1)))
        return false;
    const Vec3 X = pt(S, x), Y = pt(S, y), Z1 = pt(S, z1), Z2 = pt(S, z2);
    const Vec3 o1 = normalOf(X, Y, Z1), o2 = normalOf(Y, X, Z2), n1 = normalOf(X, Z2, Z1),
               n2 = normalOf(Z2, Y, Z1);
    // On the patch side a flip may not turn a normal more than maxNormalChangeDeg. Outside the patch
    // it may not change the surface: the pieces are coplanar, or they are pieces of one mesh face
    // (tilted only where they reach a patch vertex) and the new ones are tilted no more.
    const bool patchSide = loc.patchSide[S.face(h)];
    if (patchSide != loc.patchSide[S.face(o)]) return false;
    nearPlanar = false;
    const double turn =
        std::max({angleBetween(o1, n1), angleBetween(o1, n2), angleBetween(o2, n1), angleBetween(o2, n2)});
    if (patchSide) {
        if (turn > maxTurn) return false;
    } else if (turn > kCoplanar) {
        const Vec3 &p1 = loc.planeNormal[S.face(h)], &p2 = loc.planeNormal[S.face(o)];
        bool allowed = false;
        if (angleBetween(p1, p2) <= kCoplanar) {
            const double tilt = std::max(angleBetween(o1, p1), angleBetween(o2, p1));
            allowed =
                std::max(angleBetween(n1, p1), angleBetween(n2, p1)) <= tilt + kCoplanar && turn <= maxTurn;
        }
        // Pieces of two mesh faces that are nearly coplanar (a smoothly curved part of the mesh): the
        // flip moves the surface by the gap between the two diagonals, allowed up to a small
        // fraction of the patch's edge length (far below a pixel footprint).
        nearPlanar = !allowed && turn <= maxTurn && segmentGap(X, Y, Z1, Z2) <= kNearPlanarFlipGap * comp_.h3;
        if (!allowed && !nearPlanar) return false;
    }
    oldMin = std::min(minAngle(X, Y, Z1), minAngle(Y, X, Z2));
    newMin = std::min(minAngle(X, Z2, Z1), minAngle(Z2, Y, Z1));
    return true;
}

void ComponentStitcher::flip(Local& loc, HalfedgeIndex h, bool nearPlanar) {
    Mesh& S = loc.star.S;
    const HalfedgeIndex o = S.opposite(h);
    CGAL::Euler::flip_edge(h, S);
    if (nearPlanar) // the new pieces keep their own planes from now on
        for (HalfedgeIndex g : {h, o}) {
            const FaceIndex f = S.face(g);
            const HalfedgeIndex k = S.halfedge(f);
            loc.planeNormal[f] =
                normalOf(pt(S, S.source(k)), pt(S, S.target(k)), pt(S, S.target(S.next(k)))).normalized();
        }
}

void ComponentStitcher::flipPass(Local& loc, Plan& plan) {
    Mesh& S = loc.star.S;
    const auto near = seamNeighbourhood(loc);
    // Degrees and border flags, read once per vertex and pass and kept by the pass's flips (a flip changes
    // the degree of its four vertices by one and never which vertices are on the border): the score reads
    // them eight times per edge, each a walk around the vertex.
    std::vector<int> degree(S.num_vertices(), -1);
    std::vector<char> border(S.num_vertices(), 0);
    auto valenceCost = [&](VertexIndex v, int delta) {
        const std::size_t i = std::size_t(v);
        if (degree[i] < 0) {
            degree[i] = int(S.degree(v));
            border[i] = char(S.is_border(v));
        }
        const int target = border[i] ? 4 : 6;
        return std::abs(degree[i] + delta - target);
    };
    // `near` as a mask by vertex index: the loop below asks it twice per edge it takes from the queue.
    std::vector<char> isNear(S.num_vertices(), 0);
    for (std::uint32_t v : near)
        isNear[v] = 1;
    std::deque<EdgeIndex> queue;
    std::vector<char> queued(S.num_edges(), 0); // by edge index (a flip adds no edge)
    for (EdgeIndex e : edgesAround(S, near)) {
        const HalfedgeIndex h = S.halfedge(e);
        if (isNear[std::size_t(S.source(h))] && isNear[std::size_t(S.target(h))]) {
            queue.push_back(e);
            queued[std::uint32_t(e)] = 1;
        }
    }
    std::size_t flips = 0;
    const std::size_t maxFlips = 20 * queue.size() + 100;
    while (!queue.empty() && flips < maxFlips) {
        const EdgeIndex e = queue.front();
        queue.pop_front();
        progress_.tick();
        queued[std::uint32_t(e)] = 0;
        if (S.is_removed(e)) continue;
        const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
        // The score first (flipAllowed's own angles, the same doubles), the checks only for a flip worth
        // making: most edges near the seam fail the score, and the checks cost several times more.
        const FaceIndex fh = S.face(h), fo = S.face(o);
        if (fh == Mesh::null_face() || fo == Mesh::null_face() || loc.star.kept[fh] || loc.star.kept[fo])
            continue;
        const VertexIndex x = S.source(h), y = S.target(h), z1 = S.target(S.next(h)),
                          z2 = S.target(S.next(o));
        if (!isNear[std::size_t(x)] || !isNear[std::size_t(y)]) continue;
        const Vec3 X = pt(S, x), Y = pt(S, y), Z1 = pt(S, z1), Z2 = pt(S, z2);
        const auto [before, after] = loc.flipAngles.get(std::size_t(h), X, Y, Z1, Z2, [&] {
            return std::pair{std::min(minAngle(X, Y, Z1), minAngle(Y, X, Z2)),
                             std::min(minAngle(X, Z2, Z1), minAngle(Z2, Y, Z1))};
        });
        if (after < std::min(before, 20.0 * kDeg)) continue;
        const int devOld = valenceCost(x, 0) + valenceCost(y, 0) + valenceCost(z1, 0) + valenceCost(z2, 0);
        const int devNew = valenceCost(x, -1) + valenceCost(y, -1) + valenceCost(z1, 1) + valenceCost(z2, 1);
        // Score: smallest angle in degrees minus 3° per unit of valence deviation.
        if (!((after - before) / kDeg - 3.0 * double(devNew - devOld) > 0.5)) continue;
        double oldMin = 0, newMin = 0;
        bool nearPlanar = false;
        if (!flipAllowed(loc, h, near, oldMin, newMin, nearPlanar)) continue;
        const double gain = (newMin - oldMin) / kDeg - 3.0 * double(devNew - devOld);
        if (!(gain > 0.5) || newMin < std::min(oldMin, 20.0 * kDeg)) continue;
        flip(loc, h, nearPlanar);
        ++flips;
        // (all four degrees are known: the score read them)
        --degree[std::size_t(x)];
        --degree[std::size_t(y)];
        ++degree[std::size_t(z1)];
        ++degree[std::size_t(z2)];
        for (HalfedgeIndex g : {S.next(h), S.prev(h), S.next(o), S.prev(o)}) {
            const EdgeIndex ge = S.edge(g);
            if (!queued[std::uint32_t(ge)]) {
                queued[std::uint32_t(ge)] = 1;
                queue.push_back(ge);
            }
        }
    }
    plan.flips += flips;
}

std::vector<std::pair<double, FaceIndex>> ComponentStitcher::thinFaces(const Local& loc,
                                                                       const VertexSet& near) {
    const Mesh& S = loc.star.S;
    // The faces with a vertex in `near` (found around those vertices, not among all faces of S), each once
    // by increasing index: marked in a bitmap and read back in order (a FaceIndex is its index alone).
    std::vector<std::uint64_t> marks(S.num_faces() / 64 + 1, 0);
    for (std::uint32_t vi : near) {
        const VertexIndex v(vi);
        if (S.is_removed(v) || S.is_isolated(v)) continue;
        for (FaceIndex f : CGAL::faces_around_target(S.halfedge(v), S))
            if (f != Mesh::null_face())
                marks[std::size_t(f) / 64] |= std::uint64_t(1) << (std::size_t(f) % 64);
    }
    std::vector<FaceIndex> faces;
    for (std::size_t w = 0; w < marks.size(); ++w)
        for (std::uint64_t word = marks[w]; word; word &= word - 1)
            faces.push_back(FaceIndex(std::uint32_t(64 * w + std::size_t(std::countr_zero(word)))));
    std::vector<std::pair<double, FaceIndex>> thin;
    for (FaceIndex f : faces) {
        progress_.tick();
        if (loc.star.kept[f]) continue;
        const HalfedgeIndex h0 = S.halfedge(f);
        const VertexIndex v[3] = {S.source(h0), S.target(h0), S.target(S.next(h0))};
        const double ang = minAngle(pt(S, v[0]), pt(S, v[1]), pt(S, v[2]));
        if (ang < kNeedleDeg * kDeg) thin.push_back({ang, f});
    }
    std::sort(thin.begin(), thin.end()); // (angle, face): the same order however the faces were found
    return thin;
}

void ComponentStitcher::valencePass(Local& loc, Plan& plan) {
    Mesh& S = loc.star.S;
    const auto near = seamNeighbourhood(loc);
    std::unordered_set<std::uint32_t> seamVs;
    for (const auto& [a, b] : loc.seam) {
        seamVs.insert(a);
        seamVs.insert(b);
    }
    // Flips the candidate (flipAllowed) with the largest smallest angle after, above `above` and, when
    // the smallest angle before was larger, at least `floor`; none that raises a seam vertex above
    // kMaxSeamValence. Returns whether it flipped.
    std::size_t flips = 0;
    auto flipBest = [&](const std::vector<HalfedgeIndex>& candidates, double above, double floor) {
        HalfedgeIndex best = Mesh::null_halfedge();
        double bestMin = above;
        bool bestNearPlanar = false;
        for (HalfedgeIndex h : candidates) {
            double oldMin = 0, newMin = 0;
            bool nearPlanar = false;
            if (!flipAllowed(loc, h, near, oldMin, newMin, nearPlanar)) continue;
            if (newMin < std::min(oldMin, floor) || newMin <= bestMin) continue;
            const VertexIndex z1 = S.target(S.next(h)), z2 = S.target(S.next(S.opposite(h)));
            if ((seamVs.count(std::uint32_t(z1)) && S.degree(z1) >= kMaxSeamValence) ||
                (seamVs.count(std::uint32_t(z2)) && S.degree(z2) >= kMaxSeamValence))
                continue;
            best = h;
            bestMin = newMin;
            bestNearPlanar = nearPlanar;
        }
        if (best == Mesh::null_halfedge()) return false;
        flip(loc, best, bestNearPlanar);
        ++flips;
        return true;
    };
    std::vector<std::uint32_t> order(seamVs.begin(), seamVs.end());
    std::sort(order.begin(), order.end());
    for (std::uint32_t vi : order) {
        const VertexIndex v(vi);
        for (int guard = 0; guard < 4; ++guard) {
            progress_.tick();
            if (S.is_removed(v) || S.halfedge(v) == Mesh::null_halfedge() || S.degree(v) <= kMaxSeamValence)
                break;
            const auto around = CGAL::halfedges_around_target(S.halfedge(v), S);
            if (!flipBest({around.begin(), around.end()}, -1.0, kValenceFlipMinDeg * kDeg)) break;
        }
    }
    // A seam vertex with fewer than kMinSeamValence edges gains one by the flip of the edge opposite it
    // in one of its faces (every check of flipAllowed; the smallest angle there at least min(before,
    // 15°); the edge's ends keep kMinSeamValence edges when on the seam, 3 otherwise); the best first.
    for (std::uint32_t vi : order) {
        const VertexIndex v(vi);
        progress_.tick();
        if (S.is_removed(v) || S.halfedge(v) == Mesh::null_halfedge() || S.is_border(v) ||
            S.degree(v) >= kMinSeamValence)
            continue;
        std::vector<HalfedgeIndex> opposite;
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
            const HalfedgeIndex h = S.next(S.next(g)); // the side of g's face across from v
            bool keeps = !S.is_border(S.opposite(h));
            for (VertexIndex end : {S.source(h), S.target(h)})
                keeps = keeps && S.degree(end) > (seamVs.count(std::uint32_t(end)) ? kMinSeamValence : 3u);
            if (keeps) opposite.push_back(h);
        }
        flipBest(opposite, -1.0, kValenceFlipMinDeg * kDeg);
    }
    // Faces near the seam with a small angle: the flip of one of their edges that raises the smallest
    // angle there most (valence aside, but raising no seam vertex above kMaxSeamValence).
    for (const auto& [ang, f] : thinFaces(loc, near)) {
        progress_.tick();
        if (S.is_removed(f)) continue;
        const HalfedgeIndex h0 = S.halfedge(f);
        if (std::abs(minAngle(pt(S, S.source(h0)), pt(S, S.target(h0)), pt(S, S.target(S.next(h0)))) - ang) >
            1e-12)
            continue; // changed by an earlier flip
        const auto sides = CGAL::halfedges_around_face(h0, S);
        flipBest({sides.begin(), sides.end()}, ang + 0.5 * kDeg, 0.0);
    }
    plan.flips += flips;
}

bool ComponentStitcher::seamVertex(const Local& loc, VertexIndex v) const {
    return loc.seam.touches(std::uint32_t(v));
}

void ComponentStitcher::collapse(Local& loc, VertexIndex from, VertexIndex to) {
    Mesh& S = loc.star.S;
    const HalfedgeIndex h = S.halfedge(from, to);
    const EdgeIndex e = S.edge(h);
    const VertexIndex v0 = S.source(S.halfedge(e)), v1 = S.target(S.halfedge(e));
    const VertexIndex kept = CGAL::Euler::collapse_edge(e, S);
    (void)kept;
    if (v1 != to) {
        // The descriptor of `from` survived: give it the data of `to`.
        S.point(v1) = S.point(to);
        loc.lid[v1] = loc.lid[to];
        loc.uv[v1] = loc.uv[to];
        loc.locked[v1] = loc.locked[to];
        loc.star.cur[v1] = loc.star.cur[to];
    }
    // The seam edges at v0 become edges at v1 (v0's neighbours are v1's now): renamed in place, not by
    // rebuilding the whole set per collapse.
    const std::uint32_t a0 = std::uint32_t(v0), a1 = std::uint32_t(v1);
    int left = loc.seam.edgesAt(a0);
    if (left == 0) return;
    left -= int(loc.seam.erase(std::minmax(a0, a1)));
    for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(v1), S)) {
        if (left == 0) break;
        const std::uint32_t b = std::uint32_t(w);
        if (b == a1 || !loc.seam.erase(std::minmax(a0, b))) continue;
        --left;
        loc.seam.insert(std::minmax(a1, b));
    }
    if (left == 0) return;
    // A seam edge at v0 that is no edge of the mesh (not expected): rename every one of them.
    std::vector<SeamEdges::Key> rest;
    for (const auto& e : loc.seam)
        if (e.first == a0 || e.second == a0) rest.push_back(e);
    for (const auto& e : rest) {
        loc.seam.erase(e);
        const std::uint32_t b = e.first == a0 ? e.second : e.first;
        if (b != a1) loc.seam.insert(std::minmax(a1, b));
    }
}

} // namespace fss::detail::stitching
