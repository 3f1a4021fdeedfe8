#pragma once
// Internal (not installed): the sharp edges of the reference as the fishbone scan sees them, for the crease
// following of traced backbones and issue 20's crease stops (fishbone_scan.cpp).
#include "fss/camera.h"
#include "fss/fishbone.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/raycast.h"

#include <CGAL/Kernel/global_functions.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace fss::detail {

/// A sharp edge of the reference as seen from the scan camera (screen positions of its end points).
struct CreaseSegment {
    Eigen::Vector2d a, b;
};

/// The crease edges visible in \p buffers: projected, and kept when the ID buffer shows one of the edge's
/// two faces within a pixel of the edge's midpoint — or, given \p caster (the stops of issue 20), when the
/// ray through the midpoint's screen position hits the reference within a pixel footprint of it: where the
/// faces are smaller than a pixel the ID buffer mostly shows other faces beside the crease, and the first
/// test alone missed most of the creased ring's ridge at 80². (The backbone's crease following keeps the
/// first test alone, so that recorded sessions replay as before.)
inline std::vector<CreaseSegment> visibleCreases(const Mesh& mesh, const std::vector<EdgeIndex>& edges,
                                                 const FrameBuffers& buffers,
                                                 const RayCaster* caster = nullptr) {
    std::vector<CreaseSegment> out;
    if (edges.empty()) return out;
    const Camera& camera = buffers.camera;
    const Eigen::Matrix4d vp = camera.viewProjectionMatrix();
    auto project = [&](const Point3& p) {
        const Eigen::Vector4d clip = vp * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
        return Eigen::Vector2d((clip.x() / clip.w() + 1.0) * 0.5 * camera.width,
                               (1.0 - clip.y() / clip.w()) * 0.5 * camera.height);
    };
    const int w = buffers.width(), h = buffers.height();
    for (EdgeIndex e : edges) {
        const HalfedgeIndex he = mesh.halfedge(e);
        const std::uint32_t f0 = std::uint32_t(mesh.face(he).idx()),
                            f1 = std::uint32_t(mesh.face(mesh.opposite(he)).idx());
        const Eigen::Vector2d a = project(mesh.point(mesh.source(he))),
                              b = project(mesh.point(mesh.target(he)));
        if (!a.allFinite() || !b.allFinite()) continue;
        const Eigen::Vector2d m = 0.5 * (a + b);
        const int mx = int(std::floor(m.x())), my = int(std::floor(m.y()));
        bool visible = false;
        for (int dy = -1; dy <= 1 && !visible; ++dy)
            for (int dx = -1; dx <= 1 && !visible; ++dx) {
                const int x = mx + dx, y = my + dy;
                if (x < 0 || y < 0 || x >= w || y >= h) continue;
                const std::uint32_t id = buffers.faceAt(x, y);
                visible = id == f0 || id == f1;
            }
        if (!visible && caster && mx >= 0 && my >= 0 && mx < w && my < h) {
            const Point3 p = CGAL::midpoint(mesh.point(mesh.source(he)), mesh.point(mesh.target(he)));
            const Eigen::Vector3d m3(p.x(), p.y(), p.z());
            const std::uint32_t id = buffers.faceAt(mx, my);
            const SurfacePoint hit = caster->intersect(
                camera.ray(m.x(), m.y()), id == FrameBuffers::kNoFace ? Mesh::null_face() : FaceIndex(id));
            visible = hit && (hit.point - m3).norm() <= camera.pixelFootprint(m3);
        }
        if (visible) out.push_back({a, b});
    }
    return out;
}

/// The visible crease segments bucketed on a coarse screen grid: each cell lists, in segment order, the
/// segments whose bounding box grown by the snap radius (plus a pixel against round-off) overlaps it, so
/// a query looks only at the segments that can lie within the radius of its point (the backbone queries
/// once per step; scanning every visible crease edge each time cost about a millisecond on fandisk).
class CreaseIndex {
public:
    CreaseIndex(std::vector<CreaseSegment> segments, double radius, int width, int height)
        : segments_(std::move(segments)), radius_(radius), cellsX_(std::max(1, (width + kCell - 1) / kCell)),
          cellsY_(std::max(1, (height + kCell - 1) / kCell)),
          cells_(std::size_t(cellsX_) * std::size_t(cellsY_)) {
        const double grow = radius + 1.0;
        for (std::size_t i = 0; i < segments_.size(); ++i) {
            const CreaseSegment& s = segments_[i];
            const int x0 = cellOf(std::min(s.a.x(), s.b.x()) - grow, cellsX_),
                      x1 = cellOf(std::max(s.a.x(), s.b.x()) + grow, cellsX_),
                      y0 = cellOf(std::min(s.a.y(), s.b.y()) - grow, cellsY_),
                      y1 = cellOf(std::max(s.a.y(), s.b.y()) + grow, cellsY_);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                    cells_[std::size_t(y) * std::size_t(cellsX_) + std::size_t(x)].push_back(i);
        }
    }

    bool empty() const { return segments_.empty(); }

    /// The point nearest to \p q on a crease segment within the radius that runs along \p heading (within
    /// 30°), if any; of equally near segments the last in segment order.
    std::optional<Eigen::Vector2d> nearestAlong(const Eigen::Vector2d& q,
                                                const Eigen::Vector2d& heading) const {
        if (!q.allFinite()) return std::nullopt;
        const double cosMax = std::cos(30.0 * std::numbers::pi / 180.0);
        std::optional<Eigen::Vector2d> best;
        double bestDistance = radius_;
        const std::vector<std::size_t>& cell =
            cells_[std::size_t(cellOf(q.y(), cellsY_)) * std::size_t(cellsX_) +
                   std::size_t(cellOf(q.x(), cellsX_))];
        for (std::size_t i : cell) {
            const CreaseSegment& s = segments_[i];
            const Eigen::Vector2d d = s.b - s.a;
            const double len2 = d.squaredNorm();
            if (!(len2 > 1e-12) || std::abs(d.dot(heading)) < cosMax * std::sqrt(len2)) continue;
            const double t = std::clamp((q - s.a).dot(d) / len2, 0.0, 1.0);
            const Eigen::Vector2d c = s.a + t * d;
            const double dist = (c - q).norm();
            if (dist <= bestDistance) {
                bestDistance = dist;
                best = c;
            }
        }
        return best;
    }

    /// Whether the segment \p a – \p b crosses a crease segment (proper crossing: each segment's end
    /// points strictly on both sides of the other's line).
    bool crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
        return crossing(a, b, std::numeric_limits<double>::infinity());
    }

    /// Whether the segment \p a – \p b crosses a crease segment at more than 30° (a crease the segment runs
    /// along, such as the one a backbone follows, does not count).
    bool crossesAcross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
        return crossing(a, b, std::cos(30.0 * std::numbers::pi / 180.0));
    }

    // A proper crossing of \p a – \p b with a crease segment that is not within acos(\p cosAlong) of its
    // direction (cosAlong = ∞: any crease segment).
    bool crossing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double cosAlong) const {
        const Eigen::Vector2d d = b - a;
        return crossingIf(a, b, [&](const CreaseSegment& s) {
            const Eigen::Vector2d e = s.b - s.a;
            return !(std::abs(d.dot(e)) >= cosAlong * d.norm() * e.norm());
        });
    }

    // A proper crossing of \p a – \p b with a crease segment for which \p counts is true.
    template <class Counts>
    bool crossingIf(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Counts& counts) const {
        if (!a.allFinite() || !b.allFinite()) return false;
        auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
            const double v = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
            return v > 0 ? 1 : (v < 0 ? -1 : 0);
        };
        const int x0 = cellOf(std::min(a.x(), b.x()), cellsX_), x1 = cellOf(std::max(a.x(), b.x()), cellsX_),
                  y0 = cellOf(std::min(a.y(), b.y()), cellsY_), y1 = cellOf(std::max(a.y(), b.y()), cellsY_);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                for (std::size_t i : cells_[std::size_t(y) * std::size_t(cellsX_) + std::size_t(x)]) {
                    const CreaseSegment& s = segments_[i];
                    if (!counts(s)) continue;
                    if (side(a, b, s.a) * side(a, b, s.b) < 0 && side(s.a, s.b, a) * side(s.a, s.b, b) < 0)
                        return true;
                }
        return false;
    }

    /// Cuts \p backbone outwards from its seed before its first edge that crosses a crease (crossesAcross);
    /// a closed backbone with such an edge becomes open. Returns the number of samples removed.
    std::size_t cutBackbone(Backbone& backbone) const {
        const Polyline2& s = backbone.samples;
        const std::size_t n = s.size();
        if (n < 2) return 0;
        if (backbone.closed) {
            // Forward from the seed (sample 0) to the first crossing edge, backward likewise.
            std::size_t f = 0, b = 0; // kept: samples n − b … n − 1, 0 … f
            while (f + 1 < n && !crossesAcross(s[f], s[f + 1]))
                ++f;
            if (f + 1 == n && !crossesAcross(s[n - 1], s[0])) return 0; // no crossing: stays closed
            while (b + 1 + f < n && !crossesAcross(s[(n - b) % n], s[n - 1 - b]))
                ++b;
            Polyline2 open(s.end() - std::ptrdiff_t(b), s.end());
            open.insert(open.end(), s.begin(), s.begin() + std::ptrdiff_t(f) + 1);
            backbone.seedIndex = b;
            backbone.samples = std::move(open);
            backbone.closed = false;
            return n - backbone.samples.size();
        }
        std::size_t lo = backbone.seedIndex, hi = backbone.seedIndex;
        while (hi + 1 < n && !crossesAcross(s[hi], s[hi + 1]))
            ++hi;
        while (lo > 0 && !crossesAcross(s[lo], s[lo - 1]))
            --lo;
        const std::size_t removed = n - (hi - lo + 1);
        backbone.samples = Polyline2(s.begin() + std::ptrdiff_t(lo), s.begin() + std::ptrdiff_t(hi) + 1);
        backbone.seedIndex -= lo;
        return removed;
    }

    /// Stops the half-ribs of \p grid where an edge after the first (which starts on the backbone, maybe
    /// on the crease it follows) crosses a crease: that edge's outer vertex and every one beyond become
    /// absent. With \p spareFollowed, a crease segment that runs along the backbone at the rib's row (within
    /// 30° of its tangent) and lies within 2h of its sample is the crease the backbone follows and stops no
    /// rib of that row (on CAD meshes the backbone wanders up to a pixel or two about the crease's screen
    /// image, and its ribs' second edges crossed it back: ribs of 1–2 edges). Returns the number of
    /// vertices removed.
    std::size_t stopRibsAtCreases(FishboneGrid& grid, bool spareFollowed) const {
        std::size_t removed = 0;
        const int bc = grid.backboneColumn;
        const double cosAlong = std::cos(30.0 * std::numbers::pi / 180.0), near = 2.0 * grid.spacing;
        for (int r = 0; r < grid.rows; ++r) {
            // The backbone's screen tangent at row r (zero: not known, nothing is spared).
            Eigen::Vector2d tangent = Eigen::Vector2d::Zero();
            const int prev = grid.closed ? (r + grid.rows - 1) % grid.rows : std::max(r - 1, 0),
                      next = grid.closed ? (r + 1) % grid.rows : std::min(r + 1, grid.rows - 1);
            if (spareFollowed && grid.isPresent(prev, bc) && grid.isPresent(next, bc) && prev != next)
                tangent = (grid.at(next, bc) - grid.at(prev, bc)).normalized();
            const bool spare = tangent.allFinite() && !tangent.isZero() && grid.isPresent(r, bc);
            auto counts = [&](const CreaseSegment& s) {
                if (!spare) return true;
                const Eigen::Vector2d e = s.b - s.a, o = grid.at(r, bc);
                const double len2 = e.squaredNorm();
                if (!(len2 > 0) || std::abs(e.dot(tangent)) < cosAlong * std::sqrt(len2)) return true;
                const double t = std::clamp((o - s.a).dot(e) / len2, 0.0, 1.0);
                return (s.a + t * e - o).norm() > near;
            };
            for (const int side : {1, -1}) {
                bool stopped = false;
                for (int c = bc + 2 * side; c >= 0 && c < grid.cols; c += side) {
                    const std::size_t i = grid.index(r, c);
                    if (!grid.present[i]) {
                        stopped = true;
                        continue;
                    }
                    if (!stopped && grid.isPresent(r, c - side) &&
                        crossingIf(grid.at(r, c - side), grid.at(r, c), counts))
                        stopped = true;
                    if (stopped) {
                        grid.present[i] = 0;
                        ++removed;
                    }
                }
            }
        }
        return removed;
    }

private:
    static constexpr int kCell = 16; // pixels
    // The cell column (row) of a coordinate, clamped to the grid: positions outside the image share the
    // border cells, which list every segment reaching beyond the border.
    static int cellOf(double v, int cells) {
        if (!(v >= 0)) return 0;
        return int(std::min(double(cells - 1), std::floor(v / kCell)));
    }

    std::vector<CreaseSegment> segments_;
    double radius_;
    int cellsX_, cellsY_;
    std::vector<std::vector<std::size_t>> cells_;
};

} // namespace fss::detail
