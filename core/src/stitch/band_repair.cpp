// Stitch v2, design B: the repair of the band's faces still below the aim, the band's growth, the
// diagnostics (band_remesher.h).
#include "stitch/band_remesher.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace fss::stitch::band {

void BandRemesher::grow() {
    if (!in_.growable || stageOff("grow")) return;
    const double aim = in_.growBelowDeg * kBandDeg, floor = 20.0 * kBandDeg;
    for (int round = 0; round < in_.maxGrowRounds; ++round) {
        std::vector<FaceIndex> add;
        auto around = [&](VertexIndex v) {
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
                const FaceIndex g = S_.face(h);
                if (!S_.is_border(h) && !inBand(g) && growable(g)) add.push_back(g);
            }
        };
        auto touchesBand = [&](FaceIndex f) {
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
                for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_))
                    if (!S_.is_border(h) && inBand(S_.face(h))) return true;
            return false;
        };
        for (FaceIndex f : S_.faces()) {
            if (inBand(f) || !growable(f)) continue;
            const double a = faceMinAngle(f);
            if (a >= aim || (a >= floor && !touchesBand(f))) continue;
            add.push_back(f);
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
                around(v);
        }
        for (FaceIndex f : bandList_) {
            if (faceMinAngle(f) >= aim) continue;
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
                if (!(in_.fixed && in_.fixed(v)) && !wholeStarInBand(v)) around(v);
        }
        std::sort(add.begin(), add.end());
        add.erase(std::unique(add.begin(), add.end()), add.end());
        if (add.empty()) break;
        for (FaceIndex f : add) {
            at(band_, std::size_t(f), char(0)) = 1;
            bandList_.push_back(f);
        }
        report_.grown += add.size();
    }
    std::sort(bandList_.begin(), bandList_.end());
}

void BandRemesher::countBelow20() {
    if (!bandDiagnostics()) return;
    const double floor = 20.0 * kBandDeg;
    const char* e = std::getenv("FSS_STITCH_BAND_DIAG");
    const bool verbose = e && std::string(e) == "2";
    if (verbose) {
        // Band vertices of valence 9 or more (issue 4's seam criterion allows 4..8): held or free, and
        // whether the local mesh knows their whole star (a vertex on its border has an unknown valence).
        std::unordered_set<std::uint32_t> seen;
        for (std::size_t i = 0; i < band_.size(); ++i) {
            const FaceIndex f(static_cast<std::uint32_t>(i));
            if (!band_[i] || S_.is_removed(f)) continue;
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
                if (S_.degree(v) >= 9 && seen.insert(std::uint32_t(v)).second)
                    std::fprintf(stderr, "  vertex %u valence %zu%s%s%s crease %d\n", std::uint32_t(v),
                                 std::size_t(S_.degree(v)), isFixed(v) ? " fixed" : "",
                                 wholeStarInBand(v) ? "" : " rim", S_.is_border(v) ? " local-border" : "",
                                 creaseDegree(v));
        }
    }
    for (FaceIndex f : S_.faces()) {
        const bool band = inBand(f), unseen = in_.unseen && in_.unseen(f);
        if (!band && !unseen && !growable(f)) continue;
        if (faceMinAngle(f) >= floor) continue;
        if (!band && unseen) {
            ++report_.below20Unseen;
        } else if (!band) {
            ++report_.below20Beyond;
        } else {
            bool free = false;
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
                free = free || !isFixed(v);
            ++(free ? report_.below20Free : report_.below20Held);
            if (verbose) {
                std::fprintf(stderr, "  face %u %.2f deg%s:", std::uint32_t(f), faceMinAngle(f) / kBandDeg,
                             unseen ? " unseen" : "");
                for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
                    const VertexIndex v = S_.target(h);
                    const V3 p = detail::pos(S_, v), a = detail::pos(S_, S_.source(h)),
                             b = detail::pos(S_, S_.target(S_.next(h)));
                    std::fprintf(stderr, " [v%u %.1f deg%s%s crease %d deg %zu edge %.3g%s]",
                                 std::uint32_t(v), detail::angleBetween(a - p, b - p) / kBandDeg,
                                 isFixed(v) ? " fixed" : "", wholeStarInBand(v) ? "" : " rim",
                                 creaseDegree(v), std::size_t(S_.degree(v)), (p - a).norm(),
                                 isCrease(S_.source(h), v) ? " (crease)" : "");
                }
                std::fprintf(stderr, "\n");
            }
        }
    }
}

bool BandRemesher::repairPass() {
    const double aim = in_.minAngleDeg * kBandDeg;
    std::vector<std::pair<double, FaceIndex>> bad;
    for (std::size_t f = 0; f < band_.size(); ++f) {
        const FaceIndex g(static_cast<std::uint32_t>(f));
        if (!band_[f] || S_.is_removed(g)) continue;
        const double a = faceMinAngle(g);
        if (a < aim) bad.push_back({a, g});
    }
    std::sort(bad.begin(), bad.end());
    bool changed = false;
    for (const auto& [angle, f] : bad) {
        if (S_.is_removed(f) || !inBand(f) || faceMinAngle(f) >= aim) continue;
        if (repairFlip(f) || repairCollapse(f) || repairCap(f) || (!stageOff("split") && repairSplit(f)) ||
            (faceMinAngle(f) < kSplitFloorDeg * kBandDeg && repairStar(f))) {
            changed = true;
            ++report_.repairs;
        }
    }
    return changed;
}

bool BandRemesher::repairFlip(FaceIndex f) {
    const double before = faceMinAngle(f);
    for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
        if (!interiorEdge(h)) continue;
        const VertexIndex a = S_.source(h), b = S_.target(h);
        if (isCrease(a, b) || !detail::canFlip(S_, h)) continue;
        const FaceIndex g = S_.face(S_.opposite(h));
        if (unseen(f) != unseen(g)) continue;
        const VertexIndex c = S_.target(S_.next(h)), d = S_.target(S_.next(S_.opposite(h)));
        if (!valenceOk(a, -1) || !valenceOk(b, -1) || !valenceOk(c, 1) || !valenceOk(d, 1)) continue;
        const V3 pa = detail::pos(S_, a), pb = detail::pos(S_, b), pc = detail::pos(S_, c),
                 pd = detail::pos(S_, d);
        const double oldMin = std::min(before, faceMinAngle(g));
        const double newMin = std::min(detail::minAngle(pa, pd, pc), detail::minAngle(pb, pc, pd));
        if (!(newMin > oldMin + 0.5 * kBandDeg)) continue;
        const V3 quad = (areaVector(f) + areaVector(g)).normalized();
        const V3 n1 = referenceNormal(f, quad), n2 = referenceNormal(g, quad);
        const bool seen = !unseen(f);
        if (!acceptableFace(pa, pd, pc, n1, seen) || !acceptableFace(pa, pd, pc, n2, seen) ||
            !acceptableFace(pb, pc, pd, n1, seen) || !acceptableFace(pb, pc, pd, n2, seen))
            continue;
        if (distanceToRef(0.5 * (pc + pd), c) > 0.1 * (pc - pd).norm()) continue;
        CGAL::Euler::flip_edge(h, S_);
        ++report_.flips;
        return true;
    }
    return false;
}

bool BandRemesher::repairCollapse(FaceIndex f) {
    // Each of the face's interior edges, either way (its shortest edge first: the first of equal scores
    // wins): the collapse that gives the largest smallest angle around it, where that beats the face's. A
    // cap's shortest edge often cannot go (a valence, a normal) while another of its edges can.
    std::vector<std::pair<double, HalfedgeIndex>> edges;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_))
        if (interiorEdge(h))
            edges.push_back({(detail::pos(S_, S_.source(h)) - detail::pos(S_, S_.target(h))).norm(), h});
    if (edges.empty()) return false;
    std::stable_sort(edges.begin(), edges.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    const std::size_t tried = stageOff("collapseall") ? 1 : edges.size();
    VertexIndex bestFrom, bestTo;
    double best = faceMinAngle(f);
    for (std::size_t i = 0; i < tried; ++i) {
        const VertexIndex a = S_.source(edges[i].second), b = S_.target(edges[i].second);
        for (const auto& [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
            double score = -1;
            if (collapsible(from, to, score, 2.0) && score > best) {
                best = score;
                bestFrom = from;
                bestTo = to;
            }
        }
    }
    if (bestFrom == VertexIndex()) return false;
    collapse(bestFrom, bestTo);
    return true;
}

bool BandRemesher::repairCap(FaceIndex f) {
    const HalfedgeIndex h0 = S_.halfedge(f);
    HalfedgeIndex opposite = Mesh::null_halfedge();
    for (HalfedgeIndex h : CGAL::halfedges_around_face(h0, S_)) {
        // The angle at the corner opposite h.
        const V3 p = detail::pos(S_, S_.target(S_.next(h)));
        const V3 u = detail::pos(S_, S_.source(h)) - p, w = detail::pos(S_, S_.target(h)) - p;
        if (detail::angleBetween(u, w) > 120.0 * kBandDeg) opposite = h;
    }
    if (opposite == Mesh::null_halfedge() || !interiorEdge(opposite)) return false;
    minSplitGain_ = 1.0 + 1e-6; // the split must raise the smallest angle of the two faces
    const bool ok = split(opposite);
    minSplitGain_ = 0;
    return ok;
}

} // namespace fss::stitch::band
