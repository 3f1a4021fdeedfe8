#include "remesh/crease_snap.h"

#include "mesh/features.h"
#include "mesh/local_ops.h"
#include "mesh/triangle_geometry.h"

#include "fss/raycast.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
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
    CreaseIndex(const Mesh& reference, double creaseAngleDeg, double cell) : cell_(cell) {
        const std::vector<char> sharp = sharpEdges(reference, creaseAngleDeg);
        for (EdgeIndex e : reference.edges()) {
            if (!sharp[e.idx()]) continue;
            const HalfedgeIndex h = reference.halfedge(e);
            const Vec a = pos(reference, reference.source(h)), b = pos(reference, reference.target(h));
            const int id = int(segments_.size());
            segments_.push_back({a, b});
            const Vec lo = a.cwiseMin(b).array() - cell, hi = a.cwiseMax(b).array() + cell;
            const Key k0 = keyOf(lo), k1 = keyOf(hi);
            for (std::int64_t x = k0.x; x <= k1.x; ++x)
                for (std::int64_t y = k0.y; y <= k1.y; ++y)
                    for (std::int64_t z = k0.z; z <= k1.z; ++z)
                        cells_[hash({x, y, z})].push_back(id);
        }
        for (VertexIndex v : creaseCorners(reference, sharp))
            corners_.push_back(pos(reference, v));
    }
    /// The corners of the creases: reference vertices where a crease ends or branches (one crease edge,
    /// or three and more).
    const std::vector<Vec>& corners() const { return corners_; }
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
    std::vector<Vec> corners_;
};

struct Tri {
    Vec a, b, c;
};

class CreaseSnapper {
public:
    CreaseSnapper(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& o)
        : m_(mesh), ref_(reference), o_(o), L_(o.edgeLength),
          floor_(o.minAngleDeg * std::numbers::pi / 180.0), caster_(reference),
          creases_(reference, o.creaseAngleDeg, o.edgeLength) {}

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
        r.snaps += cornerSweep();
        r.snaps += snapSweep();
        r.removals += removeSweep();
        markFrozen();
        r.repairs += shortCreaseEdgeSweep();
        r.repairs += repairSweep();
        markFrozen();
        r.splits += splitSweep();
        markFrozen();
        r.splits += errorSplitSweep();
        markFrozen();
        for (int sweep = 0; sweep < 4; ++sweep) {
            const std::size_t f = flipSweep();
            r.flips += f;
            if (f == 0) break;
        }
    }

private:
    Mesh& m_;
    const Mesh& ref_;
    const CreaseSnapOptions& o_;
    const double L_, floor_;
    RayCaster caster_;
    CreaseIndex creases_;
    std::vector<char> frozen_;   // vertices that never move: border vertices
    std::vector<char> onCrease_; // vertices this step put on a crease
    /// The corners of a triangle, in order (exact: a cache key).
    struct TriKey {
        std::array<double, 9> x;
        bool operator==(const TriKey& o) const { return x == o.x; }
    };
    struct TriKeyHash {
        std::size_t operator()(const TriKey& k) const {
            std::uint64_t h = 1469598103934665603ull;
            for (double d : k.x)
                h = (h ^ std::bit_cast<std::uint64_t>(d)) * 1099511628211ull;
            return std::size_t(h);
        }
    };

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
        return PMP::does_self_intersect(faceIndicesAround(ring), m_);
    }

    /// The faces around \p vertices (each once).
    std::vector<FaceIndex> faceIndicesAround(const std::vector<VertexIndex>& vertices) const {
        std::vector<FaceIndex> faces;
        for (VertexIndex v : vertices)
            for (FaceIndex f : CGAL::faces_around_target(m_.halfedge(v), m_))
                if (f != Mesh::null_face()) faces.push_back(f);
        std::sort(faces.begin(), faces.end());
        faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
        return faces;
    }

    /// Distance of a triangle to the reference, sampled at its centroid, edge midpoints and three inner
    /// points: the largest, and the area times the mean square.
    struct Error {
        double max = 0, integral = 0;
    };
    mutable std::unordered_map<TriKey, Error, TriKeyHash> errors_; // error() of the triangles measured
    Error error(const Tri& t) const {
        // The same triangles are measured again and again (each face lies in the stars of its three vertices
        // and next to three edges, over the sweeps and rounds): by their exact corners, once.
        TriKey key;
        for (int i = 0; i < 3; ++i) {
            key.x[std::size_t(i)] = t.a[i];
            key.x[std::size_t(3 + i)] = t.b[i];
            key.x[std::size_t(6 + i)] = t.c[i];
        }
        if (const auto it = errors_.find(key); it != errors_.end()) return it->second;
        const Error e = measureError(t);
        errors_.emplace(key, e);
        return e;
    }
    Error measureError(const Tri& t) const {
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
            if (n.dot(ref) <= 0 && !liesOnReference(t, n)) return false;
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

    /// Whether the triangle \p t (unit normal \p n) lies on the reference: its centroid within a tenth of an
    /// edge length of the reference, on a reference face whose normal is within 60° of \p n. Such a face
    /// replaces faces that fold over (a bevel whose two faces overlap), whose normals say nothing of the
    /// surface's side.
    bool liesOnReference(const Tri& t, const Vec& n) const {
        const SurfacePoint sp = caster_.closestPoint((t.a + t.b + t.c) / 3.0);
        return sp && sp.distance <= 0.1 * L_ && referenceNormalOf(sp.face).dot(n) > 0.5;
    }

    /// Moves, for each corner of the creases (crease_snap.h), the nearest vertex within twice the snap
    /// radius onto it (else the next nearest, up to three), where that brings its faces closer to the
    /// reference: the snap sweep alone puts a vertex on one of the creases there, not at their meeting point.
    std::size_t cornerSweep() {
        const std::vector<Vec>& corners = creases_.corners();
        if (corners.empty()) return 0;
        const double radius = 2 * o_.snapRadius * L_;
        // The corners in a uniform grid of cells of the radius: the vertices within the radius of a corner
        // lie in the 27 cells around their own.
        auto cellOf = [&](const Vec& p) {
            return std::array<std::int64_t, 3>{std::int64_t(std::floor(p.x() / radius)),
                                               std::int64_t(std::floor(p.y() / radius)),
                                               std::int64_t(std::floor(p.z() / radius))};
        };
        std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> grid;
        for (std::size_t i = 0; i < corners.size(); ++i)
            grid[cellOf(corners[i])].push_back(i);
        std::vector<std::vector<std::pair<double, VertexIndex>>> near(corners.size());
        std::vector<char> taken(corners.size(), 0);
        for (VertexIndex v : m_.vertices()) {
            const Vec p = pos(m_, v);
            const auto c = cellOf(p);
            for (std::int64_t dx = -1; dx <= 1; ++dx)
                for (std::int64_t dy = -1; dy <= 1; ++dy)
                    for (std::int64_t dz = -1; dz <= 1; ++dz) {
                        const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
                        if (it == grid.end()) continue;
                        for (std::size_t i : it->second) {
                            const double d = (p - corners[i]).norm();
                            if (d < 1e-9 * L_)
                                taken[i] = 1;
                            else if (d < radius && !frozen_[v.idx()])
                                near[i].emplace_back(d, v);
                        }
                    }
        }
        std::size_t snaps = 0;
        for (std::size_t i = 0; i < corners.size(); ++i) {
            if (taken[i] || near[i].empty()) continue;
            std::sort(near[i].begin(), near[i].end());
            if (near[i].size() > 3) near[i].resize(3);
            for (const auto& [d, v] : near[i])
                if (!m_.is_removed(v) && (pos(m_, v) - corners[i]).norm() < radius &&
                    moveVertex(v, corners[i])) {
                    onCrease_[v.idx()] = 1;
                    ++snaps;
                    break;
                }
        }
        return snaps;
    }

    /// Moves \p v to \p target where its faces come closer to the reference (better, with the same number of
    /// faces) and the faces around it intersect no other; false (and \p v where it was) otherwise.
    bool moveVertex(VertexIndex v, const Vec& target) {
        const Vec p = pos(m_, v);
        std::vector<Tri> before, after;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const HalfedgeIndex n1 = m_.next(h);
            const Vec q = pos(m_, m_.target(n1)), r = pos(m_, m_.target(m_.next(n1)));
            before.push_back({p, q, r});
            after.push_back({target, q, r});
        }
        return better(before, after, true, 0.99) && place(v, target);
    }

    /// Puts \p v at \p target unless the faces around it then intersect others (then \p v stays where it
    /// was).
    bool place(VertexIndex v, const Vec& target) {
        const Point3 old = m_.point(v);
        m_.point(v) = Point3(target.x(), target.y(), target.z());
        if (!intersectsAround({v})) return true;
        m_.point(v) = old;
        return false;
    }

    /// Removes vertices of valence 3 whose three faces lie farther from the reference than the one face
    /// that replaces them (better): the stitches leave a few inside the bevel of a crease, off the reference,
    /// where no snap can move them. The three faces must all be scanned or all be left from the input.
    std::size_t removeSweep() {
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
        std::vector<VertexIndex> candidates;
        for (VertexIndex v : m_.vertices())
            if (!frozen_[v.idx()] && m_.degree(v) == 3) candidates.push_back(v);
        std::size_t removals = 0;
        for (VertexIndex v : candidates) {
            if (m_.is_removed(v) || m_.degree(v) != 3) continue;
            std::vector<Tri> before;
            std::vector<VertexIndex> ring;
            std::vector<FaceIndex> faces;
            bool mixed = false, tooSmall = false;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
                const HalfedgeIndex n1 = m_.next(h);
                before.push_back({pos(m_, v), pos(m_, m_.target(n1)), pos(m_, m_.target(m_.next(n1)))});
                ring.push_back(m_.source(h));
                faces.push_back(m_.face(h));
                mixed = mixed || isInput(faces.front()) != isInput(faces.back());
                tooSmall = tooSmall || m_.degree(m_.source(h)) <= 3;
            }
            if (mixed || tooSmall) continue;
            // The ring (v's neighbours around it, in order) becomes one face with v's faces' orientation.
            const Tri merged{pos(m_, ring[2]), pos(m_, ring[1]), pos(m_, ring[0])};
            if (!better(before, {merged}, false, 0.99, 0.02 * L_)) continue;
            std::int32_t oldIds[3] = {-1, -1, -1};
            float oldQuality[3] = {0.f, 0.f, 0.f};
            for (std::size_t i = 0; i < 3; ++i) {
                if (haveIds) oldIds[i] = ids[faces[i]];
                if (haveQuality) oldQuality[i] = quality[faces[i]];
            }
            const Point3 old = m_.point(v);
            const HalfedgeIndex hv = m_.halfedge(v);
            const HalfedgeIndex border = CGAL::Euler::remove_center_vertex(hv, m_);
            const FaceIndex f = m_.face(border);
            if (haveIds) ids[f] = oldIds[0];
            if (haveQuality) quality[f] = oldQuality[0];
            if (intersectsAround({ring[0], ring[1], ring[2]})) { // undo: the vertex back in the face
                const HalfedgeIndex hn = CGAL::Euler::add_center_vertex(border, m_);
                m_.point(m_.target(hn)) = old;
                // Each new face has the halfedge (ring[i] → v) of the old face faces[i].
                for (HalfedgeIndex h : CGAL::halfedges_around_target(hn, m_)) {
                    const std::size_t i =
                        std::size_t(std::find(ring.begin(), ring.end(), m_.source(h)) - ring.begin());
                    if (haveIds) ids[m_.face(h)] = oldIds[i];
                    if (haveQuality) quality[m_.face(h)] = oldQuality[i];
                }
                continue;
            }
            ++removals;
        }
        return removals;
    }

    /// The reference's unit normal at the point closest to \p p (zero when there is none).
    Vec referenceNormal(const Vec& p) const {
        const SurfacePoint sp = caster_.closestPoint(p);
        return sp ? referenceNormalOf(sp.face) : Vec::Zero();
    }

    /// Whether \p t faces away from the reference: its normal against the reference's normal at the point
    /// closest to its centroid (a degenerate triangle counts as turned over).
    /// Whether \p t lies farther from the reference than errorSplitDistance edge lengths (sampled), looked at
    /// only for the faces within 1.5 edge lengths of a crease or whose centroid is off the reference by more
    /// than a tenth of an edge length (\p centroidDistance): a face whose centroid lies on the reference is
    /// that far from it only across a crease.
    bool far(const Tri& t, double centroidDistance) const {
        Vec q;
        double d;
        const bool nearCrease = creases_.closest((t.a + t.b + t.c) / 3.0, q, d) && d <= 1.5 * L_;
        if (!nearCrease && centroidDistance <= 0.1 * L_) return false;
        return error(t).max > o_.errorSplitDistance * L_;
    }

    Vec referenceNormalOf(FaceIndex f) const {
        const HalfedgeIndex h = ref_.halfedge(f);
        return unitNormal(pos(ref_, ref_.source(h)), pos(ref_, ref_.target(h)),
                          pos(ref_, ref_.target(ref_.next(h))));
    }

    bool turnedOver(const Tri& t) const {
        const Vec n = unitNormal(t.a, t.b, t.c);
        return n.isZero() || n.dot(referenceNormal((t.a + t.b + t.c) / 3.0)) < 0;
    }

    /// The smallest angle and the largest distance to the reference of the faces an operation replaces.
    struct Before {
        double minAngle = std::numbers::pi, maxError = 0;
    };
    Before measure(const std::vector<Tri>& before) const {
        Before b;
        for (const Tri& t : before) {
            b.minAngle = std::min(b.minAngle, minAngle(t.a, t.b, t.c));
            b.maxError = std::max(b.maxError, error(t).max);
        }
        return b;
    }

    /// Whether \p after may replace faces measured as \p before, among which a face turned over or far from
    /// the reference: none of \p after is turned over, no angle below the floor (or the smallest angle
    /// before), and a largest distance to the reference at most \p gain times the one before.
    bool repairs(const Before& before, const std::vector<Tri>& after, double gain) const {
        for (const Tri& t : after)
            if (minAngle(t.a, t.b, t.c) < std::min(before.minAngle, floor_)) return false;
        for (const Tri& t : after)
            if (turnedOver(t)) return false;
        const double limit = gain * before.maxError + 1e-6 * L_;
        for (const Tri& t : after)
            if (error(t).max > limit) return false;
        return true;
    }

    /// Whether \p v is on a crease: put there by this step, or lying on one (within 10⁻⁶ edge lengths).
    bool onACrease(VertexIndex v) const {
        if (onCrease_[v.idx()]) return true;
        Vec q;
        double d;
        return creases_.closest(pos(m_, v), q, d) && d < 1e-6 * L_;
    }

    /// Collapses edges shorter than a third of an edge length between two vertices on a crease (two snaps,
    /// splits or grid samples next to each other), onto one of them, where that turns no face over, makes no
    /// angle below the floor (or the smallest one there) and takes no face farther from the reference.
    std::size_t shortCreaseEdgeSweep() {
        std::vector<EdgeIndex> edges;
        for (EdgeIndex e : m_.edges()) {
            const HalfedgeIndex h = m_.halfedge(e);
            if (onACrease(m_.source(h)) && onACrease(m_.target(h)) &&
                (pos(m_, m_.source(h)) - pos(m_, m_.target(h))).norm() < L_ / 3)
                edges.push_back(e);
        }
        std::size_t collapses = 0;
        for (EdgeIndex e : edges)
            if (!m_.is_removed(e) && tryCollapse(m_.halfedge(e), 1.0)) ++collapses;
        return collapses;
    }

    /// Repairs the faces turned over against the reference (folds the stitches and the seam relaxation leave
    /// at a crease, where two faces overlap) and the faces still farther from it than errorSplitDistance edge
    /// lengths (far): for each, the first of these that leaves no face there turned over and (for a far face)
    /// lowers the largest distance to the reference by a fifth (repairs) is taken: a flip of one of its
    /// edges, else a move of one of its corners onto the crease within an edge length of it, else a
    /// collapse of one of its edges to one end, to the crease point within an edge length of its midpoint,
    /// or to the reference point closest to its midpoint. Vertices put on a crease stay there; no edge
    /// between a face left from the input and a scanned one changes; an operation after which the faces
    /// around it intersect others is undone.
    std::size_t repairSweep() {
        // Turned over: the gain 1 (no farther from the reference); far from it (only faces near a crease,
        // where the scans leave such faces): the gain 0.8.
        auto bad = [&](FaceIndex f) {
            const Tri t = triangle(f);
            const SurfacePoint sp = caster_.closestPoint((t.a + t.b + t.c) / 3.0);
            if (!sp) return 0.0;
            const Vec n = unitNormal(t.a, t.b, t.c);
            if (n.isZero() || n.dot(referenceNormalOf(sp.face)) < 0) return 1.0;
            return far(t, sp.distance) ? 0.8 : 0.0;
        };
        std::vector<FaceIndex> folded;
        for (FaceIndex f : m_.faces())
            if (bad(f) > 0) folded.push_back(f);
        std::size_t repaired = 0;
        for (FaceIndex f : folded) {
            if (m_.is_removed(f)) continue;
            const double gain = bad(f);
            if (gain == 0) continue;
            // The three edges, taken before any of them changes the face.
            const HalfedgeIndex h0 = m_.halfedge(f);
            const std::array<HalfedgeIndex, 3> edges = {h0, m_.next(h0), m_.prev(h0)};
            bool done = false;
            for (std::size_t i = 0; i < 3 && !done; ++i)
                done = tryFlip(edges[i], gain);
            for (std::size_t i = 0; i < 3 && !done; ++i)
                done = tryMoveToCrease(m_.target(edges[i]), gain);
            for (std::size_t i = 0; i < 3 && !done; ++i)
                done = tryCollapse(edges[i], gain);
            repaired += done;
        }
        return repaired;
    }

    Tri triangle(FaceIndex f) const {
        const HalfedgeIndex h = m_.halfedge(f);
        return {pos(m_, m_.source(h)), pos(m_, m_.target(h)), pos(m_, m_.target(m_.next(h)))};
    }

    /// Whether the faces on the two sides of \p h are both scanned or both left from the input.
    bool sameKind(HalfedgeIndex h) const { return isInput(m_.face(h)) == isInput(m_.face(m_.opposite(h))); }

    bool tryFlip(HalfedgeIndex h, double gain) {
        const HalfedgeIndex o = m_.opposite(h);
        if (m_.is_border(m_.edge(h)) || !sameKind(h) || !canFlip(m_, h)) return false;
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
        if (!repairs(measure({{pa, pb, pc}, {pb, pa, pd}}), {{pa, pd, pc}, {pd, pb, pc}}, gain)) return false;
        return applyOrUndo([&] { CGAL::Euler::flip_edge(h, m_); }, {a, b, c, d});
    }

    /// Moves \p v onto its closest crease point when that is within one edge length, then flips the edge
    /// opposite \p v in each of its faces that the move flattened into a cap (an angle above 160° at \p v,
    /// between two vertices on the crease): the move with those flips must repair (repairs) the faces
    /// around \p v and the caps' neighbours, else the mesh is restored.
    bool tryMoveToCrease(VertexIndex v, double gain) {
        if (frozen_[v.idx()] || onCrease_[v.idx()]) return false;
        Vec q;
        double dist;
        if (!creases_.closest(pos(m_, v), q, dist) || dist > L_) return false;
        for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
            if (onCrease_[w.idx()] && (pos(m_, w) - q).norm() < o_.snapRadius * L_) return false; // crowded
        const Vec p = pos(m_, v);
        std::vector<Tri> before, moved;
        std::vector<HalfedgeIndex> caps; // the edges opposite v in the faces with an angle above 160° at q
        for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
            const HalfedgeIndex opposite = m_.prev(h); // from target(next(h)) to source(h)
            const Vec x = pos(m_, m_.source(opposite)), y = pos(m_, m_.target(opposite));
            before.push_back({p, x, y});
            moved.push_back({q, x, y});
            if (angleBetween(x - q, y - q) > 160.0 * std::numbers::pi / 180.0) caps.push_back(opposite);
        }
        const Before measured = measure(before);
        if (caps.empty() && repairs(measured, moved, gain)) { // the move alone
            if (!place(v, q)) return false;
            onCrease_[v.idx()] = 1;
            return true;
        }
        // The move alone does not repair: with the caps flipped, then edges around v flipped where that
        // raises the smaller angle of their two faces (the edges opposite v, the edges from v), it may. Only
        // worth trying when the move brings the faces close enough and turns none over (its angles are what
        // the flips mend). The faces compared are those around v and its neighbours, before and after.
        if (!caps.empty() || closeEnough(measured, moved, gain)) {
            std::vector<VertexIndex> region{v};
            for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                region.push_back(w);
            const std::vector<Tri> regionBefore = facesAround(region);
            const Mesh saved = m_;
            auto restore = [&] {
                m_ = saved;
                return false;
            };
            m_.point(v) = Point3(q.x(), q.y(), q.z());
            for (HalfedgeIndex c : caps)
                if (!flipIfValid(c)) return restore();
            if (!mendAround(v, region, regionBefore, gain * measured.maxError)) return restore();
            onCrease_[v.idx()] = 1;
            return true;
        }
        return false;
    }

    /// Flips edges around \p v (opposite it or from it) where that raises the smaller angle of their two
    /// faces (at most eight, the best first), then whether the faces around \p region may replace \p
    /// regionBefore (the faces around the same vertices before the operation at \p v): none turned over, no
    /// angle below the floor (or the smallest angle before), none farther than \p maxError from the
    /// reference, and no intersection around \p v. The caller restores the mesh when not.
    bool mendAround(VertexIndex v, const std::vector<VertexIndex>& region,
                    const std::vector<Tri>& regionBefore, double maxError) {
        for (int flips = 0; flips < 8; ++flips) {
            HalfedgeIndex best;
            double bestGain = 1e-3;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_))
                for (HalfedgeIndex c : {m_.prev(h), h}) {
                    const double g = flipAngleGain(c);
                    if (g > bestGain) bestGain = g, best = c;
                }
            if (best == Mesh::null_halfedge() || !flipIfValid(best)) break;
        }
        Before limits = measure(regionBefore);
        limits.maxError = maxError;
        return repairs(limits, facesAround(region), 1.0) && !intersectsAround({v});
    }

    /// The triangles around \p vertices (each once).
    std::vector<Tri> facesAround(const std::vector<VertexIndex>& vertices) const {
        std::vector<Tri> tris;
        for (FaceIndex f : faceIndicesAround(vertices))
            tris.push_back(triangle(f));
        return tris;
    }

    /// How much a flip of the edge of \p c raises the smaller angle of its two faces (radians; ≤ 0 when it
    /// does not, or when the flipped faces would bend by more than 60° against each other).
    double flipAngleGain(HalfedgeIndex c) const {
        const HalfedgeIndex o = m_.opposite(c);
        if (m_.is_border(m_.edge(c))) return 0;
        const Vec x = pos(m_, m_.source(c)), y = pos(m_, m_.target(c));
        const Vec a = pos(m_, m_.target(m_.next(c))), b = pos(m_, m_.target(m_.next(o)));
        // Faces (x, y, a), (y, x, b) become (x, b, a), (b, y, a).
        if (unitNormal(x, b, a).dot(unitNormal(b, y, a)) < 0.5) return 0;
        return std::min(minAngle(x, b, a), minAngle(b, y, a)) -
               std::min(minAngle(x, y, a), minAngle(y, x, b));
    }

    /// Flips the edge of \p c when that keeps the mesh valid (not a border, faces of one kind, valences above
    /// 3, the other diagonal not an edge yet).
    bool flipIfValid(HalfedgeIndex c) {
        if (m_.is_border(m_.edge(c)) || !sameKind(c) || !canFlip(m_, c)) return false;
        CGAL::Euler::flip_edge(c, m_);
        return true;
    }

    /// Whether \p after, with no face turned over, lies within \p gain times the largest distance of the
    /// faces measured as \p before (repairs without the angles).
    bool closeEnough(const Before& before, const std::vector<Tri>& after, double gain) const {
        for (const Tri& t : after)
            if (turnedOver(t)) return false;
        for (const Tri& t : after)
            if (error(t).max > gain * before.maxError + 1e-6 * L_) return false;
        return true;
    }

    bool tryCollapse(HalfedgeIndex h, double gain) {
        const HalfedgeIndex o = m_.opposite(h);
        const EdgeIndex e = m_.edge(h);
        if (m_.is_border(e) || !sameKind(h)) return false;
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        if (frozen_[a.idx()] || frozen_[b.idx()]) return false;
        const bool onA = onACrease(a), onB = onACrease(b);
        if (!canCollapse(m_, e)) return false;
        const Vec pa = pos(m_, a), pb = pos(m_, b);
        // Where the merged vertex goes, and whether that is on a crease.
        std::vector<std::pair<Vec, bool>> targets;
        if (onA && onB)
            targets = {{pa, true}, {pb, true}};
        else if (onA)
            targets = {{pa, true}};
        else if (onB)
            targets = {{pb, true}};
        else {
            targets = {{pa, false}, {pb, false}};
            Vec q;
            double dist;
            const Vec mid = 0.5 * (pa + pb);
            if (creases_.closest(mid, q, dist) && dist < L_) targets.emplace_back(q, true);
            if (const SurfacePoint sp = caster_.closestPoint(mid)) targets.emplace_back(sp.point, false);
        }
        std::vector<Tri> before;
        std::vector<std::array<VertexIndex, 3>> ring; // the faces that stay, by their corners
        for (VertexIndex v : {a, b})
            for (FaceIndex g : CGAL::faces_around_target(m_.halfedge(v), m_)) {
                if (g == m_.face(h) || g == m_.face(o)) continue;
                if (isInput(g) != isInput(m_.face(h)))
                    return false; // a border of the scanned area would move
                const HalfedgeIndex k = m_.halfedge(g);
                ring.push_back({m_.source(k), m_.target(k), m_.target(m_.next(k))});
                before.push_back(triangle(g));
            }
        for (FaceIndex g : {m_.face(h), m_.face(o)})
            before.push_back(triangle(g));
        const Before measured = measure(before);
        // The targets that repair, the one with the largest smallest angle first.
        std::vector<std::pair<double, std::size_t>> order;
        for (std::size_t i = 0; i < targets.size(); ++i) {
            std::vector<Tri> after;
            double smallest = std::numbers::pi;
            for (const auto& r : ring) {
                Vec corner[3];
                for (int k = 0; k < 3; ++k)
                    corner[k] = r[std::size_t(k)] == a || r[std::size_t(k)] == b ? targets[i].first
                                                                                 : pos(m_, r[std::size_t(k)]);
                after.push_back({corner[0], corner[1], corner[2]});
                smallest = std::min(smallest, minAngle(corner[0], corner[1], corner[2]));
            }
            if (repairs(measured, after, gain)) order.emplace_back(-smallest, i);
        }
        std::sort(order.begin(), order.end());
        for (const auto& [negAngle, i] : order) {
            const auto& [t, marked] = targets[i];
            if (applyOrUndo(
                    [&] {
                        const VertexIndex kept = CGAL::Euler::collapse_edge(e, m_);
                        m_.point(kept) = Point3(t.x(), t.y(), t.z());
                        onCrease_[kept.idx()] = marked;
                    },
                    {c, d}))
                return true;
        }
        return false;
    }

    /// Runs \p op; undoes it (the whole mesh and the vertex marks restored) when the faces within two rings
    /// of \p around then intersect others. True when it stays.
    template <typename Op> bool applyOrUndo(Op op, std::initializer_list<VertexIndex> around) {
        const Mesh saved = m_;
        const std::vector<char> frozen = frozen_, onCrease = onCrease_;
        op();
        if (!intersectsAround(around)) return true;
        m_ = saved;
        frozen_ = frozen;
        onCrease_ = onCrease;
        return false;
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
            if (crowded || !moveVertex(v, c.target)) continue;
            onCrease_[v.idx()] = c.crease;
            ++snaps;
        }
        return snaps;
    }

    /// The split of the edge of \p h at \p q that `better` refused, taken with the flips around the new
    /// vertex that mend its angles (mendAround) when its four faces, turned over none, lie within \p gain
    /// times the largest distance of the two faces it replaces; the new vertex, or the null vertex and the
    /// mesh as it was.
    VertexIndex mendedSplit(HalfedgeIndex h, const Vec& q, double gain) {
        const HalfedgeIndex o = m_.opposite(h);
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
        const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
        const Before before = measure({{pa, pb, pc}, {pb, pa, pd}});
        if (!closeEnough(before, {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, gain))
            return Mesh::null_vertex();
        std::vector<VertexIndex> region = {a, b, c, d};
        const std::vector<Tri> regionBefore = facesAround(region);
        const Mesh saved = m_;
        const VertexIndex v = splitAt(h, q);
        if (v == Mesh::null_vertex()) return v;
        region.push_back(v);
        if (mendAround(v, region, regionBefore, gain * before.maxError)) return v;
        m_ = saved;
        return Mesh::null_vertex();
    }

    /// Splits, at the crease, edges that pass a crease point farther from both ends than the snap radius and
    /// farther from the edge than a tenth of the edge length (the bevel no snap could remove).
    std::size_t splitSweep() {
        std::vector<EdgeIndex> edges(m_.edges().begin(), m_.edges().end());
        std::size_t splits = 0;
        for (EdgeIndex e : edges) {
            if (m_.is_removed(e) || m_.is_border(e)) continue;
            const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
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
            const VertexIndex v = better({{pa, pb, pc}, {pb, pa, pd}},
                                         {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, false, 0.99)
                                      ? splitAt(h, q)
                                      : mendedSplit(h, q, 0.9);
            if (v == Mesh::null_vertex()) continue;
            onCrease_[v.idx()] = 1;
            ++splits;
        }
        return splits;
    }

    /// Splits the edge of \p h at \p q (the faces (a, b, c), (b, a, d) become (a, q, c), (q, b, c),
    /// (b, q, d), (q, a, d); new faces keep the scan id and quality of the face they split), unless the faces
    /// around the new vertex then intersect others: the null vertex and the mesh as it was. Returns the new
    /// vertex (not marked on a crease).
    VertexIndex splitAt(HalfedgeIndex h, const Vec& q) {
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const auto [quality, haveQuality] = m_.property_map<FaceIndex, float>(props::faceQuality);
        const FaceIndex f = m_.face(h), g = m_.face(m_.opposite(h));
        const VertexIndex a = m_.source(h), b = m_.target(h);
        const std::int32_t idF = haveIds ? ids[f] : -1, idG = haveIds ? ids[g] : -1;
        const float qualityF = haveQuality ? quality[f] : 0.f, qualityG = haveQuality ? quality[g] : 0.f;
        const EdgeSplit split = splitEdge(m_, h, Point3(q.x(), q.y(), q.z()));
        const VertexIndex v = split.vertex;
        const HalfedgeIndex h3 = split.first, h4 = split.second;
        for (FaceIndex nf : {m_.face(h3), m_.face(m_.opposite(h3)), m_.face(h4), m_.face(m_.opposite(h4))}) {
            const bool sideF = nf == m_.face(h3) || nf == m_.face(m_.opposite(h3));
            if (haveIds) ids[nf] = sideF ? idF : idG;
            if (haveQuality) quality[nf] = sideF ? qualityF : qualityG;
        }
        if (intersectsAround({v, a, b})) {
            undoSplitEdge(m_, h, split);
            return Mesh::null_vertex();
        }
        frozen_.resize(m_.number_of_vertices() + m_.number_of_removed_vertices(), 0);
        onCrease_.resize(frozen_.size(), 0);
        frozen_[v.idx()] = 0;
        onCrease_[v.idx()] = 0;
        return v;
    }

    /// Splits the longest edge of each face still farther from the reference than errorSplitDistance edge
    /// lengths (far: a face the crease runs through, away from its edges' ends, or one spanning a sharp bend)
    /// at the reference point closest to the edge's midpoint, or at the closest crease point when a
    /// crease passes within the snap radius of it, where that brings the faces closer (better).
    std::size_t errorSplitSweep() {
        std::vector<FaceIndex> faces(m_.faces().begin(), m_.faces().end());
        std::size_t splits = 0;
        for (FaceIndex f : faces) {
            if (m_.is_removed(f)) continue;
            HalfedgeIndex h = m_.halfedge(f);
            const Tri t = triangle(f);
            const SurfacePoint sp = caster_.closestPoint((t.a + t.b + t.c) / 3.0);
            if (!sp || !far(t, sp.distance)) continue;
            for (HalfedgeIndex k : CGAL::halfedges_around_face(m_.halfedge(f), m_))
                if ((pos(m_, m_.source(k)) - pos(m_, m_.target(k))).squaredNorm() >
                    (pos(m_, m_.source(h)) - pos(m_, m_.target(h))).squaredNorm())
                    h = k;
            if (m_.is_border(m_.opposite(h))) continue;
            const HalfedgeIndex o = m_.opposite(h);
            const Vec pa = pos(m_, m_.source(h)), pb = pos(m_, m_.target(h));
            const Vec pc = pos(m_, m_.target(m_.next(h))), pd = pos(m_, m_.target(m_.next(o)));
            const Vec mid = 0.5 * (pa + pb);
            Vec q;
            double d;
            bool crease = creases_.closest(mid, q, d) && d < o_.snapRadius * L_;
            if (!crease) {
                const SurfacePoint sp = caster_.closestPoint(mid);
                if (!sp) continue;
                q = sp.point;
            }
            const VertexIndex v = better({{pa, pb, pc}, {pb, pa, pd}},
                                         {{pa, q, pc}, {q, pb, pc}, {pb, q, pd}, {q, pa, pd}}, false, 0.99)
                                      ? splitAt(h, q)
                                      : mendedSplit(h, q, 0.8);
            if (v == Mesh::null_vertex()) continue;
            onCrease_[v.idx()] = crease;
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
            if (!canFlip(m_, h)) continue;
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
            const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
            Vec q;
            double dist;
            if (!creases_.closest(0.25 * (pa + pb + pc + pd), q, dist) || dist > L_) continue;
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
    const bool intersectedBefore = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
    for (int round = 0; round < options.rounds; ++round) {
        const Mesh before = mesh;
        std::vector<char> marksBefore = snapper.creaseMarks();
        CreaseSnapReport r;
        snapper.round(r);
        if (r.snaps + r.splits + r.flips + r.removals + r.repairs == 0) break;
        if (!intersectedBefore && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) {
            mesh = before;
            snapper.setCreaseMarks(std::move(marksBefore));
            ++report.roundsReverted;
            break;
        }
        report.snaps += r.snaps;
        report.splits += r.splits;
        report.flips += r.flips;
        report.removals += r.removals;
        report.repairs += r.repairs;
    }
    snapper.markCreaseVertices();
    mesh.collect_garbage();
    return report;
}

} // namespace fss::detail
