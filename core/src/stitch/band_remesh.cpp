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
    std::vector<VertexIndex> verts;
    std::unordered_set<std::uint32_t> seen;
    for (std::size_t f = 0; f < band_.size(); ++f) {
        const FaceIndex g(static_cast<std::uint32_t>(f));
        if (!band_[f] || S_.is_removed(g)) continue;
        const HalfedgeIndex h = S_.halfedge(g);
        if (detail::minAngle(detail::pos(S_, S_.source(h)), detail::pos(S_, S_.target(h)),
                             detail::pos(S_, S_.target(S_.next(h)))) >= in_.minAngleDeg * kBandDeg)
            continue;
        for (VertexIndex v : CGAL::vertices_around_face(h, S_))
            if (!isFixed(v) && creaseDegree(v) == 0 && wholeStarInBand(v) &&
                at(hint_, std::size_t(v), Mesh::null_face()) != Mesh::null_face() &&
                seen.insert(std::uint32_t(v)).second)
                verts.push_back(v);
    }
    std::sort(verts.begin(), verts.end());
    const double creaseCos = std::cos(in_.creaseAngleDeg * kBandDeg);
    const double maxTurn = in_.maxNormalTurnDeg * kBandDeg;
    for (VertexIndex v : verts) {
        const V3 p = detail::pos(S_, v);
        const FaceIndex hint = hint_[std::size_t(v)];
        const HalfedgeIndex rh = ref_.halfedge(hint);
        const V3 n0 =
            detail::unitNormal(detail::pos(ref_, ref_.source(rh)), detail::pos(ref_, ref_.target(rh)),
                               detail::pos(ref_, ref_.target(ref_.next(rh))));
        if (!(n0.squaredNorm() > 0)) continue;
        const V3 u = (std::abs(n0.x()) < 0.9 ? V3(1, 0, 0) : V3(0, 1, 0)).cross(n0).normalized();
        const V3 w = n0.cross(u);
        double shortest = std::numeric_limits<double>::infinity();
        for (VertexIndex x : CGAL::vertices_around_target(S_.halfedge(v), S_))
            shortest = std::min(shortest, (detail::pos(S_, x) - p).norm());
        double best = starMinAngle(v, p);
        V3 bestP = p;
        FaceIndex bestFace = hint;
        for (double r : {0.4, 0.2, 0.1})
            for (int k = 0; k < 12; ++k) {
                const double t = 2 * std::numbers::pi * k / 12;
                const V3 q = p + r * shortest * (std::cos(t) * u + std::sin(t) * w);
                const SurfacePoint sp = near1_(q, hint);
                if (!sp || sp.distance > 0.5 * r * shortest) continue;
                const HalfedgeIndex sh = ref_.halfedge(sp.face);
                const V3 n =
                    detail::unitNormal(detail::pos(ref_, ref_.source(sh)), detail::pos(ref_, ref_.target(sh)),
                                       detail::pos(ref_, ref_.target(ref_.next(sh))));
                if (n.dot(n0) < creaseCos) continue;
                const V3 lifted = smoothPoint(sp.face, sp.point);
                const double a = starMinAngle(v, lifted);
                if (a > best + 1e-9 && starAcceptable(v, lifted, maxTurn)) {
                    best = a;
                    bestP = lifted;
                    bestFace = sp.face;
                }
            }
        if (bestP != p) {
            S_.point(v) = Point3(bestP.x(), bestP.y(), bestP.z());
            hint_[std::size_t(v)] = bestFace;
            touch(v);
            ++report_.moves;
        }
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
