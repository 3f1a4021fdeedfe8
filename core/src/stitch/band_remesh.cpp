// Stitch v2, design B: the seam band remeshed in 3D on the draft surface. See band_remesh.h.
#include "stitch/band_remesh.h"
#include "stitch/band_remesher.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace fss::stitch {
namespace band {

void BandRemesher::setup() {
    // Vertices of the band; border ones (a face around them outside the band) and the caller's are fixed.
    std::vector<VertexIndex> verts;
    std::unordered_set<std::uint32_t> seen;
    for (FaceIndex f : bandList_)
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
            if (seen.insert(std::uint32_t(v)).second) verts.push_back(v);
    std::sort(verts.begin(), verts.end());
    for (VertexIndex v : verts)
        at(fixed_, std::size_t(v), char(1)) = (!wholeStarInBand(v) || (in_.fixed && in_.fixed(v))) ? 1 : 0;
    findCreases();
    // Crease corners and ends stay (a vertex with other than two crease edges).
    for (const auto& [v, d] : creaseDeg_)
        if (d != 0 && d != 2) at(fixed_, std::size_t(v), char(1)) = 1;
    buildCreaseChains();
    // The reference: a copy of the band (the draft surface), and each band vertex's face on it.
    std::unordered_map<std::uint32_t, VertexIndex> toRef;
    for (VertexIndex v : verts)
        toRef[std::uint32_t(v)] = ref_.add_vertex(S_.point(v));
    for (std::size_t i = 0; i < bandList_.size(); ++i) {
        const FaceIndex f = bandList_[i];
        std::array<VertexIndex, 3> r;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
            r[std::size_t(k++)] = toRef.at(std::uint32_t(v));
        const FaceIndex g = ref_.add_face(r[0], r[1], r[2]);
        if (g == Mesh::null_face()) continue; // cannot happen for faces of one manifold mesh
        at(refOrigin_, std::size_t(g), std::size_t(-1)) = i;
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_))
            at(hint_, std::size_t(v), Mesh::null_face()) = g;
    }
    smoothNormals();
    // Sizes: on the border the mean length of the border edges there (the patch's edges on one side,
    // the old mesh's on the other), inside graded between them by Jacobi smoothing (a discrete harmonic
    // interpolation; the band is a few rings wide, so a few sweeps suffice).
    std::vector<VertexIndex> inner;
    for (VertexIndex v : verts) {
        double sum = 0, all = 0;
        int n = 0, m = 0;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
            const double len = (detail::pos(S_, S_.source(h)) - detail::pos(S_, v)).norm();
            all += len;
            ++m;
            const bool borderEdge = !interiorEdge(h);
            if (borderEdge) {
                sum += len;
                ++n;
            }
        }
        if (!wholeStarInBand(v)) {
            at(size_, std::size_t(v), in_.edgeLength) = n ? sum / n : (m ? all / m : in_.edgeLength);
        } else {
            at(size_, std::size_t(v), in_.edgeLength) = in_.edgeLength;
            inner.push_back(v);
        }
    }
    for (int sweep = 0; sweep < 12; ++sweep) {
        std::vector<double> next(inner.size());
        for (std::size_t i = 0; i < inner.size(); ++i) {
            double sum = 0;
            int n = 0;
            for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(inner[i]), S_)) {
                sum += sizeOf(w);
                ++n;
            }
            next[i] = n ? sum / n : in_.edgeLength;
        }
        for (std::size_t i = 0; i < inner.size(); ++i)
            size_[std::size_t(inner[i])] = next[i];
    }
}

void BandRemesher::improvePass() {
    const std::vector<VertexIndex> verts =
        cornersOfFacesBelow(in_.minAngleDeg * kBandDeg, [&](VertexIndex v) { return relocatable(v); });
    const double maxTurn = in_.maxNormalTurnDeg * kBandDeg;
    for (VertexIndex v : verts) {
        const V3 p = detail::pos(S_, v);
        double best = starMinAngle(v, p);
        V3 bestP = p;
        FaceIndex bestFace = hint_[std::size_t(v)];
        aroundOnDraft(v, {0.4, 0.2, 0.1}, 12, [&](const V3& lifted, FaceIndex face) {
            if (raisesStar(v, lifted, best, maxTurn)) {
                bestP = lifted;
                bestFace = face;
            }
        });
        if (bestP != p) relocate(v, bestP, bestFace);
    }
}

} // namespace band

bool bandDiagnostics() {
    static const bool on = [] {
        const char* e = std::getenv("FSS_STITCH_BAND_DIAG");
        return e && (std::string(e) == "1" || std::string(e) == "2");
    }();
    return on;
}

BandRemeshReport remeshBand(const BandRemeshInput& input) {
    band::BandRemesher r(input);
    return r.run();
}

} // namespace fss::stitch
