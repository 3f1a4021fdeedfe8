#include "detail/crease_snap.h"

#include "detail/triangle_geometry.h"

#include "fss/raycast.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <unordered_map>
#include <vector>

namespace fss::detail {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Vec = Eigen::Vector3d;

/// Closest points of segments [p1, q1] and [p2, q2] (Ericson, Real-Time Collision Detection, 5.1.9): the
/// parameters s (on the first) and t (on the second).
void closestSegmentParameters(const Vec& p1, const Vec& q1, const Vec& p2, const Vec& q2, double& s,
                              double& t) {
    const Vec d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    constexpr double eps = 1e-300;
    if (a <= eps && e <= eps) {
        s = t = 0;
        return;
    }
    if (a <= eps) {
        s = 0;
        t = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = d1.dot(r);
    if (e <= eps) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = d1.dot(d2), denom = a * e - b * b;
    s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

/// The crease edges of the reference as segments, in a uniform grid of cells of one edge length: the
/// segments within one cell of a point are found in the point's cell.
class CreaseIndex {
public:
    CreaseIndex(const Mesh& reference, double creaseAngle, double cell) : cell_(cell) {
        const double cosCrease = std::cos(creaseAngle);
        for (EdgeIndex e : reference.edges()) {
            if (reference.is_border(e)) continue;
            const HalfedgeIndex h = reference.halfedge(e), o = reference.opposite(h);
            const Vec a = pos(reference, reference.source(h)), b = pos(reference, reference.target(h));
            const Vec n1 = unitNormal(a, b, pos(reference, reference.target(reference.next(h))));
            const Vec n2 = unitNormal(b, a, pos(reference, reference.target(reference.next(o))));
            if (n1.isZero() || n2.isZero() || n1.dot(n2) >= cosCrease) continue;
            const int id = int(segments_.size());
            segments_.push_back({a, b});
            const Vec lo = a.cwiseMin(b).array() - cell, hi = a.cwiseMax(b).array() + cell;
            const Key k0 = keyOf(lo), k1 = keyOf(hi);
            for (std::int64_t x = k0.x; x <= k1.x; ++x)
                for (std::int64_t y = k0.y; y <= k1.y; ++y)
                    for (std::int64_t z = k0.z; z <= k1.z; ++z)
                        cells_[hash({x, y, z})].push_back(id);
        }
    }
    std::size_t size() const { return segments_.size(); }
    /// The crease segments that may lie within one cell of \p p (and possibly a few more).
    const std::vector<int>& near(const Vec& p) const {
        const auto it = cells_.find(hash(keyOf(p)));
        return it == cells_.end() ? empty_ : it->second;
    }
    const Vec& a(int s) const { return segments_[std::size_t(s)].a; }
    const Vec& b(int s) const { return segments_[std::size_t(s)].b; }
    /// The closest crease point to \p p among the segments near it; false when there is none.
    bool closest(const Vec& p, Vec& out, double& distance) const {
        distance = std::numeric_limits<double>::infinity();
        for (int s : near(p)) {
            const Vec d = b(s) - a(s);
            const double len2 = d.squaredNorm();
            const double t = len2 > 0 ? std::clamp((p - a(s)).dot(d) / len2, 0.0, 1.0) : 0.0;
            const Vec q = a(s) + t * d;
            const double dist = (p - q).norm();
            if (dist < distance) distance = dist, out = q;
        }
        return std::isfinite(distance);
    }

private:
    struct Segment {
        Vec a, b;
    };
    struct Key {
        std::int64_t x, y, z;
    };
    Key keyOf(const Vec& p) const {
        return {std::int64_t(std::floor(p.x() / cell_)), std::int64_t(std::floor(p.y() / cell_)),
                std::int64_t(std::floor(p.z() / cell_))};
    }
    static std::uint64_t hash(const Key& k) {
        return std::uint64_t(k.x) * 73856093ULL ^ std::uint64_t(k.y) * 19349663ULL ^
               std::uint64_t(k.z) * 83492791ULL;
    }
    double cell_;
    std::vector<Segment> segments_;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
    std::vector<int> empty_;
};

struct Tri {
    Vec a, b, c;
};

class CreaseSnapper {
public:
    CreaseSnapper(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& o)
        : m_(mesh), o_(o), L_(o.edgeLength), floor_(o.minAngleDeg * std::numbers::pi / 180.0),
          caster_(reference), creases_(reference, o.creaseAngleDeg * std::numbers::pi / 180.0, o.edgeLength) {
    }

    std::size_t creaseEdges() const { return creases_.size(); }

    /// Sets the vertex property kOnCreaseProperty of the vertices this step put on a crease.
    void markCreaseVertices() {
        auto on = m_.add_property_map<VertexIndex, bool>(kOnCreaseProperty, false).first;
        for (VertexIndex v : m_.vertices())
            if (v.idx() < onCrease_.size() && onCrease_[v.idx()]) on[v] = true;
    }

    /// The vertices this step put on a crease (one flag per vertex index), to be restored with the mesh.
    std::vector<char> creaseMarks() const { return onCrease_; }
    void setCreaseMarks(std::vector<char> marks) { onCrease_ = std::move(marks); }

    /// One round: snaps, splits, flips; adds their counts to \p r.
    void round(CreaseSnapReport& r) {
        markFrozen();
        r.snaps += snapSweep();
        markFrozen();
        r.splits += splitSweep();
        markFrozen();
        for (int sweep = 0; sweep < 4; ++sweep) {
            const std::size_t f = flipSweep();
            r.flips += f;
            if (f == 0) break;
        }
    }

private:
    Mesh& m_;
    const CreaseSnapOptions& o_;
    const double L_, floor_;
    RayCaster caster_;
    CreaseIndex creases_;
    std::vector<char> frozen_;   // vertices that never move: border vertices
    std::vector<char> onCrease_; // vertices this step put on a crease

    bool isInput(FaceIndex f) const {
        const auto [ids, have] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        return !have || ids[f] < 0;
    }

    void markFrozen() {
        const std::size_t nv = m_.number_of_vertices() + m_.number_of_removed_vertices();
        frozen_.assign(nv, 0);
        onCrease_.resize(nv, 0);
        for (VertexIndex v : m_.vertices())
            frozen_[v.idx()] = m_.is_border(v);
    }

    /// Whether the faces within two vertex rings of \p vertices intersect each other (CGAL PMP, exact
    /// predicates): checked after each operation, which is undone when they do.
    bool intersectsAround(std::initializer_list<VertexIndex> vertices) const {
        std::vector<VertexIndex> ring(vertices);
        for (VertexIndex v : vertices)
            for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                ring.push_back(w);
        std::vector<FaceIndex> faces;
        for (VertexIndex v : ring)
            for (FaceIndex f : CGAL::faces_around_target(m_.halfedge(v), m_))
                if (f != Mesh::null_face()) faces.push_back(f);
        std::sort(faces.begin(), faces.end());
        faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
        return PMP::does_self_intersect(faces, m_);
    }

    /// Distance of a triangle to the reference, sampled at its centroid, edge midpoints and three inner
    /// points: the largest, and the area times the mean square.
    struct Error {
        double max = 0, integral = 0;
    };
    Error error(const Tri& t) const {
        static constexpr double w[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3},
                                           {0.5, 0.5, 0},
                                           {0, 0.5, 0.5},
                                           {0.5, 0, 0.5},
                                           {4.0 / 6, 1.0 / 6, 1.0 / 6},
                                           {1.0 / 6, 4.0 / 6, 1.0 / 6},
                                           {1.0 / 6, 1.0 / 6, 4.0 / 6}};
        Error e;
        for (const auto& k : w) {
            const double d = caster_.closestPoint(k[0] * t.a + k[1] * t.b + k[2] * t.c).distance;
            e.max = std::max(e.max, d);
            e.integral += d * d;
        }
        e.integral *= 0.5 * (t.b - t.a).cross(t.c - t.a).norm() / 7.0;
        return e;
    }

    /// Whether the triangles \p after may replace \p before: no degenerate face, no normal turned by 90° or
    /// more (each face against its own old normal when \p sameCount, else against the old faces' mean
    /// normal), no angle below the floor (or the smallest old angle), a largest distance to the reference
    /// that does not grow and an integrated squared distance that falls below \p gain times the old one;
    /// never when the old faces are within \p minOldError of the reference already.
    bool better(const std::vector<Tri>& before, const std::vector<Tri>& after, bool sameCount, double gain,
                double minOldError = 0) const {
        Vec mean(0, 0, 0);
        double oldMin = std::numbers::pi, newMin = std::numbers::pi;
        for (const Tri& t : before) {
            mean += (t.b - t.a).cross(t.c - t.a);
            oldMin = std::min(oldMin, minAngle(t.a, t.b, t.c));
        }
        for (std::size_t i = 0; i < after.size(); ++i) {
            const Tri& t = after[i];
            const Vec n = unitNormal(t.a, t.b, t.c);
            if (n.isZero()) return false;
            const Vec ref = sameCount ? unitNormal(before[i].a, before[i].b, before[i].c) : mean;
            if (n.dot(ref) <= 0) return false;
            newMin = std::min(newMin, minAngle(t.a, t.b, t.c));
        }
        if (newMin < std::min(oldMin, floor_)) return false;
        Error oldErr, newErr;
        for (const Tri& t : before) {
            const Error e = error(t);
            oldErr.max = std::max(oldErr.max, e.max);
            oldErr.integral += e.integral;
        }
        if (oldErr.max < minOldError) return false;
        for (const Tri& t : after) {
            const Error e = error(t);
            newErr.max = std::max(newErr.max, e.max);
            newErr.integral += e.integral;
        }
        return newErr.max <= oldErr.max + 1e-6 * L_ && newErr.integral < gain * oldErr.integral;
    }

    /// Moves vertices near a crease onto their closest crease point, nearest first; a vertex next to one
    /// already on a crease within the snap radius of that point stays (two vertices there make a short edge).
    /// Vertices farther from the crease but off the reference go onto their closest reference point.
    std::size_t snapSweep() {
        struct Candidate {
            double distance;
            VertexIndex v;
            Vec target;
            bool crease; // the target is on a crease (else the closest reference point)
        };
        std::vector<Candidate> candidates;
        for (VertexIndex v : m_.vertices()) {
            if (frozen_[v.idx()] || onCrease_[v.idx()]) continue;
            Vec q;
            double d;
            if (!creases_.closest(pos(m_, v), q, d)) continue; // no crease near
            if (d < o_.snapRadius * L_) {
                if (d > 1e-9 * L_) candidates.push_back({d, v, q, true});
                continue;
            }
            // Farther from the crease but off the reference (the stitches' collapses leave a few vertices
            // inside a bevel): onto the closest reference point.
            const SurfacePoint sp = caster_.closestPoint(pos(m_, v));
            if (sp && sp.distance > 0.1 * L_) candidates.push_back({sp.distance, v, sp.point, false});
        }
        std::sort(candidates.begin(), candidates.end(),
                  [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
        std::size_t snaps = 0;
        for (const Candidate& c : candidates) {
            const VertexIndex v = c.v;
            bool crowded = false;
            for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                crowded =
                    crowded || (onCrease_[w.idx()] && (pos(m_, w) - c.target).norm() < o_.snapRadius * L_);
            if (crowded) continue;
            const Vec p = pos(m_, v);
            std::vector<Tri> before, after;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
                const HalfedgeIndex n1 = m_.next(h);
                const Vec q = pos(m_, m_.target(n1)), r = pos(m_, m_.target(m_.next(n1)));
                before.push_back({p, q, r});
                after.push_back({c.target, q, r});
            }
            if (!better(before, after, true, 0.99)) continue;
            m_.point(v) = Point3(c.target.x(), c.target.y(), c.target.z());
            if (intersectsAround({v})) {
                m_.point(v) = Point3(p.x(), p.y(), p.z());
                continue;
            }
            onCrease_[v.idx()] = c.crease;
            ++snaps;
        }
        return snaps;
    }

    /// Splits, at the crease, edges that pass a crease point farther from both ends than the snap radius and
    /// farther from the edge than a tenth of the edge length (the bevel no snap could remove).
    std::size_t splitSweep() {
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
        std::vector<EdgeIndex> edges(m_.edges().begin(), m_.edges().end());
        std::size_t splits = 0;
        for (EdgeIndex e : edges) {
            if (m_.is_removed(e) || m_.is_border(e)) continue;
            const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
            const FaceIndex f = m_.face(h), g = m_.face(o);
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
            const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
            // The crease point closest to the edge.
            double best = std::numeric_limits<double>::infinity(), along = 0;
            Vec q;
            for (int s : creases_.near(0.5 * (pa + pb))) {
                double u, t;
                closestSegmentParameters(pa, pb, creases_.a(s), creases_.b(s), u, t);
                const Vec x = pa + u * (pb - pa), y = creases_.a(s) + t * (creases_.b(s) - creases_.a(s));
                if ((x - y).norm() < best) best = (x - y).norm(), q = y, along = u;
            }
            // The edge passes the crease between its ends, at a bevel of a tenth to most of an edge length.
            if (!std::isfinite(best) || best < 0.1 * L_ || best > L_ || along <= 0.1 || along >= 0.9)
                continue;
            const double radius = o_.snapRadius * L_;
            if ((q - pa).norm() < radius || (q - pb).norm() < radius) continue;
            // Faces (a, b, c), (b, a, d) become (a, q, c), (q, b, c), (b, q, d), (q, a, d).
            if (!better({{pa, pb, pc}, {pb, pa, pd}}, {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}},
                        false, 0.99))
                continue;
            const std::int32_t idF = haveIds ? ids[f] : -1, idG = haveIds ? ids[g] : -1;
            const float qualityF = haveQuality ? quality[f] : 0.f, qualityG = haveQuality ? quality[g] : 0.f;
            const HalfedgeIndex hn = CGAL::Euler::split_edge(h, m_);
            const VertexIndex v = m_.target(hn);
            m_.point(v) = Point3(q.x(), q.y(), q.z());
            const HalfedgeIndex h3 = CGAL::Euler::split_face(hn, m_.next(m_.next(hn)), m_);
            const HalfedgeIndex og = m_.opposite(h);
            const HalfedgeIndex h4 = CGAL::Euler::split_face(og, m_.next(m_.next(og)), m_);
            for (FaceIndex nf :
                 {m_.face(h3), m_.face(m_.opposite(h3)), m_.face(h4), m_.face(m_.opposite(h4))}) {
                const bool sideF = nf == m_.face(h3) || nf == m_.face(m_.opposite(h3));
                if (haveIds) ids[nf] = sideF ? idF : idG;
                if (haveQuality) quality[nf] = sideF ? qualityF : qualityG;
            }
            if (intersectsAround({v, a, b})) { // undo: the two new edges, then the new vertex
                CGAL::Euler::join_face(h4, m_);
                CGAL::Euler::join_face(h3, m_);
                CGAL::Euler::join_vertex(h, m_); // removes v, the source of h
                continue;
            }
            frozen_.resize(m_.number_of_vertices() + m_.number_of_removed_vertices(), 0);
            onCrease_.resize(frozen_.size(), 0);
            onCrease_[v.idx()] = 1;
            ++splits;
        }
        return splits;
    }

    /// Flips edges near a crease where the other diagonal of their two faces lies closer to the reference.
    std::size_t flipSweep() {
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
        std::size_t flips = 0;
        for (EdgeIndex e : m_.edges()) {
            if (m_.is_border(e)) continue;
            const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
            if (isInput(m_.face(h)) != isInput(m_.face(o))) continue; // the scanned area stays
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
            if (c == d || m_.degree(a) <= 3 || m_.degree(b) <= 3) continue;
            const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
            Vec q;
            double dist;
            if (!creases_.closest(0.25 * (pa + pb + pc + pd), q, dist) || dist > L_) continue;
            if (CGAL::halfedge(c, d, m_).second) continue;
            // Faces (a, b, c), (b, a, d) become (a, d, c), (d, b, c).
            if (!better({{pa, pb, pc}, {pb, pa, pd}}, {{pa, pd, pc}, {pd, pb, pc}}, false, 0.8, 0.02 * L_))
                continue;
            const FaceIndex f = m_.face(h), g = m_.face(o);
            const std::int32_t idF = haveIds ? ids[f] : -1, idG = haveIds ? ids[g] : -1;
            const float qualityF = haveQuality ? quality[f] : 0.f, qualityG = haveQuality ? quality[g] : 0.f;
            CGAL::Euler::flip_edge(h, m_);
            if (intersectsAround({a, b, c, d})) { // undo: the second flip rotates the edge back to (a, b)
                CGAL::Euler::flip_edge(h, m_);
                // The faces may have swapped sides: the one with corner c is (a, b, c) again.
                for (FaceIndex k : {m_.face(h), m_.face(m_.opposite(h))}) {
                    bool hasC = false;
                    for (VertexIndex w : CGAL::vertices_around_face(m_.halfedge(k), m_))
                        hasC = hasC || w == c;
                    if (haveIds) ids[k] = hasC ? idF : idG;
                    if (haveQuality) quality[k] = hasC ? qualityF : qualityG;
                }
                continue;
            }
            ++flips;
        }
        return flips;
    }
};

} // namespace

CreaseSnapReport snapToCreases(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& options) {
    CreaseSnapReport report;
    if (options.rounds <= 0 || mesh.is_empty() || reference.is_empty()) return report;
    CreaseSnapper snapper(mesh, reference, options);
    report.creaseEdges = snapper.creaseEdges();
    if (report.creaseEdges == 0) return report;
    const bool intersectedBefore = PMP::does_self_intersect(mesh);
    for (int round = 0; round < options.rounds; ++round) {
        const Mesh before = mesh;
        std::vector<char> marksBefore = snapper.creaseMarks();
        CreaseSnapReport r;
        snapper.round(r);
        if (r.snaps + r.splits + r.flips == 0) break;
        if (!intersectedBefore && PMP::does_self_intersect(mesh)) {
            mesh = before;
            snapper.setCreaseMarks(std::move(marksBefore));
            ++report.roundsReverted;
            break;
        }
        report.snaps += r.snaps;
        report.splits += r.splits;
        report.flips += r.flips;
    }
    snapper.markCreaseVertices();
    mesh.collect_garbage();
    return report;
}

} // namespace fss::detail
