#include "fss/fishbone.h"

#include "fss/error.h"

#include "base/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

namespace fss {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

Eigen::Vector2d rotate(const Eigen::Vector2d& v, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

void requireSpacing(double h) {
    if (!(h > 0) || !std::isfinite(h))
        throw InvalidInputError("The fishbone spacing h must be positive and finite.");
}

void requireBackbone(const Backbone& backbone) {
    if (backbone.samples.size() < 2)
        throw InvalidInputError(
            "The backbone has fewer than two samples; it must be longer than the spacing h.");
}

// Closest point of a polyline to p: (segment index, parameter on it, distance).
struct Closest {
    std::size_t segment = 0;
    double t = 0;
    double distance = std::numeric_limits<double>::infinity();
};
Closest closestOnPolyline(const Polyline2& line, const Eigen::Vector2d& p) {
    Closest best;
    if (line.size() == 1) {
        best.distance = (line[0] - p).norm();
        return best;
    }
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Eigen::Vector2d d = line[i + 1] - line[i];
        const double len2 = d.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - line[i]).dot(d) / len2, 0.0, 1.0) : 0.0;
        const double dist = (line[i] + t * d - p).norm();
        if (dist < best.distance) best = {i, t, dist};
    }
    return best;
}

// Whether a rib half can be traced from p0 (else it is just {p0}): the rib field is defined there.
bool ribHalfTraceable(const DirectionField& field, const Eigen::Vector2d& p0, const Eigen::Vector2d& side,
                      const FishboneOptions& options) {
    const StreamlineOptions& o = options.ribTracing;
    const bool inImage = p0.x() >= 0 && p0.y() >= 0 && p0.x() <= field.width && p0.y() <= field.height;
    const std::optional<DirectionSample> s = inImage ? field.sample(p0, side) : std::nullopt;
    const bool undefined =
        s && s->anisotropy < o.minAnisotropy && o.lowAnisotropy == LowAnisotropyPolicy::Stop;
    return s && !undefined && (!o.insideRegion || o.insideRegion(p0));
}

// Splits a dense polyline at its point nearest to p0 into two halves starting at p0.
std::pair<Polyline2, Polyline2> splitAt(const Polyline2& line, const Closest& c, const Eigen::Vector2d& p0) {
    Polyline2 after{p0}, before{p0};
    after.insert(after.end(), line.begin() + std::ptrdiff_t(c.segment) + 1, line.end());
    for (std::size_t i = c.segment + 1; i-- > 0;)
        before.push_back(line[i]);
    return {after, before};
}

} // namespace

// ---- Backbone -------------------------------------------------------------------------------------------

Eigen::Vector2d Backbone::tangent(std::size_t r) const {
    requireBackbone(*this);
    const std::size_t n = samples.size();
    if (closed && n > 2) return (samples[(r + 1) % n] - samples[(r + n - 1) % n]).normalized();
    const std::size_t a = r == 0 ? 0 : r - 1, b = std::min(r + 1, n - 1);
    return (samples[b] - samples[a]).normalized();
}

Eigen::Vector2d Backbone::normal(std::size_t r) const {
    const Eigen::Vector2d t = tangent(r);
    return {-t.y(), t.x()};
}

std::size_t Backbone::nearestSample(const Eigen::Vector2d& p) const {
    if (samples.empty()) throw InvalidInputError("The backbone has no samples.");
    std::size_t best = 0;
    for (std::size_t i = 1; i < samples.size(); ++i)
        if ((samples[i] - p).squaredNorm() < (samples[best] - p).squaredNorm()) best = i;
    return best;
}

BackbonePoint Backbone::nearestPoint(const Eigen::Vector2d& p) const {
    requireBackbone(*this);
    const Closest c = closestOnPolyline(samples, p);
    BackbonePoint b;
    b.position = double(c.segment) + c.t;
    b.point = samples[c.segment] + c.t * (samples[c.segment + 1] - samples[c.segment]);
    const Eigen::Vector2d t = (1 - c.t) * tangent(c.segment) + c.t * tangent(c.segment + 1);
    b.tangent = t.norm() > 0 ? Eigen::Vector2d(t.normalized()) : tangent(c.segment);
    b.distance = c.distance;
    return b;
}

std::size_t FishboneGrid::presentCount() const {
    std::size_t n = 0;
    for (auto p : present)
        n += p != 0;
    return n;
}

// ---- Rib shapes and blending ----------------------------------------------------------------------------

RibShape ribShape(const Polyline2& halfRib) {
    RibShape shape;
    if (halfRib.size() < 2) return shape;
    shape.firstEdge = halfRib[1] - halfRib[0];
    for (std::size_t i = 1; i + 1 < halfRib.size(); ++i) {
        const Eigen::Vector2d e0 = halfRib[i] - halfRib[i - 1], e1 = halfRib[i + 1] - halfRib[i];
        shape.turningAngles.push_back(std::atan2(cross(e0, e1), e0.dot(e1)));
    }
    return shape;
}

Polyline2 ribFromShape(const Eigen::Vector2d& p0, const RibShape& shape, double h) {
    requireSpacing(h);
    Polyline2 out{p0};
    if (shape.edgeCount() == 0) return out;
    // p_k = p0 + G0 + h·Σ_{i=1}^{k−1} R(θ0)(cos Σ_{j≤i}γj, sin Σ_{j≤i}γj)
    const Eigen::Vector2d unit = shape.firstEdge.normalized();
    out.push_back(p0 + shape.firstEdge);
    double angle = 0;
    for (double gamma : shape.turningAngles) {
        angle += gamma;
        out.push_back(out.back() + h * rotate(unit, angle));
    }
    return out;
}

RibShape blendRibShapes(const RibShape& e, const RibShape& f, double t, double h) {
    requireSpacing(h);
    if (!(t >= 0 && t <= 1)) throw InvalidInputError("The rib blending parameter t must lie in [0, 1].");
    RibShape g;
    if (e.edgeCount() == 0 || f.edgeCount() == 0) return g;
    const Eigen::Vector2d average = (1 - t) * e.firstEdge + t * f.firstEdge;
    const double len = average.norm();
    if (!(len > 1e-12 * (e.firstEdge.norm() + f.firstEdge.norm())))
        throw InvalidInputError("Two key-ribs leave the backbone in opposite directions on the same side; "
                                "they cannot be blended.");
    // t = 0 and t = 1 reproduce the key-rib's first edge bit for bit when its length is h.
    g.firstEdge = t == 0 ? e.firstEdge : t == 1 ? f.firstEdge : Eigen::Vector2d(average * (h / len));
    const std::size_t n = std::min(e.turningAngles.size(), f.turningAngles.size());
    g.turningAngles.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        g.turningAngles[i] = (1 - t) * e.turningAngles[i] + t * f.turningAngles[i];
    return g;
}

Rib blendRibs(const Rib& a, const Rib& b, const Eigen::Vector2d& p0, double t, double h) {
    Rib r;
    r.positive = ribFromShape(p0, blendRibShapes(ribShape(a.positive), ribShape(b.positive), t, h), h);
    r.negative = ribFromShape(p0, blendRibShapes(ribShape(a.negative), ribShape(b.negative), t, h), h);
    return r;
}

// ---- Hand-drawn curves ----------------------------------------------------------------------------------

Polyline2 catmullRomSpline(const Polyline2& input, double maxSegment) {
    if (!(maxSegment > 0) || !std::isfinite(maxSegment))
        throw InvalidInputError("The spline's maximum segment length must be positive and finite.");
    Polyline2 pts;
    for (const Eigen::Vector2d& p : input) {
        if (!p.allFinite()) throw InvalidInputError("A drawn curve contains a non-finite point.");
        if (pts.empty() || (p - pts.back()).norm() > 0) pts.push_back(p);
    }
    if (pts.size() < 2) return pts;
    const std::size_t n = pts.size();
    auto point = [&](std::ptrdiff_t i) -> Eigen::Vector2d {
        if (i < 0) return 2 * pts[0] - pts[1];
        if (i >= std::ptrdiff_t(n)) return 2 * pts[n - 1] - pts[n - 2];
        return pts[std::size_t(i)];
    };
    Polyline2 out{pts[0]};
    for (std::size_t s = 0; s + 1 < n; ++s) {
        const std::ptrdiff_t i = std::ptrdiff_t(s);
        const Eigen::Vector2d P0 = point(i - 1), P1 = point(i), P2 = point(i + 1), P3 = point(i + 2);
        // Centripetal knots: t_{k+1} = t_k + |P_{k+1} − P_k|^½.
        const double t0 = 0, t1 = t0 + std::sqrt((P1 - P0).norm()), t2 = t1 + std::sqrt((P2 - P1).norm()),
                     t3 = t2 + std::sqrt((P3 - P2).norm());
        auto eval = [&](double t) { // Barry–Goldman pyramid
            const Eigen::Vector2d A1 = ((t1 - t) * P0 + (t - t0) * P1) / (t1 - t0);
            const Eigen::Vector2d A2 = ((t2 - t) * P1 + (t - t1) * P2) / (t2 - t1);
            const Eigen::Vector2d A3 = ((t3 - t) * P2 + (t - t2) * P3) / (t3 - t2);
            const Eigen::Vector2d B1 = ((t2 - t) * A1 + (t - t0) * A2) / (t2 - t0);
            const Eigen::Vector2d B2 = ((t3 - t) * A2 + (t - t1) * A3) / (t3 - t1);
            return Eigen::Vector2d(((t2 - t) * B1 + (t - t1) * B2) / (t2 - t1));
        };
        // Subdivide until every piece is at most maxSegment long.
        std::size_t pieces = std::size_t(std::ceil((P2 - P1).norm() / maxSegment)) + 1;
        Polyline2 segment;
        for (;;) {
            segment.clear();
            for (std::size_t k = 1; k < pieces; ++k)
                segment.push_back(eval(t1 + (t2 - t1) * double(k) / double(pieces)));
            segment.push_back(P2); // exactly the input point
            double longest = (segment.front() - P1).norm();
            for (std::size_t k = 1; k < segment.size(); ++k)
                longest = std::max(longest, (segment[k] - segment[k - 1]).norm());
            if (longest <= maxSegment) break;
            pieces *= 2;
        }
        out.insert(out.end(), segment.begin(), segment.end());
    }
    return out;
}

// ---- Backbone and ribs ----------------------------------------------------------------------------------

namespace {

// Unit tangent of a dense polyline at point i (central difference, one-sided at the ends).
Eigen::Vector2d denseTangent(const Polyline2& c, std::size_t i) {
    const std::size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, c.size() - 1);
    const Eigen::Vector2d d = c[b] - c[a];
    const double len = d.norm();
    return len > 0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d::Zero();
}

// The closed loop through the seed of a dense streamline, resampled at equal arcs from the seed, if the
// streamline closes (see FishboneOptions::closeLoops): the shortest stretch c[i … j] around the seed
// (i ≤ seed ≤ j) whose ends lie within h/2 of each other, at least 4h of arc apart, heading the same way.
std::optional<Polyline2> closedLoop(const Polyline2& c, std::size_t seed, double h) {
    if (c.size() < 3) return std::nullopt;
    std::vector<double> arc(c.size(), 0.0);
    for (std::size_t k = 1; k < c.size(); ++k)
        arc[k] = arc[k - 1] + (c[k] - c[k - 1]).norm();
    double best = std::numeric_limits<double>::infinity();
    std::size_t bi = 0, bj = 0;
    for (std::size_t j = seed; j < c.size(); ++j)
        for (std::size_t i = seed + 1; i-- > 0;) {
            const double span = arc[j] - arc[i];
            if (span >= best) break;
            if (span < 4 * h || (c[j] - c[i]).norm() >= 0.5 * h) continue;
            if (denseTangent(c, i).dot(denseTangent(c, j)) < 0.5) continue;
            best = span;
            bi = i;
            bj = j;
        }
    if (!std::isfinite(best)) return std::nullopt;
    // The loop from the seed: c[seed … bj], then c[bi … seed] (c[bj] joins c[bi]).
    Polyline2 loop(c.begin() + std::ptrdiff_t(seed), c.begin() + std::ptrdiff_t(bj) + 1);
    loop.insert(loop.end(), c.begin() + std::ptrdiff_t(bi), c.begin() + std::ptrdiff_t(seed) + 1);
    double length = 0;
    for (std::size_t k = 1; k < loop.size(); ++k)
        length += (loop[k] - loop[k - 1]).norm();
    const std::size_t n = std::max<std::size_t>(3, std::size_t(std::lround(length / h)));
    const double step = length / double(n);
    Polyline2 out{loop.front()};
    double at = 0; // arc length at loop[k]
    for (std::size_t k = 1; k < loop.size() && out.size() < n; ++k) {
        const double len = (loop[k] - loop[k - 1]).norm();
        while (out.size() < n && double(out.size()) * step <= at + len) {
            const double t = len > 0 ? (double(out.size()) * step - at) / len : 0.0;
            out.push_back(loop[k - 1] + t * (loop[k] - loop[k - 1]));
        }
        at += len;
    }
    return out;
}

} // namespace

Backbone backboneFromStreamline(const Streamline& line, double h, bool closeLoops) {
    requireSpacing(h);
    Backbone b;
    if (closeLoops && !line.points.empty())
        if (std::optional<Polyline2> loop = closedLoop(line.points, line.seedIndex, h)) {
            b.samples = std::move(*loop);
            b.closed = true;
            return b;
        }
    const Streamline resampled = resampleAtSpacing(line, h);
    b.samples = resampled.points;
    b.seedIndex = resampled.seedIndex;
    if (!closeLoops || b.samples.size() < 4) return b;
    // Cut outwards from the seed before the first sample that comes back near a kept one (a loop).
    const Polyline2& s = b.samples;
    std::size_t lo = b.seedIndex, hi = b.seedIndex; // kept: [lo, hi]
    auto nearKept = [&](std::size_t j) {
        for (std::size_t i = lo; i <= hi; ++i)
            if ((i + 3 <= j || j + 3 <= i) && (s[i] - s[j]).norm() < 0.5 * h) return true;
        return false;
    };
    bool forward = true, backward = true;
    while (forward || backward) {
        if (forward) {
            if (hi + 1 < s.size() && !nearKept(hi + 1))
                ++hi;
            else
                forward = false;
        }
        if (backward) {
            if (lo > 0 && !nearKept(lo - 1))
                --lo;
            else
                backward = false;
        }
    }
    b.samples.assign(s.begin() + std::ptrdiff_t(lo), s.begin() + std::ptrdiff_t(hi) + 1);
    b.seedIndex -= lo;
    return b;
}

Backbone traceBackbone(const DirectionField& backboneField, const Eigen::Vector2d& seed,
                       const FishboneOptions& options) {
    requireSpacing(options.spacing);
    return backboneFromStreamline(traceStreamline(backboneField, seed, options.backboneTracing),
                                  options.spacing, options.closeLoops);
}

Backbone drawnBackbone(const Polyline2& points, const FishboneOptions& options) {
    requireSpacing(options.spacing);
    const Polyline2 dense = catmullRomSpline(points);
    if (dense.size() < 2) throw InvalidInputError("A drawn backbone needs at least two distinct points.");
    Backbone b;
    b.samples = resampleAtSpacing(dense, options.spacing);
    b.seedIndex = 0;
    requireBackbone(b);
    return b;
}

namespace {

// Resamples a dense rib half at equal surface arc length \p target (FishboneOptions::surfaceLength): the
// first vertex is kept, each further one where the surface length along the polyline since the previous
// vertex reaches target, but never closer than \p minScreen to it on the screen (on a surface seen almost
// edge-on the vertices would crowd into a pixel, where the ray casts are least reliable: there the edges
// grow longer than target instead). A dense segment longer than 3·target on the surface spans a depth jump
// (an occlusion boundary): the rib ends before it.
Polyline2
resampleOnSurface(const Polyline2& dense, double target, double minScreen,
                  const std::function<double(const Eigen::Vector2d&, const Eigen::Vector2d&)>& length) {
    Polyline2 out;
    if (dense.empty()) return out;
    out.push_back(dense.front());
    double since = 0; // surface length from the last vertex to dense[i − 1]
    for (std::size_t i = 1; i < dense.size(); ++i) {
        const double seg = length(dense[i - 1], dense[i]);
        if (!std::isfinite(seg) || seg > 3 * target) break;
        if (!(seg > 0)) continue;
        double t0 = 0; // the part of this segment before t0 is accounted for
        for (;;) {
            const double t = std::max(t0, t0 + (target - since) / seg); // since may exceed target
            if (t > 1) break;
            const Eigen::Vector2d q = dense[i - 1] + t * (dense[i] - dense[i - 1]);
            if ((q - out.back()).norm() < minScreen) { // too close on the screen: go on along the segment
                const Eigen::Vector2d e = dense[i] - dense[i - 1];
                // The point of the segment at distance minScreen from the last vertex, if any.
                const Eigen::Vector2d f = dense[i - 1] - out.back();
                const double A = e.squaredNorm(), B = e.dot(f), C = f.squaredNorm() - minScreen * minScreen;
                const double disc = B * B - A * C;
                const double u = disc >= 0 && A > 0 ? (-B + std::sqrt(disc)) / A : 2.0;
                if (u > 1) break;
                out.push_back(dense[i - 1] + std::max(u, t) * e);
                since = 0;
                t0 = std::max(u, t);
                continue;
            }
            out.push_back(q);
            since = 0;
            t0 = t;
        }
        since += (1 - t0) * seg;
    }
    return out;
}

// The surface spacing of the backbone at sample r: the mean surface length of its edges to its neighbours.
double backboneSurfaceSpacing(const Backbone& b, std::size_t r, const FishboneOptions& options) {
    const std::size_t n = b.samples.size();
    double sum = 0;
    int count = 0;
    if (r > 0 || b.closed) {
        sum += options.surfaceLength(b.samples[(r + n - 1) % n], b.samples[r]);
        ++count;
    }
    if (r + 1 < n || b.closed) {
        sum += options.surfaceLength(b.samples[r], b.samples[(r + 1) % n]);
        ++count;
    }
    return count ? sum / count : 0.0;
}

} // namespace

std::vector<Rib> traceRibs(const DirectionField& ribField, const Backbone& backbone, std::size_t first,
                           std::size_t count, const FishboneOptions& options) {
    requireSpacing(options.spacing);
    requireBackbone(backbone);
    if (first + count > backbone.samples.size() || first + count < first)
        throw InvalidInputError("The ribs' backbone samples " + std::to_string(first) + " to " +
                                std::to_string(first + count) + " do not exist (the backbone has " +
                                std::to_string(backbone.samples.size()) + " samples).");
    // Every half whose start is defined, all traced in lockstep (traceHalvesInLockstep), then resampled.
    std::vector<Rib> ribs(count);
    std::vector<HalfStart> starts;
    std::vector<Polyline2*> targets;
    std::vector<std::size_t> owners; // the rib of each target
    for (std::size_t i = 0; i < count; ++i) {
        const Eigen::Vector2d p0 = backbone.samples[first + i], n = backbone.normal(first + i);
        ribs[i] = Rib{{p0}, {p0}};
        for (const bool positive : {true, false}) {
            const Eigen::Vector2d side = positive ? n : Eigen::Vector2d(-n);
            if (!ribHalfTraceable(ribField, p0, side, options)) continue;
            starts.push_back({p0, side});
            targets.push_back(positive ? &ribs[i].positive : &ribs[i].negative);
            owners.push_back(i);
        }
    }
    const std::vector<StreamlineHalf> halves = traceHalvesInLockstep(ribField, starts, options.ribTracing);
    std::vector<double> surface(count, 0.0);
    if (options.isotropicRibs && options.surfaceLength)
        for (std::size_t i = 0; i < count; ++i)
            // At most 2.5 h: the triangulation drops edges longer than 3 h footprints (a backbone seen
            // almost end-on is stretched on the surface; its quads stay long that way).
            surface[i] =
                std::min(backboneSurfaceSpacing(backbone, first + i, options), 2.5 * options.spacing);
    for (std::size_t k = 0; k < halves.size(); ++k) {
        const std::size_t i = owners[k];
        *targets[k] = surface[i] > 0 ? resampleOnSurface(halves[k].points, surface[i], 0.5 * options.spacing,
                                                         options.surfaceLength)
                                     : resampleAtSpacing(halves[k].points, options.spacing);
    }
    return ribs;
}

Rib traceRib(const DirectionField& ribField, const Backbone& backbone, std::size_t row,
             const FishboneOptions& options) {
    if (row >= backbone.samples.size()) {
        requireBackbone(backbone);
        throw InvalidInputError("The rib's backbone sample " + std::to_string(row) +
                                " does not exist (the backbone has " +
                                std::to_string(backbone.samples.size()) + " samples).");
    }
    return traceRibs(ribField, backbone, row, 1, options).front();
}

KeyRib tracedKeyRib(const DirectionField& ribField, const Backbone& backbone, const Eigen::Vector2d& p,
                    const FishboneOptions& options) {
    requireSpacing(options.spacing);
    const BackbonePoint at = backbone.nearestPoint(p);
    // A three-sample backbone whose middle sample is the start, with the interpolated tangent there.
    Backbone local;
    const Eigen::Vector2d d = 0.5 * options.spacing * at.tangent;
    local.samples = {at.point - d, at.point, at.point + d};
    KeyRib key;
    key.rib = traceRib(ribField, local, 1, options);
    key.row = std::min(std::size_t(std::lround(at.position)), backbone.samples.size() - 1);
    // A half that cannot start where the rib field is undefined (a pixel whose interpolated principal
    // direction vanishes: beside fandisk's flat faces, whose vertices have no curvature direction) runs
    // straight along the backbone's normal to the first point where the field is defined, at most 8h away,
    // and is traced from there. The nearest backbone sample, where a key-rib started before, usually lies
    // in the same region: tests/cli/fishbone_scan_test.cpp's drawn case had both halves empty either way
    // and the grid left nothing to triangulate with continuous key-ribs; its negative half runs 4.7 h.
    const Eigen::Vector2d n = local.normal(1);
    for (const bool positive : {true, false}) {
        Polyline2& half = positive ? key.rib.positive : key.rib.negative;
        if (half.size() >= 2) continue;
        const Eigen::Vector2d side = positive ? n : Eigen::Vector2d(-n);
        const double step = options.ribTracing.step;
        for (double s = step; s <= 8 * options.spacing; s += step) {
            const Eigen::Vector2d q = at.point + s * side;
            if (!ribHalfTraceable(ribField, q, side, options)) continue;
            Polyline2 dense{at.point};
            const std::vector<StreamlineHalf> traced =
                traceHalvesInLockstep(ribField, {{q, side}}, options.ribTracing);
            dense.insert(dense.end(), traced.front().points.begin(), traced.front().points.end());
            half = resampleAtSpacing(dense, options.spacing);
            break;
        }
    }
    key.position = at.position;
    return key;
}

KeyRib drawnKeyRib(const Backbone& backbone, const Polyline2& points, const FishboneOptions& options) {
    requireSpacing(options.spacing);
    requireBackbone(backbone);
    const Polyline2 dense = catmullRomSpline(points);
    if (dense.size() < 2) throw InvalidInputError("A drawn key-rib needs at least two distinct points.");
    KeyRib key;
    Closest best;
    for (std::size_t r = 0; r < backbone.samples.size(); ++r) {
        const Closest c = closestOnPolyline(dense, backbone.samples[r]);
        if (c.distance < best.distance) {
            best = c;
            key.row = r;
        }
    }
    if (best.distance > 2 * options.spacing)
        throw InvalidInputError("The drawn key-rib does not cross the backbone (it passes " +
                                std::to_string(best.distance) + " pixels from the nearest backbone sample).");
    const Eigen::Vector2d p0 = backbone.samples[key.row], n = backbone.normal(key.row);
    auto [after, before] = splitAt(dense, best, p0);
    Polyline2 a = resampleAtSpacing(after, options.spacing), b = resampleAtSpacing(before, options.spacing);
    // Side of each part: its first edge against the backbone normal (the other part takes the other side).
    const double sa = a.size() > 1 ? (a[1] - p0).dot(n) : 0.0, sb = b.size() > 1 ? (b[1] - p0).dot(n) : 0.0;
    const bool aPositive = sa != 0 ? sa > 0 : sb < 0;
    key.rib.positive = aPositive ? std::move(a) : std::move(b);
    key.rib.negative = aPositive ? std::move(b) : std::move(a);
    return key;
}

// ---- Grids ----------------------------------------------------------------------------------------------

FishboneGrid assembleFishboneGrid(const Backbone& backbone, const std::vector<Rib>& ribs, double spacing,
                                  int width, int height) {
    requireSpacing(spacing);
    if (ribs.size() != backbone.samples.size())
        throw InvalidInputError("A fishbone grid needs exactly one rib per backbone sample.");
    std::size_t neg = 0, pos = 0;
    for (const Rib& r : ribs) {
        neg = std::max(neg, r.negative.empty() ? 0 : r.negative.size() - 1);
        pos = std::max(pos, r.positive.empty() ? 0 : r.positive.size() - 1);
    }
    FishboneGrid g;
    g.rows = int(ribs.size());
    g.cols = int(neg + 1 + pos);
    g.backboneColumn = int(neg);
    g.spacing = spacing;
    g.closed = backbone.closed && ribs.size() > 2;
    g.screen.assign(std::size_t(g.rows) * std::size_t(g.cols), Eigen::Vector2d::Zero());
    g.present.assign(g.screen.size(), 0);
    const bool clip = width > 0 && height > 0;
    auto put = [&](int r, int c, const Eigen::Vector2d& p) {
        const std::size_t i = g.index(r, c);
        g.screen[i] = p;
        g.present[i] =
            p.allFinite() && (!clip || (p.x() >= 0 && p.y() >= 0 && p.x() <= width && p.y() <= height));
    };
    for (int r = 0; r < g.rows; ++r) {
        const Rib& rib = ribs[std::size_t(r)];
        put(r, g.backboneColumn, backbone.samples[std::size_t(r)]);
        for (std::size_t k = 1; k < rib.positive.size(); ++k)
            put(r, g.backboneColumn + int(k), rib.positive[k]);
        for (std::size_t k = 1; k < rib.negative.size(); ++k)
            put(r, g.backboneColumn - int(k), rib.negative[k]);
    }
    return g;
}

std::size_t trimRibs(FishboneGrid& grid, const Backbone& backbone, const FishboneOptions& options) {
    if (grid.rows < 2 || std::size_t(grid.rows) != backbone.samples.size()) return 0;
    const double minGap = options.minRibGap * grid.spacing;
    const double cosTurn = std::cos(options.maxRibTurnDeg * std::numbers::pi / 180.0);
    const bool turnBound = options.maxRibTurnDeg < 180.0;
    const double maxAspect = options.maxRibAspect;
    if (!(minGap > 0) && !turnBound && !(maxAspect >= 1)) return 0;
    // Lengths for the aspect bound: on the surface (isotropicRibs), else on the screen.
    auto length = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        return options.surfaceLength ? options.surfaceLength(a, b) : (a - b).norm();
    };
    std::size_t removed = 0;
    for (int r = 0; r < grid.rows; ++r) {
        const Eigen::Vector2d normal = backbone.normal(std::size_t(r));
        for (const int side : {1, -1}) {
            bool stopped = false;
            for (int c = grid.backboneColumn + side; c >= 0 && c < grid.cols; c += side) {
                const std::size_t i = grid.index(r, c);
                if (!grid.present[i]) {
                    stopped = true; // a half-rib that has ended stays ended
                    continue;
                }
                if (!stopped && grid.isPresent(r, c - side)) {
                    const Eigen::Vector2d edge = grid.at(r, c) - grid.at(r, c - side);
                    const double len = edge.norm();
                    if (turnBound && len > 0 && (double(side) * edge).dot(normal) < cosTurn * len)
                        stopped = true;
                }
                for (const int dr : {-1, 1}) {
                    const int n = grid.closed ? (r + dr + grid.rows) % grid.rows : r + dr;
                    if (!stopped && minGap > 0 && grid.isPresent(n, c) &&
                        (grid.at(n, c) - grid.at(r, c)).norm() < minGap)
                        stopped = true;
                    if (!stopped && maxAspect >= 1 && grid.isPresent(n, c) && grid.isPresent(r, c - side)) {
                        const double gap = length(grid.at(n, c), grid.at(r, c));
                        const double edge = length(grid.at(r, c), grid.at(r, c - side));
                        if (gap > 0 && edge > 0 && (gap > maxAspect * edge || edge > maxAspect * gap))
                            stopped = true;
                    }
                }
                if (stopped) {
                    grid.present[i] = 0;
                    ++removed;
                }
            }
        }
    }
    return removed;
}

std::vector<Rib> traceAllRibs(const DirectionField& ribField, const Backbone& backbone,
                              const FishboneOptions& options) {
    requireBackbone(backbone);
    // Independent streamlines: groups of kRibsInLockstep neighbouring ribs (their halves traced in
    // lockstep) on the scan threads, each group into its own slots (parallel.h).
    constexpr std::size_t kRibsInLockstep = 2;
    const std::size_t n = backbone.samples.size(), groups = (n + kRibsInLockstep - 1) / kRibsInLockstep;
    std::vector<Rib> ribs(n);
    detail::parallelItems(groups, 2, [&](std::size_t g) {
        const std::size_t first = g * kRibsInLockstep, count = std::min(kRibsInLockstep, n - first);
        std::vector<Rib> traced = traceRibs(ribField, backbone, first, count, options);
        std::move(traced.begin(), traced.end(), ribs.begin() + std::ptrdiff_t(first));
    });
    return ribs;
}

FishboneGrid automaticFishbone(const DirectionField& backboneField, const DirectionField& ribField,
                               const Eigen::Vector2d& seed, const FishboneOptions& options) {
    if (backboneField.width != ribField.width || backboneField.height != ribField.height)
        throw InvalidInputError("The backbone and rib direction fields must have the same size.");
    const Backbone backbone = traceBackbone(backboneField, seed, options);
    requireBackbone(backbone);
    // The ribs are independent streamlines: traced on several threads, each into its own slot (parallel.h).
    const std::vector<Rib> ribs = traceAllRibs(ribField, backbone, options);
    FishboneGrid grid =
        assembleFishboneGrid(backbone, ribs, options.spacing, ribField.width, ribField.height);
    trimRibs(grid, backbone, options);
    return grid;
}

FishboneGrid keyRibFishbone(const Backbone& backbone, std::vector<KeyRib> keyRibs,
                            const FishboneOptions& options, int width, int height) {
    requireSpacing(options.spacing);
    requireBackbone(backbone);
    if (keyRibs.empty()) throw InvalidInputError("The key-rib mode needs at least one key-rib.");
    for (const KeyRib& k : keyRibs)
        if (k.row >= backbone.samples.size() || !(k.at() <= double(backbone.samples.size() - 1)))
            throw InvalidInputError("A key-rib sits at backbone sample " + std::to_string(k.at()) +
                                    ", but the backbone has only " + std::to_string(backbone.samples.size()) +
                                    " samples.");
    // Sorted by position; of several key-ribs at one position the last given wins.
    std::stable_sort(keyRibs.begin(), keyRibs.end(),
                     [](const KeyRib& a, const KeyRib& b) { return a.at() < b.at(); });
    std::vector<KeyRib> keys;
    for (KeyRib& k : keyRibs) {
        if (!keys.empty() && keys.back().at() == k.at())
            keys.back() = std::move(k);
        else
            keys.push_back(std::move(k));
    }

    const double h = options.spacing;
    const std::size_t first = options.extendBeyondKeyRibs ? 0 : std::size_t(std::ceil(keys.front().at()));
    const std::size_t last =
        options.extendBeyondKeyRibs ? backbone.samples.size() - 1 : std::size_t(std::floor(keys.back().at()));
    Backbone part; // open: key-ribs are blended along the backbone, not across a closed backbone's seam
    part.samples.assign(backbone.samples.begin() + std::ptrdiff_t(first),
                        backbone.samples.begin() + std::ptrdiff_t(last) + 1);
    part.seedIndex =
        backbone.seedIndex >= first && backbone.seedIndex <= last ? backbone.seedIndex - first : 0;
    std::vector<Rib> ribs;
    ribs.reserve(part.samples.size());
    std::size_t next = 0; // first key with row ≥ r
    for (std::size_t r = first; r <= last; ++r) {
        while (next < keys.size() && keys[next].at() < double(r))
            ++next;
        const Eigen::Vector2d& p0 = backbone.samples[r];
        if (next < keys.size() && keys[next].at() == double(r)) {
            ribs.push_back(keys[next].rib);
        } else if (next == 0) {
            ribs.push_back(blendRibs(keys.front().rib, keys.front().rib, p0, 0.0, h));
        } else if (next == keys.size()) {
            ribs.push_back(blendRibs(keys.back().rib, keys.back().rib, p0, 0.0, h));
        } else {
            const KeyRib& a = keys[next - 1];
            const KeyRib& b = keys[next];
            const double t = (double(r) - a.at()) / (b.at() - a.at());
            ribs.push_back(blendRibs(a.rib, b.rib, p0, t, h));
        }
    }
    FishboneGrid grid = assembleFishboneGrid(part, ribs, h, width, height);
    trimRibs(grid, part, options);
    return grid;
}

} // namespace fss
