#include "fishbone/lasso_clip.h"

#include "fss/sample_grid.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

namespace fss::detail {
namespace {

// The parameter t ∈ (0, 1] along a → b (a inside the lasso, b outside) where the segment leaves the lasso:
// of the crossings with the lasso's edges in order, the first after which the segment is outside (a
// self-overlapping stroke has crossings inside its region). std::nullopt when none is found (round-off).
std::optional<double> exitParameter(const Lasso& lasso, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const std::vector<Eigen::Vector2d>& p = lasso.points;
    const Eigen::Vector2d d = b - a;
    std::vector<double> ts;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Eigen::Vector2d& u = p[i];
        const Eigen::Vector2d e = p[(i + 1) % p.size()] - u;
        const double den = d.x() * e.y() - d.y() * e.x();
        if (den == 0) continue;
        const Eigen::Vector2d w = u - a;
        const double t = (w.x() * e.y() - w.y() * e.x()) / den;
        const double s = (w.x() * d.y() - w.y() * d.x()) / den;
        if (t >= 0 && t <= 1 && s >= 0 && s <= 1) ts.push_back(t);
    }
    std::sort(ts.begin(), ts.end());
    for (std::size_t i = 0; i < ts.size(); ++i) {
        const double next = i + 1 < ts.size() ? ts[i + 1] : 1.0;
        if (!insideLasso(lasso, a + 0.5 * (ts[i] + next) * d)) return ts[i];
    }
    return std::nullopt;
}

} // namespace

std::size_t clipRibsAtLasso(FishboneGrid& grid, const Lasso& lasso, double minLast) {
    std::size_t dropped = 0;
    const int bc = grid.backboneColumn;
    std::vector<std::uint8_t> inside(grid.present.size(), 0);
    for (std::size_t i = 0; i < inside.size(); ++i)
        inside[i] = grid.present[i] && insideLasso(lasso, grid.screen[i]);
    auto in = [&](int r, int c) { return grid.isPresent(r, c) && inside[grid.index(r, c)] != 0; };
    // Moves vertex (r, to) of the edge from inside vertex (r, from) to outside vertex (r, out) onto the
    // crossing at parameter t ∈ [0, 1] of from → out (1e-3 px inside), if still inside the lasso there.
    auto moveOnto = [&](int r, int to, int from, int out, double t) {
        const Eigen::Vector2d a = grid.at(r, from), b = grid.at(r, out);
        const double length = (b - a).norm();
        const Eigen::Vector2d x = a + std::max(0.0, t - 1e-3 / length) * (b - a);
        if (!insideLasso(lasso, x)) return false;
        grid.screen[grid.index(r, to)] = x;
        inside[grid.index(r, to)] = 1;
        return true;
    };
    for (int r = 0; r < grid.rows; ++r) {
        if (!grid.isPresent(r, bc)) continue;
        for (const int dir : {1, -1}) {
            // Every edge of the half-rib (and the backbone sample's first edge) that crosses the lasso: the
            // vertex outside moves onto the crossing when it lies at least minLast of the edge from the
            // vertex inside, else the inside one does (never the backbone sample).
            for (int c = bc; grid.isPresent(r, c + dir); c += dir) {
                const int a = c, b = c + dir;
                if (in(r, a) == in(r, b)) continue;
                const int from = in(r, a) ? a : b, out = in(r, a) ? b : a;
                const Eigen::Vector2d p = grid.at(r, from), q = grid.at(r, out);
                if (!((q - p).norm() > 0)) continue;
                const std::optional<double> t = exitParameter(lasso, p, q);
                if (!t) continue;
                if (*t >= minLast || from == bc) {
                    if (out != bc) moveOnto(r, out, from, out, *t);
                } else {
                    moveOnto(r, from, from, out, *t);
                }
            }
        }
    }
    for (std::size_t i = 0; i < inside.size(); ++i)
        if (grid.present[i] && !inside[i] && int(i % std::size_t(grid.cols)) != bc) {
            grid.present[i] = 0;
            ++dropped;
        }
    return dropped;
}

namespace {

bool usable(const Sample& s) {
    return s.hit && s.valid && s.admissible;
}

// The smallest angle of the 3D triangle a, b, c, in degrees.
double smallestAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const std::array<Eigen::Vector3d, 3> p{a, b, c};
    double smallest = 180;
    for (std::size_t i = 0; i < 3; ++i) {
        const Eigen::Vector3d u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
        const double nu = u.norm(), nw = w.norm();
        if (!(nu > 0 && nw > 0)) return 0;
        smallest = std::min(smallest,
                            std::acos(std::clamp(u.dot(w) / (nu * nw), -1.0, 1.0)) * 180 / std::numbers::pi);
    }
    return smallest;
}

} // namespace

std::size_t peelSliverRibEnds(SampleGrid& grid, int backboneColumn, double minDeg, int passes) {
    std::size_t dropped = 0;
    const int bc = backboneColumn;
    std::vector<std::size_t> peel;
    for (int pass = 0; pass < passes; ++pass) {
        peel.clear();
        for (int r = 0; r < grid.rows; ++r)
            for (int c = 0; c < grid.cols; ++c) {
                if (c == bc || !usable(grid.at(r, c))) continue;
                // An end of a run of usable samples along the rib: its quads towards the run.
                bool bad = false;
                for (const int dir : {1, -1}) {
                    const bool onward = grid.inside(r, c + dir) && usable(grid.at(r, c + dir));
                    const bool back = grid.inside(r, c - dir) && usable(grid.at(r, c - dir));
                    if (onward || !back) continue;
                    for (const int dr : {-1, 1}) {
                        const int r0 = std::min(r, r + dr), c0 = std::min(c, c - dir);
                        if (!grid.inside(r0, c0) || !grid.inside(r0 + 1, c0 + 1)) continue;
                        const Sample &s00 = grid.at(r0, c0), &s01 = grid.at(r0, c0 + 1),
                                     &s10 = grid.at(r0 + 1, c0), &s11 = grid.at(r0 + 1, c0 + 1);
                        if (!usable(s00) || !usable(s01) || !usable(s10) || !usable(s11)) continue;
                        // The triangulation's split: (r0, c0)–(r0 + 1, c0 + 1).
                        bad = bad || smallestAngle(s00.point, s10.point, s11.point) < minDeg ||
                              smallestAngle(s00.point, s11.point, s01.point) < minDeg;
                    }
                }
                if (bad) peel.push_back(grid.index(r, c));
            }
        if (peel.empty()) break;
        for (const std::size_t i : peel) {
            grid.samples[i].admissible = grid.samples[i].valid = false;
            ++dropped;
        }
    }
    return dropped;
}

} // namespace fss::detail
