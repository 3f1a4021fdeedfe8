// Stitch v2, design B: the band's last pass, aimed at issue 19's share of created faces >= 30 deg
// (band_remesher.h). The earlier passes raise the smallest angle of a star (improvePass) or of a pair of
// faces (repairFlip); where a star holds several faces just below 30 deg beside a held rim, no single move
// raises its minimum, so they stay (measured, FSS_STITCH_PROPERTY_DIAG=1: most created faces below 30 deg
// have their small angle at a vertex held by kept faces, with room for a larger angle in the wedge of new
// faces there). Here a free vertex of such a face moves on the draft, and a crease vertex along its crease,
// where fewer faces of its star are below 30 deg, without the star's smallest angle falling below the smaller
// of its value before and kFinishFloorDeg.
// Also the relocation helpers that improvePass (band_remesh.cpp) shares with it, and the corner lists of the
// slide passes.
#include "stitch/band_remesher.h"

namespace fss::stitch::band {

namespace {
// A move may lower the smallest angle of a star to this (degrees), never below (nor below issue 19's 20).
constexpr double kFinishFloorDeg = 24.0;
// The aim: issue 19's bound on the share of created faces.
constexpr double kFinishAimDeg = 30.0;
} // namespace

std::vector<VertexIndex> BandRemesher::cornersOfFacesBelow(double aim,
                                                           const std::function<bool(VertexIndex)>& take) {
    std::vector<VertexIndex> verts;
    std::unordered_set<std::uint32_t> seen;
    for (std::size_t f = 0; f < band_.size(); ++f) {
        const FaceIndex g(static_cast<std::uint32_t>(f));
        if (!band_[f] || S_.is_removed(g) || faceMinAngle(g) >= aim) continue;
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(g), S_))
            if (take(v) && seen.insert(std::uint32_t(v)).second) verts.push_back(v);
    }
    std::sort(verts.begin(), verts.end());
    return verts;
}

bool BandRemesher::relocatable(VertexIndex v) {
    return !isFixed(v) && creaseDegree(v) == 0 && wholeStarInBand(v) &&
           at(hint_, std::size_t(v), Mesh::null_face()) != Mesh::null_face();
}

bool BandRemesher::tangentFrame(FaceIndex hint, V3& n0, V3& u, V3& w) const {
    const HalfedgeIndex rh = ref_.halfedge(hint);
    n0 = detail::unitNormal(detail::pos(ref_, ref_.source(rh)), detail::pos(ref_, ref_.target(rh)),
                            detail::pos(ref_, ref_.target(ref_.next(rh))));
    if (!(n0.squaredNorm() > 0)) return false;
    u = (std::abs(n0.x()) < 0.9 ? V3(1, 0, 0) : V3(0, 1, 0)).cross(n0).normalized();
    w = n0.cross(u);
    return true;
}

bool BandRemesher::ontoDraft(const V3& q, FaceIndex hint, double maxDistance, const V3& n0, double creaseCos,
                             V3& lifted, FaceIndex& face) {
    const SurfacePoint sp = near1_(q, hint);
    if (!sp || sp.distance > maxDistance) return false;
    const HalfedgeIndex sh = ref_.halfedge(sp.face);
    const V3 n = detail::unitNormal(detail::pos(ref_, ref_.source(sh)), detail::pos(ref_, ref_.target(sh)),
                                    detail::pos(ref_, ref_.target(ref_.next(sh))));
    if (n.dot(n0) < creaseCos) return false;
    lifted = smoothPoint(sp.face, sp.point);
    face = sp.face;
    return true;
}

double BandRemesher::shortestEdgeAt(VertexIndex v) const {
    double shortest = std::numeric_limits<double>::infinity();
    for (VertexIndex x : CGAL::vertices_around_target(S_.halfedge(v), S_))
        shortest = std::min(shortest, (detail::pos(S_, x) - detail::pos(S_, v)).norm());
    return shortest;
}

bool BandRemesher::aroundOnDraft(VertexIndex v, std::initializer_list<double> radii, int directions,
                                 const std::function<void(const V3&, FaceIndex)>& tryPoint) {
    const V3 p = detail::pos(S_, v);
    const FaceIndex hint = hint_[std::size_t(v)];
    V3 n0, u, w;
    if (!tangentFrame(hint, n0, u, w)) return false;
    const double shortest = shortestEdgeAt(v), creaseCos = std::cos(in_.creaseAngleDeg * kBandDeg);
    for (double r : radii)
        for (int k = 0; k < directions; ++k) {
            const double t = 2 * std::numbers::pi * k / directions;
            const V3 q = p + r * shortest * (std::cos(t) * u + std::sin(t) * w);
            V3 lifted;
            FaceIndex face;
            if (ontoDraft(q, hint, 0.5 * r * shortest, n0, creaseCos, lifted, face)) tryPoint(lifted, face);
        }
    return true;
}

bool BandRemesher::raisesStar(VertexIndex v, const V3& q, double& best, double maxTurn) const {
    const double a = starMinAngle(v, q);
    if (!(a > best + 1e-9 && starAcceptable(v, q, maxTurn))) return false;
    best = a;
    return true;
}

void BandRemesher::relocate(VertexIndex v, const V3& p, FaceIndex face) {
    S_.point(v) = Point3(p.x(), p.y(), p.z());
    hint_[std::size_t(v)] = face;
    touch(v);
    ++report_.moves;
}

int BandRemesher::starBelow(VertexIndex v, const V3& at, double bound, double& smallest) const {
    int n = 0;
    smallest = std::numeric_limits<double>::infinity();
    for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
        if (S_.is_border(h)) continue;
        const double a =
            detail::minAngle(detail::pos(S_, S_.source(h)), at, detail::pos(S_, S_.target(S_.next(h))));
        smallest = std::min(smallest, a);
        n += a < bound;
    }
    return n;
}

void BandRemesher::finishPass() {
    const double aim = kFinishAimDeg * kBandDeg, floor = kFinishFloorDeg * kBandDeg;
    const double maxTurn = in_.maxNormalTurnDeg * kBandDeg;
    // The search for one vertex: its star's faces below the aim now, the fewest found, the smallest angle
    // there and the least it may fall to.
    struct Search {
        int below = 0, best = 0;
        double bestMin = 0, keep = 0;
    };
    auto start = [&](VertexIndex v, Search& s) {
        s.below = s.best = starBelow(v, detail::pos(S_, v), aim, s.bestMin);
        s.keep = std::min(s.bestMin, floor);
        return s.below > 0;
    };
    // Whether v at q beats the best so far (then it becomes the best): fewer faces below the aim than now,
    // no more than the best, a larger smallest angle at equal counts, never below the floor, acceptable.
    auto better = [&](VertexIndex v, const V3& q, Search& s) {
        double m = 0;
        const int b = starBelow(v, q, aim, m);
        if (m < s.keep || b >= s.below || b > s.best || (b == s.best && !(m > s.bestMin + 1e-9)))
            return false;
        if (!starAcceptable(v, q, maxTurn)) return false;
        s.best = b;
        s.bestMin = m;
        return true;
    };
    for (VertexIndex v : cornersOfFacesBelow(aim, [&](VertexIndex v) { return relocatable(v); })) {
        Search s;
        if (!start(v, s)) continue;
        const V3 p = detail::pos(S_, v);
        V3 bestP = p;
        FaceIndex bestFace = hint_[std::size_t(v)];
        aroundOnDraft(v, {0.4, 0.25, 0.1}, 16, [&](const V3& lifted, FaceIndex face) {
            if (better(v, lifted, s)) bestP = lifted, bestFace = face;
        });
        if (bestP != p) relocate(v, bestP, bestFace);
    }
    // Crease vertices between two crease edges: along them, on the draft's crease polyline.
    for (VertexIndex v : cornersOfFacesBelow(
             aim, [&](VertexIndex v) { return !isFixed(v) && creaseDegree(v) == 2 && wholeStarInBand(v); })) {
        Search s;
        if (!start(v, s)) continue;
        const V3 p = detail::pos(S_, v);
        V3 bestP = p;
        CreasePos bestPos;
        for (VertexIndex e : CGAL::vertices_around_target(S_.halfedge(v), S_)) {
            if (!isCrease(v, e)) continue;
            for (double t : {0.1, 0.2, 0.3, 0.4}) {
                V3 q = p + t * (detail::pos(S_, e) - p);
                const CreasePos cp = creaseBetween(v, e, t, q);
                if (cp.chain >= 0 && better(v, q, s)) bestP = q, bestPos = cp;
            }
        }
        if (bestP != p) moveAlongCrease(v, bestP, bestPos);
    }
}

} // namespace fss::stitch::band
