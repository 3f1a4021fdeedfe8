// Stitch v2, design B: the seam band grown past held rim vertices (DESIGN.md §6.2, session 19). Member
// functions of ComponentStitcher (stitch_stages.h).
//
// The band (band_remesh.h) never moves a vertex that a kept face of the current mesh touches: the band's rim.
// Where a face the band leaves below 20 deg has such a corner, no re-triangulation inside the band can reach
// it (the main job's 19.44 deg: a rim vertex of valence 8 that ends a crease, the face's small angle at it,
// every variant of the compound repair's disk at 19.44 deg). Here the kept faces around such a corner are
// opened as themselves (as the seamRings ring is: replaced by copies that the band may change) and the
// component is built again with the corner's whole star in the band, so the corner moves like any band
// vertex (and a crease through it continues instead of ending there). The faces opened share a vertex with
// a replaced face, so they lie within the seam neighbourhood; every check of the stitch applies to the
// build again as to the first, and the first result stays unless the band's smallest angle rises.
#include "stitch/band_remesher.h"
#include "stitch/stitch_stages.h"

#include <cstdio>

namespace fss::detail::stitching {

namespace {
// Rounds of growth past the rim (each a build of the component again).
constexpr int kRimRounds = 2;
// Faces below this (degrees) ask for it: issue 19's bound on the faces a stitch creates.
constexpr double kRimBelowDeg = 20.0;
} // namespace

void ComponentStitcher::noteHeldRim(Local& loc, const std::vector<FaceIndex>& bandFaces) {
    const Mesh& S = loc.star.S;
    if (O_.seamRings < 1) return;
    // Only corners of the region's faces (seam faces, faces under the patch): the faces opened around them
    // then lie one ring from the region, as the seamRings ring does, within the seam neighbourhood (a corner
    // of a face of that ring would put them two rings out, past it where a region face barely meets the
    // patch: measured on couplingdown, a changed face outside the neighbourhood).
    std::unordered_set<std::uint32_t> regionVertices;
    auto inRegion = [&](std::uint32_t c) {
        if (regionVertices.empty())
            for (const auto* list : {&reg_.faces, &reg_.interior})
                for (FaceIndex f : *list)
                    for (VertexIndex w : faceVertices(f))
                        regionVertices.insert(std::uint32_t(w));
        return regionVertices.count(c) > 0;
    };
    for (FaceIndex f : bandFaces) {
        const HalfedgeIndex fh = S.halfedge(f);
        if (minAngle(pt(S, S.source(fh)), pt(S, S.target(fh)), pt(S, S.target(S.next(fh)))) >=
            kRimBelowDeg * kDeg)
            continue;
        for (VertexIndex v : CGAL::vertices_around_face(fh, S)) {
            // Held by kept faces only: not on the local mesh's border (its whole star is in S), not new.
            if (!loc.locked[v] || S.is_border(v) || !loc.star.isFull(v) || loc.star.cur[v] == kNone ||
                !inRegion(loc.star.cur[v])) {
                if (loc.locked[v] && stitch::band::bandDiagnosticsVerbose())
                    std::fprintf(stderr, "  rim: corner %u of a face below 20 deg not grown past: %s\n",
                                 std::uint32_t(v),
                                 S.is_border(v)             ? "on the local mesh's border"
                                 : !loc.star.isFull(v)      ? "star not whole"
                                 : loc.star.cur[v] == kNone ? "new vertex"
                                                            : "not a corner of a region face");
                continue;
            }
            bool ok = true;
            int kept = 0;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S)) {
                const FaceIndex q = S.face(h);
                if (!loc.star.kept[q]) {
                    ok = ok && !loc.patchSide[q]; // (the band does not grow into the patch)
                    continue;
                }
                ++kept;
                // The kept face in the current mesh: a triangle (one the view does not see joins the band as
                // a piece of a face the view does not see: it keeps its own orientation).
                const HalfedgeIndex mh = M_.halfedge(VertexIndex(loc.star.cur[S.source(h)]),
                                                     VertexIndex(loc.star.cur[S.target(h)]));
                const FaceIndex g = mh == Mesh::null_halfedge() ? Mesh::null_face() : M_.face(mh);
                ok = ok && g != Mesh::null_face() && M_.next(M_.next(M_.next(mh))) == mh;
            }
            if (ok && kept > 0) heldRim_.push_back(loc.star.cur[v]);
            if (!(ok && kept > 0) && stitch::band::bandDiagnosticsVerbose())
                std::fprintf(stderr, "  rim: corner %u of a face below 20 deg not grown past: %s\n",
                             std::uint32_t(v),
                             kept ? "a patch face or a non-triangle around it" : "no kept face");
        }
    }
    std::sort(heldRim_.begin(), heldRim_.end());
    heldRim_.erase(std::unique(heldRim_.begin(), heldRim_.end()), heldRim_.end());
}

void ComponentStitcher::growPastHeldRim(Attempt& a) {
    if (!remesh_ || stitch::band::stageOff("rim")) return;
    for (int round = 0; round < kRimRounds && !heldRim_.empty(); ++round) {
        const double before = bandMinAfterDeg_;
        const LocalProblem saved = cut_;
        const std::unordered_set<std::uint32_t> savedStars = rimStars_;
        std::unordered_set<std::uint32_t> taken;
        for (FaceIndex f : cut_.replaced)
            taken.insert(std::uint32_t(f));
        for (std::uint32_t c : heldRim_) {
            rimStars_.insert(c);
            for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(VertexIndex(c)), M_))
                if (g != Mesh::null_face() && taken.insert(std::uint32_t(g)).second)
                    openAsItself(g, !acceptable(g));
        }
        const std::size_t held = heldRim_.size();
        Attempt b;
        const bool ok = buildAndOptimise(b);
        const bool better = ok && bandMinAfterDeg_ > before + 1e-6;
        if (stitch::bandDiagnostics())
            std::fprintf(stderr, "band: grown past %zu held rim vertices: %s (min %.2f -> %.2f)\n", held,
                         !ok      ? "fails"
                         : better ? "kept"
                                  : "not better, first kept",
                         before, bandMinAfterDeg_);
        if (!better) {
            cut_ = saved;
            rimStars_ = savedStars;
            break;
        }
        a = std::move(b);
    }
    rimStars_.clear();
}

} // namespace fss::detail::stitching
