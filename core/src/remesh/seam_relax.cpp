#include "remesh/seam_relax.h"

#include "mesh/features.h"
#include "mesh/local_ops.h"
#include "mesh/triangle_geometry.h"
#include "remesh/crease_snap.h"

#include "fss/raycast.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace fss::detail {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Vec = Eigen::Vector3d;

class Relaxer {
public:
    Relaxer(Mesh& mesh, const Mesh& reference, const SeamRelaxOptions& o)
        : m_(mesh), ref_(reference), o_(o), floor_(o.minAngleDeg * std::numbers::pi / 180.0),
          maxTurn_(o.maxNormalChangeDeg * std::numbers::pi / 180.0),
          feature_(o.featureAngleDeg * std::numbers::pi / 180.0) {}

    /// The relaxation; with \p checkStages, a stage (the projection, a round's flips, its collapses or its
    /// smoothing) after which the mesh intersects itself is undone and run again with the vertices of the
    /// intersecting faces left out of the zone (every operation that made one of those faces moves one of
    /// them or changes a face around one of them), up to kStageRetries times; a stage that still makes the
    /// mesh intersect itself is undone, and that kind of stage is not run again.
    SeamRelaxReport run(bool checkStages) {
        SeamRelaxReport report;
        markFeaturesAndZone();
        report.zoneVertices = std::size_t(std::count(zone_.begin(), zone_.end(), 1));
        Mesh before;
        std::vector<char> fixedBefore, fixedEdgeBefore; // the collapses carry these flags over
        if (checkStages) before = m_, fixedBefore = fixed_, fixedEdgeBefore = fixedEdge_;
        // Runs one stage (\p work returns its operation count): false when it was finally undone.
        auto stage = [&](auto&& work, std::size_t& total) {
            for (int attempt = 0;; ++attempt) {
                touched_.clear();
                const std::size_t count = work();
                if (count == 0) return true;
                if (checkStages) {
                    const std::vector<std::pair<FaceIndex, FaceIndex>> pairs = intersectionsAtTouched();
                    if (!pairs.empty()) {
                        const std::vector<VertexIndex> frozen = cornersOf(m_, pairs);
                        m_ = before; // vertex indices are those of `before` (stages only remove vertices)
                        fixed_ = fixedBefore;
                        fixedEdge_ = fixedEdgeBefore;
                        if (attempt == kStageRetries) {
                            report.reverted = true;
                            return false;
                        }
                        for (VertexIndex v : frozen)
                            zone_[v.idx()] = 0;
                        continue;
                    }
                    before = m_, fixedBefore = fixed_, fixedEdgeBefore = fixedEdge_;
                }
                total += count;
                return true;
            }
        };
        stage([&] { return projectOffSurface(); }, report.projected);
        bool flipping = true, collapsing = o_.collapses, smoothing = true;
        for (int round = 0; round < o_.rounds; ++round) {
            std::size_t flips = 0, collapses = 0, moves = 0;
            if (flipping)
                flipping = stage(
                    [&] {
                        flips = 0;
                        for (int sweep = 0; sweep < 4; ++sweep) {
                            const std::size_t f = flipSweep();
                            flips += f;
                            if (f == 0) break;
                        }
                        return flips;
                    },
                    report.flips);
            if (collapsing) collapsing = stage([&] { return collapses = collapseSweep(); }, report.collapses);
            if (smoothing) smoothing = stage([&] { return moves = smoothSweep(); }, report.moves);
            if (flips == 0 && collapses == 0 && moves == 0) break;
        }
        return report;
    }

private:
    Mesh& m_;
    const Mesh& ref_;
    const SeamRelaxOptions& o_;
    const double floor_, maxTurn_, feature_;
    RayCaster caster_{ref_};
    static constexpr int kStageRetries = 3;
    std::vector<char> zone_, fixed_, fixedEdge_, touchesInput_;
    /// The vertices whose faces the current stage changed (moved, flipped, made by a collapse).
    std::vector<VertexIndex> touched_;

    /// The pairs of intersecting faces around the vertices in touched_: as the mesh was free of
    /// intersections before the stage (run checks stages only then), all the pairs of the whole mesh.
    std::vector<std::pair<FaceIndex, FaceIndex>> intersectionsAtTouched() const {
        return intersectionsAround(m_, touched_);
    }

    void markFeaturesAndZone() {
        const std::size_t nv = m_.number_of_vertices() + m_.number_of_removed_vertices();
        fixedEdge_.assign(m_.number_of_edges() + m_.number_of_removed_edges(), 0);
        fixed_.assign(nv, 0);
        zone_.assign(nv, 0);
        touchesInput_.assign(nv, 0);
        const auto [ids, haveIds] = m_.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        auto isInput = [&](FaceIndex f) { return f != Mesh::null_face() && (!haveIds || ids[f] < 0); };
        const std::vector<char> sharp = sharpEdges(m_, o_.featureAngleDeg);
        // Border and feature edges, and the edges between a face left from the input and a scanned one (so
        // that the scanned area, the coverage, stays as it is), are fixed: never flipped or collapsed, their
        // vertices never smoothed.
        for (EdgeIndex e : m_.edges()) {
            const HalfedgeIndex h = m_.halfedge(e);
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const bool border = m_.is_border(e);
            const bool input1 = isInput(m_.face(h)), input2 = isInput(m_.face(m_.opposite(h)));
            if (input1 || input2) touchesInput_[a.idx()] = touchesInput_[b.idx()] = 1;
            if (border || input1 != input2 || sharp[e.idx()]) {
                fixedEdge_[e.idx()] = 1;
                fixed_[a.idx()] = fixed_[b.idx()] = 1;
            }
        }
        // Vertices the crease recovery put on a crease of the reference stay there.
        if (const auto [onCrease, have] = m_.property_map<VertexIndex, bool>(kOnCreaseProperty); have)
            for (VertexIndex v : m_.vertices())
                if (onCrease[v]) fixed_[v.idx()] = 1;
        for (VertexIndex v : m_.vertices()) {
            bool seed = m_.degree(v) != 6;
            std::int32_t first = -2;
            for (FaceIndex f : CGAL::faces_around_target(m_.halfedge(v), m_)) {
                if (f == Mesh::null_face()) {
                    seed = true;
                    continue;
                }
                const std::int32_t id = haveIds ? ids[f] : -1;
                if (id < 0 || (first != -2 && id != first)) seed = true;
                first = id;
            }
            zone_[v.idx()] = seed;
        }
        for (int ring = 0; ring < o_.zoneRings; ++ring) {
            std::vector<char> grown(zone_);
            for (VertexIndex v : m_.vertices())
                if (zone_[v.idx()])
                    for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                        grown[w.idx()] = 1;
            zone_.swap(grown);
        }
    }

    /// Cost of a valence: an irregular vertex (valence ≠ 6) costs more than the squared deviations from 6 of
    /// the four vertices an operation changes can add up to in practice, so flips and collapses first lower
    /// the number of irregular vertices, then the squared deviation (which alone would trade a 4 and an 8
    /// for a 5 and a 7 but also a 9 for an 8, a 7 and a 7).
    static int deviation(int degree) { return (degree != 6) * 64 + (degree - 6) * (degree - 6); }

    /// One pass of valence-improving flips over the zone's edges.
    std::size_t flipSweep() {
        std::size_t flips = 0;
        const double tolerance = 0.05 * o_.edgeLength;
        for (EdgeIndex e : m_.edges()) {
            if (m_.is_removed(e) || fixedEdge_[e.idx()]) continue;
            const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
            if (c == d || !zone_[a.idx()] || !zone_[b.idx()] || !zone_[c.idx()] || !zone_[d.idx()]) continue;
            if (!canFlip(m_, h)) continue;
            const int da = int(m_.degree(a)), db = int(m_.degree(b));
            const int dc = int(m_.degree(c)), dd = int(m_.degree(d));
            const int before = deviation(da) + deviation(db) + deviation(dc) + deviation(dd);
            const int after = deviation(da - 1) + deviation(db - 1) + deviation(dc + 1) + deviation(dd + 1);
            if (after >= before) continue;
            const Vec pa = pos(m_, a), pb = pos(m_, b), pc = pos(m_, c), pd = pos(m_, d);
            // Faces (a, b, c), (b, a, d) become (a, d, c), (d, b, c).
            const double oldMin = std::min(minAngle(pa, pb, pc), minAngle(pb, pa, pd));
            const double newMin = std::min(minAngle(pa, pd, pc), minAngle(pd, pb, pc));
            if (newMin < std::min(oldMin, floor_)) continue;
            const Vec n1 = unitNormal(pa, pb, pc), n2 = unitNormal(pb, pa, pd);
            const Vec m1 = unitNormal(pa, pd, pc), m2 = unitNormal(pd, pb, pc);
            if (n1.isZero() || n2.isZero() || m1.isZero() || m2.isZero()) continue;
            const Vec mean = (n1 + n2).normalized();
            if (angleBetween(m1, mean) > maxTurn_ || angleBetween(m2, mean) > maxTurn_ ||
                angleBetween(m1, m2) > feature_)
                continue;
            // The new edge stays as close to the reference surface as the old one (or within a tolerance).
            const double oldGap = caster_.closestPoint(0.5 * (pa + pb)).distance;
            const double newGap = caster_.closestPoint(0.5 * (pc + pd)).distance;
            if (newGap > std::max(oldGap, tolerance)) continue;
            CGAL::Euler::flip_edge(h, m_);
            touched_.insert(touched_.end(), {a, b, c, d});
            ++flips;
        }
        return flips;
    }

    /// One pass of valence-improving edge collapses over the zone's edges between two free vertices: the
    /// kept vertex gets both valences minus four, the two opposite vertices lose one each (two valence-5
    /// vertices next to two valence-7 ones become four valence-6 vertices). The merged vertex sits at the
    /// reference point closest to the edge's midpoint.
    std::size_t collapseSweep() {
        std::size_t collapses = 0;
        const double maxLength = 4.0 / 3.0 * o_.edgeLength;
        for (EdgeIndex e : m_.edges()) {
            if (m_.is_removed(e) || fixedEdge_[e.idx()]) continue;
            const HalfedgeIndex h = m_.halfedge(e), o = m_.opposite(h);
            const VertexIndex a = m_.source(h), b = m_.target(h);
            const VertexIndex c = m_.target(m_.next(h)), d = m_.target(m_.next(o));
            // A vertex on a feature line may absorb a free neighbour (and stays where it is); two never
            // merge.
            if (c == d || (fixed_[a.idx()] && fixed_[b.idx()])) continue;
            if (!zone_[a.idx()] || !zone_[b.idx()] || !zone_[c.idx()] || !zone_[d.idx()]) continue;
            const int da = int(m_.degree(a)), db = int(m_.degree(b));
            const int dc = int(m_.degree(c)), dd = int(m_.degree(d));
            if (dc <= 3 || dd <= 3) continue;
            const int before = deviation(da) + deviation(db) + deviation(dc) + deviation(dd);
            const int after = deviation(da + db - 4) + deviation(dc - 1) + deviation(dd - 1);
            if (after >= before) continue;
            if (!canCollapse(m_, e)) continue;
            Vec q;
            if (fixed_[a.idx()] || fixed_[b.idx()]) {
                q = pos(m_, fixed_[a.idx()] ? a : b);
            } else {
                const SurfacePoint sp = caster_.closestPoint(0.5 * (pos(m_, a) + pos(m_, b)));
                if (!sp) continue;
                q = sp.point;
            }
            // The faces around a and b but the two of e, with a or b at q.
            double oldMin = std::min(faceMinAngle(m_.face(h)), faceMinAngle(m_.face(o)));
            double newMin = std::numbers::pi, longestBefore = 0, longestAfter = 0;
            bool ok = true;
            for (VertexIndex v : {a, b}) {
                const Vec p = pos(m_, v);
                for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
                    const FaceIndex f = m_.face(g);
                    if (f == m_.face(h) || f == m_.face(o)) continue;
                    const HalfedgeIndex n1 = m_.next(g);
                    const Vec s = pos(m_, m_.target(n1)), t = pos(m_, m_.target(m_.next(n1)));
                    oldMin = std::min(oldMin, minAngle(p, s, t));
                    newMin = std::min(newMin, minAngle(q, s, t));
                    longestBefore = std::max({longestBefore, (s - p).norm(), (t - p).norm()});
                    longestAfter = std::max({longestAfter, (s - q).norm(), (t - q).norm()});
                    const Vec n0 = unitNormal(p, s, t), n = unitNormal(q, s, t);
                    if (n0.isZero() || n.isZero() || angleBetween(n, n0) > maxTurn_) ok = false;
                }
            }
            if (!ok || newMin < std::min(oldMin, floor_) || longestAfter > std::max(maxLength, longestBefore))
                continue;
            // The new faces stay as close to the reference as the old ones (or within a tolerance): their
            // centroids, against the largest gap of the old faces' centroids.
            double oldGap = 0, newGap = 0;
            for (VertexIndex v : {a, b}) {
                const Vec p = pos(m_, v);
                for (HalfedgeIndex g : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
                    const HalfedgeIndex n1 = m_.next(g);
                    const Vec s = pos(m_, m_.target(n1)), t = pos(m_, m_.target(m_.next(n1)));
                    oldGap = std::max(oldGap, caster_.closestPoint((p + s + t) / 3.0).distance);
                    const FaceIndex f = m_.face(g);
                    if (f != m_.face(h) && f != m_.face(o))
                        newGap = std::max(newGap, caster_.closestPoint((q + s + t) / 3.0).distance);
                }
            }
            if (newGap > std::max(oldGap, 0.05 * o_.edgeLength)) continue;
            // The collapse keeps one edge of each pair (a, c), (b, c) and (a, d), (b, d): it keeps their
            // flags.
            auto featureOf = [&](VertexIndex u, VertexIndex w) {
                return char(fixedEdge_[m_.edge(CGAL::halfedge(u, w, m_).first).idx()]);
            };
            const char fc = featureOf(a, c) | featureOf(b, c), fd = featureOf(a, d) | featureOf(b, d);
            const char fixedKept = fixed_[a.idx()] | fixed_[b.idx()];
            const VertexIndex kept = CGAL::Euler::collapse_edge(e, m_);
            m_.point(kept) = Point3(q.x(), q.y(), q.z());
            fixed_[kept.idx()] = fixedKept;
            touchesInput_[kept.idx()] = touchesInput_[a.idx()] | touchesInput_[b.idx()];
            fixedEdge_[m_.edge(CGAL::halfedge(kept, c, m_).first).idx()] = fc;
            fixedEdge_[m_.edge(CGAL::halfedge(kept, d, m_).first).idx()] = fd;
            touched_.insert(touched_.end(), {kept, c, d});
            ++collapses;
        }
        return collapses;
    }

    double faceMinAngle(FaceIndex f) const {
        const HalfedgeIndex h = m_.halfedge(f);
        return minAngle(pos(m_, m_.source(h)), pos(m_, m_.target(h)), pos(m_, m_.target(m_.next(h))));
    }

    /// Moves the zone's vertices that lie off the reference surface (by more than a tenth of the edge
    /// length: the stitches' collapses on creases leave a few) onto their closest reference point, feature
    /// vertices included (not those of input faces), where no face of their star degenerates, turns over
    /// (normal change above 60°) or gets an angle below the floor.
    std::size_t projectOffSurface() {
        std::size_t moves = 0;
        const double tolerance = 0.1 * o_.edgeLength;
        const double maxTurn = std::numbers::pi / 3.0;
        for (VertexIndex v : m_.vertices()) {
            if (!zone_[v.idx()] || touchesInput_[v.idx()] || m_.is_border(v)) continue;
            const Vec p = pos(m_, v);
            const SurfacePoint sp = caster_.closestPoint(p);
            if (!sp || sp.distance <= tolerance) continue;
            const Vec q = sp.point;
            if (!moveKeepsStar(m_, v, q, maxTurn, floor_)) continue;
            m_.point(v) = Point3(q.x(), q.y(), q.z());
            touched_.push_back(v);
            ++moves;
        }
        return moves;
    }

    /// Whether the faces \p star (corners q, r after the moving vertex) stay as close to the reference with
    /// the vertex at \p to as at \p from, or within a twentieth of the edge length: their centroids' largest
    /// distance to the reference.
    template <class Star> bool staysNearReference(const Vec& from, const Vec& to, const Star& star) const {
        const double tolerance = 0.05 * o_.edgeLength;
        double newGap = 0;
        for (const auto& k : star)
            newGap = std::max(newGap, caster_.closestPoint((to + k.q + k.r) / 3.0).distance);
        if (newGap <= tolerance) return true;
        double oldGap = 0;
        for (const auto& k : star)
            oldGap = std::max(oldGap, caster_.closestPoint((from + k.q + k.r) / 3.0).distance);
        return newGap <= oldGap;
    }

    /// One pass of tangential smoothing of the zone's free vertices, projected onto the reference.
    std::size_t smoothSweep() {
        std::size_t moves = 0;
        for (VertexIndex v : m_.vertices()) {
            if (m_.is_removed(v) || !zone_[v.idx()] || fixed_[v.idx()]) continue;
            const Vec p = pos(m_, v);
            Vec centroid(0, 0, 0), normal(0, 0, 0);
            int n = 0;
            for (VertexIndex w : CGAL::vertices_around_target(m_.halfedge(v), m_))
                centroid += pos(m_, w), ++n;
            struct Corner {
                Vec q, r; // the face's other two vertices, in order after v
            };
            std::vector<Corner> star;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(m_.halfedge(v), m_)) {
                const HalfedgeIndex n1 = m_.next(h);
                const Corner k{pos(m_, m_.target(n1)), pos(m_, m_.target(m_.next(n1)))};
                normal += (k.q - p).cross(k.r - p);
                star.push_back(k);
            }
            if (n < 3 || normal.isZero()) continue;
            normal.normalize();
            centroid /= double(n);
            Vec t = centroid - p;
            t -= t.dot(normal) * normal;
            const SurfacePoint sp = caster_.closestPoint(p + o_.smoothingStep * t);
            if (!sp) continue;
            const Vec q = sp.point;
            if ((q - p).norm() <= 1e-9 * o_.edgeLength) continue;
            if (!moveKeepsStar(m_, v, q, maxTurn_, floor_)) continue;
            if (!staysNearReference(p, q, star)) continue;
            m_.point(v) = Point3(q.x(), q.y(), q.z());
            touched_.push_back(v);
            ++moves;
        }
        return moves;
    }
};

} // namespace

SeamRelaxReport relaxSeams(Mesh& mesh, const Mesh& reference, const SeamRelaxOptions& options) {
    if (options.rounds <= 0 || mesh.is_empty()) return {.freeAfter = options.knownFree};
    const bool intersectedBefore =
        !options.knownFree && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
    SeamRelaxReport report = Relaxer(mesh, reference, options).run(!intersectedBefore);
    mesh.collect_garbage();
    report.freeAfter = !intersectedBefore;
    return report;
}

} // namespace fss::detail
