// The sliver repair of auto v2 (sliver_repair.h).
#include "remesh/sliver_repair.h"

#include "mesh/features.h"
#include "mesh/local_ops.h"
#include "mesh/triangle_geometry.h"
#include "remesh/crease_index.h"
#include "remesh/crease_snap.h"
#include "remesh/join_regions.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <vector>

namespace fss::detail {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Vec = Eigen::Vector3d;

constexpr double kDeg = std::numbers::pi / 180.0;

/// An operation's new triangles must raise the smallest angle by this much (radians) at least.
constexpr double kGain = 1e-4;

struct Tri {
    Vec a, b, c;
};

/// Largest turn of a face's normal against its own old normal (collapses, moves).
constexpr double kMaxTurn = 60.0 * kDeg;

class SliverRepairer {
public:
    SliverRepairer(Mesh& mesh, const RayCaster& caster, const SliverRepairOptions& o)
        : m_(mesh), caster_(caster), o_(o), floor_(o.belowDeg * kDeg), feature_(o.featureAngleDeg * kDeg),
          tolerance_(o.tolerance * o.edgeLength), creases_(caster.mesh(), o.featureAngleDeg, o.edgeLength),
          corners_(1e-3 * o.edgeLength) {
        for (const Vec& c : creases_.corners())
            corners_.add(c);
    }

    SliverRepairReport run() {
        SliverRepairReport report;
        report.before = countSlivers();
        Mesh before = m_;
        for (int round = 0; round < o_.rounds; ++round) {
            std::size_t ops = 0;
            for (int attempt = 0;; ++attempt) {
                std::size_t flips = 0, collapses = 0, moves = 0;
                touched_.clear();
                markFixed();
                sweep(flips, collapses, moves);
                ops = flips + collapses + moves;
                if (ops == 0) break;
                const std::vector<std::pair<FaceIndex, FaceIndex>> pairs = intersectionsAround(m_, touched_);
                if (pairs.empty()) {
                    report.flips += flips, report.collapses += collapses, report.moves += moves;
                    before = m_;
                    // The next round looks only at the slivers around what this one changed.
                    active_.assign(m_.number_of_vertices() + m_.number_of_removed_vertices(), 0);
                    for (VertexIndex v : touched_)
                        if (!m_.is_removed(v)) {
                            active_[v.idx()] = 1;
                            for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                                active_[w.idx()] = 1;
                        }
                    break;
                }
                ++report.sweepsReverted;
                if (std::getenv("FSS_AUTO_V2_DEBUG"))
                    std::fprintf(stderr,
                                 "v2 slivers: round %d attempt %d: %zu operations, %zu intersecting pairs\n",
                                 round, attempt, ops, pairs.size());
                const std::vector<VertexIndex> stuck = cornersOf(m_, pairs);
                m_ = before; // vertex indices are those of `before` (the collapses only remove vertices)
                for (VertexIndex v : stuck)
                    frozen_.push_back(v);
                if (attempt == 3) {
                    ops = 0;
                    break;
                }
            }
            if (ops == 0) break;
        }
        m_.collect_garbage();
        report.after = countSlivers();
        report.freeAfter = true;
        return report;
    }

private:
    Mesh& m_;
    const RayCaster& caster_;
    const SliverRepairOptions& o_;
    const double floor_, feature_, tolerance_;
    /// fixedEdge_: 1 a crease edge, 2 a border edge or one between a face left from the input and a scanned
    /// face. fixed_: a vertex that never moves (on a fixed edge, marked on a crease, on the border).
    std::vector<char> fixed_, fixedEdge_;
    std::vector<int> creaseDegree_;
    std::vector<VertexIndex> touched_, frozen_;
    /// After the first round: the vertices around the operations of the last sweep kept (the slivers
    /// elsewhere were tried already).
    std::vector<char> active_;
    const creases::CreaseIndex creases_;
    PointGrid corners_; // the corners of the reference's creases

    static double minAngleOf(const Tri& t) { return minAngle(t.a, t.b, t.c); }
    static Vec normalOf(const Tri& t) { return unitNormal(t.a, t.b, t.c); }
    Tri triangle(FaceIndex f) const {
        const HalfedgeIndex h = m_.halfedge(f);
        return {pos(m_, m_.source(h)), pos(m_, m_.target(h)), pos(m_, m_.target(m_.next(h)))};
    }

    std::size_t countSlivers() const {
        std::size_t n = 0;
        for (FaceIndex f : m_.faces())
            n += minAngleOf(triangle(f)) < floor_;
        return n;
    }

    void markFixed() {
        const std::size_t nv = m_.number_of_vertices() + m_.number_of_removed_vertices();
        fixed_.assign(nv, 0);
        creaseDegree_.assign(nv, 0);
        fixedEdge_.assign(m_.number_of_edges() + m_.number_of_removed_edges(), 0);
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        auto isInput = [&](FaceIndex f) { return f != Mesh::null_face() && (!haveIds || ids[f] < 0); };
        const std::vector<char> sharp = sharpEdges(m_, o_.featureAngleDeg);
        for (EdgeIndex e : m_.edges()) {
            const HalfedgeIndex h = m_.halfedge(e);
            const VertexIndex a = m_.source(h), b = m_.target(h);
            if (m_.is_border(e) || isInput(m_.face(h)) != isInput(m_.face(m_.opposite(h))))
                fixedEdge_[e.idx()] = 2;
            else if (sharp[e.idx()] && nearCrease(pos(m_, a)) && nearCrease(pos(m_, b)))
                fixedEdge_[e.idx()] = 1, ++creaseDegree_[a.idx()], ++creaseDegree_[b.idx()];
            if (fixedEdge_[e.idx()]) fixed_[a.idx()] = fixed_[b.idx()] = 1;
        }
        if (const auto [onCrease, have] = m_.property_map<VertexIndex, bool>(kOnCreaseProperty); have)
            for (VertexIndex v : m_.vertices())
                if (onCrease[v]) fixed_[v.idx()] = 1;
        for (VertexIndex v : m_.vertices())
            if (m_.is_border(v)) fixed_[v.idx()] = 1;
        for (VertexIndex v : frozen_)
            if (v.idx() < nv) fixed_[v.idx()] = 2; // not even a crease collapse removes it
    }

    /// Whether \p p lies within a tenth of an edge length of a crease of the reference: a sharp edge of the
    /// mesh between two such points follows a crease; elsewhere it is a fold a sliver makes.
    bool nearCrease(const Vec& p) const {
        Vec q;
        double d = 0;
        return creases_.closest(p, q, d) && d <= 0.1 * o_.edgeLength;
    }

    /// The reference's point closest to \p p. The reference never changes, so the answer depends on \p p
    /// alone: it is kept by the bits of \p p for the whole run (the sweeps measure the same corners, edge
    /// midpoints and centroids again and again, and a sweep undone is run again on the same mesh).
    struct PointKey {
        std::uint64_t x, y, z;
        bool operator==(const PointKey&) const = default;
    };
    struct PointKeyHash {
        std::size_t operator()(const PointKey& k) const {
            std::uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
            h ^= k.y + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
            h ^= k.z + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
            return std::size_t(h);
        }
    };
    mutable std::unordered_map<PointKey, SurfacePoint, PointKeyHash> closest_;
    const SurfacePoint& closestPoint(const Vec& p) const {
        PointKey key{};
        std::memcpy(&key.x, &p.x(), sizeof(double));
        std::memcpy(&key.y, &p.y(), sizeof(double));
        std::memcpy(&key.z, &p.z(), sizeof(double));
        auto [it, inserted] = closest_.try_emplace(key);
        if (inserted) it->second = caster_.closestPoint(p);
        return it->second;
    }

    /// The reference's unit normal at the point closest to \p p, and the distance to it.
    std::pair<Vec, double> referenceAt(const Vec& p) const {
        const SurfacePoint& sp = closestPoint(p);
        if (!sp) return {Vec::Zero(), 0.0};
        return {faceNormal(caster_.mesh(), sp.face), sp.distance};
    }

    /// What the triangles replaced measure: their smallest angle, the largest distance of their centroids
    /// and edge midpoints from the reference and the largest angle of their normals to the reference's.
    struct Measure {
        double minAngle = std::numbers::pi, gap = 0, deviation = 0;
    };
    Measure measure(const std::vector<Tri>& tris, bool angleOnly = false) const {
        Measure m;
        for (const Tri& t : tris)
            m.minAngle = std::min(m.minAngle, minAngleOf(t));
        if (angleOnly) return m;
        for (const Tri& t : tris) {
            const Vec n = normalOf(t);
            for (const Vec& p : {Vec((t.a + t.b + t.c) / 3.0), Vec(0.5 * (t.a + t.b)), Vec(0.5 * (t.b + t.c)),
                                 Vec(0.5 * (t.c + t.a))}) {
                const auto [rn, d] = referenceAt(p);
                m.gap = std::max(m.gap, d);
                if (!rn.isZero() && !n.isZero()) m.deviation = std::max(m.deviation, angleBetween(n, rn));
            }
        }
        return m;
    }

    /// A candidate operation: its kind, where, and the smallest angle it reaches.
    struct Candidate {
        enum Kind { None, Flip, Collapse, Move } kind = None;
        HalfedgeIndex h;   // flip: the edge; collapse: the halfedge whose target is removed
        VertexIndex v;     // move: the vertex
        Vec to{0, 0, 0};   // collapse, move: the new position
        double newMin = 0; // the smallest angle of the new faces
        int valence = 0;   // the change in the number of vertices of valence ≠ 6 it makes
    };

    static int irregular(std::size_t degree) { return degree != 6; }

    /// Whether an operation reaching \p newMin with the valence change \p valence beats \p best: among
    /// operations that lift every face they make to the bound, the one that leaves fewer irregular vertices
    /// (then the higher angle); else the higher angle.
    bool beats(double newMin, int valence, const Candidate& best) const {
        if (best.kind == Candidate::None) return true;
        if (newMin >= floor_ && best.newMin >= floor_)
            return valence < best.valence || (valence == best.valence && newMin > best.newMin);
        return newMin > best.newMin;
    }

    /// Whether \p after may replace \p before and beats the best candidate so far (\p best, its smallest
    /// angle): a smallest angle higher by kGain than the old one and higher than \p best, no face farther
    /// from the reference than the old ones (or the tolerance), no normal turned from the reference's
    /// farther than the crease angle (or the old faces' largest such angle). The cheap angle test first: the
    /// distances are measured only for a candidate that passes it.
    bool acceptable(const std::vector<Tri>& before, const std::vector<Tri>& after, const Candidate& best,
                    int valence, double& newMin) const {
        const double oldMin = measure(before, true).minAngle, a = measure(after, true).minAngle;
        if (a < oldMin + kGain || !beats(a, valence, best)) return false;
        const Measure full = measure(after);
        if (full.gap > tolerance_ || full.deviation > feature_) {
            const Measure old = measure(before);
            if (full.gap > std::max(old.gap, tolerance_)) return false;
            if (full.deviation > std::max(old.deviation, feature_)) return false;
        }
        newMin = a;
        return true;
    }

    void tryFlip(HalfedgeIndex h, Candidate& best) const {
        if (fixedEdge_[m_.edge(h).idx()] || !canFlip(m_, h)) return;
        const HalfedgeIndex o = m_.opposite(h);
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        for (VertexIndex v : {a, b, c, d})
            if (fixed_[v.idx()] == 2) return; // frozen
        const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
        const std::vector<Tri> before{{pa, pb, pc}, {pb, pa, pd}}, after{{pa, pd, pc}, {pd, pb, pc}};
        const Vec n1 = normalOf(after[0]), n2 = normalOf(after[1]);
        if (n1.isZero() || n2.isZero()) return;
        // No new crease between the two new faces (unless the old two met at a sharper one).
        const double oldFold = angleBetween(normalOf(before[0]), normalOf(before[1]));
        if (angleBetween(n1, n2) > std::max(0.5 * feature_, oldFold)) return;
        const int valence = irregular(m_.degree(a) - 1) + irregular(m_.degree(b) - 1) +
                            irregular(m_.degree(c) + 1) + irregular(m_.degree(d) + 1) -
                            irregular(m_.degree(a)) - irregular(m_.degree(b)) - irregular(m_.degree(c)) -
                            irregular(m_.degree(d));
        double newMin = 0;
        if (!acceptable(before, after, best, valence, newMin)) return;
        best = {Candidate::Flip, h, {}, {0, 0, 0}, newMin, valence};
    }

    /// The triangles around \p v but those of \p skip1, \p skip2, with \p v at \p at; false when one turns
    /// by more than kMaxTurn or degenerates.
    bool starWith(VertexIndex v, const Vec& at, FaceIndex skip1, FaceIndex skip2, std::vector<Tri>& before,
                  std::vector<Tri>& after) const {
        const Vec p = pos(m_, v);
        for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const FaceIndex f = m_.face(g);
            if (f == Mesh::null_face()) return false;
            const HalfedgeIndex n1 = m_.next(g);
            const Vec s = pos(m_, m_.target(n1)), t = pos(m_, m_.target(m_.next(n1)));
            before.push_back({p, s, t});
            if (f == skip1 || f == skip2) continue;
            after.push_back({at, s, t});
            const Vec n0 = normalOf(before.back()), n = normalOf(after.back());
            if (n.isZero() || (!n0.isZero() && angleBetween(n, n0) > kMaxTurn)) return false;
        }
        return true;
    }

    /// Collapse of the edge of \p h onto its source (the target is removed), the source moved to \p at.
    void tryCollapse(HalfedgeIndex h, const Vec& at, Candidate& best) const {
        const EdgeIndex e = m_.edge(h);
        const VertexIndex keep = m_.source(h), gone = m_.target(h);
        if (fixedEdge_[e.idx()] == 2 || fixed_[gone.idx()] == 2 || fixed_[keep.idx()] == 2) return;
        if (fixedEdge_[e.idx()] == 1) {
            // Along a crease: the vertex removed lies on this crease only (two crease edges), the one kept
            // stays where it is.
            if (creaseDegree_[gone.idx()] != 2 || (at - pos(m_, keep)).squaredNorm() > 0) return;
            for (HalfedgeIndex g : CGAL::halfedges_around_target(h, m_))
                if (fixedEdge_[m_.edge(g).idx()] == 2) return;
        } else if (fixed_[gone.idx()]) {
            return;
        } else if (fixed_[keep.idx()] && (at - pos(m_, keep)).squaredNorm() > 0) {
            return;
        }
        if (!canCollapse(m_, e)) return;
        std::vector<Tri> before, after;
        const FaceIndex f1 = m_.face(h), f2 = m_.face(m_.opposite(h));
        if (!starWith(keep, at, f1, f2, before, after) || !starWith(gone, at, f1, f2, before, after)) return;
        double longestBefore = 0, longestAfter = 0;
        for (const Tri& t : before)
            longestBefore = std::max({longestBefore, (t.b - t.a).norm(), (t.c - t.a).norm()});
        for (const Tri& t : after)
            longestAfter = std::max({longestAfter, (t.b - t.a).norm(), (t.c - t.a).norm()});
        if (longestAfter > std::max(1.5 * o_.edgeLength, longestBefore)) return;
        const VertexIndex x = m_.target(m_.next(h)), y = m_.target(m_.next(m_.opposite(h)));
        const int valence = irregular(m_.degree(keep) + m_.degree(gone) - 4) + irregular(m_.degree(x) - 1) +
                            irregular(m_.degree(y) - 1) - irregular(m_.degree(keep)) -
                            irregular(m_.degree(gone)) - irregular(m_.degree(x)) - irregular(m_.degree(y));
        double newMin = 0;
        if (!acceptable(before, after, best, valence, newMin)) return;
        best = {Candidate::Collapse, h, {}, at, newMin, valence};
    }

    void tryMove(VertexIndex v, const Vec& target, Candidate& best) const {
        if (fixed_[v.idx()]) return;
        const SurfacePoint sp = closestPoint(target);
        if (sp) tryPosition(v, sp.point, best);
    }

    void tryPosition(VertexIndex v, const Vec& to, Candidate& best) const {
        std::vector<Tri> before, after;
        if (!starWith(v, to, Mesh::null_face(), Mesh::null_face(), before, after)) return;
        double newMin = 0;
        if (!acceptable(before, after, best, 0, newMin)) return;
        best = {Candidate::Move, {}, v, to, newMin, 0};
    }

    /// Slides \p v, a vertex on one crease (two crease edges, no other fixed edge, not at a corner of the
    /// reference's creases), along the reference's crease: towards the midpoint of its two crease
    /// neighbours, whole and halfway, projected onto the crease.
    void trySlide(VertexIndex v, Candidate& best) const {
        if (creaseDegree_[v.idx()] != 2 || fixed_[v.idx()] == 2 || m_.is_border(v)) return;
        Vec ends(0, 0, 0);
        for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const char flag = fixedEdge_[m_.edge(g).idx()];
            if (flag == 2) return;
            if (flag == 1) ends += pos(m_, m_.source(g));
        }
        const Vec p = pos(m_, v);
        if (corners_.near(p)) return;
        const Vec mid = 0.5 * ends;
        for (const Vec& target : {mid, Vec(0.5 * (p + mid))}) {
            Vec q;
            double d = 0;
            if (!creases_.closest(target, q, d) || d > 0.25 * o_.edgeLength || corners_.near(q)) continue;
            tryPosition(v, q, best);
        }
    }

    /// The move targets of \p v: the centroid of its neighbours and the mean of the points that would make
    /// each face of its star equilateral over its opposite edge, both in the tangent plane, whole and
    /// halfway.
    std::vector<Vec> moveTargets(VertexIndex v) const {
        const Vec p = pos(m_, v);
        Vec centroid(0, 0, 0), ideal(0, 0, 0), normal(0, 0, 0);
        int n = 0;
        for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const HalfedgeIndex n1 = m_.next(g);
            const Vec s = pos(m_, m_.target(n1)), t = pos(m_, m_.target(m_.next(n1)));
            normal += (s - p).cross(t - p);
        }
        if (normal.isZero()) return {};
        normal.normalize();
        for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const HalfedgeIndex n1 = m_.next(g);
            const Vec s = pos(m_, m_.target(n1)), t = pos(m_, m_.target(m_.next(n1)));
            centroid += s;
            // The apex of the equilateral triangle over (s, t) on v's side, in the tangent plane.
            const Vec mid = 0.5 * (s + t), side = normal.cross(t - s);
            ideal += mid + std::sqrt(3.0) / 2.0 * side.normalized() * (t - s).norm();
            ++n;
        }
        std::vector<Vec> out;
        for (Vec q : {Vec(centroid / n), Vec(ideal / n)}) {
            q -= (q - p).dot(normal) * normal;
            out.push_back(q);
            out.push_back(0.5 * (p + q));
        }
        return out;
    }

    void sweep(std::size_t& flips, std::size_t& collapses, std::size_t& moves) {
        std::vector<std::pair<double, FaceIndex>> slivers;
        for (FaceIndex f : m_.faces())
            if (const double a = minAngleOf(triangle(f)); a < floor_) slivers.push_back({a, f});
        std::sort(slivers.begin(), slivers.end());
        for (const auto& [angle, f] : slivers) {
            if (m_.is_removed(f) || minAngleOf(triangle(f)) >= floor_) continue;
            Candidate best;
            const HalfedgeIndex h0 = m_.halfedge(f);
            const HalfedgeIndex hs[3] = {h0, m_.next(h0), m_.next(m_.next(h0))};
            if (!active_.empty() && std::none_of(std::begin(hs), std::end(hs), [&](HalfedgeIndex h) {
                    const std::size_t i = m_.target(h).idx();
                    return i < active_.size() && active_[i];
                }))
                continue;
            for (HalfedgeIndex h : hs)
                tryFlip(h, best);
            HalfedgeIndex shortest = hs[0];
            for (HalfedgeIndex h : hs)
                if (m_.is_removed(shortest) ||
                    (pos(m_, m_.source(h)) - pos(m_, m_.target(h))).squaredNorm() <
                        (pos(m_, m_.source(shortest)) - pos(m_, m_.target(shortest))).squaredNorm())
                    shortest = h;
            for (HalfedgeIndex h : {shortest, m_.opposite(shortest)}) {
                const VertexIndex a = m_.source(h), b = m_.target(h);
                tryCollapse(h, pos(m_, a), best);
                if (!fixed_[a.idx()] && !fixed_[b.idx()])
                    if (const SurfacePoint sp = closestPoint(0.5 * (pos(m_, a) + pos(m_, b))))
                        tryCollapse(h, sp.point, best);
            }
            for (HalfedgeIndex h : hs)
                trySlide(m_.target(h), best);
            for (HalfedgeIndex h : hs)
                if (!fixed_[m_.target(h).idx()])
                    for (const Vec& q : moveTargets(m_.target(h)))
                        tryMove(m_.target(h), q, best);
            apply(best, flips, collapses, moves);
        }
    }

    void apply(const Candidate& c, std::size_t& flips, std::size_t& collapses, std::size_t& moves) {
        switch (c.kind) {
        case Candidate::None:
            return;
        case Candidate::Flip: {
            const HalfedgeIndex o = m_.opposite(c.h);
            touched_.insert(touched_.end(),
                            {m_.source(c.h), m_.target(c.h), m_.target(m_.next(c.h)), m_.target(m_.next(o))});
            CGAL::Euler::flip_edge(c.h, m_);
            ++flips;
            return;
        }
        case Candidate::Collapse: {
            const HalfedgeIndex h = c.h, o = m_.opposite(h);
            const VertexIndex keep = m_.source(h), gone = m_.target(h);
            const VertexIndex x = m_.target(m_.next(h)), y = m_.target(m_.next(o));
            auto flagOf = [&](VertexIndex u, VertexIndex w) {
                return fixedEdge_[m_.edge(CGAL::halfedge(u, w, m_).first).idx()];
            };
            const char fx = std::max(flagOf(keep, x), flagOf(gone, x));
            const char fy = std::max(flagOf(keep, y), flagOf(gone, y));
            const char fixedKept = std::max(fixed_[keep.idx()], fixed_[gone.idx()]);
            const int creaseKept = creaseDegree_[keep.idx()];
            auto [onCrease, haveMarks] = m_.property_map<VertexIndex, bool>(kOnCreaseProperty);
            const bool marked = haveMarks && (onCrease[keep] || onCrease[gone]);
            // Euler::collapse_edge keeps either end: the one kept gets both ends' flags and the position.
            const VertexIndex kept = CGAL::Euler::collapse_edge(m_.edge(h), m_);
            m_.point(kept) = Point3(c.to.x(), c.to.y(), c.to.z());
            if (haveMarks) onCrease[kept] = marked;
            fixed_[kept.idx()] = fixedKept;
            creaseDegree_[kept.idx()] = creaseKept;
            fixedEdge_[m_.edge(CGAL::halfedge(kept, x, m_).first).idx()] = fx;
            fixedEdge_[m_.edge(CGAL::halfedge(kept, y, m_).first).idx()] = fy;
            touched_.insert(touched_.end(), {kept, x, y});
            ++collapses;
            return;
        }
        case Candidate::Move:
            m_.point(c.v) = Point3(c.to.x(), c.to.y(), c.to.z());
            touched_.push_back(c.v);
            ++moves;
            return;
        }
    }
};

} // namespace

SliverRepairReport repairSlivers(Mesh& mesh, const RayCaster& caster, const SliverRepairOptions& options) {
    if (options.rounds <= 0 || mesh.is_empty()) return {.freeAfter = options.knownFree};
    if (!options.knownFree && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) return {};
    return SliverRepairer(mesh, caster, options).run();
}

} // namespace fss::detail
