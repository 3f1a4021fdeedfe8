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

// The patch's footprint in the scan's image: the pixels of its vertices, dilated by one pixel.
std::unordered_set<std::uint64_t> patchFootprint(const PatchData& P, const Camera& cam) {
    std::unordered_set<std::uint64_t> fp;
    for (const Vec3& p : P.pos) {
        const Eigen::Vector3d s = cam.project(p);
        const int x = int(std::floor(s.x())), y = int(std::floor(s.y()));
        if (x < 0 || y < 0 || x >= cam.width || y >= cam.height) continue;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int X = x + dx, Y = y + dy;
                if (X >= 0 && Y >= 0 && X < cam.width && Y < cam.height)
                    fp.insert(std::uint64_t(std::uint32_t(Y)) << 32 | std::uint32_t(X));
            }
    }
    return fp;
}

// Does face f of m touch the footprint (a corner in a footprint pixel, or a footprint pixel's centre inside
// its projection)?
bool touchesFootprint(const Mesh& m, FaceIndex f, const Camera& cam,
                      const std::unordered_set<std::uint64_t>& fp) {
    auto at = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < cam.width && y < cam.height &&
               fp.count(std::uint64_t(std::uint32_t(y)) << 32 | std::uint32_t(x)) > 0;
    };
    Eigen::Vector3d s[3];
    int k = 0;
    for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m)) {
        if (k == 3) return false;
        const Vec3 p = toVec(m.point(v));
        if (cam.viewDepth(p) <= 0) return false;
        s[k] = cam.project(p);
        if (at(int(std::floor(s[k].x())), int(std::floor(s[k].y())))) return true;
        ++k;
    }
    if (k != 3) return false;
    const double area =
        (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[1].y() - s[0].y()) * (s[2].x() - s[0].x());
    if (area == 0 || !std::isfinite(area)) return false;
    auto inside = [&](double px, double py) {
        for (int i = 0; i < 3; ++i) {
            const Eigen::Vector3d &p = s[(i + 1) % 3], &q = s[(i + 2) % 3];
            if (((q.x() - p.x()) * (py - p.y()) - (q.y() - p.y()) * (px - p.x())) / area < 0) return false;
        }
        return true;
    };
    const int x0 = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
    const int x1 = std::min(cam.width - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
    const int y1 = std::min(cam.height - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
    if (double(x1 - x0 + 1) * double(y1 - y0 + 1) > double(fp.size())) {
        for (std::uint64_t key : fp) {
            const int x = int(key & 0xffffffffu), y = int(key >> 32);
            if (x >= x0 && x <= x1 && y >= y0 && y <= y1 && inside(x + 0.5, y + 0.5)) return true;
        }
        return false;
    }
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            if (at(x, y) && inside(x + 0.5, y + 0.5)) return true;
    return false;
}
} // namespace

// Is every face of current-mesh vertex c's star within seamRings vertex rings of a face that touches the
// patch's footprint (the seam neighbourhood, as the property test defines it)?
bool ComponentStitcher::starInSeamNeighbourhood(std::uint32_t c) {
    const Camera& cam = V_.camera();
    if (!footprintBuilt_) {
        footprint_ = patchFootprint(P_, cam);
        footprintBuilt_ = true;
    }
    auto touching = [&](FaceIndex f) {
        auto [it, fresh] = touchesCache_.try_emplace(std::uint32_t(f), false);
        if (fresh) it->second = touchesFootprint(M_, f, cam, footprint_);
        return it->second;
    };
    for (FaceIndex q : CGAL::faces_around_target(M_.halfedge(VertexIndex(c)), M_)) {
        if (q == Mesh::null_face()) continue;
        std::unordered_set<std::uint32_t> seen{std::uint32_t(q)};
        std::vector<FaceIndex> ring{q};
        bool ok = touching(q);
        for (int r = 0; r < O_.seamRings && !ok; ++r) {
            std::vector<FaceIndex> next;
            for (FaceIndex g : ring)
                for (VertexIndex w : CGAL::vertices_around_face(M_.halfedge(g), M_))
                    for (FaceIndex h : CGAL::faces_around_target(M_.halfedge(w), M_))
                        if (h != Mesh::null_face() && seen.insert(std::uint32_t(h)).second) next.push_back(h);
            for (FaceIndex g : next)
                ok = ok || touching(g);
            ring.swap(next);
        }
        if (!ok) return false;
    }
    return true;
}

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
                (!inRegion(loc.star.cur[v]) && !starInSeamNeighbourhood(loc.star.cur[v]))) {
                if (loc.locked[v] && stitch::band::bandDiagnosticsVerbose())
                    std::fprintf(stderr, "  rim: corner %u of a face below 20 deg not grown past: %s\n",
                                 std::uint32_t(v),
                                 S.is_border(v)        ? "on the local mesh's border"
                                 : !loc.star.isFull(v) ? "star not whole"
                                 : loc.star.cur[v] == kNone
                                     ? "new vertex"
                                     : "not a corner of a region face, star not in the seam neighbourhood");
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
