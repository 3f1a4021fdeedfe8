#include "remesh/crease_snapper.h"

namespace fss::detail::creases {

CreaseSnapper::Error CreaseSnapper::error(const Tri& t) const {
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

std::array<Vec, 7> CreaseSnapper::errorSamples(const Tri& t) {
    static constexpr double w[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3},
                                       {0.5, 0.5, 0},
                                       {0, 0.5, 0.5},
                                       {0.5, 0, 0.5},
                                       {4.0 / 6, 1.0 / 6, 1.0 / 6},
                                       {1.0 / 6, 4.0 / 6, 1.0 / 6},
                                       {1.0 / 6, 1.0 / 6, 4.0 / 6}};
    std::array<Vec, 7> samples;
    for (std::size_t i = 0; i < 7; ++i)
        samples[i] = w[i][0] * t.a + w[i][1] * t.b + w[i][2] * t.c;
    return samples;
}

CreaseSnapper::Error CreaseSnapper::measureError(const Tri& t) const {
    Error e;
    for (const Vec& p : errorSamples(t)) {
        const double d = closest_(p).distance;
        e.max = std::max(e.max, d);
        e.integral += d * d;
    }
    e.integral *= 0.5 * (t.b - t.a).cross(t.c - t.a).norm() / 7.0;
    return e;
}

void CreaseSnapper::prefetchFaces() const {
    std::vector<Vec> centroids;
    centroids.reserve(m_.number_of_faces());
    for (FaceIndex f : m_.faces()) {
        const Tri t = triangle(f);
        centroids.push_back((t.a + t.b + t.c) / 3.0);
    }
    closest_.prefetch(centroids);
    std::vector<Vec> samples;
    for (FaceIndex f : m_.faces()) {
        const Tri t = triangle(f);
        const SurfacePoint sp = closest_((t.a + t.b + t.c) / 3.0);
        if (!sp || !mayBeFar(t, sp.distance)) continue;
        for (const Vec& p : errorSamples(t))
            samples.push_back(p);
    }
    closest_.prefetch(samples);
}

bool CreaseSnapper::better(const std::vector<Tri>& before, const std::vector<Tri>& after, bool sameCount,
                           double gain, double minOldError) const {
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

bool CreaseSnapper::liesOnReference(const Tri& t, const Vec& n) const {
    const SurfacePoint sp = closest_((t.a + t.b + t.c) / 3.0);
    return sp && sp.distance <= 0.1 * L_ && referenceNormalOf(sp.face).dot(n) > 0.5;
}

Vec CreaseSnapper::referenceNormal(const Vec& p) const {
    const SurfacePoint sp = closest_(p);
    return sp ? referenceNormalOf(sp.face) : Vec::Zero();
}

bool CreaseSnapper::mayBeFar(const Tri& t, double centroidDistance) const {
    Vec q;
    double d;
    const bool nearCrease = creases_.closest((t.a + t.b + t.c) / 3.0, q, d) && d <= 1.5 * L_;
    return nearCrease || centroidDistance > 0.1 * L_;
}

bool CreaseSnapper::far(const Tri& t, double centroidDistance) const {
    return mayBeFar(t, centroidDistance) && error(t).max > o_.errorSplitDistance * L_;
}

Vec CreaseSnapper::referenceNormalOf(FaceIndex f) const {
    const HalfedgeIndex h = ref_.halfedge(f);
    return unitNormal(pos(ref_, ref_.source(h)), pos(ref_, ref_.target(h)),
                      pos(ref_, ref_.target(ref_.next(h))));
}

bool CreaseSnapper::turnedOver(const Tri& t) const {
    const Vec n = unitNormal(t.a, t.b, t.c);
    return n.isZero() || n.dot(referenceNormal((t.a + t.b + t.c) / 3.0)) < 0;
}

CreaseSnapper::Before CreaseSnapper::measure(const std::vector<Tri>& before) const {
    Before b;
    for (const Tri& t : before) {
        b.minAngle = std::min(b.minAngle, minAngle(t.a, t.b, t.c));
        b.maxError = std::max(b.maxError, error(t).max);
    }
    return b;
}

bool CreaseSnapper::repairs(const Before& before, const std::vector<Tri>& after, double gain) const {
    for (const Tri& t : after)
        if (minAngle(t.a, t.b, t.c) < std::min(before.minAngle, floor_)) return false;
    for (const Tri& t : after)
        if (turnedOver(t)) return false;
    const double limit = gain * before.maxError + 1e-6 * L_;
    for (const Tri& t : after)
        if (error(t).max > limit) return false;
    return true;
}

bool CreaseSnapper::onACrease(VertexIndex v) const {
    if (onCrease_[v.idx()]) return true;
    Vec q;
    double d;
    return creases_.closest(pos(m_, v), q, d) && d < 1e-6 * L_;
}

Tri CreaseSnapper::triangle(FaceIndex f) const {
    const HalfedgeIndex h = m_.halfedge(f);
    return {pos(m_, m_.source(h)), pos(m_, m_.target(h)), pos(m_, m_.target(m_.next(h)))};
}

std::vector<Tri> CreaseSnapper::facesAround(const std::vector<VertexIndex>& vertices) const {
    std::vector<Tri> tris;
    for (FaceIndex f : faceIndicesAround(vertices))
        tris.push_back(triangle(f));
    return tris;
}

bool CreaseSnapper::closeEnough(const Before& before, const std::vector<Tri>& after, double gain) const {
    for (const Tri& t : after)
        if (turnedOver(t)) return false;
    for (const Tri& t : after)
        if (error(t).max > gain * before.maxError + 1e-6 * L_) return false;
    return true;
}

} // namespace fss::detail::creases
