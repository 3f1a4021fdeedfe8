#include "fishbone/crease_backbone.h"

#include "mesh/features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>

namespace fss::detail {
namespace {

// A crease chain as an arc-length parametrised 3D polyline (closed: its first and last points coincide).
class Chain {
public:
    explicit Chain(std::vector<Eigen::Vector3d> points) : p_(std::move(points)), arc_(p_.size(), 0.0) {
        for (std::size_t i = 1; i < p_.size(); ++i)
            arc_[i] = arc_[i - 1] + (p_[i] - p_[i - 1]).norm();
        closed_ = p_.size() > 3 && (p_.front() - p_.back()).norm() <= 1e-12 * (1.0 + arc_.back());
    }
    double length() const { return arc_.back(); }
    bool closed() const { return closed_; }
    /// The point at arc length \p s (a closed chain wraps around; an open one is clamped).
    Eigen::Vector3d at(double s) const {
        const double L = length();
        if (closed_ && L > 0) s -= L * std::floor(s / L);
        s = std::clamp(s, 0.0, L);
        const std::size_t i = std::min<std::size_t>(
            std::size_t(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin()), p_.size() - 1);
        const std::size_t a = i == 0 ? 0 : i - 1;
        const double len = arc_[i] - arc_[a];
        return len > 0 ? Eigen::Vector3d(p_[a] + (s - arc_[a]) / len * (p_[i] - p_[a])) : p_[a];
    }
    /// The arc length of the point of the chain nearest to \p q, and its distance.
    std::pair<double, double> nearest(const Eigen::Vector3d& q) const {
        double best = std::numeric_limits<double>::infinity(), where = 0;
        for (std::size_t i = 0; i + 1 < p_.size(); ++i) {
            const Eigen::Vector3d d = p_[i + 1] - p_[i];
            const double len2 = d.squaredNorm();
            const double t = len2 > 0 ? std::clamp((q - p_[i]).dot(d) / len2, 0.0, 1.0) : 0.0;
            const double dist = (p_[i] + t * d - q).norm();
            if (dist < best) {
                best = dist;
                where = arc_[i] + t * std::sqrt(len2);
            }
        }
        return {where, best};
    }

private:
    std::vector<Eigen::Vector3d> p_;
    std::vector<double> arc_;
    bool closed_ = false;
};

// Where crease point \p q (on the chain, tangent \p along in 3D) is seen on the screen: the screen position
// whose viewing ray first hits the surface within 0.05 footprints of q, or std::nullopt where q is behind
// the eye, outside the image or hidden. That is q's projection, or, where the ray through it grazes past the
// crease (a crease on the silhouette: the ray passes outside both faces by rounding and hits the surface
// behind, 5–9 footprints deep on fandisk −z/+x, where the backbone used to stop after 1–3 samples), the
// projection moved by 0.01 px across the crease's screen image to the side that shows it (0.002 footprints
// from q there). A point whose ray meets the surface in front of it is hidden. The scan casts that ray at
// the backbone sample, so the sample lies on the crease (an eye-ray test, "nothing between the eye and q",
// accepted such points, but the grid's rays through their projections passed them and sampled the surface
// behind: 12.7 h off on anchor +z).
std::optional<Eigen::Vector2d> seenAt(const CreaseBackboneInput& in, const Eigen::Vector3d& q,
                                      const Eigen::Vector3d& along) {
    const Camera& cam = in.camera;
    if (!(cam.viewDepth(q) > 0)) return std::nullopt;
    const Eigen::Vector2d s = cam.project(q).head<2>();
    if (!s.allFinite() || s.x() < 0 || s.y() < 0 || s.x() > cam.width || s.y() > cam.height)
        return std::nullopt;
    const double footprint = cam.pixelFootprint(q);
    const Eigen::Vector2d t = Eigen::Vector2d(cam.project(q + footprint * along.normalized()).head<2>()) - s;
    const Eigen::Vector2d across =
        t.norm() > 0 ? Eigen::Vector2d(Eigen::Vector2d(-t.y(), t.x()).normalized()) : Eigen::Vector2d(0, 0);
    for (const double offset : {0.0, 0.01, -0.01}) {
        const Eigen::Vector2d p = s + offset * across;
        const SurfacePoint hit = in.caster->intersect(cam.ray(p.x(), p.y()));
        if (hit && (hit.point - q).norm() <= 0.05 * footprint) return p;
        // The surface in front of q: hidden, whichever side.
        if (hit && cam.viewDepth(hit.point) < cam.viewDepth(q) - footprint) return std::nullopt;
    }
    return std::nullopt;
}

// A sample of the walk: arc length and screen position (seenAt).
struct Step {
    double s = 0;
    Eigen::Vector2d screen{0, 0};
};

// The walk along a chain from arc length s0 one way (dir = ±1), every h footprints, until one of
// creaseBackbone's stops or until \p budget of arc length is used. Returns the samples after s0.
std::vector<Step> walk(const CreaseBackboneInput& in, const Chain& chain, double s0, int dir, double budget) {
    const Camera& cam = in.camera;
    const double cosCorner = std::cos(45.0 * std::numbers::pi / 180.0);
    auto screen = [&](const Eigen::Vector3d& q) { return Eigen::Vector2d(cam.project(q).head<2>()); };
    std::vector<Step> out;
    double s = s0, used = 0, screenLength = 0;
    Eigen::Vector3d previous = Eigen::Vector3d::Zero();
    for (;;) {
        const Eigen::Vector3d q = chain.at(s);
        const double step = in.spacing * cam.pixelFootprint(q);
        if (!(step > 0) || used + step > budget) break;
        const double next = s + dir * step;
        if (!chain.closed() && (next < 0 || next > chain.length())) break;
        const Eigen::Vector3d qn = chain.at(next), edge = qn - q;
        if (!previous.isZero() && edge.dot(previous) < cosCorner * edge.norm() * previous.norm()) break;
        const double onScreen = (screen(qn) - screen(q)).norm();
        // A crease seen end-on: its samples crowd on the screen and the backbone's tangent is undefined.
        if (onScreen < 0.3 * in.spacing) break;
        const std::optional<Eigen::Vector2d> seen = seenAt(in, qn, edge);
        if (!seen) break;
        screenLength += onScreen;
        if (screenLength > in.maxLength && !chain.closed()) break; // a closed chain is bounded by itself
        out.push_back({next, *seen});
        s = next;
        used += step;
        previous = edge;
    }
    return out;
}

} // namespace

std::optional<CreaseBackbone> creaseBackbone(const CreaseBackboneInput& in, const Eigen::Vector2d& seed) {
    if (!in.mesh || !in.creaseEdges || !in.caster || in.creaseEdges->empty() || !(in.spacing > 0))
        return std::nullopt;
    const Camera& cam = in.camera;
    const SurfacePoint seedHit = in.caster->intersect(cam.ray(seed.x(), seed.y()));
    if (!seedHit) return std::nullopt;
    const Mesh& mesh = *in.mesh;
    std::vector<char> sharp(mesh.number_of_edges() + mesh.number_of_removed_edges(), 0);
    for (EdgeIndex e : *in.creaseEdges)
        sharp[e.idx()] = 1;
    // Chains between corners and branches only (no split where the faces' bisector turns: a closed ridge
    // turns it all the way round).
    std::optional<Chain> best;
    double bestDistance = in.snapDistance * in.spacing * cam.pixelFootprint(seedHit.point), s0 = 0;
    for (CreaseChain& c : creaseChains(mesh, sharp, 180.0)) {
        if (c.points.size() < 2) continue;
        Chain chain(std::move(c.points));
        const auto [where, distance] = chain.nearest(seedHit.point);
        if (distance <= bestDistance) {
            bestDistance = distance;
            s0 = where;
            best = std::move(chain);
        }
    }
    if (!best) return std::nullopt;
    const Chain& chain = *best;
    const Eigen::Vector3d start = chain.at(s0);
    const double L = chain.length();
    auto tangentAt = [&](double s) {
        const double d = 1e-3 * std::max(L, 1e-300);
        return Eigen::Vector3d(chain.at(s + d) - chain.at(s - d));
    };
    const std::optional<Eigen::Vector2d> startSeen = seenAt(in, start, tangentAt(s0));
    if (!startSeen) return std::nullopt;
    CreaseBackbone out;
    Backbone& b = out.backbone;
    auto add = [&](double s, const Eigen::Vector2d& p) {
        out.points.push_back(chain.at(s));
        b.samples.push_back(p);
    };
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<Step> forward = walk(in, chain, s0, 1, chain.closed() ? L : inf);
    if (chain.closed() && !forward.empty()) {
        const double covered = forward.back().s - s0;
        const double step = covered / double(forward.size());
        if (covered + step >= L - 0.5 * step) { // all the way round: a closed backbone of equal arcs
            const std::size_t n = std::max<std::size_t>(3, std::size_t(std::lround(L / step)));
            for (std::size_t k = 0; k < n; ++k) {
                const double s = s0 + L * double(k) / double(n);
                const std::optional<Eigen::Vector2d> seen = seenAt(in, chain.at(s), tangentAt(s));
                add(s, seen ? *seen : Eigen::Vector2d(cam.project(chain.at(s)).head<2>()));
            }
            b.closed = true;
            return out;
        }
    }
    const double used = forward.empty() ? 0.0 : forward.back().s - s0;
    const std::vector<Step> backward = walk(
        in, chain, s0, -1, chain.closed() ? L - used - 0.5 * in.spacing * cam.pixelFootprint(start) : inf);
    for (std::size_t k = backward.size(); k-- > 0;)
        add(backward[k].s, backward[k].screen);
    b.seedIndex = backward.size();
    add(s0, *startSeen);
    for (const Step& f : forward)
        add(f.s, f.screen);
    if (b.samples.size() < 2) return std::nullopt;
    return out;
}

namespace {

// The unit normal of face \p f.
Eigen::Vector3d unitNormal(const Mesh& m, FaceIndex f) {
    std::array<Eigen::Vector3d, 3> v;
    int k = 0;
    for (VertexIndex x : m.vertices_around_face(m.halfedge(f)))
        v[std::size_t(k++)] = Eigen::Vector3d(m.point(x).x(), m.point(x).y(), m.point(x).z());
    return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
}

} // namespace

std::vector<Rib> creaseRibs(const CreaseBackboneInput& in, const CreaseBackbone& crease) {
    const Camera& cam = in.camera;
    const Backbone& b = crease.backbone;
    const std::vector<Eigen::Vector3d>& q = crease.points;
    const std::size_t n = q.size();
    auto screen = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d(cam.project(p).head<2>()); };
    // The visible surface under screen point s (front-facing), if any.
    auto surfaceAt = [&](const Eigen::Vector2d& s) -> SurfacePoint {
        if (!s.allFinite() || s.x() < 0 || s.y() < 0 || s.x() > cam.width || s.y() > cam.height) return {};
        const Ray ray = cam.ray(s.x(), s.y());
        SurfacePoint hit = in.caster->intersect(ray);
        if (hit && !(unitNormal(*in.mesh, hit.face).dot(ray.direction) < 0)) hit = {};
        return hit;
    };
    std::vector<Rib> ribs(n);
    for (std::size_t r = 0; r < n; ++r) {
        const Eigen::Vector2d p0 = b.samples[r], normal = b.normal(r);
        ribs[r] = Rib{{p0}, {p0}};
        const std::size_t prev = b.closed ? (r + n - 1) % n : (r == 0 ? 0 : r - 1);
        const std::size_t next = b.closed ? (r + 1) % n : std::min(r + 1, n - 1);
        const Eigen::Vector3d tangent = (q[next] - q[prev]).normalized();
        const double step = in.spacing * cam.pixelFootprint(q[r]);
        if (!tangent.allFinite() || !(step > 0)) continue;
        for (const int side : {1, -1}) {
            SurfacePoint at = surfaceAt(p0 + 0.5 * in.spacing * side * normal);
            if (!at) continue;
            // Perpendicular to the crease in the face beside it, towards this side on the screen: the face
            // at the crease on the side of the one seen h/2 beside (the nearest face to a point a tenth of a
            // step from the crease towards that one). The face seen beside lies 1.8 steps out where the side
            // is seen obliquely (the creased ring from 75° above), its plane tilted by the side's curvature
            // there, and the first step ended 0.4 steps off the surface, 1.4 steps from the crease.
            const Eigen::Vector3d towards = at.point - q[r];
            if (towards.norm() > 0.1 * step) {
                const SurfacePoint near = in.caster->closestPoint(q[r] + 0.1 * step * towards.normalized());
                if (near && unitNormal(*in.mesh, near.face).dot(unitNormal(*in.mesh, at.face)) > 0.5)
                    at = near;
            }
            Eigen::Vector3d n3 = unitNormal(*in.mesh, at.face), u = n3.cross(tangent).normalized();
            if ((screen(q[r] + step * u) - p0).dot(side * normal) < 0) u = -u;
            Polyline2& half = side > 0 ? ribs[r].positive : ribs[r].negative;
            Eigen::Vector3d from = q[r];
            double length = 0;
            for (;;) {
                // One step straight on, onto the surface under it: straight on a planar face, the surface's
                // straightest line on a curved one. It ends off the surface, at a depth jump (the surface
                // point farther than half a step from the step's end) and where its screen edges shrink.
                const Eigen::Vector3d to = from + step * u;
                // The surface point nearest to the step's end, seen there: the viewing ray through its
                // projection hits it (the ray through the end's own projection slides along a surface seen
                // obliquely, by 0.1 step per step on the creased ring from 75° above).
                const SurfacePoint nearest = in.caster->closestPoint(to);
                if (!nearest || (nearest.point - to).norm() > 0.5 * step) break;
                if (!(cam.viewDepth(nearest.point) > 0)) break;
                const Eigen::Vector2d s = screen(nearest.point);
                const double edge = (s - half.back()).norm();
                if (edge < 0.3 * in.spacing || length + edge > in.ribMaxLength) break;
                const SurfacePoint hit = surfaceAt(s);
                if (!hit || (hit.point - nearest.point).norm() > 0.05 * step) break;
                length += edge;
                half.push_back(s);
                n3 = unitNormal(*in.mesh, hit.face);
                const Eigen::Vector3d along = (hit.point - from) - (hit.point - from).dot(n3) * n3;
                if (!(along.norm() > 0)) break;
                u = along.normalized();
                from = hit.point;
            }
        }
    }
    return ribs;
}

} // namespace fss::detail
