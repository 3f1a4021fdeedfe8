// Internal to the stitch module: geometry helpers and small types shared by the stitch stages (DESIGN.md §6).
#pragma once

#include "base/disjoint_sets.h"
#include "fss/stitch.h"
#include "mesh/local_ops.h"
#include "mesh/triangle_geometry.h"
#include "stitch/band_remesh.h"
#include "stitch/lift.h"
#include "stitch/seam_quality.h"
#include "stitch/stitch_edits.h"
#include "stitch/strip_refill.h"

#include "fss/error.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <limits>
#include <map>
#include <numbers>
#include <queue>
#include <set>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace fss::detail::stitching {

namespace PMP = CGAL::Polygon_mesh_processing;
using Point2 = Kernel::Point_2;
using Triangle2 = Kernel::Triangle_2;
using Segment2 = Kernel::Segment_2;
using Vec3 = Eigen::Vector3d;
using Triangle3 = Kernel::Triangle_3;

inline constexpr std::uint32_t kNone = 0xFFFFFFFFu;
inline constexpr double kDeg = std::numbers::pi / 180.0;
// Normals of pieces of one planar face agree to rounding; a flip between such pieces keeps the surface.
inline constexpr double kCoplanar = 1e-4 * kDeg;

inline Vec3 toVec(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}
inline Point3 toPoint(const Vec3& v) {
    return {v.x(), v.y(), v.z()};
}
inline std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t(a) << 32) | b;
}
inline std::uint64_t dirKey(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(a) << 32) | b;
}

inline bool leftTurn(const Point2& a, const Point2& b, const Point2& c) {
    return CGAL::orientation(a, b, c) == CGAL::LEFT_TURN;
}
// Closed containment of p in the counter-clockwise triangle abc (exact).
inline bool inTriangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
    return CGAL::orientation(a, b, p) != CGAL::RIGHT_TURN && CGAL::orientation(b, c, p) != CGAL::RIGHT_TURN &&
           CGAL::orientation(c, a, p) != CGAL::RIGHT_TURN;
}
inline double area2(const Point2& a, const Point2& b, const Point2& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}
inline double dist2(const Point2& a, const Point2& b) {
    return CGAL::squared_distance(a, b);
}
// Parameter of the projection of p onto the line ab (0 at a, 1 at b).
inline double lineParam(const Point2& p, const Point2& a, const Point2& b) {
    const double dx = b.x() - a.x(), dy = b.y() - a.y();
    const double l2 = dx * dx + dy * dy;
    return l2 > 0 ? ((p.x() - a.x()) * dx + (p.y() - a.y()) * dy) / l2 : 0.0;
}
inline double segmentDistance(const Point2& p, const Point2& a, const Point2& b, double& t) {
    t = lineParam(p, a, b);
    const double tc = std::clamp(t, 0.0, 1.0);
    const Point2 q(a.x() + tc * (b.x() - a.x()), a.y() + tc * (b.y() - a.y()));
    return std::sqrt(dist2(p, q));
}
inline CGAL::Bbox_2 bboxOf(const Point2& a, const Point2& b) {
    return a.bbox() + b.bbox();
}
inline CGAL::Bbox_2 bboxOf(const Point2& a, const Point2& b, const Point2& c) {
    return a.bbox() + b.bbox() + c.bbox();
}
inline CGAL::Bbox_2 grown(const CGAL::Bbox_2& b, double r) {
    return {b.xmin() - r, b.ymin() - r, b.xmax() + r, b.ymax() + r};
}

// Smallest corner angle of a 3D triangle (radians); 0 for degenerate ones.
using detail::minAngle;
// Distance between the segments pq and rs.
inline double segmentGap(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
    const Vec3 d1 = q - p, d2 = s - r, w = p - r;
    const double a = d1.dot(d1), b = d1.dot(d2), c = d2.dot(d2), d = d1.dot(w), e = d2.dot(w);
    const double den = a * c - b * b;
    double t = den > 1e-300 ? std::clamp((b * e - c * d) / den, 0.0, 1.0) : 0.0;
    double u = c > 0 ? std::clamp((b * t + e) / c, 0.0, 1.0) : 0.0;
    t = a > 0 ? std::clamp((b * u - d) / a, 0.0, 1.0) : 0.0;
    return (p + t * d1 - (r + u * d2)).norm();
}
// A flip outside the patch between pieces of two mesh faces may move the surface by this × the patch's
// median edge length.
inline constexpr double kNearPlanarFlipGap = 0.05;
// Faces near the seam with a smaller angle (degrees) get a collapse of their shortest edge tried.
inline constexpr double kNeedleDeg = 20.0;
// Seam vertices with more edges get flips that take one away, with fewer one that adds one (valencePass).
inline constexpr std::size_t kMaxSeamValence = 8;
inline constexpr std::size_t kMinSeamValence = 4;
// ... unless the flip leaves an angle below this (degrees) where there was none.
inline constexpr double kValenceFlipMinDeg = 15.0;
// In the last smoothing, a vertex whose smallest angle around stays below this (degrees) after moving to its
// neighbours' centre searches for a better place: a compass search halving its step kSearchLevels times, in
// at most kSearchRounds rounds.
inline constexpr double kSearchBelowDeg = 20.0;
inline constexpr int kSearchLevels = 6;
inline constexpr int kSearchRounds = 64;
// ... and a seam vertex on a mesh edge tries this many evenly spaced points of the edge, keeping this
// fraction of the edge clear at each end.
inline constexpr int kSlideSamples = 48;
inline constexpr double kSlideEnd = 0.02;

inline Vec3 normalOf(const Vec3& a, const Vec3& b, const Vec3& c) {
    return (b - a).cross(c - a);
}
inline double angleBetween(const Vec3& n1, const Vec3& n2) {
    return std::atan2(n1.cross(n2).norm(), n1.dot(n2));
}

// ---------------------------------------------------------------------------------------------------
// The scan's view: projection to a 2D plane where front-facing triangles are counter-clockwise.
// uv = (screen x, −screen y); the screen's y axis points down.
class View {
public:
    explicit View(const Camera& c) : cam_(c), vp_(c.viewProjectionMatrix()), dir_(c.viewDirection()) {}

    // False for points behind the eye (or not finite).
    bool project(const Vec3& p, Point2& uv, double& w) const {
        const Eigen::Vector4d clip = vp_ * p.homogeneous();
        w = clip.w();
        if (!(w > 0) || !clip.allFinite()) return false;
        const double sx = (clip.x() / w + 1.0) * 0.5 * cam_.width;
        const double sy = (1.0 - clip.y() / w) * 0.5 * cam_.height;
        if (!std::isfinite(sx) || !std::isfinite(sy)) return false;
        uv = Point2(sx, -sy);
        return true;
    }
    // Unit vector from p towards the viewer.
    Vec3 towardsViewer(const Vec3& p) const {
        return cam_.parallel ? Vec3(-dir_) : Vec3((cam_.eye - p).normalized());
    }
    // The view ray through p.
    void rayThrough(const Vec3& p, Vec3& origin, Vec3& direction) const {
        if (cam_.parallel) {
            origin = p;
            direction = dir_;
        } else {
            origin = cam_.eye;
            direction = (p - cam_.eye).normalized();
        }
    }
    // 3D parameter along an edge from u (clip w = wu) to w (clip w = ww) of the point whose projection is
    // at 2D parameter s along the projected edge (perspective-correct: 1/w is affine on the screen).
    static double perspectiveParam(double s, double wu, double ww) {
        const double a = s / ww, b = (1.0 - s) / wu;
        const double t = a / (a + b);
        return std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : s;
    }
    const Camera& camera() const { return cam_; }

private:
    Camera cam_;
    Eigen::Matrix4d vp_;
    Vec3 dir_;
};

// ---------------------------------------------------------------------------------------------------
// Uniform bucket grid over 2D boxes; queries report each id once. With `bounds` (the box the inserted boxes
// mostly lie in), the cells there are a dense array (no hashing: the searches over the faces under a patch
// query this grid for every face); cells outside stay in a hash map. Either way the same ids are reported in
// the same order (cells by x, then y; ids in insertion order).
class BucketGrid {
public:
    BucketGrid() = default;
    BucketGrid(double cell, std::size_t ids) : inv_(1.0 / cell), stamp_(ids, 0) {}
    BucketGrid(double cell, std::size_t ids, const CGAL::Bbox_2& bounds) : BucketGrid(cell, ids) {
        if (!(bounds.xmax() >= bounds.xmin()) || !(bounds.ymax() >= bounds.ymin())) return;
        const double x0 = std::floor(bounds.xmin() * inv_), x1 = std::floor(bounds.xmax() * inv_);
        const double y0 = std::floor(bounds.ymin() * inv_), y1 = std::floor(bounds.ymax() * inv_);
        const double cells = (x1 - x0 + 1) * (y1 - y0 + 1);
        // (Only where the array stays small next to the ids it holds.)
        if (!(cells <= 4.0 * double(ids) + 4096.0) || std::abs(x0) > 1e15 || std::abs(y0) > 1e15) return;
        x0_ = std::int64_t(x0);
        y0_ = std::int64_t(y0);
        nx_ = std::int64_t(x1 - x0) + 1;
        ny_ = std::int64_t(y1 - y0) + 1;
        dense_.resize(std::size_t(nx_ * ny_));
    }

    void insert(int id, const CGAL::Bbox_2& b) {
        forCells(b, [&](std::int64_t x, std::int64_t y) { cellAt(x, y).push_back(id); });
    }
    template <class F> void query(const CGAL::Bbox_2& b, F&& f) {
        ++current_;
        forCells(b, [&](std::int64_t x, std::int64_t y) {
            const std::vector<int>* cell = find(x, y);
            if (!cell) return;
            for (int id : *cell)
                if (stamp_[std::size_t(id)] != current_) {
                    stamp_[std::size_t(id)] = current_;
                    f(id);
                }
        });
    }
    // Whether pred(id) holds for one of the ids query(b, …) would visit, visited in query's order up to the
    // first that does (what a query whose callback ignores the ids after a hit answers, without them).
    template <class P> bool any(const CGAL::Bbox_2& b, P&& pred) {
        ++current_;
        return forCells(b, [&](std::int64_t x, std::int64_t y) {
            const std::vector<int>* cell = find(x, y);
            if (!cell) return false;
            for (int id : *cell)
                if (stamp_[std::size_t(id)] != current_) {
                    stamp_[std::size_t(id)] = current_;
                    if (pred(id)) return true;
                }
            return false;
        });
    }

private:
    static std::uint64_t key(std::int64_t x, std::int64_t y) {
        return (std::uint64_t(std::uint32_t(x)) << 32) | std::uint32_t(y);
    }
    bool inDense(std::int64_t x, std::int64_t y) const {
        return x >= x0_ && x < x0_ + nx_ && y >= y0_ && y < y0_ + ny_;
    }
    std::vector<int>& cellAt(std::int64_t x, std::int64_t y) {
        if (inDense(x, y)) return dense_[std::size_t((x - x0_) * ny_ + (y - y0_))];
        return cells_[key(x, y)];
    }
    const std::vector<int>* find(std::int64_t x, std::int64_t y) const {
        if (inDense(x, y)) {
            const std::vector<int>& c = dense_[std::size_t((x - x0_) * ny_ + (y - y0_))];
            return c.empty() ? nullptr : &c;
        }
        if (cells_.empty()) return nullptr;
        auto it = cells_.find(key(x, y));
        return it == cells_.end() ? nullptr : &it->second;
    }
    // Calls f(x, y) for the cells b touches; an f returning bool stops the walk at its first true (then
    // the result is true).
    template <class F> bool forCells(const CGAL::Bbox_2& b, F&& f) const {
        const auto x0 = std::int64_t(std::floor(b.xmin() * inv_)),
                   x1 = std::int64_t(std::floor(b.xmax() * inv_));
        const auto y0 = std::int64_t(std::floor(b.ymin() * inv_)),
                   y1 = std::int64_t(std::floor(b.ymax() * inv_));
        for (std::int64_t x = x0; x <= x1; ++x)
            for (std::int64_t y = y0; y <= y1; ++y) {
                if constexpr (std::is_same_v<decltype(f(x, y)), bool>) {
                    if (f(x, y)) return true;
                } else {
                    f(x, y);
                }
            }
        return false;
    }
    double inv_ = 1.0;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
    std::vector<std::vector<int>> dense_;
    std::int64_t x0_ = 0, y0_ = 0, nx_ = 0, ny_ = 0;
    std::vector<unsigned> stamp_;
    unsigned current_ = 0;
};

// ---------------------------------------------------------------------------------------------------
// Map from mesh indices (vertex or face numbers, never kNone) to values: open addressing with linear
// probing. The searches over the faces under a patch look indices up millions of times; this is several
// times faster than std::unordered_map there. Pointers to values stay valid until the next insertion.
template <class V, class Key = std::uint32_t> class IndexMap {
public:
    // The value of key and whether it was inserted now (then set to `init`).
    std::pair<V*, bool> try_emplace(Key key, const V& init = V()) {
        if (2 * (size_ + 1) > keys_.size()) grow();
        std::size_t i = slot(key);
        if (keys_[i] == key) return {&values_[i], false};
        keys_[i] = key;
        values_[i] = init;
        ++size_;
        return {&values_[i], true};
    }
    bool insert(Key key) { return try_emplace(key).second; }
    V& operator[](Key key) { return *try_emplace(key).first; }
    const V* find(Key key) const {
        if (keys_.empty()) return nullptr;
        const std::size_t i = slot(key);
        return keys_[i] == key ? &values_[i] : nullptr;
    }
    // The value of a key that must be there.
    const V& at(Key key) const {
        const V* v = find(key);
        if (!v) throw std::logic_error("IndexMap::at: no such key");
        return *v;
    }
    std::size_t count(Key key) const { return find(key) ? 1 : 0; }
    std::size_t size() const { return size_; }
    void clear() {
        keys_.clear();
        values_.clear();
        size_ = 0;
    }

private:
    static constexpr Key kEmpty = std::numeric_limits<Key>::max(); // never a key (kNone, or two of them)
    std::size_t slot(Key key) const {
        const std::size_t mask = keys_.size() - 1;
        std::size_t i = std::size_t((std::uint64_t(key) * 0x9E3779B97F4A7C15ull) >> 20) & mask;
        while (keys_[i] != key && keys_[i] != kEmpty)
            i = (i + 1) & mask;
        return i;
    }
    void grow() {
        std::vector<Key> keys(std::max<std::size_t>(64, 2 * keys_.size()), kEmpty);
        std::vector<V> values(keys.size());
        keys.swap(keys_);
        values.swap(values_);
        for (std::size_t j = 0; j < keys.size(); ++j)
            if (keys[j] != kEmpty) {
                const std::size_t i = slot(keys[j]);
                keys_[i] = keys[j];
                values_[i] = std::move(values[j]);
            }
    }
    std::vector<Key> keys_;
    std::vector<V> values_;
    std::size_t size_ = 0;
};
using IndexSet = IndexMap<char>;

// ---------------------------------------------------------------------------------------------------
// The patch, projected once.
struct PatchData {
    std::vector<Vec3> pos;
    std::vector<Point2> uv;
    std::vector<std::array<int, 3>> tri; // counter-clockwise in the view
    std::vector<float> quality;
    std::vector<std::int32_t> scanId;
    std::vector<std::uint32_t> face; // the patch's face index of each tri
    bool hasQuality = false, hasScanId = false;
};

// ---------------------------------------------------------------------------------------------------
// Removes face f like CGAL::Euler::remove_face, but keeps the vertices for which keep(v) is true when
// they become isolated (they are reused by the faces added next).
template <class Keep> void removeFaceKeeping(Mesh& m, FaceIndex f, const Keep& keep) {
    HalfedgeIndex h = m.halfedge(f);
    const HalfedgeIndex end = h;
    do {
        CGAL::internal::set_border(h, m);
        const HalfedgeIndex nh = m.next(h);
        const bool hBorder = m.is_border(m.opposite(h));
        const bool nhBorder = m.is_border(m.opposite(nh));
        if (hBorder && nhBorder && m.next(m.opposite(nh)) == m.opposite(h)) {
            const VertexIndex v = m.target(h);
            if (keep(v))
                m.set_halfedge(v, Mesh::null_halfedge());
            else
                m.remove_vertex(v);
            if (h != end) m.remove_edge(m.edge(h));
        } else {
            if (nhBorder) {
                CGAL::internal::set_vertex_halfedge(m.opposite(m.next(m.opposite(nh))), m);
                CGAL::internal::remove_tip(h, m);
            }
            if (hBorder) {
                CGAL::internal::set_vertex_halfedge(m.opposite(m.next(h)), m);
                CGAL::internal::remove_tip(m.prev(m.opposite(h)), m);
                if (h != end) m.remove_edge(m.edge(h));
            }
        }
        h = nh;
    } while (h != end);
    m.remove_face(f);
    if (m.is_border(m.opposite(h))) m.remove_edge(m.edge(h));
}

// ---------------------------------------------------------------------------------------------------
// A vertex of a plan: an existing vertex of the current mesh or the k-th new one.
struct PlanVertex {
    std::uint32_t index = 0;
    bool fresh = false;
};

// Everything needed to apply one component's stitch to the mesh, computed without touching it.
struct Plan {
    std::vector<FaceIndex> removed;               // faces of the current mesh replaced (in this order)
    std::vector<VertexIndex> reused;              // vertices of removed faces that new faces use
    std::vector<Vec3> freshPositions;             // new vertices, added in this order
    std::vector<std::array<PlanVertex, 3>> faces; // new faces, added in this order
    std::vector<float> quality;
    std::vector<std::int32_t> scanId;
    // The patch's core (faces deep inside the component, added after `faces` straight into the hole they
    // leave, without the local mesh: DESIGN.md §6.1 "Core bypass"): corners, and for every face the bit k
    // set when its edge k → k+1 lies on the core's border (the face beyond it is one of `faces`).
    std::vector<std::array<PlanVertex, 3>> coreFaces;
    std::vector<std::uint8_t> coreBorder;
    std::vector<float> coreQuality;
    std::vector<std::int32_t> coreScanId;
    std::size_t seamEdges = 0;
    double seamLength = 0;
    std::vector<double> seamFaceMinAngles; // degrees, one per face touching the seam
    std::vector<std::size_t> seamValences; // one per seam vertex
    std::size_t collapses = 0, flips = 0;
};

struct Attempt {
    bool ok = false;
    std::string reason;   // why not (without the component's name), when !ok
    std::vector<int> bad; // patch vertices near the problem: trim there and retry
    Plan plan;
};

// Adds the plan's core faces (after its other faces: their border is then a set of border halfedges of m,
// each the core border edge of one core face) by linking halfedges directly, not through add_face: the
// core is a piece of the scan's grid, valid and oriented by construction, and the stitcher checked that
// the hole its border leaves is exactly the core's border (validate), so nothing here can fail half-way
// except on an internal error (false, as replay). onFace gets indices after plan.faces.
template <class VertexOf, class OnFace>
inline bool fillCore(Mesh& m, const Plan& plan, const std::vector<VertexIndex>& fresh,
                     const VertexOf& vertexOf, const OnFace& onFace) {
    if (plan.coreFaces.empty()) return true;
    auto vertex = [&](const PlanVertex& pv) {
        return pv.fresh ? fresh[pv.index] : vertexOf(VertexIndex(pv.index));
    };
    // Core border: the border halfedges of m there (checked first, before any edit).
    std::vector<HalfedgeIndex> border;
    for (std::size_t i = 0; i < plan.coreFaces.size(); ++i)
        for (int k = 0; k < 3; ++k)
            if (plan.coreBorder[i] & (1u << k)) {
                const HalfedgeIndex h = m.halfedge(vertex(plan.coreFaces[i][std::size_t(k)]),
                                                   vertex(plan.coreFaces[i][std::size_t((k + 1) % 3)]));
                if (h == Mesh::null_halfedge() || !m.is_border(h)) return false;
                border.push_back(h);
            }
    std::size_t nextBorder = 0;
    // Inner edges: the halfedge x → y made with the first face that uses the edge (y → x then waits).
    IndexMap<HalfedgeIndex, std::uint64_t> waiting;
    for (std::size_t i = 0; i < plan.coreFaces.size(); ++i) {
        std::array<VertexIndex, 3> vs;
        for (int k = 0; k < 3; ++k)
            vs[std::size_t(k)] = vertex(plan.coreFaces[i][std::size_t(k)]);
        std::array<HalfedgeIndex, 3> hs;
        for (int k = 0; k < 3; ++k) {
            const VertexIndex x = vs[std::size_t(k)], y = vs[std::size_t((k + 1) % 3)];
            if (plan.coreBorder[i] & (1u << k)) {
                hs[std::size_t(k)] = border[nextBorder++];
                continue;
            }
            const std::uint64_t key = (std::uint64_t(std::uint32_t(x)) << 32) | std::uint32_t(y);
            const HalfedgeIndex* h = waiting.find(key);
            if (h) {
                hs[std::size_t(k)] = *h;
            } else {
                hs[std::size_t(k)] = m.add_edge(x, y); // x → y; its opposite y → x for the face beyond
                waiting[(std::uint64_t(std::uint32_t(y)) << 32) | std::uint32_t(x)] =
                    m.opposite(hs[std::size_t(k)]);
            }
        }
        const FaceIndex f = m.add_face();
        for (int k = 0; k < 3; ++k) {
            const HalfedgeIndex h = hs[std::size_t(k)];
            m.set_face(h, f);
            m.set_next(h, hs[std::size_t((k + 1) % 3)]);
            m.set_halfedge(m.target(h), h); // every core vertex is interior once the core is in
        }
        m.set_halfedge(f, hs[0]);
        onFace(plan.faces.size() + i, f);
    }
    return true;
}

// Applies the edits of a plan to a mesh whose vertices are addressed through `vertexOf` (current
// vertices → vertices of m) and whose faces through `faceOf`. Returns false when a face cannot be added.
template <class VertexOf, class FaceOf, class OnFace>
inline bool replay(Mesh& m, const Plan& plan, const VertexOf& vertexOf, const FaceOf& faceOf,
                   const OnFace& onFace) {
    std::vector<VertexIndex> fresh;
    fresh.reserve(plan.freshPositions.size());
    for (const Vec3& p : plan.freshPositions)
        fresh.push_back(m.add_vertex(toPoint(p)));
    std::unordered_set<std::uint32_t> keep;
    for (VertexIndex v : plan.reused)
        keep.insert(std::uint32_t(vertexOf(v)));
    for (FaceIndex f : plan.removed)
        removeFaceKeeping(m, faceOf(f), [&](VertexIndex v) { return keep.count(std::uint32_t(v)) > 0; });
    for (std::size_t i = 0; i < plan.faces.size(); ++i) {
        std::array<VertexIndex, 3> vs;
        for (int k = 0; k < 3; ++k) {
            const PlanVertex& pv = plan.faces[i][std::size_t(k)];
            vs[std::size_t(k)] = pv.fresh ? fresh[pv.index] : vertexOf(VertexIndex(pv.index));
        }
        const FaceIndex f = m.add_face(vs[0], vs[1], vs[2]);
        if (f == Mesh::null_face()) return false;
        onFace(i, f);
    }
    return fillCore(m, plan, fresh, vertexOf, onFace);
}

// ---------------------------------------------------------------------------------------------------
// The star of a set of faces of the current mesh (all faces sharing a vertex with them), copied into a
// small local mesh on which the stitch is built, optimised, checked and rehearsed.
struct Star {
    Mesh S;
    IndexMap<VertexIndex> fromCurrent;                  // current vertex → S vertex
    IndexMap<FaceIndex> faceFromCurrent;                // current face → S face
    Mesh::Property_map<VertexIndex, std::uint32_t> cur; // S vertex → current vertex (kNone: new)
    Mesh::Property_map<FaceIndex, bool> kept;           // face of the current mesh that stays
    std::vector<VertexIndex> full; // S vertices whose whole star is in S (vertices of the replaced faces)
    std::unordered_set<std::uint32_t> fullCurrent; // the same, as current-mesh vertices
    // Is the whole star of S vertex v in S (a vertex of the replaced faces, or a new one)?
    bool isFull(VertexIndex v) const { return cur[v] == kNone || fullCurrent.count(cur[v]) > 0; }
};

inline bool buildStar(const Mesh& M, const std::vector<FaceIndex>& replaced, Star& st) {
    st.cur = st.S.add_property_map<VertexIndex, std::uint32_t>("v:cur", kNone).first;
    st.kept = st.S.add_property_map<FaceIndex, bool>("f:kept", true).first;
    std::vector<FaceIndex> faces;
    std::unordered_set<std::uint32_t> seenFace, seenVertex;
    std::vector<VertexIndex> centre;
    for (FaceIndex f : replaced)
        for (VertexIndex v : CGAL::vertices_around_face(M.halfedge(f), M))
            if (seenVertex.insert(std::uint32_t(v)).second) centre.push_back(v);
    for (VertexIndex v : centre)
        for (FaceIndex f : CGAL::faces_around_target(M.halfedge(v), M))
            if (f != Mesh::null_face() && seenFace.insert(std::uint32_t(f)).second) faces.push_back(f);
    auto vertexOf = [&](VertexIndex v) {
        auto [it, fresh] = st.fromCurrent.try_emplace(std::uint32_t(v));
        if (fresh) {
            *it = st.S.add_vertex(M.point(v));
            st.cur[*it] = std::uint32_t(v);
        }
        return *it;
    };
    for (FaceIndex f : faces) {
        std::array<VertexIndex, 3> vs;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(M.halfedge(f), M)) {
            if (k == 3) return false;
            vs[std::size_t(k++)] = vertexOf(v);
        }
        if (k != 3) return false;
        const FaceIndex g = st.S.add_face(vs[0], vs[1], vs[2]);
        if (g == Mesh::null_face()) return false;
        st.faceFromCurrent[std::uint32_t(f)] = g;
    }
    for (VertexIndex v : centre) {
        const VertexIndex s = st.fromCurrent.at(std::uint32_t(v));
        // The whole umbrella must have been copied (else the mesh is not vertex-manifold here).
        if (st.S.degree(s) != M.degree(v) || st.S.is_border(s) != M.is_border(v)) return false;
        st.full.push_back(s);
        st.fullCurrent.insert(std::uint32_t(v));
    }
    return true;
}

// ---------------------------------------------------------------------------------------------------
// Constrained Delaunay triangulation of the view.
struct CdtFaceInfo {
    int region = -1;         // index of the region face the triangle lies in
    std::int8_t inside = -1; // 1 inside the patch, 0 outside, -1 unknown
};
struct CdtVertexInfo {
    int id = -1; // local vertex id; -1 for a vertex the triangulation made itself
};
using CdtVb = CGAL::Triangulation_vertex_base_with_info_2<CdtVertexInfo, Kernel>;
using CdtFb = CGAL::Triangulation_face_base_with_info_2<CdtFaceInfo, Kernel,
                                                        CGAL::Constrained_triangulation_face_base_2<Kernel>>;
using CdtTds = CGAL::Triangulation_data_structure_2<CdtVb, CdtFb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, CdtTds, CGAL::Exact_predicates_tag>;
using CdtVertex = Cdt::Vertex_handle;
using CdtFace = Cdt::Face_handle;

// A vertex of the local problem.
struct LVert {
    enum Kind : std::uint8_t { Region, PatchBoundary, Crossing, PatchInterior };
    Kind kind = Region;
    std::uint32_t cur = kNone;    // Region: the current-mesh vertex
    int patchA = -1, patchB = -1; // the patch vertex it stands for, or the patch boundary edge it lies on
    bool alive = true;            // false for patch boundary vertices merged into a region vertex
    bool chain = false;           // lies on the patch boundary (a seam vertex)
    int edgeU = -1, edgeW = -1;   // crossings and vertices snapped onto a mesh edge: that edge's ends
    bool onOuterEdge = false;     // snapped onto a mesh edge whose other face is not a region face
    Vec3 pos{0, 0, 0};
    Point2 uv{0, 0};
};

// A face of the stitched result in local vertex ids.
struct LFace {
    std::array<int, 3> v;
    float quality;
    std::int32_t scanId;
    bool patchSide; // a patch face (or a piece of one); else a piece of a mesh face outside the patch
    Vec3 planeNormal{0, 0, 0}; // pieces outside: unit normal of the mesh face they lie in
    double minAllowed = 0;     // smallest angle accepted (radians): the floor, or less if the parent had less
    bool offView = false;      // a piece of a mesh face the view does not see: checked in 3D, in its plane
};

// ---------------------------------------------------------------------------------------------------
// Progress inside one component's computation (which never touches the current mesh, so stopping there
// abandons the component): the long loops count elementary operations and report every kReportEvery of
// them, so a cancel is noticed after a bounded amount of work. The fraction advances through [from, to)
// with the steps of the computation and never goes back (trim rounds retry a component).
class ComponentProgress {
public:
    static constexpr std::size_t kReportEvery = 4096;
    ComponentProgress(const Progress& progress, double& last, double from, double to)
        : progress_(progress), last_(last), from_(from), to_(to) {}
    // Counts n operations; reports (and may throw CancelledError) when enough have accumulated.
    void tick(std::size_t n = 1) {
        work_ += n;
        if (work_ >= kReportEvery) report();
    }
    // Enters step `step` (1 ≤ step ≤ steps) of the computation; the application that follows it is the
    // last share of [from, to).
    void step(int step, int steps) {
        stepFraction_ = double(step) / double(steps + 1);
        tick(0);
    }
    void report() {
        work_ = 0;
        last_ = std::max(last_, std::min(1.0, from_ + (to_ - from_) * stepFraction_));
        progress_.report(last_, "stitch");
    }

private:
    const Progress& progress_;
    double& last_;
    double from_, to_;
    double stepFraction_ = 0;
    std::size_t work_ = 0;
};

// Time per stage of the stitch, printed to stderr by stitchPatch when the environment variable
// FSS_STITCH_PROFILE is 1 (issue 19's breakdown; off otherwise, one branch per stage).
class StageClock {
public:
    static bool enabled() {
        static const bool on = [] {
            const char* e = std::getenv("FSS_STITCH_PROFILE");
            return e && std::string_view(e) == "1";
        }();
        return on;
    }
    // Adds the time since the previous lap (or start()) to `stage`.
    static void lap(const char* stage) {
        if (!enabled()) return;
        const double now = cpuMs();
        auto& t = totals();
        auto it = std::find_if(t.begin(), t.end(), [&](const auto& e) { return e.first == stage; });
        if (it == t.end()) it = t.insert(t.end(), {stage, 0.0});
        it->second += now - last();
        last() = now;
    }
    static void start() {
        if (!enabled()) return;
        totals().clear();
        last() = cpuMs();
    }
    static void print() {
        if (!enabled()) return;
        double sum = 0;
        for (const auto& [stage, ms] : totals())
            sum += ms;
        std::fprintf(stderr, "stitch stages (ms):");
        for (const auto& [stage, ms] : totals())
            std::fprintf(stderr, " %s %.1f;", stage, ms);
        std::fprintf(stderr, " total %.1f\n", sum);
    }

private:
    // Per thread: a widget's trial stitch may run beside the accept's.
    static std::vector<std::pair<const char*, double>>& totals() {
        thread_local std::vector<std::pair<const char*, double>> t;
        return t;
    }
    // CPU time of the calling thread (the stitch is single-threaded; the machine may be shared).
    static double cpuMs() {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
    }
    static double& last() {
        thread_local double t = 0;
        return t;
    }
};

} // namespace fss::detail::stitching
