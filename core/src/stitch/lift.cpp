// Stitch v2, stage "lift" (lift.h, DESIGN.md §6.2 step 4).
#include "stitch/lift.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fss::stitch {
namespace {

double liftCross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
}

// Distance (pixels) from p to the triangle abc in the view; 0 inside.
double liftDistanceToTriangle(const Eigen::Vector2d& p, const std::array<Eigen::Vector2d, 3>& t) {
    const double area = liftCross2(t[1] - t[0], t[2] - t[0]);
    bool inside = true;
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d& a = t[std::size_t(i)];
        const Eigen::Vector2d& b = t[std::size_t((i + 1) % 3)];
        const double side = liftCross2(b - a, p - a);
        if ((area >= 0 && side < 0) || (area < 0 && side > 0)) inside = false;
        const Eigen::Vector2d ab = b - a;
        const double len2 = ab.squaredNorm();
        const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, (a + s * ab - p).norm());
    }
    return inside ? 0.0 : best;
}

} // namespace

Eigen::Vector2d viewPoint(const Camera& camera, const Eigen::Vector3d& p) {
    const Eigen::Vector3d s = camera.project(p);
    return {s.x(), -s.y()};
}

std::optional<Eigen::Vector3d> liftOntoPlane(const Camera& camera, const Eigen::Vector2d& uv,
                                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                             const Eigen::Vector3d& c) {
    const Ray ray = camera.ray(uv.x(), -uv.y());
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double denom = n.dot(ray.direction);
    if (!(std::abs(denom) > 1e-300)) return std::nullopt;
    const double t = n.dot(a - ray.origin) / denom;
    if (!std::isfinite(t) || (!camera.parallel && t <= 0)) return std::nullopt;
    return ray.origin + t * ray.direction;
}

ReferenceLocator::ReferenceLocator(const Camera& camera, const LiftReference& reference)
    : camera_(camera), reference_(reference), proj_(reference.points.size()) {
    for (std::size_t i = 0; i < proj_.size(); ++i)
        proj_[i] = viewPoint(camera, reference.points[i]);
    double sum = 0;
    for (const auto& t : reference.triangles)
        sum += (proj_[std::size_t(t[0])] - proj_[std::size_t(t[1])]).norm();
    if (!reference.triangles.empty()) cell_ = std::max(2.0 * sum / double(reference.triangles.size()), 1e-3);
    for (std::size_t i = 0; i < reference.triangles.size(); ++i) {
        const auto& t = reference.triangles[i];
        Eigen::Vector2d lo = proj_[std::size_t(t[0])], hi = lo;
        for (int k : t) {
            lo = lo.cwiseMin(proj_[std::size_t(k)]);
            hi = hi.cwiseMax(proj_[std::size_t(k)]);
        }
        // A margin of a tenth of a cell serves queries with a tolerance up to that.
        lo.array() -= 0.1 * cell_;
        hi.array() += 0.1 * cell_;
        for (double x = std::floor(lo.x() / cell_); x <= std::floor(hi.x() / cell_); ++x)
            for (double y = std::floor(lo.y() / cell_); y <= std::floor(hi.y() / cell_); ++y)
                grid_[key((x + 0.5) * cell_, (y + 0.5) * cell_)].push_back(int(i));
    }
}

std::int64_t ReferenceLocator::key(double x, double y) const {
    return (std::int64_t(std::floor(x / cell_)) << 32) ^ (std::int64_t(std::floor(y / cell_)) & 0xffffffff);
}

std::optional<ReferenceLocator::Hit> ReferenceLocator::lift(const Eigen::Vector2d& uv,
                                                            double tolerance) const {
    auto it = grid_.find(key(uv.x(), uv.y()));
    if (it == grid_.end()) return std::nullopt;
    std::optional<Hit> best;
    double bestDistance = std::numeric_limits<double>::infinity(), bestDepth = bestDistance;
    for (int ti : it->second) {
        const auto& t = reference_.triangles[std::size_t(ti)];
        const double d = liftDistanceToTriangle(
            uv, {proj_[std::size_t(t[0])], proj_[std::size_t(t[1])], proj_[std::size_t(t[2])]});
        if (d > tolerance) continue;
        const auto p =
            liftOntoPlane(camera_, uv, reference_.points[std::size_t(t[0])],
                          reference_.points[std::size_t(t[1])], reference_.points[std::size_t(t[2])]);
        if (!p) continue;
        const double depth = camera_.viewDepth(*p);
        // Inside beats near; among equals, the nearest to the eye.
        if (d < bestDistance || (d == bestDistance && depth < bestDepth)) {
            bestDistance = d;
            bestDepth = depth;
            best = Hit{ti, *p};
        }
    }
    return best;
}

bool ReferenceLocator::covers(const Eigen::Vector2d& uv, double tolerance) const {
    auto it = grid_.find(key(uv.x(), uv.y()));
    if (it == grid_.end()) return false;
    for (int ti : it->second) {
        const auto& t = reference_.triangles[std::size_t(ti)];
        if (liftDistanceToTriangle(uv, {proj_[std::size_t(t[0])], proj_[std::size_t(t[1])],
                                        proj_[std::size_t(t[2])]}) <= tolerance)
            return true;
    }
    return false;
}

} // namespace fss::stitch
