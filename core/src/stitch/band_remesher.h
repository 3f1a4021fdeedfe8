#pragma once
// The state and operations of one seam band remesh (band_remesh.h): internal to band_remesh.cpp and
// band_repair.cpp (the repair of faces still bad at the end, the band's growth and the diagnostics).
#include "stitch/band_remesh.h"
#include "stitch/gap_triangulation.h"

#include "fss/raycast.h"

#include "mesh/local_closest_point.h"
#include "mesh/local_ops.h"
#include "mesh/relax.h"
#include "mesh/triangle_geometry.h"

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace fss::stitch::band {

constexpr double kBandDeg = std::numbers::pi / 180.0;
// Faces with a smaller smallest angle (degrees) have no reliable normal for finding creases.
constexpr double kSliverDeg = 10.0;
// A crease vertex between two crease edges that turn by at most this (degrees) may be collapsed along them.
constexpr double kStraightCreaseDeg = 20.0;
// ... and slid along them (the crease line moves off the surface by at most ~7 % of the edge).
constexpr double kSlideCreaseDeg = 10.0;
// No split makes a face below this (degrees) unless one of the two faces it splits was already below.
constexpr double kSplitFloorDeg = 20.0;
using V3 = Eigen::Vector3d;

// FSS_STITCH_BAND_DIAG=2: the band prints each face below 20 deg and what its repairs tried.
inline bool bandDiagnosticsVerbose() {
    static const bool on = [] {
        const char* e = std::getenv("FSS_STITCH_BAND_DIAG");
        return e && std::string(e) == "2";
    }();
    return on;
}

// FSS_STITCH_BAND_OFF=grow,unseen,repair,slide,endslide,finish,creasefilter,collapseall,short,star,bridge
// (and lift, split, smooth) turns parts of the band remesh off (to measure what each brings).
inline bool stageOff(const char* name) {
    static const std::string off = [] {
        const char* e = std::getenv("FSS_STITCH_BAND_OFF");
        return e ? std::string(",") + e + "," : std::string();
    }();
    return off.find(std::string(",") + name + ",") != std::string::npos;
}

// A place on one of the draft's crease polylines: chain index and arc length along it.
struct CreasePos {
    int chain = -1;
    double s = 0;
};
// A crease vertex between two crease edges may be collapsed along them when the draft's crease polyline
// stays within this fraction of the new edge's length from it.
constexpr double kCreaseChordDev = 0.08;

inline std::uint64_t bandKey(VertexIndex a, VertexIndex b) {
    const std::uint32_t x = std::uint32_t(a), y = std::uint32_t(b); // (std::minmax of temporaries dangles)
    return x < y ? (std::uint64_t(x) << 32) | y : (std::uint64_t(y) << 32) | x;
}

// The state of one remeshing: the mesh, which faces are in the band, per-vertex sizes and reference hints.
class BandRemesher {
public:
    explicit BandRemesher(const BandRemeshInput& in) : in_(in), S_(*in.mesh) {}

    BandRemeshReport run() {
        bandList_ = in_.band;
        for (FaceIndex f : bandList_)
            at(band_, std::size_t(f), char(0)) = 1;
        grow();
        if (in_.unseen && !stageOff("unseen"))
            for (FaceIndex f : bandList_)
                at(unseen_, std::size_t(f), char(0)) = char(in_.unseen(f));
        if (in_.draft) in_.draft(bandList_);
        setup();
        measure(report_.minAngleBeforeDeg, report_.fracAbove30Before);
        for (int it = 0; it < in_.iterations; ++it) {
            splitPass();
            collapsePass();
            flipPass();
            relaxPass(2);
        }
        flipPass();
        relaxPass(2);
        flipPass();
        for (int it = 0; it < 3; ++it) {
            improvePass();
            flipPass();
        }
        for (int it = 0; it < 3 && !stageOff("repair"); ++it) {
            const bool merged = !stageOff("short") && shortEdgePass();
            const bool changed = repairPass() || merged;
            if (!stageOff("slide")) slidePass();
            if (!stageOff("endslide")) slideCreaseEndPass();
            improvePass();
            flipPass();
            if (!changed) break;
        }
        for (int it = 0; it < 2 && !stageOff("finish"); ++it)
            finishPass();
        measure(report_.minAngleAfterDeg, report_.fracAbove30After);
        for (std::size_t f = 0; f < band_.size(); ++f)
            if (band_[f] && !S_.is_removed(FaceIndex(std::uint32_t(f))))
                report_.faces.push_back(FaceIndex(std::uint32_t(f)));
        for (std::size_t v = 0; v < touched_.size(); ++v)
            if (touched_[v] && !S_.is_removed(VertexIndex(std::uint32_t(v))))
                report_.touched.push_back(VertexIndex(std::uint32_t(v)));
        findOrigins();
        countBelow20();
        return report_;
    }

private:
    // ---- element data (vectors indexed by descriptor, grown on demand)
    template <class T> static T& at(std::vector<T>& v, std::size_t i, const T& init = T()) {
        if (v.size() <= i) v.resize(i + 1, init);
        return v[i];
    }
    bool inBand(FaceIndex f) {
        return f != Mesh::null_face() && std::size_t(f) < band_.size() && band_[std::size_t(f)];
    }
    bool unseen(FaceIndex f) const { return std::size_t(f) < unseen_.size() && unseen_[std::size_t(f)]; }
    bool isFixed(VertexIndex v) { return at(fixed_, std::size_t(v), char(1)) != 0; }
    double sizeOf(VertexIndex v) { return at(size_, std::size_t(v), in_.edgeLength); }
    bool isCrease(VertexIndex a, VertexIndex b) const { return crease_.count(bandKey(a, b)) > 0; }
    int creaseDegree(VertexIndex v) const {
        auto it = creaseDeg_.find(std::uint32_t(v));
        return it == creaseDeg_.end() ? 0 : it->second;
    }
    V3 faceNormal(FaceIndex f) const {
        const HalfedgeIndex h = S_.halfedge(f);
        return detail::unitNormal(detail::pos(S_, S_.source(h)), detail::pos(S_, S_.target(h)),
                                  detail::pos(S_, S_.target(S_.next(h))));
    }
    V3 areaVector(FaceIndex f) const {
        const HalfedgeIndex h = S_.halfedge(f);
        const V3 a = detail::pos(S_, S_.source(h));
        return (detail::pos(S_, S_.target(h)) - a).cross(detail::pos(S_, S_.target(S_.next(h))) - a);
    }
    // The normal a face's replacement is compared with: its own where it is well shaped, else \p fallback
    // (an area-weighted normal around it: a sliver's own normal says nothing about the surface).
    V3 referenceNormal(FaceIndex f, const V3& fallback) const {
        if (unseen(f) && in_.creaseNormal) {
            // A piece of a face the view does not see: the plane of the face it was cut from.
            const V3 n = in_.creaseNormal(f);
            if (n.squaredNorm() > 0) return n;
        }
        const HalfedgeIndex h = S_.halfedge(f);
        const V3 a = detail::pos(S_, S_.source(h)), b = detail::pos(S_, S_.target(h)),
                 c = detail::pos(S_, S_.target(S_.next(h)));
        // (minAngle(a, b, c) >= kSliverDeg, decided as minAngleBelow does: the same answer)
        return !detail::minAngleBelow(a, b, c, sliver_) ? detail::unitNormal(a, b, c) : fallback;
    }
    bool facing(const V3& a, const V3& b, const V3& c) const {
        const V3 n = (b - a).cross(c - a);
        if (!(n.norm() > 0)) return false;
        const Camera& cam = *in_.camera;
        const V3 centroid = (a + b + c) / 3.0;
        const V3 toViewer = cam.parallel ? V3(-cam.viewDirection()) : V3(cam.eye - centroid);
        return n.dot(toViewer) > 0;
    }
    // A triangle that may replace one of normal n0: facing, not degenerate, turned by at most the bound.
    // A face the view does not see (`seen` false) keeps its own orientation instead: the normal bound holds.
    bool acceptableFace(const V3& a, const V3& b, const V3& c, const V3& n0, bool seen = true) const {
        if (seen && !facing(a, b, c)) return false;
        const V3 n = detail::unitNormal(a, b, c);
        return n.squaredNorm() > 0 && detail::angleAtMost(n, n0, maxTurn_);
    }
    // Whether every face around v is a band face (and v is not on the mesh border).
    bool wholeStarInBand(VertexIndex v) {
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_))
            if (S_.is_border(h) || !inBand(S_.face(h))) return false;
        return true;
    }
    bool interiorEdge(HalfedgeIndex h) {
        return !S_.is_border(S_.edge(h)) && inBand(S_.face(h)) && inBand(S_.face(S_.opposite(h)));
    }
    void touch(VertexIndex v) { at(touched_, std::size_t(v), char(0)) = 1; }
    // Whether changing v's valence by delta keeps it within 4..8 (the seam criterion of issue 4). A vertex
    // on the local mesh's border has an unknown valence: no bound.
    bool valenceOk(VertexIndex v, int delta) const {
        if (delta == 0 || S_.is_border(v)) return true;
        const int n = int(S_.degree(v)) + delta;
        return delta > 0 ? n <= 8 : n >= 4;
    }

    // ---- setup: band marks, fixed vertices, creases, reference copy, sizes
    void setup();
    double faceMinAngle(FaceIndex f) const {
        const HalfedgeIndex h = S_.halfedge(f);
        return detail::minAngle(detail::pos(S_, S_.source(h)), detail::pos(S_, S_.target(h)),
                                detail::pos(S_, S_.target(S_.next(h))));
    }
    bool growable(FaceIndex f) const { return f != Mesh::null_face() && in_.growable && in_.growable(f); }

    // ---- growth: the band takes in the faces at and beyond its border that it would otherwise leave bad
    void grow();

    // ---- diagnostics: where the new faces below 20 deg are after the remesh
    void countBelow20();

    void addCrease(VertexIndex a, VertexIndex b) {
        if (crease_.insert(bandKey(a, b)).second) {
            ++creaseDeg_[std::uint32_t(a)];
            ++creaseDeg_[std::uint32_t(b)];
        }
    }
    void removeCrease(VertexIndex a, VertexIndex b) {
        if (crease_.erase(bandKey(a, b))) {
            --creaseDeg_[std::uint32_t(a)];
            --creaseDeg_[std::uint32_t(b)];
        }
    }

    void measure(double& minDeg, double& frac30) {
        std::size_t n = 0, good = 0;
        double smallest = 180;
        for (std::size_t f = 0; f < band_.size(); ++f) {
            const FaceIndex g(static_cast<std::uint32_t>(f));
            if (!band_[f] || S_.is_removed(g)) continue;
            const HalfedgeIndex h = S_.halfedge(g);
            const double a = detail::minAngle(detail::pos(S_, S_.source(h)), detail::pos(S_, S_.target(h)),
                                              detail::pos(S_, S_.target(S_.next(h)))) /
                             kBandDeg;
            smallest = std::min(smallest, a);
            ++n;
            good += a >= 30.0;
        }
        minDeg = smallest;
        frac30 = n ? double(good) / double(n) : 1.0;
    }

    // Band edges (each once, by one halfedge), in descriptor order.
    std::vector<HalfedgeIndex> bandEdges() {
        std::vector<HalfedgeIndex> out;
        for (std::size_t f = 0; f < band_.size(); ++f) {
            const FaceIndex g(static_cast<std::uint32_t>(f));
            if (!band_[f] || S_.is_removed(g)) continue;
            for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(g), S_))
                if (interiorEdge(h) && std::uint32_t(S_.face(S_.opposite(h))) > std::uint32_t(g))
                    out.push_back(h);
        }
        return out;
    }

    // ---- splits of edges longer than 4/3 of the local size
    void splitPass() {
        std::vector<std::pair<double, std::pair<VertexIndex, VertexIndex>>> cands;
        for (HalfedgeIndex h : bandEdges()) {
            const VertexIndex a = S_.source(h), b = S_.target(h);
            const double len = (detail::pos(S_, a) - detail::pos(S_, b)).norm();
            const double target = 0.5 * (sizeOf(a) + sizeOf(b));
            if (len > 4.0 / 3.0 * target) cands.push_back({-len / target, {a, b}});
        }
        std::sort(cands.begin(), cands.end());
        for (const auto& c : cands) {
            const auto [a, b] = c.second;
            if (S_.is_removed(a) || S_.is_removed(b)) continue;
            const HalfedgeIndex h = S_.halfedge(a, b);
            if (h == Mesh::null_halfedge() || !interiorEdge(h)) continue;
            split(h);
        }
    }
    // Where a split of h at parameter t (from its source) puts the new vertex: on a crease, the point of the
    // reference crease between the two ends (lifted onto the draft's crease polyline, band_crease.cpp);
    // elsewhere the point of the edge projected onto the draft when it is near. Sets the new vertex's hint,
    // and its crease position (crease) when it is on a crease with one.
    struct SplitPoint {
        V3 q;
        FaceIndex hint;
        CreasePos crease;
    };
    SplitPoint splitPoint(HalfedgeIndex h, double t) {
        const VertexIndex a = S_.source(h), b = S_.target(h);
        const V3 pa = detail::pos(S_, a), pb = detail::pos(S_, b);
        SplitPoint sp{pa + t * (pb - pa), at(hint_, std::size_t(a), Mesh::null_face()), CreasePos{}};
        if (isCrease(a, b)) {
            if (!stageOff("lift")) sp.crease = creaseBetween(a, b, t, sp.q);
        } else if (sp.hint != Mesh::null_face()) {
            const SurfacePoint r = near2_(sp.q, sp.hint);
            if (r && r.distance <= 0.25 * (pa - pb).norm()) {
                sp.q = smoothPoint(r.face, r.point);
                sp.hint = r.face;
            }
        }
        return sp;
    }
    // The smallest angle of the four faces a split of h at q makes, or -1 when one of them is not acceptable.
    double splitMinAngle(HalfedgeIndex h, const V3& q) const {
        const VertexIndex a = S_.source(h), b = S_.target(h);
        const VertexIndex c = S_.target(S_.next(h)), d = S_.target(S_.next(S_.opposite(h)));
        const V3 pa = detail::pos(S_, a), pb = detail::pos(S_, b), pc = detail::pos(S_, c),
                 pd = detail::pos(S_, d);
        const FaceIndex f1 = S_.face(h), f2 = S_.face(S_.opposite(h));
        const V3 quad = (areaVector(f1) + areaVector(f2)).normalized();
        const V3 n1 = referenceNormal(f1, quad), n2 = referenceNormal(f2, quad);
        const bool s1 = !unseen(f1), s2 = !unseen(f2);
        if (!acceptableFace(pa, q, pc, n1, s1) || !acceptableFace(q, pb, pc, n1, s1) ||
            !acceptableFace(pb, q, pd, n2, s2) || !acceptableFace(q, pa, pd, n2, s2))
            return -1;
        return std::min({detail::minAngle(pa, q, pc), detail::minAngle(q, pb, pc),
                         detail::minAngle(pb, q, pd), detail::minAngle(q, pa, pd)});
    }
    bool split(HalfedgeIndex h, double t = 0.5) {
        const VertexIndex a = S_.source(h), b = S_.target(h);
        const VertexIndex c = S_.target(S_.next(h)), d = S_.target(S_.next(S_.opposite(h)));
        const V3 pa = detail::pos(S_, a), pb = detail::pos(S_, b), pc = detail::pos(S_, c),
                 pd = detail::pos(S_, d);
        const bool onCrease = isCrease(a, b);
        const SplitPoint sp = splitPoint(h, t);
        const V3 q = sp.q;
        const FaceIndex hint = sp.hint;
        const FaceIndex f1 = S_.face(h), f2 = S_.face(S_.opposite(h));
        const double newMin = splitMinAngle(h, q);
        if (newMin < 0 || !valenceOk(c, 1) || !valenceOk(d, 1)) return false;
        // No split makes a face below the floor that was not there (a split next to a small angle halves it).
        const double oldMin = std::min(detail::minAngle(pa, pb, pc), detail::minAngle(pb, pa, pd));
        if (newMin < std::min(oldMin, kSplitFloorDeg * kBandDeg) || newMin < minSplitGain_ * oldMin)
            return false;
        const detail::EdgeSplit s = detail::splitEdge(S_, h, Point3(q.x(), q.y(), q.z()));
        const VertexIndex v = s.vertex;
        at(fixed_, std::size_t(v), char(1)) = 0;
        at(size_, std::size_t(v), in_.edgeLength) = 0.5 * (sizeOf(a) + sizeOf(b));
        at(hint_, std::size_t(v), Mesh::null_face()) = hint;
        at(touched_, std::size_t(v), char(0)) = 1;
        if (in_.vertexData) in_.vertexData(v, Mesh::null_vertex());
        for (const auto& [e, parent] : {std::pair{s.first, f1}, std::pair{s.second, f2}})
            for (FaceIndex g : {S_.face(e), S_.face(S_.opposite(e))})
                if (g != parent) {
                    at(band_, std::size_t(g), char(0)) = 1;
                    at(unseen_, std::size_t(g), char(0)) = char(unseen(parent));
                    if (in_.faceData) in_.faceData(g, parent);
                }
        at(band_, std::size_t(f1), char(0)) = 1;
        at(band_, std::size_t(f2), char(0)) = 1;
        if (onCrease) {
            removeCrease(a, b);
            addCrease(a, v);
            addCrease(v, b);
        }
        creasePos_.erase(std::uint32_t(v)); // (a recycled descriptor)
        if (onCrease && sp.crease.chain >= 0) creasePos_[std::uint32_t(v)] = {sp.crease};
        ++report_.splits;
        return true;
    }

    // ---- repair of the faces still below the aim, whatever the sizes and valences: a flip of one of their
    // edges, a collapse of their shortest edge, a split of the long edge of a cap (an angle above 120 deg),
    // each only where it raises the smallest angle there. True when something changed.
    bool repairPass();
    bool repairFlip(FaceIndex f);
    bool repairCollapse(FaceIndex f);
    bool repairCap(FaceIndex f);
    // ---- the compound repair of a face no single operation improves (band_star.cpp): a small disk of band
    // faces around it triangulated anew in the view (the gap's quality CDT), new vertices on the draft's
    // smooth surface, kept only where the disk's smallest angle rises and every band rule holds.
    struct StarDisk {
        std::vector<FaceIndex> faces;   // sorted
        std::vector<VertexIndex> loop;  // its border, counter-clockwise in the view
        std::vector<VertexIndex> inner; // its interior vertices (free: they go)
    };
    struct StarPlan {
        StarDisk disk;
        std::vector<V3> points;                    // new vertices (GapTriangulation points past the loop's)
        std::vector<FaceIndex> hints;              // their faces on the draft
        std::vector<double> sizes;                 // their local sizes
        std::vector<std::array<int, 3>> triangles; // loop indices, then n + new vertex index
        std::vector<FaceIndex> parents;            // per triangle: the old face under its centroid
        double minAngle = -1;                      // radians
    };
    // The disk seen in the view: the CDT's input (loop constraints, crease chords), each vertex's place, the
    // disk's edges, mean normal, smallest angle and local size in pixels.
    struct StarView {
        const StarDisk* disk = nullptr;
        GapBoundary gap;
        std::unordered_map<std::uint32_t, Eigen::Vector2d> uvOf;
        std::vector<Eigen::Vector2d> innerUv;
        std::unordered_set<std::uint64_t> diskEdges;
        V3 starNormal{0, 0, 0};
        double oldMin = 0, sizePx = 0;
    };
    bool repairStar(FaceIndex f);
    bool viewStar(const StarDisk& disk, StarView& sv);
    FaceIndex starFaceAt(const StarView& sv, const Eigen::Vector2d& p, std::array<double, 3>& w) const;
    // Empty when the triangulation t of the disk passes every rule (then in plan), else why not.
    std::string judgeStar(const StarView& sv, const GapTriangulation& t, StarPlan& plan);
    bool starDisk(const std::vector<FaceIndex>& faces, StarDisk& disk);
    bool planStar(const StarDisk& disk, StarPlan& best);
    bool applyStar(const StarPlan& plan);

    // ---- the smooth surface through the draft (band_crease.cpp): a point of a draft face lifted by Phong
    // tessellation (Boubekeur & Alexa 2008, shape factor 1/2: exact to second order on a sphere) with the
    // draft's vertex normals, taken per face corner over the faces on the same side of a crease. A vertex
    // placed on the draft's chord of a curved surface would lie up to the chord's sag below it, on top of
    // the sag of the draft's own vertices (measured: icosphere seen at 80 deg, Stitch.PatchPastThe
    // SilhouetteIsTrimmed, 0.00479 against the input's sag of 0.00453); lifted, it lies about as far off the
    // surface as the draft's vertices do.
    void smoothNormals();
    // BandRemeshReport::origin: the draft face (ref_) under each final face's centroid.
    void findOrigins();
    V3 smoothPoint(FaceIndex refFace, const V3& onFace) const;
    // After a relaxation: each moved vertex lifted from the draft face it ends on, where its star allows it
    // (else it stays where the relaxation put it, on the draft).
    void liftRelaxed(const std::vector<VertexIndex>& verts, const std::vector<V3>& before);

    // ---- creases as polylines of the draft (band_crease.cpp): each crease vertex's place on them, so that
    // splits and slides put crease vertices on the draft's crease line, not on a chord of it
    void buildCreaseChains();
    // The band's creases at setup (band_crease.cpp): edges between faces whose normals differ by more than
    // the crease angle, outlier faces and weak stubs left out.
    void findCreases();
    // Crease ends facing each other across a sliver (no reliable normal) joined into one crease.
    void bridgeCreases(const std::unordered_map<std::uint32_t, V3>& normal);
    // Whether a face has an angle above 120 deg.
    bool isCap(FaceIndex f) const;
    // The point at parameter t between crease vertices a and b on their common crease polyline (into q);
    // chain -1 when they have none (q is left as it is).
    CreasePos creaseBetween(VertexIndex a, VertexIndex b, double t, V3& q) const;
    V3 creasePoint(int chain, double s) const;
    // Whether collapsing crease vertex `from` into `to` (its neighbour on the crease, `other` the one on the
    // far side) keeps the crease near its line: the crease turns by at most kStraightCreaseDeg at `from`,
    // or the draft's crease polyline between `to` and `other` stays within kCreaseChordDev of the new edge.
    bool creaseCollapseKeepsLine(VertexIndex from, VertexIndex to, VertexIndex other) const;
    // A split of an edge of a face below the aim whose vertices cannot move (crease vertices, the band's
    // border): the edge and place (a few parameters along it, creases lifted) that raise the smallest angle
    // of the two faces most.
    bool repairSplit(FaceIndex f);

    // ---- collapses of edges shorter than 4/5 of the local size
    void collapsePass() {
        std::vector<std::pair<double, std::pair<VertexIndex, VertexIndex>>> cands;
        for (HalfedgeIndex h : bandEdges()) {
            const VertexIndex a = S_.source(h), b = S_.target(h);
            const double len = (detail::pos(S_, a) - detail::pos(S_, b)).norm();
            const double target = 0.5 * (sizeOf(a) + sizeOf(b));
            if (len < 0.8 * target) cands.push_back({len / target, {a, b}});
        }
        std::sort(cands.begin(), cands.end());
        for (const auto& c : cands) {
            const auto [a, b] = c.second;
            if (S_.is_removed(a) || S_.is_removed(b)) continue;
            const HalfedgeIndex h = S_.halfedge(a, b);
            if (h == Mesh::null_halfedge() || !interiorEdge(h)) continue;
            double sa = -1, sb = -1;
            const bool okA = collapsible(a, b, sa), okB = collapsible(b, a, sb);
            if (!okA && !okB) continue;
            const VertexIndex from = (okA && (!okB || sa >= sb)) ? a : b, to = from == a ? b : a;
            collapse(from, to);
        }
    }
    // Whether `from` may go into `to` (to keeps its place); score: the smallest angle after.
    bool collapsible(VertexIndex from, VertexIndex to, double& score, double limitFactor = 4.0 / 3.0) {
        if (isFixed(from) || !wholeStarInBand(from)) return false;
        if (creaseDegree(from) > 0) {
            // Only along a nearly straight crease, onto its neighbour on it: the crease keeps its line.
            if (creaseDegree(from) != 2 || !isCrease(from, to)) return false;
            VertexIndex other = Mesh::null_vertex();
            for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(from), S_))
                if (w != to && isCrease(from, w)) other = w;
            if (other == Mesh::null_vertex()) return false;
            if (!creaseCollapseKeepsLine(from, to, other)) return false;
        }
        const HalfedgeIndex h = S_.halfedge(from, to);
        // The survivor's valence, and the two opposite vertices' (one edge less each); then the link
        // condition (both pure tests: the cheaper first).
        if (!valenceOk(to, int(S_.degree(from)) - 4) || !valenceOk(S_.target(S_.next(h)), -1) ||
            !valenceOk(S_.target(S_.next(S_.opposite(h))), -1))
            return false;
        if (!detail::canCollapse(S_, S_.edge(h), true)) return false;
        const V3 pt = detail::pos(S_, to);
        const double limit = limitFactor * sizeOf(to);
        V3 star(0, 0, 0);
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S_.halfedge(from), S_))
            star += areaVector(S_.face(g));
        star.normalize();
        double oldMin = std::numbers::pi, newMin = std::numbers::pi;
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S_.halfedge(from), S_)) {
            const VertexIndex p = S_.target(S_.next(g)), q = S_.source(g);
            const V3 pp = detail::pos(S_, p), pq = detail::pos(S_, q), pf = detail::pos(S_, from);
            oldMin = std::min(oldMin, detail::minAngle(pf, pp, pq));
            if (p == to || q == to) continue;
            if (!acceptableFace(pt, pp, pq, referenceNormal(S_.face(g), star), !unseen(S_.face(g))))
                return false;
            if ((pp - pt).norm() > limit) return false;
            newMin = std::min(newMin, detail::minAngle(pt, pp, pq));
        }
        if (newMin < std::min(oldMin, in_.minAngleDeg * kBandDeg)) return false;
        score = newMin;
        return true;
    }
    // Returns the surviving vertex (at `to`'s place, with its data; the descriptor may be `from`'s).
    VertexIndex collapse(VertexIndex from, VertexIndex to) {
        const HalfedgeIndex h = S_.halfedge(from, to);
        const FaceIndex f1 = S_.face(h), f2 = S_.face(S_.opposite(h));
        const V3 keep = detail::pos(S_, to);
        const double keepSize = sizeOf(to);
        const FaceIndex keepHint = at(hint_, std::size_t(to), Mesh::null_face());
        const char keepFixed = char(isFixed(to));
        const char keepTouched = at(touched_, std::size_t(to), char(0));
        // Crease edges at either end go to the survivor (a crease through `from` continues from `to`).
        std::vector<VertexIndex> creaseEnds;
        for (VertexIndex x : {from, to})
            for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(x), S_))
                if (w != from && w != to && isCrease(x, w)) creaseEnds.push_back(w);
        for (VertexIndex x : {from, to})
            for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(x), S_))
                removeCrease(x, w);
        const VertexIndex kept = CGAL::Euler::collapse_edge(S_.edge(h), S_);
        band_[std::size_t(f1)] = 0;
        band_[std::size_t(f2)] = 0;
        if (kept == to) {
            creasePos_.erase(std::uint32_t(from));
        } else {
            if (auto it = creasePos_.find(std::uint32_t(to)); it != creasePos_.end()) {
                std::vector<CreasePos> pos = std::move(it->second);
                creasePos_.erase(it);
                creasePos_[std::uint32_t(kept)] = std::move(pos);
            } else {
                creasePos_.erase(std::uint32_t(kept));
            }
            S_.point(kept) = Point3(keep.x(), keep.y(), keep.z());
            if (in_.vertexData) in_.vertexData(kept, to);
            size_[std::size_t(kept)] = keepSize;
            hint_[std::size_t(kept)] = keepHint;
            fixed_[std::size_t(kept)] = keepFixed;
            touched_[std::size_t(kept)] = keepTouched;
        }
        for (VertexIndex w : creaseEnds)
            addCrease(kept, w);
        ++report_.collapses;
        return kept;
    }
    // ---- short edges (band_cluster.cpp): a band edge much shorter than the local size (a crease edge a
    // draft's sliver left, DESIGN.md §6.2) goes with the cluster of short edges around it, judged on the
    // faces after the whole cluster is merged into one of its vertices. True when something changed.
    bool shortEdgePass();
    bool collapseCluster(VertexIndex a);

    // ---- flips towards valence 6 and larger angles
    void flipPass() {
        // Degrees and border flags, read once per vertex and pass and kept by the pass's flips (a flip
        // changes the degree of its four vertices by one and never which vertices are on the border): the
        // tests below read them up to twelve times per edge, each a walk around the vertex.
        std::vector<int> degree(S_.num_vertices(), -1);
        std::vector<char> border(S_.num_vertices(), 0);
        auto know = [&](VertexIndex v) {
            const std::size_t i = std::size_t(v);
            if (degree[i] < 0) {
                degree[i] = int(S_.degree(v));
                border[i] = char(S_.is_border(v));
            }
        };
        auto cost = [&](VertexIndex v, int delta) {
            const int target = border[std::size_t(v)] ? 4 : 6;
            return std::abs(degree[std::size_t(v)] + delta - target);
        };
        auto valenceFits = [&](VertexIndex v, int delta) { // valenceOk on the pass's degrees
            if (delta == 0 || border[std::size_t(v)]) return true;
            const int n = degree[std::size_t(v)] + delta;
            return delta > 0 ? n <= 8 : n >= 4;
        };
        // Within a pass only the flips change what the tests below read (positions, creases, band, hints and
        // face data stay), and a flip changes the degree of each of its four vertices, so every face, degree
        // and edge around an edge whose four vertices no flip touched is as it was: an edge tested and left
        // is tested again in a later round only when a flip since touched one of its four vertices. Same
        // decisions, fewer tests. Stamps: per vertex the last flip at it, per halfedge the test that left it.
        struct Left {
            std::uint64_t stamp = 0; // 0: not left in this pass
            std::array<VertexIndex, 4> quad;
        };
        std::vector<Left> left(S_.num_halfedges());
        std::vector<std::uint64_t> flippedAt(S_.num_vertices(), 0);
        std::uint64_t stamp = 1;
        for (int round = 0; round < 3; ++round) {
            std::size_t flips = 0;
            for (HalfedgeIndex h : bandEdges()) {
                if (S_.is_removed(S_.edge(h)) || !interiorEdge(h)) continue;
                const VertexIndex a = S_.source(h), b = S_.target(h);
                const VertexIndex c = S_.target(S_.next(h)), d = S_.target(S_.next(S_.opposite(h)));
                Left& l = left[std::size_t(h)];
                if (l.stamp && l.quad == std::array{a, b, c, d} &&
                    std::max({flippedAt[std::size_t(a)], flippedAt[std::size_t(b)], flippedAt[std::size_t(c)],
                              flippedAt[std::size_t(d)]}) <= l.stamp)
                    continue;
                l = Left{stamp, {a, b, c, d}}; // (cleared below when it flips)
                if (isCrease(a, b) || c == d) continue;
                for (VertexIndex v : {a, b, c, d})
                    know(v);
                // detail::canFlip on the pass's degrees (h is interior), its edge test after the gain's.
                if (degree[std::size_t(a)] <= 3 || degree[std::size_t(b)] <= 3) continue;
                if (!valenceFits(a, -1) || !valenceFits(b, -1) || !valenceFits(c, 1) || !valenceFits(d, 1))
                    continue;
                if (unseen(S_.face(h)) != unseen(S_.face(S_.opposite(h)))) continue;
                const V3 pa = detail::pos(S_, a), pb = detail::pos(S_, b), pc = detail::pos(S_, c),
                         pd = detail::pos(S_, d);
                // New faces (a, d, c) and (b, c, d). The tests are pure: the cheap gain test comes first
                // (most candidates fail it), then the faces' orientation and normals, then the projection.
                const auto [oldMin, newMin] = flipAngles_.get(std::size_t(h), pa, pb, pc, pd, [&] {
                    return std::pair{std::min(detail::minAngle(pa, pb, pc), detail::minAngle(pb, pa, pd)),
                                     std::min(detail::minAngle(pa, pd, pc), detail::minAngle(pb, pc, pd))};
                });
                const int devOld = cost(a, 0) + cost(b, 0) + cost(c, 0) + cost(d, 0);
                const int devNew = cost(a, -1) + cost(b, -1) + cost(c, 1) + cost(d, 1);
                // Score (as version 1's flips): smallest angle in degrees minus 3 deg per unit of valence
                // deviation; never below the smaller of the angle before and the aim.
                const double gain = (newMin - oldMin) / kBandDeg - 3.0 * double(devNew - devOld);
                if (!(gain > 0.5) || newMin < std::min(oldMin, in_.minAngleDeg * kBandDeg)) continue;
                if (CGAL::halfedge(c, d, S_).second) continue; // (the edge the flip makes exists already)
                const V3 quad = (areaVector(S_.face(h)) + areaVector(S_.face(S_.opposite(h)))).normalized();
                const bool seen = !unseen(S_.face(h));
                const V3 n1 = referenceNormal(S_.face(h), quad),
                         n2 = referenceNormal(S_.face(S_.opposite(h)), quad);
                if (!acceptableFace(pa, pd, pc, n1, seen) || !acceptableFace(pa, pd, pc, n2, seen) ||
                    !acceptableFace(pb, pc, pd, n1, seen) || !acceptableFace(pb, pc, pd, n2, seen))
                    continue;
                // The new edge stays near the draft (a flip over a curved place would cut under it). Tested
                // last: the projection costs most, and most candidates fail the gain already.
                if (distanceToRef(0.5 * (pc + pd), c) > 0.1 * (pc - pd).norm()) continue;
                CGAL::Euler::flip_edge(h, S_);
                ++flips;
                ++stamp;
                for (VertexIndex v : {a, b, c, d})
                    flippedAt[std::size_t(v)] = stamp;
                --degree[std::size_t(a)];
                --degree[std::size_t(b)];
                ++degree[std::size_t(c)];
                ++degree[std::size_t(d)];
                l.stamp = 0;
            }
            report_.flips += flips;
            if (!flips) break;
        }
    }
    double distanceToRef(const V3& p, VertexIndex near) {
        const FaceIndex hint = at(hint_, std::size_t(near), Mesh::null_face());
        if (hint == Mesh::null_face()) return 0;
        const SurfacePoint sp = near2_(p, hint);
        return sp ? sp.distance : 0;
    }

    // ---- tangential relaxation with projection onto the draft (mesh/relax.h)
    void relaxPass(int iterations) {
        std::vector<VertexIndex> verts;
        std::vector<FaceIndex> hints;
        std::vector<double> sizes;
        std::vector<char> seen(S_.num_vertices(), 0); // (a bitmap: the vertices are sorted below)
        for (std::size_t f = 0; f < band_.size(); ++f) {
            const FaceIndex g(static_cast<std::uint32_t>(f));
            if (!band_[f] || S_.is_removed(g)) continue;
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(g), S_)) {
                // Crease vertices stay: the crease keeps its exact line (splits put new vertices on it).
                if (isFixed(v) || creaseDegree(v) > 0 || std::exchange(seen[std::size_t(v)], char(1)))
                    continue;
                const FaceIndex hf = at(hint_, std::size_t(v), Mesh::null_face());
                if (hf == Mesh::null_face() || !wholeStarInBand(v)) continue;
                verts.push_back(v);
            }
        }
        std::sort(verts.begin(), verts.end()); // deterministic order (hints and sizes follow)
        for (VertexIndex v : verts) {
            hints.push_back(hint_[std::size_t(v)]);
            sizes.push_back(sizeOf(v));
        }
        std::vector<V3> before;
        for (VertexIndex v : verts)
            before.push_back(detail::pos(S_, v));
        detail::RelaxOptions o;
        o.iterations = iterations;
        o.step = 0.5;
        o.creaseAngleDeg = in_.creaseAngleDeg;
        o.maxNormalTurnDeg = in_.maxNormalTurnDeg;
        o.maxOffFootprints = 0.5;
        const detail::RelaxReport r =
            detail::relaxOnReference(S_, ref_, verts, hints, sizes, o, in_.camera, &near1_);
        report_.moves += r.moves;
        for (std::size_t k = 0; k < verts.size(); ++k)
            hint_[std::size_t(verts[k])] = hints[k];
        if (!stageOff("smooth")) liftRelaxed(verts, before);
        for (std::size_t k = 0; k < verts.size(); ++k)
            if (detail::pos(S_, verts[k]) != before[k]) touch(verts[k]);
    }

    // The corners of band faces below \p aim (radians) that \p take accepts, each once, in descriptor order:
    // the vertices the relocation and slide passes try. (These helpers: band_finish.cpp.)
    std::vector<VertexIndex> cornersOfFacesBelow(double aim, const std::function<bool(VertexIndex)>& take);
    // Whether v may be relocated on the draft (improvePass, finishPass): free, on no crease, its whole star
    // in the band, with a face of the draft at it.
    bool relocatable(VertexIndex v);
    // The unit normal n0 of draft face \p hint and two tangents u, w with it (false: a degenerate face).
    bool tangentFrame(FaceIndex hint, V3& n0, V3& u, V3& w) const;
    // Point q taken onto the draft near \p hint and lifted onto its smooth surface (\p lifted, on draft face
    // \p face); false where the draft is farther than \p maxDistance or its face there turns from n0 by more
    // than the crease angle (cosine \p creaseCos).
    bool ontoDraft(const V3& q, FaceIndex hint, double maxDistance, const V3& n0, double creaseCos,
                   V3& lifted, FaceIndex& face);
    double shortestEdgeAt(VertexIndex v) const;
    // Calls \p tryPoint(lifted, face) for the points around relocatable vertex v at each of \p radii times
    // its shortest edge in \p directions evenly spaced directions of the draft's tangent plane, each taken
    // onto the draft (ontoDraft, within half its offset); false where the draft face at v is degenerate.
    bool aroundOnDraft(VertexIndex v, std::initializer_list<double> radii, int directions,
                       const std::function<void(const V3&, FaceIndex)>& tryPoint);
    // Whether v at q raises its star's smallest angle above \p best (then set to it) and stays acceptable.
    bool raisesStar(VertexIndex v, const V3& q, double& best, double maxTurn) const;
    // Moves v to p on draft face \p face (a relocation).
    void relocate(VertexIndex v, const V3& p, FaceIndex face);

    // ---- relocation of the free vertices of faces below the aim: the place on the draft around the vertex
    // (a search over tangential offsets, each projected) that maximises the smallest angle of its star.
    // Own search rather than a smoothing rule: near a fixed, irregular border the centroid is often not
    // where the worst angle improves.
    void improvePass();
    // Crease vertices of faces below the aim slide along their (nearly straight) crease: candidates on the
    // two crease edges, the one that maximises the star's smallest angle wins.
    void slidePass();
    // Vertices of faces below 30 deg move (crease ones along it) to fewer star faces below (band_finish.cpp).
    void finishPass();
    // The faces of v's star (v at \p at) with a smallest angle below \p bound (radians); \p smallest gets the
    // star's smallest angle.
    int starBelow(VertexIndex v, const V3& at, double bound, double& smallest) const;
    // Crease ends of faces below the aim slide along their one crease edge (band_crease_end.cpp).
    void slideCreaseEndPass();
    // Puts crease vertex v at p, at its place pos on the draft's crease polyline (none: chain < 0), with
    // its hint and the touched set kept up to date; both slide passes end with it.
    /// Slides crease vertex v to the best of the points 0.1–0.4 of the way towards each of \p ends where its
    /// star's smallest angle rises and stays acceptable (starAcceptable): on the draft's crease polyline
    /// (creaseBetween; not looked up when \p lift is false) or, where v has no place on it, along the chord
    /// only when \p chords. Both slide passes (crease vertices and crease ends) use it.
    void slideTowards(VertexIndex v, const std::vector<VertexIndex>& ends, bool lift, bool chords,
                      double maxTurn);
    void moveAlongCrease(VertexIndex v, const V3& p, const CreasePos& pos);
    double starMinAngle(VertexIndex v, const V3& at) const {
        detail::MinAngleOfMany m; // the same double as the minimum of minAngle face by face
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
            if (S_.is_border(h)) continue;
            m.add(detail::pos(S_, S_.source(h)), at, detail::pos(S_, S_.target(S_.next(h))));
        }
        return m.value();
    }
    bool starAcceptable(VertexIndex v, const V3& at, double maxTurn) const {
        return starAcceptable(v, at, detail::AngleLimit(maxTurn));
    }
    bool starAcceptable(VertexIndex v, const V3& at, const detail::AngleLimit& maxTurn) const {
        V3 star(0, 0, 0);
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_))
            star += areaVector(S_.face(h));
        star.normalize();
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
            const V3 b = detail::pos(S_, S_.source(h)), c = detail::pos(S_, S_.target(S_.next(h)));
            if (!unseen(S_.face(h)) && !facing(b, at, c)) return false;
            const V3 n = detail::unitNormal(b, at, c);
            if (detail::angleAbove(n, referenceNormal(S_.face(h), star), maxTurn)) return false;
        }
        return true;
    }

    const BandRemeshInput& in_;
    Mesh& S_;
    const detail::AngleLimit maxTurn_{in_.maxNormalTurnDeg * kBandDeg}; // acceptableFace's normal bound
    const detail::AngleLimit sliver_{kSliverDeg * kBandDeg};            // referenceNormal's reliable face
    Mesh ref_; // the draft band, onto which vertices are projected
    // closestPointNear on ref_ (which does not change after setup) with 1 and 2 rings: the same results,
    // each face's rings collected once.
    detail::LocalClosestPoint near1_{ref_, LocalSearchOptions{.rings = 1}},
        near2_{ref_, LocalSearchOptions{.rings = 2}};
    std::vector<FaceIndex> bandList_; // the band as given and grown (descriptor order after growth)
    std::vector<char> band_, fixed_, touched_;
    double minSplitGain_ = 0;  // a split must give a smallest angle of at least this times the one before
    std::vector<char> unseen_; // per face: a new face the view does not see (BandRemeshInput::unseen)
    std::vector<double> size_;
    std::vector<FaceIndex> hint_; // per S vertex: a face of ref_ at it
    std::unordered_set<std::uint64_t> crease_;
    std::unordered_map<std::uint32_t, int> creaseDeg_;
    std::vector<std::size_t> refOrigin_; // per face of ref_: its index in bandList_ (the draft)
    std::vector<V3> cornerNormal_;       // per halfedge of ref_: the smooth normal at its target in its face
    std::vector<std::vector<V3>> chainPts_;     // the draft's crease polylines (band_crease.cpp)
    std::vector<std::vector<double>> chainArc_; // their cumulative arc lengths
    std::unordered_map<std::uint32_t, std::vector<CreasePos>> creasePos_; // per crease vertex of S_
    detail::FlipAngleMemo flipAngles_; // flipPass's angles per halfedge, while its four corners stay
    BandRemeshReport report_;
};

} // namespace fss::stitch::band
