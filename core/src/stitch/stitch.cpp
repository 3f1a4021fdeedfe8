// Stitching a scanned patch into the current mesh (DESIGN.md §1 "Stitch", §6).
//
// Per patch component (connected through vertices), without touching the mesh:
//  1. region     the faces of the current mesh under the component in the scan's view: front-facing, not
//                grazing, on the sheet the patch lies on (seeds: under the patch vertices, the face whose
//                plane is nearest along the view ray; grown over faces meeting the component's projection).
//                Faces near the patch boundary ("seam faces") are re-triangulated; the faces under the
//                patch, away from its boundary, are removed whole (folds and all).
//  2. insert     snap patch boundary vertices onto nearby mesh vertices / edges and mesh vertices onto nearby
//                patch boundary edges (no slivers), compute where patch boundary edges cross mesh edges (the
//                new vertex lies on the 3D mesh edge, perspective-correct), and build a constrained Delaunay
//                triangulation of the seam faces' edges and the patch boundary in the view (exact
//                predicates). A patch boundary vertex snapped onto an edge at the region's rim (a crease
//                whose far face the view does not see) splits that far face too, in its plane (checked in
//                3D, not in the view); its neighbours are opened to the seam flips.
//  3. cut, glue  flood-fill the triangulation: which seam face each triangle lies in, inside or outside the
//                patch. Seam faces are replaced by their outside triangles (in the face's plane: the surface
//                outside does not move); patch triangles on the boundary are re-triangulated over the seam
//                vertices of their edges (max-min angle, never three collinear points).
//  4. optimise   on a local copy (the star of the replaced faces): collapse short seam edges, refine the
//                pieces outside the patch with a graded size (new vertices on the old surface), flip for
//                angles and valence; never flip a face in the view, fold, move a vertex or bend the surface
//                outside the patch.
//  5. check      on the local copy: manifold, oriented, no degenerate or needle faces, every new face facing
//                the camera, border edges (so holes and boundary loops) unchanged, no self-intersections;
//                then rehearse the exact sequence of edits on a fresh local copy; only then edit the mesh.
// A problem that can be located (the patch reaching past a silhouette, a border, a grazing face, a fold,
// another sheet; a degenerate contact; a failed check) trims the patch faces there and the component is
// retried; what cannot be made stitchable is skipped and reported.

#include "fss/stitch.h"

#include "base/disjoint_sets.h"
#include "mesh/local_ops.h"
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
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace fss {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Point2 = Kernel::Point_2;
using Triangle2 = Kernel::Triangle_2;
using Segment2 = Kernel::Segment_2;
using Vec3 = Eigen::Vector3d;
using Triangle3 = Kernel::Triangle_3;

constexpr std::uint32_t kNone = 0xFFFFFFFFu;
constexpr double kDeg = std::numbers::pi / 180.0;
// Normals of pieces of one planar face agree to rounding; a flip between such pieces keeps the surface.
constexpr double kCoplanar = 1e-4 * kDeg;

Vec3 toVec(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}
Point3 toPoint(const Vec3& v) {
    return {v.x(), v.y(), v.z()};
}
std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t(a) << 32) | b;
}
std::uint64_t dirKey(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(a) << 32) | b;
}

bool leftTurn(const Point2& a, const Point2& b, const Point2& c) {
    return CGAL::orientation(a, b, c) == CGAL::LEFT_TURN;
}
// Closed containment of p in the counter-clockwise triangle abc (exact).
bool inTriangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
    return CGAL::orientation(a, b, p) != CGAL::RIGHT_TURN && CGAL::orientation(b, c, p) != CGAL::RIGHT_TURN &&
           CGAL::orientation(c, a, p) != CGAL::RIGHT_TURN;
}
double area2(const Point2& a, const Point2& b, const Point2& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}
double dist2(const Point2& a, const Point2& b) {
    return CGAL::squared_distance(a, b);
}
// Parameter of the projection of p onto the line ab (0 at a, 1 at b).
double lineParam(const Point2& p, const Point2& a, const Point2& b) {
    const double dx = b.x() - a.x(), dy = b.y() - a.y();
    const double l2 = dx * dx + dy * dy;
    return l2 > 0 ? ((p.x() - a.x()) * dx + (p.y() - a.y()) * dy) / l2 : 0.0;
}
double segmentDistance(const Point2& p, const Point2& a, const Point2& b, double& t) {
    t = lineParam(p, a, b);
    const double tc = std::clamp(t, 0.0, 1.0);
    const Point2 q(a.x() + tc * (b.x() - a.x()), a.y() + tc * (b.y() - a.y()));
    return std::sqrt(dist2(p, q));
}
CGAL::Bbox_2 bboxOf(const Point2& a, const Point2& b) {
    return a.bbox() + b.bbox();
}
CGAL::Bbox_2 bboxOf(const Point2& a, const Point2& b, const Point2& c) {
    return a.bbox() + b.bbox() + c.bbox();
}
CGAL::Bbox_2 grown(const CGAL::Bbox_2& b, double r) {
    return {b.xmin() - r, b.ymin() - r, b.xmax() + r, b.ymax() + r};
}

// Smallest corner angle of a 3D triangle (radians); 0 for degenerate ones.
double minAngle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e[3] = {b - a, c - b, a - c};
    double best = std::numbers::pi;
    for (int i = 0; i < 3; ++i) {
        const Vec3 u = -e[(i + 2) % 3], v = e[i];
        const double nu = u.norm(), nv = v.norm();
        if (!(nu > 0) || !(nv > 0)) return 0;
        best = std::min(best, std::atan2(u.cross(v).norm(), u.dot(v)));
    }
    return best;
}
// Distance between the segments pq and rs.
double segmentGap(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
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
constexpr double kNearPlanarFlipGap = 0.05;
// Faces near the seam with a smaller angle (degrees) get a collapse of their shortest edge tried.
constexpr double kNeedleDeg = 20.0;
// Seam vertices with more edges get flips that take one away, with fewer one that adds one (valencePass).
constexpr std::size_t kMaxSeamValence = 8;
constexpr std::size_t kMinSeamValence = 4;
// ... unless the flip leaves an angle below this (degrees) where there was none.
constexpr double kValenceFlipMinDeg = 15.0;
// In the last smoothing, a vertex whose smallest angle around stays below this (degrees) after moving to its
// neighbours' centre searches for a better place: a compass search halving its step kSearchLevels times, in
// at most kSearchRounds rounds.
constexpr double kSearchBelowDeg = 20.0;
constexpr int kSearchLevels = 6;
constexpr int kSearchRounds = 64;
// ... and a seam vertex on a mesh edge tries this many evenly spaced points of the edge, keeping this
// fraction of the edge clear at each end.
constexpr int kSlideSamples = 48;
constexpr double kSlideEnd = 0.02;

Vec3 normalOf(const Vec3& a, const Vec3& b, const Vec3& c) {
    return (b - a).cross(c - a);
}
double angleBetween(const Vec3& n1, const Vec3& n2) {
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
// Uniform bucket grid over 2D boxes; queries report each id once.
class BucketGrid {
public:
    BucketGrid() = default;
    BucketGrid(double cell, std::size_t ids) : inv_(1.0 / cell), stamp_(ids, 0) {}

    void insert(int id, const CGAL::Bbox_2& b) {
        forCells(b, [&](std::uint64_t key) { cells_[key].push_back(id); });
    }
    template <class F> void query(const CGAL::Bbox_2& b, F&& f) {
        ++current_;
        forCells(b, [&](std::uint64_t key) {
            auto it = cells_.find(key);
            if (it == cells_.end()) return;
            for (int id : it->second)
                if (stamp_[std::size_t(id)] != current_) {
                    stamp_[std::size_t(id)] = current_;
                    f(id);
                }
        });
    }

private:
    template <class F> void forCells(const CGAL::Bbox_2& b, F&& f) const {
        const auto x0 = std::int64_t(std::floor(b.xmin() * inv_)),
                   x1 = std::int64_t(std::floor(b.xmax() * inv_));
        const auto y0 = std::int64_t(std::floor(b.ymin() * inv_)),
                   y1 = std::int64_t(std::floor(b.ymax() * inv_));
        for (std::int64_t x = x0; x <= x1; ++x)
            for (std::int64_t y = y0; y <= y1; ++y)
                f((std::uint64_t(std::uint32_t(x)) << 32) | std::uint32_t(y));
    }
    double inv_ = 1.0;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
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

// Applies the edits of a plan to a mesh whose vertices are addressed through `vertexOf` (current
// vertices → vertices of m) and whose faces through `faceOf`. Returns false when a face cannot be added.
template <class VertexOf, class FaceOf, class OnFace>
bool replay(Mesh& m, const Plan& plan, const VertexOf& vertexOf, const FaceOf& faceOf, const OnFace& onFace) {
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
    return true;
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

bool buildStar(const Mesh& M, const std::vector<FaceIndex>& replaced, Star& st) {
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
    static std::vector<std::pair<const char*, double>>& totals() {
        static std::vector<std::pair<const char*, double>> t;
        return t;
    }
    // CPU time of the calling thread (the stitch is single-threaded; the machine may be shared).
    static double cpuMs() {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
    }
    static double& last() {
        static double t = 0;
        return t;
    }
};

class ComponentStitcher {
public:
    ComponentStitcher(const Mesh& m, const PatchData& p, const View& view, const StitchOptions& o,
                      std::span<const std::uint32_t> ids, const std::vector<int>& faces, bool hasQuality,
                      bool hasScanId, ComponentProgress& progress)
        : M_(m), P_(p), V_(view), O_(o), ids_(ids), faces_(faces), curHasQuality_(hasQuality),
          curHasScanId_(hasScanId), progress_(progress) {
        if (hasQuality) curQuality_ = M_.property_map<FaceIndex, float>(props::faceQuality).first;
        if (hasScanId) curScanId_ = M_.property_map<FaceIndex, std::int32_t>(props::faceScanId).first;
    }

    Attempt run() {
        Attempt a;
        // Cancellation points (progress_) lie in the steps' long loops; none of them touches the mesh.
        constexpr int kSteps = 8;
        StageClock::lap("other");
        if (!setupComponent(a)) return a;
        StageClock::lap("setup");
        progress_.step(1, kSteps);
        if (!findRegion(a)) return a;
        StageClock::lap("region");
        if (!preTrim(a)) return a;
        progress_.step(2, kSteps);
        if (!splitRegion(a)) return a;
        StageClock::lap("split");
        buildLocalVertices();
        snap();
        progress_.step(3, kSteps);
        if (!computeCrossings(a)) return a;
        StageClock::lap("snap+crossings");
        Cdt cdt;
        std::vector<CdtVertex> vh;
        if (!triangulate(cdt, vh, a)) return a;
        progress_.step(4, kSteps);
        if (!classify(cdt, vh, a)) return a;
        if (!checkCoverage(cdt, vh, a)) return a;
        StageClock::lap("cdt");
        if (!assemble(cdt, a)) return a;
        StageClock::lap("assemble");
        progress_.step(5, kSteps);
        if (!buildAndOptimise(a)) return a;
        a.ok = true;
        return a;
    }

private:
    // ---- results of the steps
    bool fail(Attempt& a, std::string reason, std::vector<int> bad = {}) {
        a.ok = false;
        a.reason = std::move(reason);
        std::sort(bad.begin(), bad.end());
        bad.erase(std::unique(bad.begin(), bad.end()), bad.end());
        bad.erase(std::remove(bad.begin(), bad.end(), -1), bad.end());
        if (O_.peelTrim) {
            // Peel: of the vertices near the problem, only those on the component's boundary.
            std::vector<int> onBoundary;
            for (int v : bad)
                if (boundary_.count(v)) onBoundary.push_back(v);
            if (!onBoundary.empty()) bad.swap(onBoundary);
        }
        a.bad = std::move(bad);
        return false;
    }

    // ---- step 0: the component's boundary, sizes and a grid over its triangles
    bool setupComponent(Attempt& a) {
        std::vector<std::uint64_t> directed;
        directed.reserve(3 * faces_.size());
        for (int f : faces_) {
            progress_.tick();
            const auto& t = P_.tri[std::size_t(f)];
            for (int k = 0; k < 3; ++k) {
                directed.push_back(
                    dirKey(std::uint32_t(t[std::size_t(k)]), std::uint32_t(t[std::size_t((k + 1) % 3)])));
                compVerts_.push_back(t[std::size_t(k)]);
            }
        }
        std::sort(directed.begin(), directed.end());
        std::sort(compVerts_.begin(), compVerts_.end());
        compVerts_.erase(std::unique(compVerts_.begin(), compVerts_.end()), compVerts_.end());
        std::vector<double> len2, len3;
        for (int f : faces_) {
            const auto& t = P_.tri[std::size_t(f)];
            for (int k = 0; k < 3; ++k) {
                const int p = t[std::size_t(k)], q = t[std::size_t((k + 1) % 3)];
                const bool border = !std::binary_search(directed.begin(), directed.end(),
                                                        dirKey(std::uint32_t(q), std::uint32_t(p)));
                if (border) {
                    pedgeIndex_[dirKey(std::uint32_t(p), std::uint32_t(q))] = int(pedges_.size());
                    pedges_.push_back({p, q, t[std::size_t((k + 2) % 3)], {}, {}});
                    boundary_.insert(p);
                }
                if (border || p < q) {
                    len2.push_back(std::sqrt(dist2(P_.uv[std::size_t(p)], P_.uv[std::size_t(q)])));
                    len3.push_back((P_.pos[std::size_t(p)] - P_.pos[std::size_t(q)]).norm());
                }
            }
        }
        if (pedges_.empty())
            return fail(a, "it has no boundary in the scan's view (it would cover the whole view)");
        for (int f : faces_)
            for (int v : P_.tri[std::size_t(f)])
                if (boundary_.count(v)) vertexFaces_[v].push_back(f);
        auto median = [](std::vector<double> v) {
            std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
            return v[v.size() / 2];
        };
        h2_ = median(len2);
        h3_ = median(len3);
        if (!(h2_ > 0) || !(h3_ > 0)) return fail(a, "its triangles have no extent in the scan's view");
        for (const auto& e : pedges_) {
            const double l = std::sqrt(dist2(P_.uv[std::size_t(e.a)], P_.uv[std::size_t(e.b)]));
            for (int v : {e.a, e.b}) {
                auto [it, fresh] = snapRadius_.try_emplace(v, l);
                if (!fresh) it->second = std::min(it->second, l);
            }
        }
        for (auto& [v, r] : snapRadius_) {
            r *= O_.collapseEdgeRatio;
            margin_ = std::max(margin_, r);
        }
        margin_ *= 1.01;
        compBox_ = CGAL::Bbox_2();
        for (int v : compVerts_)
            compBox_ += P_.uv[std::size_t(v)].bbox();
        compGrid_ = BucketGrid(2.0 * h2_, faces_.size());
        for (std::size_t i = 0; i < faces_.size(); ++i)
            compGrid_.insert(int(i), triBox(faces_[i]));
        return true;
    }
    CGAL::Bbox_2 triBox(int f) const {
        const auto& t = P_.tri[std::size_t(f)];
        return bboxOf(P_.uv[std::size_t(t[0])], P_.uv[std::size_t(t[1])], P_.uv[std::size_t(t[2])]);
    }
    Triangle2 patchTriangle(int f) const {
        const auto& t = P_.tri[std::size_t(f)];
        return {P_.uv[std::size_t(t[0])], P_.uv[std::size_t(t[1])], P_.uv[std::size_t(t[2])]};
    }
    // Patch vertices of the component near a point of the view (for trimming there).
    std::vector<int> patchVerticesNear(const Point2& q, double radius) {
        std::vector<int> out;
        const CGAL::Bbox_2 box = grown(q.bbox(), radius);
        compGrid_.query(box, [&](int i) {
            if (CGAL::do_overlap(box, triBox(faces_[std::size_t(i)])))
                for (int v : P_.tri[std::size_t(faces_[std::size_t(i)])])
                    out.push_back(v);
        });
        return out;
    }
    // Records a problem at q: the patch vertices nearest to it are to be trimmed. The marker -1 makes sure
    // the problem counts even when no patch vertex is near (fail() drops the markers).
    void addNear(std::vector<int>& bad, const Point2& q) {
        bad.push_back(-1);
        for (double r = 1.5 * h2_; r < 100.0 * h2_; r *= 2.0) {
            auto near = patchVerticesNear(q, r);
            if (near.empty()) continue;
            bad.insert(bad.end(), near.begin(), near.end());
            return;
        }
    }
    // Patch vertices to trim for a problem at local vertex i.
    void addBad(std::vector<int>& bad, int i) {
        bad.push_back(-1);
        const LVert& l = L_[std::size_t(i)];
        if (l.patchA >= 0 || l.patchB >= 0) {
            bad.push_back(l.patchA);
            bad.push_back(l.patchB);
        } else {
            addNear(bad, l.uv);
        }
    }

    // ---- the current mesh in the view (cached per vertex / face)
    struct VProj {
        Point2 uv;
        double w = 0;
        bool ok = false;
    };
    VProj vproj(VertexIndex v) {
        auto [it, fresh] = vcache_.try_emplace(std::uint32_t(v));
        if (fresh) it->ok = V_.project(toVec(M_.point(v)), it->uv, it->w);
        return *it;
    }
    // Triangle face, in front of the eye, counter-clockwise in the view and not grazing.
    bool acceptable(FaceIndex f) {
        auto [it, fresh] = accept_.try_emplace(std::uint32_t(f), 0);
        if (!fresh) return *it != 0;
        const HalfedgeIndex h = M_.halfedge(f);
        if (M_.next(M_.next(M_.next(h))) != h) return false;
        const VertexIndex a = M_.source(h), b = M_.target(h), c = M_.target(M_.next(h));
        const VProj &pa = vproj(a), &pb = vproj(b), &pc = vproj(c);
        if (!pa.ok || !pb.ok || !pc.ok || !leftTurn(pa.uv, pb.uv, pc.uv)) return false;
        const Vec3 A = toVec(M_.point(a)), B = toVec(M_.point(b)), C = toVec(M_.point(c));
        const Vec3 n = normalOf(A, B, C);
        if (!(n.norm() > 0)) return false;
        const double cosView = n.normalized().dot(V_.towardsViewer((A + B + C) / 3.0));
        *it = char(cosView >= std::cos(O_.maxViewAngleDeg * kDeg));
        return *it != 0;
    }
    std::array<VertexIndex, 3> faceVertices(FaceIndex f) const {
        const HalfedgeIndex h = M_.halfedge(f);
        return {M_.source(h), M_.target(h), M_.target(M_.next(h))};
    }
    Triangle2 faceTriangle(FaceIndex f) {
        const auto v = faceVertices(f);
        return {vproj(v[0]).uv, vproj(v[1]).uv, vproj(v[2]).uv};
    }
    // Distance from patch vertex point p to the plane of face f along p's view ray.
    double gapTo(const Vec3& p, FaceIndex f) const {
        const auto v = faceVertices(f);
        const Vec3 A = toVec(M_.point(v[0])), B = toVec(M_.point(v[1])), C = toVec(M_.point(v[2]));
        return gapToPlane(p, A, normalOf(A, B, C));
    }
    // Distance from p to the plane through A with normal n along p's view ray.
    double gapToPlane(const Vec3& p, const Vec3& A, const Vec3& n) const {
        Vec3 o, d;
        V_.rayThrough(p, o, d);
        const double den = n.dot(d);
        if (!(std::abs(den) > 0)) return std::numeric_limits<double>::infinity();
        const Vec3 q = o + d * (n.dot(A - o) / den);
        return (p - q).norm();
    }
    double longestEdge(FaceIndex f) const {
        const auto v = faceVertices(f);
        double l = 0;
        for (int k = 0; k < 3; ++k)
            l = std::max(l, std::sqrt(CGAL::squared_distance(M_.point(v[std::size_t(k)]),
                                                             M_.point(v[std::size_t((k + 1) % 3)]))));
        return l;
    }
    // The largest distance along view rays between the patch and a mesh face it belongs to.
    double gapTolerance(FaceIndex f) const { return O_.maxGapRatio * (longestEdge(f) + h3_); }
    // Does face f meet the component in the view (or come closer to it than snapping can move things), on
    // the same sheet: the patch triangles there lie on f's plane, not in front of it (an occluder) or
    // behind it (f occludes them)?
    bool meetsComponent(FaceIndex f) {
        const Triangle2 t = faceTriangle(f);
        const double r2 = margin_ * margin_;
        const double tolerance = gapTolerance(f);
        const auto fv = faceVertices(f);
        const Vec3 A = toVec(M_.point(fv[0]));
        const Vec3 n = normalOf(A, toVec(M_.point(fv[1])), toVec(M_.point(fv[2])));
        const CGAL::Bbox_2 box = grown(t.bbox(), margin_);
        bool hit = false;
        // Cheap tests first (this runs for every face under the patch): a patch triangle whose box misses
        // the face's box grown by the snapping distance is farther than that; the gaps along the view rays
        // need no triangle test; a corner of either triangle inside the other means they meet.
        compGrid_.query(box, [&](int i) {
            if (hit) return;
            const int pf = faces_[std::size_t(i)];
            if (!CGAL::do_overlap(box, triBox(pf))) return;
            bool onSheet = false;
            for (int v : P_.tri[std::size_t(pf)])
                if (gapToPlane(P_.pos[std::size_t(v)], A, n) <= tolerance) onSheet = true;
            if (!onSheet) return;
            const Triangle2 p = patchTriangle(pf);
            hit = inTriangle(p[0], t[0], t[1], t[2]) || inTriangle(t[0], p[0], p[1], p[2]) ||
                  CGAL::do_intersect(t, p) || CGAL::squared_distance(t, p) <= r2;
        });
        return hit;
    }
    // Distance along p's view ray from p to the patch surface at uv (infinite when uv is off the patch).
    double gapToPatch(const Vec3& p, const Point2& uv) {
        double gap = std::numeric_limits<double>::infinity();
        compGrid_.query(uv.bbox(), [&](int i) {
            const auto& tri = P_.tri[std::size_t(faces_[std::size_t(i)])];
            const Triangle2 t = patchTriangle(faces_[std::size_t(i)]);
            if (!inTriangle(uv, t[0], t[1], t[2])) return;
            const Vec3 &A = P_.pos[std::size_t(tri[0])], &B = P_.pos[std::size_t(tri[1])],
                       &C = P_.pos[std::size_t(tri[2])];
            const Vec3 n = normalOf(A, B, C);
            Vec3 o, d;
            V_.rayThrough(p, o, d);
            const double den = n.dot(d);
            if (!(std::abs(den) > 0)) return;
            gap = std::min(gap, (p - (o + d * (n.dot(A - o) / den))).norm());
        });
        return gap;
    }

    // ---- step 1: the region under the component
    void candidatesAt(const Point2& uv, std::vector<FaceIndex>& out) {
        out.clear();
        if (!ids_.empty()) {
            const int W = V_.camera().width, H = V_.camera().height;
            const int px = int(std::floor(uv.x())), py = int(std::floor(-uv.y()));
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int x = px + dx, y = py + dy;
                    if (x < 0 || y < 0 || x >= W || y >= H) continue;
                    const std::uint32_t id = ids_[std::size_t(y) * std::size_t(W) + std::size_t(x)];
                    if (id == kNone) continue;
                    const FaceIndex f(id);
                    if (!M_.has_valid_index(f) || M_.is_removed(f)) continue;
                    if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
                }
            return;
        }
        if (!fallbackBuilt_) buildFallback();
        fallbackGrid_.query(uv.bbox(), [&](int i) { out.push_back(fallback_[std::size_t(i)]); });
    }
    // O(mesh): all faces whose view bounding box meets the component's.
    void buildFallback() {
        fallbackBuilt_ = true;
        const CGAL::Bbox_2 box = grown(compBox_, 2.0 * h2_);
        std::vector<CGAL::Bbox_2> boxes;
        for (FaceIndex f : M_.faces()) {
            const HalfedgeIndex h = M_.halfedge(f);
            Point2 uv[3];
            double w;
            bool ok = true;
            int k = 0;
            for (VertexIndex v : CGAL::vertices_around_face(h, M_)) {
                if (k == 3 || !V_.project(toVec(M_.point(v)), uv[k], w)) {
                    ok = false;
                    break;
                }
                ++k;
            }
            if (!ok || k != 3) continue;
            const CGAL::Bbox_2 fb = bboxOf(uv[0], uv[1], uv[2]);
            if (!CGAL::do_overlap(fb, box) || !leftTurn(uv[0], uv[1], uv[2])) continue;
            fallback_.push_back(f);
            boxes.push_back(fb);
        }
        const double cell =
            std::max(4.0 * h2_, std::max(box.xmax() - box.xmin(), box.ymax() - box.ymin()) / 64.0);
        fallbackGrid_ = BucketGrid(cell, fallback_.size());
        for (std::size_t i = 0; i < fallback_.size(); ++i)
            fallbackGrid_.insert(int(i), boxes[i]);
    }
    bool findRegion(Attempt& a) {
        // Seeds: under every boundary vertex and a sample of the interior, the acceptable face containing
        // the vertex in the view whose plane is nearest to it along the view ray.
        std::vector<int> samples(boundary_.begin(), boundary_.end());
        std::sort(samples.begin(), samples.end());
        {
            std::vector<int> interior;
            for (int v : compVerts_)
                if (!boundary_.count(v)) interior.push_back(v);
            std::sort(interior.begin(), interior.end());
            const std::size_t stride = std::max<std::size_t>(1, interior.size() / 2048);
            for (std::size_t i = 0; i < interior.size(); i += stride)
                samples.push_back(interior[i]);
        }
        std::vector<FaceIndex> seeds, cands;
        for (int pass = 0; pass < 2 && seeds.empty(); ++pass) {
            if (pass == 1) {
                if (ids_.empty()) break;
                ids_ = {}; // the ID buffer found nothing valid (stale after earlier components): fall back
            }
            for (int v : samples) {
                progress_.tick();
                const Point2& uv = P_.uv[std::size_t(v)];
                candidatesAt(uv, cands);
                FaceIndex best;
                double bestGap = std::numeric_limits<double>::infinity();
                for (FaceIndex f : cands) {
                    if (!acceptable(f)) continue;
                    const Triangle2 t = faceTriangle(f);
                    if (!inTriangle(uv, t[0], t[1], t[2])) continue;
                    const double g = gapTo(P_.pos[std::size_t(v)], f);
                    if (g < bestGap) {
                        bestGap = g;
                        best = f;
                    }
                }
                if (best != FaceIndex()) seeds.push_back(best);
            }
        }
        if (seeds.empty()) return fail(a, "no visible face of the mesh lies under it in the scan's view");
        // Grow over faces sharing a vertex, keeping the acceptable ones that meet the component in the view.
        IndexSet visited;
        std::vector<FaceIndex> stack;
        for (FaceIndex f : seeds)
            if (visited.insert(std::uint32_t(f))) stack.push_back(f);
        while (!stack.empty()) {
            const FaceIndex f = stack.back();
            stack.pop_back();
            progress_.tick();
            if (!acceptable(f) || !meetsComponent(f)) continue;
            regionIndex_[std::uint32_t(f)] = int(region_.size());
            region_.push_back(f);
            for (VertexIndex v : faceVertices(f))
                for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_))
                    if (g != Mesh::null_face() && visited.insert(std::uint32_t(g))) stack.push_back(g);
        }
        if (region_.empty()) return fail(a, "no visible face of the mesh lies under it in the scan's view");
        return true;
    }

    // ---- step 1b: every patch vertex must lie over the region (else trim there)
    bool preTrim(Attempt& a) {
        double edge = 0;
        for (FaceIndex f : region_) {
            const Triangle2 t = faceTriangle(f);
            edge += std::sqrt(dist2(t[0], t[1]));
        }
        edge /= double(region_.size());
        regionGrid_ = BucketGrid(std::max(2.0 * h2_, edge), region_.size());
        for (std::size_t i = 0; i < region_.size(); ++i)
            regionGrid_.insert(int(i), faceTriangle(region_[i]).bbox());
        std::vector<int> bad;
        for (int v : compVerts_) {
            progress_.tick();
            const Point2& uv = P_.uv[std::size_t(v)];
            bool inside = false;
            regionGrid_.query(uv.bbox(), [&](int i) {
                if (inside) return;
                const Triangle2 t = faceTriangle(region_[std::size_t(i)]);
                inside = inTriangle(uv, t[0], t[1], t[2]);
            });
            if (!inside) bad.push_back(v);
        }
        if (!bad.empty()) return fail(a, "it reaches past the visible part of the mesh", std::move(bad));
        return true;
    }

    // ---- step 1c: seam faces (near the patch boundary: re-triangulated in the view) and faces under the
    // patch (removed whole, whatever their orientation, so folds under the patch go too)
    bool insidePatch(const Point2& p) {
        bool in = false;
        compGrid_.query(p.bbox(), [&](int i) {
            if (in) return;
            const Triangle2 t = patchTriangle(faces_[std::size_t(i)]);
            in = inTriangle(p, t[0], t[1], t[2]);
        });
        return in;
    }
    // Do the interiors of two (counter-clockwise) faces overlap in the view? Separating-axis test on
    // their edges with exact orientations: disjoint interiors iff one triangle lies on the closed outer
    // side of an edge of the other.
    bool interiorsOverlap(FaceIndex f, FaceIndex g) {
        const Triangle2 s = faceTriangle(f), t = faceTriangle(g);
        for (const auto& [x, y] : {std::pair{&s, &t}, std::pair{&t, &s}})
            for (int k = 0; k < 3; ++k) {
                const Point2 &p = (*x)[k], &q = (*x)[(k + 1) % 3];
                if (CGAL::orientation(p, q, (*y)[0]) != CGAL::LEFT_TURN &&
                    CGAL::orientation(p, q, (*y)[1]) != CGAL::LEFT_TURN &&
                    CGAL::orientation(p, q, (*y)[2]) != CGAL::LEFT_TURN)
                    return false;
            }
        return true;
    }
    // A point inside the overlap of two counter-clockwise triangles (centre of s clipped by t).
    static Point2 overlapCentre(const Triangle2& s, const Triangle2& t) {
        std::vector<Point2> poly{s[0], s[1], s[2]};
        for (int k = 0; k < 3 && !poly.empty(); ++k) {
            const Point2 &a = t[k], &b = t[(k + 1) % 3];
            std::vector<Point2> out;
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const Point2 &p = poly[i], &q = poly[(i + 1) % poly.size()];
                const double dp = area2(a, b, p), dq = area2(a, b, q);
                if (dp >= 0) out.push_back(p);
                if ((dp >= 0) != (dq >= 0)) {
                    const double u = dp / (dp - dq);
                    out.emplace_back(p.x() + u * (q.x() - p.x()), p.y() + u * (q.y() - p.y()));
                }
            }
            poly.swap(out);
        }
        if (poly.empty()) return CGAL::centroid(s);
        double x = 0, y = 0;
        for (const Point2& p : poly) {
            x += p.x();
            y += p.y();
        }
        return {x / double(poly.size()), y / double(poly.size())};
    }
    // Distance from the eye (along the view direction) of face f's plane at view position q.
    double depthAt(FaceIndex f, const Point2& q) const {
        const Ray ray = V_.camera().ray(q.x(), -q.y());
        const auto v = faceVertices(f);
        const Vec3 A = toVec(M_.point(v[0])), n = normalOf(A, toVec(M_.point(v[1])), toVec(M_.point(v[2])));
        const double den = n.dot(ray.direction);
        if (!(std::abs(den) > 0)) return std::numeric_limits<double>::infinity();
        return V_.camera().viewDepth(ray.origin + ray.direction * (n.dot(A - ray.origin) / den));
    }
    bool splitRegion(Attempt& a) {
        BucketGrid segments(2.0 * h2_, pedges_.size());
        for (std::size_t i = 0; i < pedges_.size(); ++i)
            segments.insert(int(i),
                            bboxOf(P_.uv[std::size_t(pedges_[i].a)], P_.uv[std::size_t(pedges_[i].b)]));
        const double reach2 = margin_ * margin_; // the snapping distance
        std::vector<FaceIndex> seam;
        std::vector<FaceIndex> stack;
        IndexSet isSeam, isInterior;
        for (FaceIndex f : region_) {
            progress_.tick();
            const Triangle2 t = faceTriangle(f);
            bool near = false;
            segments.query(grown(t.bbox(), margin_), [&](int i) {
                if (near) return;
                const Segment2 e(P_.uv[std::size_t(pedges_[std::size_t(i)].a)],
                                 P_.uv[std::size_t(pedges_[std::size_t(i)].b)]);
                near = CGAL::do_intersect(t, e) || CGAL::squared_distance(t, e) <= reach2;
            });
            if (near) {
                seam.push_back(f);
                isSeam.insert(std::uint32_t(f));
            } else if (insidePatch(CGAL::centroid(t))) {
                isInterior.insert(std::uint32_t(f));
                stack.push_back(f);
            }
        }
        std::vector<int> bad;
        // Folds: front-facing faces overlapping in the view (a step of the mesh seen obliquely). Under the
        // patch they are simply replaced; where the patch boundary crosses them there is no height field
        // to cut, so the patch is cut back around every fold that reaches its boundary.
        {
            detail::DisjointSets clusters(region_.size());
            auto find = [&](int x) { return int(clusters.find(std::size_t(x))); };
            std::vector<char> folded(region_.size(), 0), hidden(region_.size(), 0);
            // Only the clusters of overlapping faces that reach a seam face matter: found by a flood over
            // overlaps from the seam faces (work proportional to the seam and its folds, not to the faces
            // under the patch).
            std::vector<char> reached(region_.size(), 0);
            std::vector<std::size_t> todo;
            for (std::size_t i = 0; i < region_.size(); ++i)
                if (isSeam.count(std::uint32_t(region_[i]))) {
                    reached[i] = 1;
                    todo.push_back(i);
                }
            while (!todo.empty()) {
                const std::size_t i = todo.back();
                todo.pop_back();
                progress_.tick();
                regionGrid_.query(faceTriangle(region_[i]).bbox(), [&](int jj) {
                    const std::size_t j = std::size_t(jj);
                    if (j == i) return;
                    // Each pair in the order (lower, higher index), as a scan over all pairs would.
                    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
                    if (!interiorsOverlap(region_[lo], region_[hi])) return;
                    folded[lo] = folded[hi] = 1;
                    clusters.unite(lo, hi);
                    // The one farther from the eye where they overlap is hidden there.
                    const Point2 q = overlapCentre(faceTriangle(region_[lo]), faceTriangle(region_[hi]));
                    hidden[depthAt(region_[lo], q) > depthAt(region_[hi], q) ? lo : hi] = 1;
                    if (!reached[j]) {
                        reached[j] = 1;
                        todo.push_back(j);
                    }
                });
            }
            std::unordered_map<int, bool> clusterAtSeam;
            for (std::size_t i = 0; i < region_.size(); ++i)
                if (folded[i] && isSeam.count(std::uint32_t(region_[i]))) clusterAtSeam[find(int(i))] = true;
            // Cut the patch back around the hidden faces, where it lies on their sheet; if that frees
            // nothing, around the whole fold.
            // (Peeling: only the patch triangles within snapping distance; the next round sees what is left.)
            const double r = O_.peelTrim ? margin_ : margin_ + h2_;
            for (int pass = 0; pass < 2 && bad.empty(); ++pass)
                for (std::size_t i = 0; i < region_.size(); ++i) {
                    if (!folded[i] || !clusterAtSeam.count(find(int(i))) || (pass == 0 && !hidden[i]))
                        continue;
                    const FaceIndex g = region_[i];
                    const Triangle2 t = faceTriangle(g);
                    const double tolerance = gapTolerance(g);
                    compGrid_.query(grown(t.bbox(), r), [&](int k) {
                        const auto& tri = P_.tri[std::size_t(faces_[std::size_t(k)])];
                        const Triangle2 p = patchTriangle(faces_[std::size_t(k)]);
                        if (!CGAL::do_intersect(t, p) && CGAL::squared_distance(t, p) > r * r) return;
                        bool onSheet = pass == 1;
                        for (int v : tri)
                            onSheet = onSheet || gapTo(P_.pos[std::size_t(v)], g) <= tolerance;
                        if (onSheet) bad.insert(bad.end(), tri.begin(), tri.end());
                    });
                }
            if (!bad.empty())
                return fail(a, "the mesh under its boundary folds over itself in the scan's view",
                            std::move(bad));
        }
        // Faces connected to the interior ones, away from the seam, lying under the patch in the view.
        IndexMap<double> gapOfVertex;
        while (!stack.empty()) {
            const FaceIndex f = stack.back();
            stack.pop_back();
            progress_.tick();
            interior_.push_back(f);
            for (HalfedgeIndex h : CGAL::halfedges_around_face(M_.halfedge(f), M_)) {
                const FaceIndex g = M_.face(M_.opposite(h));
                if (g == Mesh::null_face()) {
                    addNear(bad, vproj(M_.target(h)).uv); // the mesh's border under the patch
                    continue;
                }
                if (isSeam.count(std::uint32_t(g)) || isInterior.count(std::uint32_t(g))) continue;
                // Under the patch in the view, on its sheet (not a part of the mesh far behind or in front).
                bool under = true;
                const double tolerance = gapTolerance(g);
                for (VertexIndex v : CGAL::vertices_around_face(M_.halfedge(g), M_)) {
                    const VProj& p = vproj(v);
                    if (!p.ok) {
                        under = false;
                        continue;
                    }
                    // Each vertex is asked by every face around it: its gap is computed once.
                    auto [gap, fresh] = gapOfVertex.try_emplace(std::uint32_t(v), 0.0);
                    if (fresh) *gap = gapToPatch(toVec(M_.point(v)), p.uv);
                    if (!(*gap <= tolerance)) under = false;
                }
                if (!under) {
                    addNear(bad,
                            vproj(M_.target(h)).uv); // a face reaching out without a seam: a fold, a hole
                    continue;
                }
                isInterior.insert(std::uint32_t(g));
                stack.push_back(g);
            }
        }
        if (!bad.empty())
            return fail(a, "the mesh under it folds or has a hole in the scan's view", std::move(bad));
        region_ = std::move(seam);
        regionIndex_.clear();
        for (std::size_t i = 0; i < region_.size(); ++i)
            regionIndex_[std::uint32_t(region_[i])] = int(i);
        if (region_.empty()) return fail(a, "no visible face of the mesh lies under its boundary");
        return true;
    }

    // ---- step 2: local vertices, snapping, crossings
    int addLocal(LVert l) {
        L_.push_back(l);
        return int(L_.size()) - 1;
    }
    int regionVertex(VertexIndex v) {
        auto [it, fresh] = lidOfCurrent_.try_emplace(std::uint32_t(v), -1);
        if (fresh) {
            LVert l;
            l.kind = LVert::Region;
            l.cur = std::uint32_t(v);
            l.pos = toVec(M_.point(v));
            l.uv = vproj(v).uv;
            it->second = addLocal(l);
        }
        return it->second;
    }
    void buildLocalVertices() {
        for (FaceIndex f : region_) {
            const HalfedgeIndex h0 = M_.halfedge(f);
            HalfedgeIndex h = h0;
            do {
                regionVertex(M_.target(h));
                h = M_.next(h);
            } while (h != h0);
        }
        for (FaceIndex f : region_) {
            const HalfedgeIndex h0 = M_.halfedge(f);
            HalfedgeIndex h = h0;
            do {
                const EdgeIndex e = M_.edge(h);
                if (!redgeIndex_.count(std::uint32_t(e))) {
                    const HalfedgeIndex he = M_.halfedge(e);
                    redgeIndex_[std::uint32_t(e)] = int(redges_.size());
                    redges_.push_back({regionVertex(M_.source(he)), regionVertex(M_.target(he)), e, {}, {}});
                }
                h = M_.next(h);
            } while (h != h0);
        }
        std::vector<int> bverts(boundary_.begin(), boundary_.end());
        std::sort(bverts.begin(), bverts.end());
        for (int v : bverts) {
            LVert l;
            l.kind = LVert::PatchBoundary;
            l.patchA = v;
            l.chain = true;
            l.pos = P_.pos[std::size_t(v)];
            l.uv = P_.uv[std::size_t(v)];
            lidOfPatch_[v] = addLocal(l);
        }
    }
    // Would the patch faces around patch vertex v stay counter-clockwise if v moved to uv?
    bool patchStaysValid(int v, const Point2& uv) const {
        for (int f : vertexFaces_.at(v)) {
            const auto& t = P_.tri[std::size_t(f)];
            Point2 q[3];
            for (int k = 0; k < 3; ++k)
                q[k] = t[std::size_t(k)] == v ? uv : L_uvOfPatch(t[std::size_t(k)]);
            if (!leftTurn(q[0], q[1], q[2])) return false;
        }
        return true;
    }
    // Current view position of a patch vertex (moved by snapping when on the boundary).
    Point2 L_uvOfPatch(int v) const {
        auto it = lidOfPatch_.find(v);
        return it == lidOfPatch_.end() ? P_.uv[std::size_t(v)] : L_[std::size_t(it->second)].uv;
    }
    // Current 3D position of a patch vertex (moved by snapping when on the boundary).
    const Vec3& posOfPatch(int v) const {
        auto it = lidOfPatch_.find(v);
        return it == lidOfPatch_.end() ? P_.pos[std::size_t(v)] : L_[std::size_t(it->second)].pos;
    }
    // Lift a point at 2D parameter s of region edge re onto the 3D mesh edge.
    void liftOnEdge(int re, double s, Vec3& pos, Point2& uv) {
        const int u = redges_[std::size_t(re)].u, w = redges_[std::size_t(re)].w;
        const VProj &pu = vproj(VertexIndex(L_[std::size_t(u)].cur)),
                    &pw = vproj(VertexIndex(L_[std::size_t(w)].cur));
        const double t = View::perspectiveParam(s, pu.w, pw.w);
        pos = L_[std::size_t(u)].pos + t * (L_[std::size_t(w)].pos - L_[std::size_t(u)].pos);
        double wq;
        if (!V_.project(pos, uv, wq))
            uv = Point2(pu.uv.x() + s * (pw.uv.x() - pu.uv.x()), pu.uv.y() + s * (pw.uv.y() - pu.uv.y()));
    }
    // A region edge may be split when both its faces are region faces (never a border edge).
    bool splittable(int re) const {
        const HalfedgeIndex h = M_.halfedge(redges_[std::size_t(re)].edge);
        for (HalfedgeIndex g : {h, M_.opposite(h)})
            if (M_.is_border(g) || !regionIndex_.count(std::uint32_t(M_.face(g)))) return false;
        return true;
    }
    // The face beyond region edge re when exactly one of its faces is a region face and the other is a
    // triangle of the mesh that stays (not under the patch); else null.
    FaceIndex outerFace(int re, const std::unordered_set<std::uint32_t>& interior) const {
        const HalfedgeIndex h = M_.halfedge(redges_[std::size_t(re)].edge);
        FaceIndex outer;
        int inRegion = 0;
        for (HalfedgeIndex g : {h, M_.opposite(h)}) {
            if (M_.is_border(g)) return FaceIndex();
            const FaceIndex f = M_.face(g);
            if (regionIndex_.count(std::uint32_t(f)))
                ++inRegion;
            else
                outer = f;
        }
        if (inRegion != 1 || interior.count(std::uint32_t(outer))) return FaceIndex();
        if (M_.next(M_.next(M_.next(M_.halfedge(outer)))) != M_.halfedge(outer)) return FaceIndex();
        return outer;
    }
    void snap() {
        const double cell = 2.0 * h2_;
        // Snapping distances are a fraction of the local edge lengths on both sides, so that snapped
        // points keep their order and no triangle folds.
        std::vector<double> regionEdgeMin(L_.size(), std::numeric_limits<double>::infinity());
        for (const auto& re : redges_) {
            const double l = std::sqrt(dist2(L_[std::size_t(re.u)].uv, L_[std::size_t(re.w)].uv));
            for (int v : {re.u, re.w})
                regionEdgeMin[std::size_t(v)] = std::min(regionEdgeMin[std::size_t(v)], l);
        }
        const double ratio = O_.collapseEdgeRatio;
        // Rule 1: a patch boundary vertex close to a mesh vertex becomes that vertex.
        {
            BucketGrid grid(cell, L_.size());
            for (std::size_t i = 0; i < L_.size(); ++i)
                if (L_[i].kind == LVert::Region) grid.insert(int(i), L_[i].uv.bbox());
            struct Cand {
                double d;
                int patch, lid;
            };
            std::vector<Cand> cands;
            for (const auto& [v, lid] : lidOfPatch_) {
                const double r = snapRadius_.at(v);
                const Point2 uv = L_[std::size_t(lid)].uv;
                grid.query(grown(uv.bbox(), r), [&](int i) {
                    const double d = std::sqrt(dist2(uv, L_[std::size_t(i)].uv));
                    if (d < std::min(r, ratio * regionEdgeMin[std::size_t(i)])) cands.push_back({d, v, i});
                });
            }
            std::sort(cands.begin(), cands.end(), [](const Cand& x, const Cand& y) {
                return x.d != y.d ? x.d < y.d : (x.patch != y.patch ? x.patch < y.patch : x.lid < y.lid);
            });
            std::unordered_set<int> usedPatch, usedRegion;
            for (const Cand& c : cands) {
                if (usedPatch.count(c.patch) || usedRegion.count(c.lid)) continue;
                if (!patchStaysValid(c.patch, L_[std::size_t(c.lid)].uv)) continue;
                usedPatch.insert(c.patch);
                usedRegion.insert(c.lid);
                const int old = lidOfPatch_.at(c.patch);
                L_[std::size_t(old)].alive = false;
                lidOfPatch_[c.patch] = c.lid;
                L_[std::size_t(c.lid)].patchA = c.patch;
                L_[std::size_t(c.lid)].chain = true;
            }
        }
        // Rule 2: a patch boundary vertex close to a mesh edge moves onto it (an edge split). On an edge at
        // the region's rim (typically a crease whose other face the view does not see) the other face is
        // split along that edge too.
        {
            const std::unordered_set<std::uint32_t> interior = [&] {
                std::unordered_set<std::uint32_t> out;
                for (FaceIndex f : interior_)
                    out.insert(std::uint32_t(f));
                return out;
            }();
            BucketGrid grid(cell, redges_.size());
            for (std::size_t i = 0; i < redges_.size(); ++i)
                grid.insert(int(i),
                            bboxOf(L_[std::size_t(redges_[i].u)].uv, L_[std::size_t(redges_[i].w)].uv));
            std::vector<int> verts;
            for (const auto& [v, lid] : lidOfPatch_)
                if (L_[std::size_t(lid)].kind == LVert::PatchBoundary) verts.push_back(v);
            std::sort(verts.begin(), verts.end());
            for (int v : verts) {
                const int lid = lidOfPatch_.at(v);
                const double r = snapRadius_.at(v);
                const Point2 uv = L_[std::size_t(lid)].uv;
                int best = -1;
                double bestD = r, bestS = 0;
                grid.query(grown(uv.bbox(), r), [&](int i) {
                    double s;
                    const Point2 &U = L_[std::size_t(redges_[std::size_t(i)].u)].uv,
                                 &W = L_[std::size_t(redges_[std::size_t(i)].w)].uv;
                    const double d = segmentDistance(uv, U, W, s);
                    if (d < bestD && d < ratio * std::sqrt(dist2(U, W)) && s > 1e-3 && s < 1 - 1e-3) {
                        bestD = d;
                        best = i;
                        bestS = s;
                    }
                });
                if (best < 0) continue;
                const FaceIndex outer = splittable(best) ? FaceIndex() : outerFace(best, interior);
                if (!splittable(best) && outer == FaceIndex()) continue;
                Vec3 pos;
                Point2 q;
                liftOnEdge(best, bestS, pos, q);
                if (!patchStaysValid(v, q)) continue;
                if (outer != FaceIndex()) {
                    // Its two pieces must pass the stitch's angle floor (else the patch keeps its place) ...
                    const auto ov = faceVertices(outer);
                    const Vec3 A = toVec(M_.point(ov[0])), B = toVec(M_.point(ov[1])),
                               C = toVec(M_.point(ov[2]));
                    const REdge& r = redges_[std::size_t(best)];
                    const Vec3 D = A + B + C - L_[std::size_t(r.u)].pos - L_[std::size_t(r.w)].pos;
                    // Its neighbours along the edge: the edge's ends or vertices snapped onto it before.
                    const double sq = lineParam(q, L_[std::size_t(r.u)].uv, L_[std::size_t(r.w)].uv);
                    double below = 0, above = 1;
                    Vec3 U = L_[std::size_t(r.u)].pos, W = L_[std::size_t(r.w)].pos;
                    for (const auto& [sp, other] : r.splits) {
                        if (sp <= sq && sp >= below) {
                            below = sp;
                            U = L_[std::size_t(other)].pos;
                        }
                        if (sp > sq && sp <= above) {
                            above = sp;
                            W = L_[std::size_t(other)].pos;
                        }
                    }
                    const double floor =
                        std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                 0.999 * minAngle(A, B, C));
                    // ... and be no worse than the sliver the snap avoids (up to the needle angle).
                    const double fan = std::min(minAngle(U, pos, D), minAngle(pos, W, D));
                    if (fan < floor ||
                        fan < std::min(minAngle(U, P_.pos[std::size_t(v)], W), kNeedleDeg * kDeg))
                        continue;
                    // At most one split edge per outer face (it becomes a fan from the opposite corner).
                    auto [it, fresh] = outerSplits_.try_emplace(std::uint32_t(outer), best);
                    if (!fresh && it->second != best) continue;
                    L_[std::size_t(lid)].onOuterEdge = true;
                }
                LVert& l = L_[std::size_t(lid)];
                l.pos = pos;
                l.uv = q;
                l.edgeU = redges_[std::size_t(best)].u;
                l.edgeW = redges_[std::size_t(best)].w;
                redges_[std::size_t(best)].splits.push_back(
                    {lineParam(q, L_[std::size_t(redges_[std::size_t(best)].u)].uv,
                               L_[std::size_t(redges_[std::size_t(best)].w)].uv),
                     lid});
            }
        }
        // Rule 3: a mesh vertex close to a patch boundary edge splits that edge. The closest go first; a
        // vertex is taken when the patch triangle on the edge stays a fan of counter-clockwise triangles.
        {
            BucketGrid grid(cell, pedges_.size());
            for (std::size_t i = 0; i < pedges_.size(); ++i)
                grid.insert(int(i), bboxOf(L_uvOfPatch(pedges_[i].a), L_uvOfPatch(pedges_[i].b)));
            struct Cand {
                double d, s;
                int lid;
            };
            std::vector<std::vector<Cand>> cands(pedges_.size());
            for (std::size_t i = 0; i < L_.size(); ++i) {
                const LVert& l = L_[i];
                if (l.kind != LVert::Region || l.chain) continue;
                int best = -1;
                double bestRel = 1, bestS = 0, bestD = 0;
                grid.query(grown(l.uv.bbox(), margin_), [&](int e) {
                    const auto& pe = pedges_[std::size_t(e)];
                    const int la = lidOfPatch_.at(pe.a), lb = lidOfPatch_.at(pe.b);
                    if (la == int(i) || lb == int(i)) return;
                    const Point2 &A = L_[std::size_t(la)].uv, &B = L_[std::size_t(lb)].uv;
                    double s;
                    const double d = segmentDistance(l.uv, A, B, s);
                    const double rel = d / (ratio * std::sqrt(dist2(A, B)));
                    if (rel < bestRel && s > 1e-3 && s < 1 - 1e-3) {
                        bestRel = rel;
                        best = e;
                        bestS = s;
                        bestD = d;
                    }
                });
                if (best >= 0) cands[std::size_t(best)].push_back({bestD, bestS, int(i)});
            }
            for (std::size_t e = 0; e < pedges_.size(); ++e) {
                auto& cs = cands[e];
                if (cs.empty()) continue;
                std::sort(cs.begin(), cs.end(), [](const Cand& x, const Cand& y) {
                    return x.d != y.d ? x.d < y.d : x.lid < y.lid;
                });
                auto& pe = pedges_[e];
                const Point2 A = L_uvOfPatch(pe.a), B = L_uvOfPatch(pe.b), C = L_uvOfPatch(pe.opposite);
                const Vec3 A3 = posOfPatch(pe.a), B3 = posOfPatch(pe.b), C3 = posOfPatch(pe.opposite);
                // The floor the final check applies to the pieces of this patch triangle.
                const double floor =
                    std::min(O_.minAngleFloorDeg * kDeg,
                             0.999 * minAngle(P_.pos[std::size_t(pe.a)], P_.pos[std::size_t(pe.b)],
                                              P_.pos[std::size_t(pe.opposite)]));
                std::vector<std::pair<double, int>> taken; // sorted by s
                for (const Cand& c : cs) {
                    const auto pos = std::lower_bound(taken.begin(), taken.end(), std::pair{c.s, -1});
                    const Point2 prev = pos == taken.begin() ? A : L_[std::size_t(std::prev(pos)->second)].uv;
                    const Point2 next = pos == taken.end() ? B : L_[std::size_t(pos->second)].uv;
                    const Point2& v = L_[std::size_t(c.lid)].uv;
                    if (!leftTurn(prev, v, C) || !leftTurn(v, next, C)) continue;
                    if (!(lineParam(v, prev, next) > 0 && lineParam(v, prev, next) < 1)) continue;
                    // The fan's pieces must pass the final check's angle floor in 3D: a mesh vertex in line
                    // with the patch triangle's other corners (a patch vertex snapped onto a mesh edge
                    // through it) would leave a needle no triangulation of that triangle avoids.
                    const Vec3& prev3 =
                        pos == taken.begin() ? A3 : L_[std::size_t(std::prev(pos)->second)].pos;
                    const Vec3& next3 = pos == taken.end() ? B3 : L_[std::size_t(pos->second)].pos;
                    const Vec3& v3 = L_[std::size_t(c.lid)].pos;
                    if (minAngle(prev3, v3, C3) < floor || minAngle(v3, next3, C3) < floor) continue;
                    taken.insert(pos, {c.s, c.lid});
                }
                for (const auto& [sp, lid] : taken) {
                    pe.splits.push_back({sp, lid});
                    LVert& l = L_[std::size_t(lid)];
                    l.chain = true;
                    l.patchA = pe.a;
                    l.patchB = pe.b;
                }
            }
        }
    }
    // Polyline (local ids) of a region edge or a patch boundary edge with its splits, sorted.
    static std::vector<int> polyline(int from, int to, std::vector<std::pair<double, int>> splits) {
        std::sort(splits.begin(), splits.end());
        std::vector<int> out{from};
        for (const auto& s : splits)
            if (s.second != out.back()) out.push_back(s.second);
        if (to != out.back()) out.push_back(to);
        return out;
    }
    bool computeCrossings(Attempt& a) {
        struct Sub {
            int p, q, owner;
        };
        std::vector<Sub> rsubs, psubs;
        for (std::size_t i = 0; i < redges_.size(); ++i) {
            const auto pl = polyline(redges_[i].u, redges_[i].w, redges_[i].splits);
            for (std::size_t k = 0; k + 1 < pl.size(); ++k)
                rsubs.push_back({pl[k], pl[k + 1], int(i)});
        }
        for (std::size_t i = 0; i < pedges_.size(); ++i) {
            const auto pl =
                polyline(lidOfPatch_.at(pedges_[i].a), lidOfPatch_.at(pedges_[i].b), pedges_[i].splits);
            for (std::size_t k = 0; k + 1 < pl.size(); ++k)
                psubs.push_back({pl[k], pl[k + 1], int(i)});
        }
        BucketGrid grid(2.0 * h2_, rsubs.size());
        for (std::size_t i = 0; i < rsubs.size(); ++i)
            grid.insert(int(i), bboxOf(L_[std::size_t(rsubs[i].p)].uv, L_[std::size_t(rsubs[i].q)].uv));
        std::vector<int> bad;
        for (const Sub& ps : psubs) {
            const Point2 P = L_[std::size_t(ps.p)].uv, Q = L_[std::size_t(ps.q)].uv;
            grid.query(bboxOf(P, Q), [&](int ri) {
                const Sub& rs = rsubs[std::size_t(ri)];
                if (rs.p == ps.p || rs.p == ps.q || rs.q == ps.p || rs.q == ps.q) return;
                const Point2 R = L_[std::size_t(rs.p)].uv, S = L_[std::size_t(rs.q)].uv;
                const auto o1 = CGAL::orientation(P, Q, R), o2 = CGAL::orientation(P, Q, S);
                const auto o3 = CGAL::orientation(R, S, P), o4 = CGAL::orientation(R, S, Q);
                if (o1 != CGAL::COLLINEAR && o2 != CGAL::COLLINEAR && o3 != CGAL::COLLINEAR &&
                    o4 != CGAL::COLLINEAR) {
                    if (o1 == o2 || o3 == o4) return; // no crossing
                    // Proper crossing: intersection in the view, then lifted onto the 3D mesh edge.
                    const double d = area2(Point2(0, 0), Point2(Q.x() - P.x(), Q.y() - P.y()),
                                           Point2(S.x() - R.x(), S.y() - R.y()));
                    const double t = area2(Point2(0, 0), Point2(R.x() - P.x(), R.y() - P.y()),
                                           Point2(S.x() - R.x(), S.y() - R.y())) /
                                     d;
                    const Point2 X(P.x() + t * (Q.x() - P.x()), P.y() + t * (Q.y() - P.y()));
                    auto& re = redges_[std::size_t(rs.owner)];
                    const double s = std::clamp(
                        lineParam(X, L_[std::size_t(re.u)].uv, L_[std::size_t(re.w)].uv), 0.0, 1.0);
                    LVert l;
                    l.kind = LVert::Crossing;
                    l.chain = true;
                    auto& pe = pedges_[std::size_t(ps.owner)];
                    l.patchA = pe.a;
                    l.patchB = pe.b;
                    liftOnEdge(rs.owner, s, l.pos, l.uv);
                    l.edgeU = re.u;
                    l.edgeW = re.w;
                    const int id = addLocal(l);
                    re.splits.push_back(
                        {lineParam(l.uv, L_[std::size_t(re.u)].uv, L_[std::size_t(re.w)].uv), id});
                    pe.splits.push_back({lineParam(l.uv, L_uvOfPatch(pe.a), L_uvOfPatch(pe.b)), id});
                    return;
                }
                if (CGAL::do_intersect(Segment2(P, Q), Segment2(R, S))) {
                    // A contact that snapping did not resolve: trim the patch there.
                    bad.push_back(pedges_[std::size_t(ps.owner)].a);
                    bad.push_back(pedges_[std::size_t(ps.owner)].b);
                }
            });
        }
        if (!bad.empty())
            return fail(a, "its boundary touches mesh edges in a degenerate way", std::move(bad));
        for (auto& re : redges_)
            re.line = polyline(re.u, re.w, re.splits);
        for (auto& pe : pedges_)
            pe.line = polyline(lidOfPatch_.at(pe.a), lidOfPatch_.at(pe.b), pe.splits);
        return true;
    }

    // ---- step 2b: the constrained triangulation of the view
    bool triangulate(Cdt& cdt, std::vector<CdtVertex>& vh, Attempt& a) {
        vh.assign(L_.size(), CdtVertex());
        std::vector<int> order;
        for (std::size_t i = 0; i < L_.size(); ++i)
            if (L_[i].alive) order.push_back(int(i));
        std::vector<int> bad;
        CdtFace hint;
        std::size_t inserted = 0;
        for (int i : order) {
            progress_.tick();
            const CdtVertex v = cdt.insert(L_[std::size_t(i)].uv, hint);
            if (v->info().id >= 0) {
                addBad(bad, i);
                addBad(bad, v->info().id);
                continue;
            }
            ++inserted;
            v->info().id = i;
            vh[std::size_t(i)] = v;
            hint = v->face();
        }
        if (!bad.empty())
            return fail(a, "some of its boundary vertices coincide with mesh vertices in the view",
                        std::move(bad));
        auto constrain = [&](const std::vector<int>& line) {
            for (std::size_t k = 0; k + 1 < line.size(); ++k) {
                const std::size_t p = std::size_t(line[k]), q = std::size_t(line[k + 1]);
                progress_.tick();
                subEdges_.push_back({line[k], line[k + 1]});
                cdt.insert_constraint(vh[p], vh[q]);
            }
        };
        for (const auto& re : redges_)
            constrain(re.line);
        const std::size_t regionSubs = subEdges_.size();
        for (const auto& pe : pedges_)
            constrain(pe.line);
        if (cdt.number_of_vertices() != inserted) {
            for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
                if (v->info().id < 0) {
                    addNear(bad, v->point());
                }
            return fail(a, "it or the mesh under it overlaps itself in the scan's view", std::move(bad));
        }
        for (std::size_t k = 0; k < subEdges_.size(); ++k) {
            const auto [p, q] = subEdges_[k];
            CdtFace f;
            int i;
            if (!cdt.is_edge(vh[std::size_t(p)], vh[std::size_t(q)], f, i)) {
                addBad(bad, p);
                addBad(bad, q);
                continue;
            }
            (k < regionSubs ? regionSub_ : patchSub_).insert(edgeKey(std::uint32_t(p), std::uint32_t(q)));
        }
        if (!bad.empty())
            return fail(a, "its boundary passes exactly through mesh vertices in the view", std::move(bad));
        return true;
    }
    // The triangle to the left of the directed edge p → q of the triangulation.
    static CdtFace leftOf(const Cdt& cdt, CdtVertex p, CdtVertex q) {
        CdtFace f;
        int i;
        cdt.is_edge(p, q, f, i);
        return f->vertex(f->ccw(i)) == p ? f : f->neighbor(i);
    }
    std::uint64_t keyOf(CdtFace f, int i) const {
        return edgeKey(std::uint32_t(f->vertex(f->ccw(i))->info().id),
                       std::uint32_t(f->vertex(f->cw(i))->info().id));
    }
    // ---- step 3a: which region face and which side of the patch boundary every triangle lies in
    bool classify(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a) {
        std::vector<int> bad;
        std::vector<CdtFace> stack;
        for (std::size_t r = 0; r < region_.size(); ++r) {
            const auto vs = faceVertices(region_[r]);
            double covered = 0;
            for (int k = 0; k < 3; ++k) {
                const int u = lidOfCurrent_.at(std::uint32_t(vs[std::size_t(k)]));
                const HalfedgeIndex he = M_.halfedge(vs[std::size_t(k)], vs[std::size_t((k + 1) % 3)]);
                const auto& re = redges_[std::size_t(redgeIndex_.at(std::uint32_t(M_.edge(he))))];
                std::vector<int> line = re.line;
                if (line.front() != u) std::reverse(line.begin(), line.end());
                for (std::size_t j = 0; j + 1 < line.size(); ++j) {
                    const CdtFace f = leftOf(cdt, vh[std::size_t(line[j])], vh[std::size_t(line[j + 1])]);
                    if (f->info().region == int(r)) continue;
                    if (f->info().region >= 0 || cdt.is_infinite(f)) {
                        addNear(bad, L_[std::size_t(line[j])].uv);
                        continue;
                    }
                    stack.push_back(f);
                    while (!stack.empty()) {
                        const CdtFace g = stack.back();
                        stack.pop_back();
                        if (g->info().region == int(r)) continue;
                        if (g->info().region >= 0 || cdt.is_infinite(g)) {
                            addNear(bad, L_[std::size_t(line[j])].uv);
                            stack.clear();
                            break;
                        }
                        g->info().region = int(r);
                        covered += area2(g->vertex(0)->point(), g->vertex(1)->point(), g->vertex(2)->point());
                        for (int e = 0; e < 3; ++e)
                            if (!regionSub_.count(keyOf(g, e))) stack.push_back(g->neighbor(e));
                    }
                }
            }
            const Triangle2 t = faceTriangle(region_[r]);
            const double full = area2(t[0], t[1], t[2]);
            if (std::abs(covered - full) > 1e-7 * full) addNear(bad, CGAL::centroid(t));
        }
        if (!bad.empty())
            return fail(a, "the mesh under it overlaps itself in the scan's view", std::move(bad));
        // Inside / outside of the patch: the interior lies to the left of every boundary edge.
        std::vector<std::pair<CdtFace, std::int8_t>> fill;
        for (const auto& pe : pedges_)
            for (std::size_t j = 0; j + 1 < pe.line.size(); ++j) {
                const CdtVertex s = vh[std::size_t(pe.line[j])], t = vh[std::size_t(pe.line[j + 1])];
                fill.emplace_back(leftOf(cdt, s, t), std::int8_t(1));
                fill.emplace_back(leftOf(cdt, t, s), std::int8_t(0));
            }
        while (!fill.empty()) {
            const auto [f, side] = fill.back();
            fill.pop_back();
            if (f->info().inside == side) continue;
            if (f->info().inside >= 0) {
                if (!cdt.is_infinite(f))
                    addNear(bad, CGAL::centroid(cdt.triangle(f)));
                else
                    bad.push_back(-1);
                continue;
            }
            f->info().inside = side;
            for (int e = 0; e < 3; ++e)
                if (!patchSub_.count(keyOf(f, e))) fill.emplace_back(f->neighbor(e), side);
        }
        if (!bad.empty()) return fail(a, "it overlaps itself in the scan's view", std::move(bad));
        return true;
    }

    // ---- step 3b: the patch must lie strictly over the region, on the same sheet
    bool checkCoverage(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a) {
        std::vector<int> bad;
        for (std::size_t i = 0; i < L_.size(); ++i) {
            const LVert& l = L_[i];
            if (!l.alive || !l.chain) continue;
            const CdtVertex v = vh[i];
            bool uncovered = false;
            CdtFace under;
            auto fc = cdt.incident_faces(v), end = fc;
            do {
                // On an edge at the region's rim, the side beyond it is not the patch's (split separately).
                if (cdt.is_infinite(fc) || fc->info().region < 0) {
                    if (!l.onOuterEdge || fc->info().inside != 0) uncovered = true;
                } else {
                    under = fc;
                }
            } while (++fc != end);
            if (under == CdtFace()) uncovered = true;
            // Around a seam vertex inside mesh faces or on mesh edges, the seam faces must surround it.
            if (uncovered && l.kind != LVert::Region) addBad(bad, int(i));
            if (l.kind == LVert::PatchBoundary && !uncovered) {
                // The patch must lie on the surface under it (not on an occluder or another sheet).
                const FaceIndex f = region_[std::size_t(under->info().region)];
                if (gapTo(l.pos, f) > gapTolerance(f)) addBad(bad, int(i));
            }
        }
        if (!bad.empty())
            return fail(a, "it reaches past the visible, stitchable part of the mesh", std::move(bad));
        return true;
    }

    // ---- step 3c: the faces of the result (local ids)
    // Triangulates a polygon whose corners lie on the edges of one patch triangle, maximising the
    // smallest angle (dynamic programming over the polygon's chains; exact orientation tests).
    // `edges` holds for every corner the triangle edges it lies on (bit k: edge k): a diagonal between
    // two corners on the same edge would leave a triangle of collinear points, so it is never used.
    bool triangulatePolygon(const std::vector<int>& poly, const std::vector<unsigned>& edges, float q,
                            std::int32_t sid, double floor) {
        const std::size_t n = poly.size();
        auto P = [&](std::size_t i) -> const Point2& { return L_[std::size_t(poly[i])].uv; };
        auto X = [&](std::size_t i) -> const Vec3& { return L_[std::size_t(poly[i])].pos; };
        if (n == 3) {
            if (!leftTurn(P(0), P(1), P(2))) return false;
            newFaces_.push_back({{poly[0], poly[1], poly[2]}, q, sid, true, Vec3(0, 0, 0), floor, false});
            return true;
        }
        // diagonal[i][j]: the segment i–j lies inside the polygon and does not run along a triangle edge.
        std::vector<char> diagonal(n * n, 0);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = i + 1; j < n; ++j) {
                if (j == i + 1 || (i == 0 && j == n - 1)) {
                    diagonal[i * n + j] = diagonal[j * n + i] = 1;
                    continue;
                }
                if (edges[i] & edges[j]) continue;
                // Inside the cone of the polygon's corner at i.
                const Point2 &pi = P(i), &prev = P((i + n - 1) % n), &next = P((i + 1) % n), &pj = P(j);
                const bool convex = CGAL::orientation(prev, pi, next) != CGAL::RIGHT_TURN;
                const bool inCone = convex ? (leftTurn(pi, next, pj) && leftTurn(prev, pi, pj))
                                           : !(CGAL::orientation(pi, next, pj) != CGAL::LEFT_TURN &&
                                               CGAL::orientation(prev, pi, pj) != CGAL::LEFT_TURN);
                if (!inCone) continue;
                bool clear = true;
                const Segment2 d(pi, pj);
                for (std::size_t e = 0; e < n && clear; ++e) {
                    const std::size_t f = (e + 1) % n;
                    if (e == i || e == j || f == i || f == j) continue;
                    if (CGAL::do_intersect(d, Segment2(P(e), P(f)))) clear = false;
                }
                if (clear) diagonal[i * n + j] = diagonal[j * n + i] = 1;
            }
        // best[i][j]: best smallest angle triangulating the chain i..j closed by i–j (i < j).
        const double none = -1;
        std::vector<double> best(n * n, none);
        std::vector<std::size_t> split(n * n, 0);
        for (std::size_t i = 0; i + 1 < n; ++i)
            best[i * n + i + 1] = 4; // an edge: nothing to do
        for (std::size_t len = 2; len < n; ++len)
            for (std::size_t i = 0; i + len < n; ++i) {
                const std::size_t j = i + len;
                if (!diagonal[i * n + j]) continue;
                for (std::size_t k = i + 1; k < j; ++k) {
                    const double left = best[i * n + k], right = best[k * n + j];
                    if (left < 0 || right < 0 || !leftTurn(P(i), P(k), P(j))) continue;
                    const double v = std::min({left, right, minAngle(X(i), X(k), X(j))});
                    if (v > best[i * n + j]) {
                        best[i * n + j] = v;
                        split[i * n + j] = k;
                    }
                }
            }
        if (best[n - 1] < 0) return false;
        std::vector<std::pair<std::size_t, std::size_t>> stack{{0, n - 1}};
        while (!stack.empty()) {
            const auto [i, j] = stack.back();
            stack.pop_back();
            if (j == i + 1) continue;
            const std::size_t k = split[i * n + j];
            newFaces_.push_back({{poly[i], poly[k], poly[j]}, q, sid, true, Vec3(0, 0, 0), floor, false});
            stack.push_back({i, k});
            stack.push_back({k, j});
        }
        return true;
    }
    bool assemble(Cdt& cdt, Attempt& a) {
        replaced_ = interior_;
        // Region faces: unchanged when they are exactly one outside triangle, else replaced by their
        // outside triangles.
        std::vector<std::vector<CdtFace>> pieces(region_.size());
        double insideArea = 0;
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
            if (f->info().region >= 0) pieces[std::size_t(f->info().region)].push_back(f);
            if (f->info().inside == 1)
                insideArea += area2(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point());
        }
        for (std::size_t r = 0; r < region_.size(); ++r) {
            const auto vs = faceVertices(region_[r]);
            bool changed = pieces[r].size() != 1 || pieces[r][0]->info().inside != 0;
            if (!changed)
                for (int k = 0; k < 3; ++k) {
                    const int lid = pieces[r][0]->vertex(k)->info().id;
                    if (L_[std::size_t(lid)].kind != LVert::Region ||
                        std::find(vs.begin(), vs.end(), VertexIndex(L_[std::size_t(lid)].cur)) == vs.end())
                        changed = true;
                }
            if (!changed) continue;
            replaced_.push_back(region_[r]);
            const float q = curHasQuality_ ? curQuality_[region_[r]] : kInputFaceQuality;
            const std::int32_t sid = curHasScanId_ ? curScanId_[region_[r]] : -1;
            const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
            const Vec3 n = normalOf(A, B, C).normalized();
            const double floor = std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                          0.999 * minAngle(A, B, C));
            for (CdtFace f : pieces[r])
                if (f->info().inside == 0)
                    newFaces_.push_back(
                        {{f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id},
                         q,
                         sid,
                         false,
                         n,
                         floor,
                         false});
        }
        // Mesh faces outside the region whose edge got seam vertices (a patch boundary along a crease, the
        // face beyond it unseen): split along that edge in 3D, a fan from the opposite corner in the face's
        // own plane, so the patch boundary meets the crease without a sliver in front of it.
        for (const auto& [fi, re] : outerSplits_) {
            const FaceIndex face(fi);
            const REdge& r = redges_[std::size_t(re)];
            if (r.line.size() <= 2) continue;
            const HalfedgeIndex he = M_.halfedge(r.edge);
            const bool forward = M_.face(he) == face;
            std::vector<int> line = r.line; // from the source to the target of `he`
            if (!forward) std::reverse(line.begin(), line.end());
            const int apex = regionVertex(M_.target(M_.next(forward ? he : M_.opposite(he))));
            const auto vs = faceVertices(face);
            const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
            const double floor = std::min(std::max(O_.minAngleFloorDeg, O_.outsideMinAngleFloorDeg) * kDeg,
                                          0.999 * minAngle(A, B, C));
            replaced_.push_back(face);
            for (std::size_t k = 0; k + 1 < line.size(); ++k)
                newFaces_.push_back({{line[k], line[k + 1], apex},
                                     curHasQuality_ ? curQuality_[face] : kInputFaceQuality,
                                     curHasScanId_ ? curScanId_[face] : -1,
                                     false,
                                     normalOf(A, B, C).normalized(),
                                     floor,
                                     !acceptable(face)});
        }
        // Their other neighbours open to the seam optimisation too (flips in their planes), as themselves.
        {
            std::unordered_set<std::uint32_t> taken;
            for (FaceIndex f : replaced_)
                taken.insert(std::uint32_t(f));
            for (FaceIndex f : interior_)
                taken.insert(std::uint32_t(f));
            for (const auto& [fi, re] : outerSplits_) {
                if (redges_[std::size_t(re)].line.size() <= 2) continue;
                for (HalfedgeIndex h : CGAL::halfedges_around_face(M_.halfedge(FaceIndex(fi)), M_)) {
                    const FaceIndex g = M_.face(M_.opposite(h));
                    if (g == Mesh::null_face() || regionIndex_.count(std::uint32_t(g)) ||
                        !taken.insert(std::uint32_t(g)).second)
                        continue;
                    if (M_.next(M_.next(M_.next(M_.halfedge(g)))) != M_.halfedge(g)) continue;
                    openAsItself(g, !acceptable(g));
                }
            }
        }
        // The seam optimisation may also change the faces around the re-triangulated ones (seamRings):
        // they join the faces replaced (by themselves, to begin with).
        {
            std::unordered_set<std::uint32_t> taken;
            for (FaceIndex f : replaced_)
                taken.insert(std::uint32_t(f));
            std::vector<FaceIndex> ring;
            for (FaceIndex f : replaced_)
                if (regionIndex_.count(std::uint32_t(f))) ring.push_back(f);
            for (int k = 1; k < O_.seamRings; ++k) {
                std::vector<FaceIndex> next;
                for (FaceIndex f : ring)
                    for (VertexIndex v : faceVertices(f))
                        for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_)) {
                            if (g == Mesh::null_face() || taken.count(std::uint32_t(g)) || !acceptable(g))
                                continue;
                            taken.insert(std::uint32_t(g));
                            next.push_back(g);
                            openAsItself(g, false);
                        }
                ring.swap(next);
            }
            // The faces the view does not see around the mesh vertices on the seam (behind a crease the
            // patch boundary runs along): flips among them (in their plane) bring those vertices' valence
            // down, where the patch's faces in front have raised it.
            std::vector<FaceIndex> unseen;
            for (const auto& pe : pedges_)
                for (int id : pe.line) {
                    const LVert& l = L_[std::size_t(id)];
                    if (l.kind != LVert::Region) continue;
                    const VertexIndex v(l.cur);
                    for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_))
                        if (g != Mesh::null_face() && !taken.count(std::uint32_t(g)) && !acceptable(g) &&
                            M_.next(M_.next(M_.next(M_.halfedge(g)))) == M_.halfedge(g)) {
                            taken.insert(std::uint32_t(g));
                            unseen.push_back(g);
                        }
                }
            for (FaceIndex g : unseen)
                openAsItself(g, true);
        }
        // Patch faces, the boundary ones re-triangulated over the seam vertices of their edges.
        double patchArea = 0;
        std::vector<int> bad;
        for (int f : faces_) {
            progress_.tick();
            const auto& t = P_.tri[std::size_t(f)];
            std::vector<int> poly;
            std::vector<unsigned> edges;
            for (int k = 0; k < 3; ++k) {
                const int p = t[std::size_t(k)], q = t[std::size_t((k + 1) % 3)];
                poly.push_back(localOfPatch(p));
                edges.push_back((1u << k) | (1u << ((k + 2) % 3)));
                auto it = pedgeIndex_.find(dirKey(std::uint32_t(p), std::uint32_t(q)));
                if (it != pedgeIndex_.end()) {
                    const auto& line = pedges_[std::size_t(it->second)].line;
                    poly.insert(poly.end(), line.begin() + 1, line.end() - 1);
                    edges.insert(edges.end(), line.size() - 2, 1u << k);
                }
            }
            const float q = P_.hasQuality ? P_.quality[std::size_t(f)] : kInputFaceQuality;
            const std::int32_t sid = P_.hasScanId ? P_.scanId[std::size_t(f)] : -1;
            const std::size_t before = newFaces_.size();
            const double floor =
                std::min(O_.minAngleFloorDeg * kDeg,
                         0.999 * minAngle(P_.pos[std::size_t(t[0])], P_.pos[std::size_t(t[1])],
                                          P_.pos[std::size_t(t[2])]));
            if (!triangulatePolygon(poly, edges, q, sid, floor)) {
                for (int v : t)
                    bad.push_back(v);
                continue;
            }
            for (std::size_t i = before; i < newFaces_.size(); ++i) {
                const auto& nf = newFaces_[i].v;
                patchArea +=
                    area2(L_[std::size_t(nf[0])].uv, L_[std::size_t(nf[1])].uv, L_[std::size_t(nf[2])].uv);
            }
        }
        if (!bad.empty())
            return fail(a, "some of its boundary triangles cannot be joined to the seam", std::move(bad));
        if (std::abs(patchArea - insideArea) > 1e-6 * insideArea)
            return fail(a, "it overlaps itself in the scan's view");
        return true;
    }
    // Opens mesh face g to the seam optimisation: replaced by itself (a face the optimisation may flip, in
    // its plane); `offView` when the scan's view does not see it (checked in 3D).
    void openAsItself(FaceIndex g, bool offView) {
        const auto vs = faceVertices(g);
        const Vec3 A = toVec(M_.point(vs[0])), B = toVec(M_.point(vs[1])), C = toVec(M_.point(vs[2]));
        replaced_.push_back(g);
        newFaces_.push_back({{regionVertex(vs[0]), regionVertex(vs[1]), regionVertex(vs[2])},
                             curHasQuality_ ? curQuality_[g] : kInputFaceQuality,
                             curHasScanId_ ? curScanId_[g] : -1,
                             false,
                             normalOf(A, B, C).normalized(),
                             std::min(O_.minAngleFloorDeg * kDeg, 0.999 * minAngle(A, B, C)),
                             offView});
    }
    int localOfPatch(int p) {
        auto it = lidOfPatch_.find(p);
        if (it != lidOfPatch_.end()) return it->second;
        LVert l;
        l.kind = LVert::PatchInterior;
        l.patchA = p;
        l.pos = P_.pos[std::size_t(p)];
        l.uv = P_.uv[std::size_t(p)];
        const int id = addLocal(l);
        lidOfPatch_[p] = id;
        return id;
    }

    // ---- steps 4 + 5: local mesh, seam optimisation, checks, rehearsal
    struct Local {
        Star star;
        Mesh::Property_map<VertexIndex, int> lid;
        Mesh::Property_map<VertexIndex, Point2> uv;
        Mesh::Property_map<VertexIndex, bool> locked;
        Mesh::Property_map<FaceIndex, float> quality;
        Mesh::Property_map<FaceIndex, std::int32_t> scanId;
        Mesh::Property_map<FaceIndex, bool> patchSide;
        Mesh::Property_map<FaceIndex, Vec3> planeNormal;  // outside pieces: normal of their mesh face
        Mesh::Property_map<FaceIndex, double> minAllowed; // smallest angle accepted (radians)
        Mesh::Property_map<FaceIndex, bool> offView;      // piece of a mesh face the view does not see
        std::set<std::pair<std::uint32_t, std::uint32_t>> seam;
        Star pristine; // the star as copied from the current mesh, for the rehearsal
        // After a strip refill (v2): `seam` holds the fill's edges; the seam line's figures as glued.
        bool refilled = false;
        bool remeshed = false; // the seam band was remeshed in 3D (band_remesh.h): `seam` holds its edges
        std::size_t seamLineEdges = 0;
        double seamLineLength = 0;
    };
    static std::pair<std::uint32_t, std::uint32_t> seamKey(VertexIndex a, VertexIndex b) {
        return std::minmax(std::uint32_t(a), std::uint32_t(b));
    }
    // Adds faces in an order that grows from the hole's border (each face next to what is there).
    static std::vector<std::size_t> growthOrder(const std::vector<std::array<VertexIndex, 3>>& faces,
                                                const Mesh& m) {
        IndexMap<std::size_t, std::uint64_t> byEdge;
        for (std::size_t i = 0; i < faces.size(); ++i)
            for (int k = 0; k < 3; ++k)
                byEdge[dirKey(std::uint32_t(faces[i][std::size_t(k)]),
                              std::uint32_t(faces[i][std::size_t((k + 1) % 3)]))] = i;
        std::vector<std::size_t> order;
        std::vector<char> done(faces.size(), 0);
        std::deque<std::size_t> queue;
        for (std::size_t i = 0; i < faces.size(); ++i)
            for (int k = 0; k < 3 && !done[i]; ++k) {
                const VertexIndex a = faces[i][std::size_t(k)], b = faces[i][std::size_t((k + 1) % 3)];
                if (!m.has_valid_index(a) || !m.has_valid_index(b) || m.is_removed(a) || m.is_removed(b))
                    continue;
                const auto h = m.halfedge(a, b);
                if (h != Mesh::null_halfedge() && m.is_border(h)) {
                    done[i] = 1;
                    queue.push_back(i);
                }
            }
        auto drain = [&] {
            while (!queue.empty()) {
                const std::size_t i = queue.front();
                queue.pop_front();
                order.push_back(i);
                for (int k = 0; k < 3; ++k) {
                    const std::size_t* j =
                        byEdge.find(dirKey(std::uint32_t(faces[i][std::size_t((k + 1) % 3)]),
                                           std::uint32_t(faces[i][std::size_t(k)])));
                    if (j && !done[*j]) {
                        done[*j] = 1;
                        queue.push_back(*j);
                    }
                }
            }
        };
        drain();
        for (std::size_t i = 0; i < faces.size(); ++i)
            if (!done[i]) {
                done[i] = 1;
                queue.push_back(i);
                drain();
            }
        return order;
    }

    bool buildAndOptimise(Attempt& a) {
        Local loc;
        Mesh& S = loc.star.S;
        StageClock::lap("other");
        if (!buildStar(M_, replaced_, loc.star)) return fail(a, "the mesh is not manifold near its seam");
        StageClock::lap("star");
        // A copy is cheaper than building the star again (the copied maps address the copy's arrays).
        loc.pristine = loc.star;
        StageClock::lap("star copy");
        loc.pristine.cur = loc.pristine.S.property_map<VertexIndex, std::uint32_t>("v:cur").first;
        loc.pristine.kept = loc.pristine.S.property_map<FaceIndex, bool>("f:kept").first;
        loc.lid = S.add_property_map<VertexIndex, int>("v:lid", -1).first;
        loc.uv = S.add_property_map<VertexIndex, Point2>("v:uv", Point2(0, 0)).first;
        loc.locked = S.add_property_map<VertexIndex, bool>("v:locked", false).first;
        loc.quality = S.add_property_map<FaceIndex, float>("f:q", kInputFaceQuality).first;
        loc.scanId = S.add_property_map<FaceIndex, std::int32_t>("f:s", -1).first;
        loc.patchSide = S.add_property_map<FaceIndex, bool>("f:patch", false).first;
        loc.planeNormal = S.add_property_map<FaceIndex, Vec3>("f:plane", Vec3(0, 0, 0)).first;
        loc.minAllowed = S.add_property_map<FaceIndex, double>("f:floor", 0.0).first;
        loc.offView = S.add_property_map<FaceIndex, bool>("f:offview", false).first;
        // Border edges around the replaced faces before (must be the same after: no new holes).
        const auto bordersBefore = bordersAround(loc);
        // Map local ids to S vertices.
        std::vector<VertexIndex> sv(L_.size());
        std::unordered_set<std::uint32_t> reusedCur;
        for (const LFace& f : newFaces_)
            for (int id : f.v)
                if (L_[std::size_t(id)].kind == LVert::Region) reusedCur.insert(L_[std::size_t(id)].cur);
        for (std::size_t i = 0; i < L_.size(); ++i) {
            const LVert& l = L_[i];
            if (!l.alive) continue;
            if (l.kind == LVert::Region) {
                const VertexIndex* it = loc.star.fromCurrent.find(l.cur);
                if (!it) continue; // a region vertex of no replaced face
                sv[i] = *it;
            }
        }
        // Fresh vertices are created on use, in order.
        std::vector<std::array<VertexIndex, 3>> faceVs;
        std::vector<Vec3> freshPos;
        for (const LFace& f : newFaces_) {
            std::array<VertexIndex, 3> vs;
            for (int k = 0; k < 3; ++k) {
                const int id = f.v[std::size_t(k)];
                if (sv[std::size_t(id)] == VertexIndex()) {
                    if (L_[std::size_t(id)].kind == LVert::Region)
                        return fail(a, "internal error: a seam vertex is missing from the local mesh");
                    sv[std::size_t(id)] = S.add_vertex(toPoint(L_[std::size_t(id)].pos));
                }
                vs[std::size_t(k)] = sv[std::size_t(id)];
            }
            faceVs.push_back(vs);
        }
        for (VertexIndex v : S.vertices()) {
            // Vertices of the star only: their place in the view (vertices behind the eye keep the origin;
            // their faces are kept and always tested for intersections).
            double w;
            Point2 uv(0, 0);
            if (loc.star.cur[v] != kNone && V_.project(pt(S, v), uv, w)) loc.uv[v] = uv;
        }
        for (std::size_t i = 0; i < L_.size(); ++i)
            if (sv[i] != VertexIndex()) {
                loc.lid[sv[i]] = int(i);
                loc.uv[sv[i]] = L_[i].uv;
            }
        StageClock::lap("local:vertices");
        for (FaceIndex f : replaced_)
            removeFaceKeeping(S, loc.star.faceFromCurrent.at(std::uint32_t(f)),
                              [&](VertexIndex v) { return reusedCur.count(loc.star.cur[v]) > 0; });
        StageClock::lap("local:remove");
        std::vector<int> bad;
        const auto order = growthOrder(faceVs, S);
        StageClock::lap("local:growthOrder");
        for (std::size_t i : order) {
            progress_.tick();
            const FaceIndex g = S.add_face(faceVs[i][0], faceVs[i][1], faceVs[i][2]);
            if (g == Mesh::null_face()) {
                for (int id : newFaces_[i].v)
                    addBad(bad, id);
                continue;
            }
            loc.star.kept[g] = false;
            loc.quality[g] = newFaces_[i].quality;
            loc.scanId[g] = newFaces_[i].scanId;
            loc.patchSide[g] = newFaces_[i].patchSide;
            loc.planeNormal[g] = newFaces_[i].planeNormal;
            loc.minAllowed[g] = newFaces_[i].minAllowed;
            loc.offView[g] = newFaces_[i].offView;
        }
        if (!bad.empty()) return fail(a, "its seam would not be manifold", std::move(bad));
        StageClock::lap("local:add_face");
        for (VertexIndex v : S.vertices()) {
            bool lockedV = S.is_border(v);
            for (FaceIndex f : CGAL::faces_around_target(S.halfedge(v), S))
                if (f == Mesh::null_face() || loc.star.kept[f]) lockedV = true;
            loc.locked[v] = lockedV || S.halfedge(v) == Mesh::null_halfedge();
        }
        for (const auto& pe : pedges_)
            for (std::size_t j = 0; j + 1 < pe.line.size(); ++j)
                loc.seam.insert(seamKey(sv[std::size_t(pe.line[j])], sv[std::size_t(pe.line[j + 1])]));

        StageClock::lap("local mesh");
        progress_.step(6, 8);
        if (O_.optimiseSeam) {
            const Refill refill = refill_ ? refillSeam(loc) : Refill::NotDone;
            if (refill == Refill::Broken) return retryWithoutRefill(a);
            if (refill == Refill::NotDone) optimise(loc, a.plan);
            if (remesh_ && refill != Refill::Applied && !remeshBand(loc, a.plan))
                return retryWithoutRemesh(a);
        }
        StageClock::lap("optimise");
        progress_.step(7, 8);
        if (!validate(loc, bordersBefore, a)) {
            if (loc.refilled) return retryWithoutRefill(a);
            if (loc.remeshed && stitch::bandDiagnostics())
                std::fprintf(stderr, "band: fails the checks (%s; v1 kept)\n", a.reason.c_str());
            if (loc.remeshed) return retryWithoutRemesh(a);
            return false;
        }
        StageClock::lap("validate:self-intersections");
        const bool ok = extractPlan(loc, a);
        StageClock::lap("plan:seam figures");
        return ok;
    }

    // ---- v2: the seam strip filled anew by construction (strip_refill.h, DESIGN.md §6.2)
    enum class Refill { NotDone, Applied, Broken };
    // Where the refill cannot be made (or its result fails the checks), version 1's seam optimisation
    // runs on a fresh build of the component instead.
    bool retryWithoutRefill(Attempt& a) {
        refill_ = false;
        a = Attempt{};
        const bool ok = buildAndOptimise(a);
        refill_ = true;
        return ok;
    }
    // ---- v2, design B: the seam band remeshed in 3D on the draft (band_remesh.h, DESIGN.md §6.2)
    // Where the band comes out worse than version 1 left it, or its result fails the checks, the component is
    // built again without it.
    bool retryWithoutRemesh(Attempt& a) {
        remesh_ = false;
        a = Attempt{};
        const bool ok = buildAndOptimise(a);
        remesh_ = true;
        return ok;
    }
    // False when the band came out worse than version 1's (the caller then builds the component again).
    bool remeshBand(Local& loc, Plan& plan) {
        Mesh& S = loc.star.S;
        // The band: new faces the view sees with a vertex within kBandRings rings (over such faces) of the
        // seam line.
        constexpr int kBandRings = 2;
        auto usable = [&](FaceIndex f) {
            return f != Mesh::null_face() && !loc.star.kept[f] && !loc.offView[f];
        };
        std::unordered_set<std::uint32_t> near;
        std::vector<VertexIndex> ring;
        for (const auto& [p, q] : loc.seam) {
            loc.seamLineLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
            for (std::uint32_t v : {p, q})
                if (near.insert(v).second) ring.push_back(VertexIndex(v));
        }
        loc.seamLineEdges = loc.seam.size();
        std::sort(ring.begin(), ring.end());
        for (int r = 0; r < kBandRings; ++r) {
            std::vector<VertexIndex> next;
            for (VertexIndex v : ring)
                for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S))
                    if (usable(S.face(h)) && near.insert(std::uint32_t(S.source(h))).second)
                        next.push_back(S.source(h));
            std::sort(next.begin(), next.end());
            ring.swap(next);
        }
        stitch::BandRemeshInput in;
        in.mesh = &S;
        for (FaceIndex f : S.faces()) {
            if (!usable(f)) continue;
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                if (near.count(std::uint32_t(v))) {
                    in.band.push_back(f);
                    break;
                }
        }
        if (in.band.empty()) return true;
        in.camera = &V_.camera();
        in.fixed = [&](VertexIndex v) { return bool(loc.locked[v]); };
        in.vertexData = [&](VertexIndex to, VertexIndex from) {
            if (from == Mesh::null_vertex()) {
                loc.star.cur[to] = kNone;
                loc.lid[to] = -1;
                loc.locked[to] = false;
            } else {
                loc.star.cur[to] = loc.star.cur[from];
                loc.lid[to] = loc.lid[from];
                loc.uv[to] = loc.uv[from];
                loc.locked[to] = loc.locked[from];
            }
        };
        in.faceData = [&](FaceIndex to, FaceIndex from) {
            loc.star.kept[to] = false;
            loc.quality[to] = loc.quality[from];
            loc.scanId[to] = loc.scanId[from];
            loc.patchSide[to] = loc.patchSide[from];
            loc.planeNormal[to] = loc.planeNormal[from];
            loc.minAllowed[to] = loc.minAllowed[from];
            loc.offView[to] = loc.offView[from];
        };
        // Creases: pieces of old faces outside the patch carry their face's plane (reliable even for a
        // sliver piece); other faces their own normal unless they are slivers.
        in.creaseNormal = [&](FaceIndex f) -> Eigen::Vector3d {
            if (!loc.patchSide[f] && loc.planeNormal[f].squaredNorm() > 0)
                return loc.planeNormal[f].normalized();
            const HalfedgeIndex h = S.halfedge(f);
            const Vec3 a = pt(S, S.source(h)), b = pt(S, S.target(h)), c = pt(S, S.target(S.next(h)));
            return minAngle(a, b, c) >= 10.0 * kDeg ? Vec3(normalOf(a, b, c).normalized()) : Vec3(0, 0, 0);
        };
        in.edgeLength = h3_;
        in.maxNormalTurnDeg = O_.maxNormalChangeDeg;
        // The band grows over new faces outside the patch only: moving the patch's samples beyond the first
        // rings puts them on its chords, up to a footprint off the reference (measured: fandisk, 80² scan).
        in.growable = [&](FaceIndex f) {
            return f != Mesh::null_face() && !loc.star.kept[f] && !loc.patchSide[f];
        };
        in.unseen = [&](FaceIndex f) { return !loc.star.kept[f] && loc.offView[f]; };
        in.growBelowDeg = 20.0;
        const stitch::BandRemeshReport r = stitch::remeshBand(in);
        progress_.tick(in.band.size());
        const bool worse = r.minAngleAfterDeg < r.minAngleBeforeDeg &&
                           !(r.minAngleAfterDeg >= 20.0 && r.fracAbove30After >= r.fracAbove30Before);
        if (stitch::bandDiagnostics())
            std::fprintf(stderr,
                         "band: %zu faces (+%zu grown), min %.2f -> %.2f%s; < 20 deg: %zu free, %zu held, "
                         "%zu beyond, %zu unseen\n",
                         in.band.size(), r.grown, r.minAngleBeforeDeg, r.minAngleAfterDeg,
                         worse ? " WORSE (v1 kept)" : "", r.below20Free, r.below20Held, r.below20Beyond,
                         r.below20Unseen);
        if (worse) return false;
        // Moved and new vertices: their place in the view; a mesh vertex that moved becomes a new vertex
        // (the old one goes with the replaced faces around it: its whole star is in the band).
        for (VertexIndex v : r.touched) {
            double w;
            Point2 uv;
            if (!V_.project(pt(S, v), uv, w)) return false;
            loc.uv[v] = uv;
            if (loc.star.cur[v] != kNone) {
                loc.star.cur[v] = kNone;
                loc.lid[v] = -1;
            }
        }
        loc.seam.clear();
        for (FaceIndex f : r.faces) {
            const HalfedgeIndex h = S.halfedge(f);
            const VertexIndex x = S.source(h), y = S.target(h), z = S.target(S.next(h));
            loc.seam.insert(seamKey(x, y));
            loc.seam.insert(seamKey(y, z));
            loc.seam.insert(seamKey(z, x));
        }
        loc.remeshed = true;
        plan.flips += r.flips;
        plan.collapses += r.collapses;
        return true;
    }

    Refill refillSeam(Local& loc) {
        Mesh& S = loc.star.S;
        // The strip: new faces the view sees with a vertex on the seam or next to it (over new faces).
        std::unordered_set<std::uint32_t> near;
        for (const auto& [p, q] : loc.seam) {
            near.insert(p);
            near.insert(q);
            loc.seamLineLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
        }
        loc.seamLineEdges = loc.seam.size();
        std::vector<std::uint32_t> line(near.begin(), near.end());
        std::sort(line.begin(), line.end());
        for (std::uint32_t v : line)
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(VertexIndex(v)), S))
                if (!S.is_border(h) && !loc.star.kept[S.face(h)]) near.insert(std::uint32_t(S.source(h)));
        std::vector<FaceIndex> strip;
        for (FaceIndex f : S.faces()) {
            if (loc.star.kept[f] || loc.offView[f]) continue;
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                if (near.count(std::uint32_t(v))) {
                    strip.push_back(f);
                    break;
                }
        }
        if (strip.empty()) return Refill::NotDone;
        stitch::StripRefillInput in;
        in.mesh = &S;
        in.strip = strip;
        in.uv = [&](VertexIndex v) { return Eigen::Vector2d(loc.uv[v].x(), loc.uv[v].y()); };
        in.keep = [&](VertexIndex v) { return bool(loc.locked[v]); };
        in.camera = &V_.camera();
        const stitch::StripRefill fill = stitch::refillStrip(in);
        progress_.tick(strip.size());
        if (!fill.ok) return Refill::NotDone;
        // Edit the local mesh: the strip goes, the fill comes (grown from the hole's border).
        struct Inherited {
            float quality;
            std::int32_t scanId;
            bool patchSide;
            Vec3 planeNormal;
            double minAllowed;
        };
        std::vector<Inherited> inherited;
        for (FaceIndex f : fill.parent)
            inherited.push_back(
                {loc.quality[f], loc.scanId[f], loc.patchSide[f], loc.planeNormal[f], loc.minAllowed[f]});
        std::unordered_set<std::uint32_t> keep;
        for (VertexIndex v : fill.kept)
            keep.insert(std::uint32_t(v));
        for (FaceIndex f : strip)
            removeFaceKeeping(S, f, [&](VertexIndex v) { return keep.count(std::uint32_t(v)) > 0; });
        std::vector<VertexIndex> vertexOf(fill.kept);
        for (std::size_t i = 0; i < fill.fresh.size(); ++i) {
            const VertexIndex v = S.add_vertex(toPoint(fill.fresh[i]));
            loc.uv[v] = Point2(fill.freshUv[i].x(), fill.freshUv[i].y());
            loc.lid[v] = -1;
            loc.locked[v] = false;
            loc.star.cur[v] = kNone;
            vertexOf.push_back(v);
        }
        std::vector<std::array<VertexIndex, 3>> faceVs;
        for (const auto& t : fill.triangles)
            faceVs.push_back(
                {vertexOf[std::size_t(t[0])], vertexOf[std::size_t(t[1])], vertexOf[std::size_t(t[2])]});
        loc.seam.clear();
        loc.refilled = true;
        for (std::size_t i : growthOrder(faceVs, S)) {
            const FaceIndex g = S.add_face(faceVs[i][0], faceVs[i][1], faceVs[i][2]);
            if (g == Mesh::null_face()) return Refill::Broken;
            loc.star.kept[g] = false;
            loc.quality[g] = inherited[i].quality;
            loc.scanId[g] = inherited[i].scanId;
            loc.patchSide[g] = inherited[i].patchSide;
            loc.planeNormal[g] = inherited[i].planeNormal;
            loc.minAllowed[g] = inherited[i].minAllowed;
            loc.offView[g] = false;
            for (int k = 0; k < 3; ++k)
                loc.seam.insert(seamKey(faceVs[i][std::size_t(k)], faceVs[i][std::size_t((k + 1) % 3)]));
        }
        return Refill::Applied;
    }

    // Border edges (pairs of current-mesh vertices) incident to the vertices of the replaced faces.
    std::set<std::pair<std::uint32_t, std::uint32_t>> bordersAround(Local& loc) const {
        std::set<std::pair<std::uint32_t, std::uint32_t>> out;
        const Mesh& S = loc.star.S;
        for (VertexIndex v : S.vertices()) {
            if (!loc.star.isFull(v) || S.halfedge(v) == Mesh::null_halfedge()) continue;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S))
                for (HalfedgeIndex g : {h, S.opposite(h)})
                    if (S.is_border(g))
                        out.insert(std::minmax(loc.star.cur[S.source(g)], loc.star.cur[S.target(g)]));
        }
        return out;
    }

    // Seam neighbourhood: vertices within seamRings rings of the seam, over new faces.
    std::unordered_set<std::uint32_t> seamNeighbourhood(Local& loc) const {
        const Mesh& S = loc.star.S;
        std::unordered_set<std::uint32_t> inside;
        std::vector<VertexIndex> ring;
        for (const auto& [a, b] : loc.seam)
            for (std::uint32_t v : {a, b})
                if (inside.insert(v).second) ring.push_back(VertexIndex(v));
        for (int r = 0; r < O_.seamRings; ++r) {
            std::vector<VertexIndex> next;
            for (VertexIndex v : ring)
                for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(v), S))
                    if (inside.insert(std::uint32_t(w)).second) next.push_back(w);
            ring.swap(next);
        }
        return inside;
    }
    Vec3 pt(const Mesh& S, VertexIndex v) const { return toVec(S.point(v)); }
    // Is the triangle (a, b, c), in place of new face f, oriented as f must be: counter-clockwise in the
    // view, or, for a piece of a mesh face the view does not see, like that face in 3D?
    static bool oriented(const Local& loc, FaceIndex f, const Point2& ua, const Point2& ub, const Point2& uc,
                         const Vec3& a, const Vec3& b, const Vec3& c) {
        if (loc.offView[f]) return normalOf(a, b, c).dot(loc.planeNormal[f]) > 0;
        return leftTurn(ua, ub, uc);
    }
    bool oriented(const Local& loc, FaceIndex f, VertexIndex a, VertexIndex b, VertexIndex c) const {
        const Mesh& S = loc.star.S;
        return oriented(loc, f, loc.uv[a], loc.uv[b], loc.uv[c], pt(S, a), pt(S, b), pt(S, c));
    }
    // Edges incident to the given vertices (each once, in a deterministic order).
    static std::vector<EdgeIndex> edgesAround(const Mesh& S,
                                              const std::unordered_set<std::uint32_t>& vertices) {
        std::vector<std::uint32_t> vs(vertices.begin(), vertices.end());
        std::sort(vs.begin(), vs.end());
        std::vector<EdgeIndex> out;
        for (std::uint32_t v : vs) {
            const VertexIndex x(v);
            if (S.is_removed(x) || S.halfedge(x) == Mesh::null_halfedge()) continue;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(x), S))
                out.push_back(S.edge(h));
        }
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    }
    // Distance from the seam along edges (Dijkstra), for the vertices of the given set.
    std::unordered_map<std::uint32_t, double>
    seamDistance(const Local& loc, const std::unordered_set<std::uint32_t>& within) const {
        const Mesh& S = loc.star.S;
        std::unordered_map<std::uint32_t, double> dist;
        using Item = std::pair<double, std::uint32_t>;
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
        for (const auto& [a, b] : loc.seam)
            for (std::uint32_t v : {a, b})
                if (dist.emplace(v, 0.0).second) queue.push({0.0, v});
        while (!queue.empty()) {
            const auto [d, v] = queue.top();
            queue.pop();
            if (d > dist[v]) continue;
            for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(VertexIndex(v)), S)) {
                if (!within.count(std::uint32_t(w))) continue;
                const double dw = d + (pt(S, VertexIndex(v)) - pt(S, w)).norm();
                auto [it, fresh] = dist.try_emplace(std::uint32_t(w), dw);
                if (fresh || dw < it->second) {
                    it->second = dw;
                    queue.push({dw, std::uint32_t(w)});
                }
            }
        }
        return dist;
    }

    void optimise(Local& loc, Plan& plan) {
        Mesh& S = loc.star.S;
        const double maxTurn = O_.maxNormalChangeDeg * kDeg;
        const double shortEdge = O_.collapseEdgeRatio * h3_;
        auto isNewFace = [&](FaceIndex f) { return f != Mesh::null_face() && !loc.star.kept[f]; };
        auto removable = [&](VertexIndex v) {
            const int id = loc.lid[v];
            // Mesh vertices stay (they carry the old surface's shape); crossings, patch and Steiner vertices
            // may go.
            return !loc.locked[v] && (id < 0 || L_[std::size_t(id)].kind != LVert::Region);
        };
        // -- collapses: remove a into b
        auto tryCollapse = [&](VertexIndex a, VertexIndex b, double& score) -> bool {
            if (!removable(a)) return false;
            const bool seamA = seamVertex(loc, a), seamB = seamVertex(loc, b);
            if (seamA && seamB && !loc.seam.count(seamKey(a, b))) return false;
            const HalfedgeIndex h = S.halfedge(a, b);
            if (h == Mesh::null_halfedge() || !isNewFace(S.face(h)) || !isNewFace(S.face(S.opposite(h))))
                return false;
            if (!detail::canCollapse(S, S.edge(h), false)) return false;
            double oldMin = std::numbers::pi, newMin = std::numbers::pi;
            for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(a), S)) {
                const FaceIndex f = S.face(g);
                if (!isNewFace(f)) return false;
                // g ends at a, so the face is (a, target(next(g)), source(g)) counter-clockwise.
                const VertexIndex p = S.target(S.next(g)), q = S.source(g);
                oldMin = std::min(oldMin, minAngle(pt(S, a), pt(S, p), pt(S, q)));
                if (p == b || q == b) continue;
                if (!oriented(loc, f, b, p, q)) return false;
                if (CGAL::collinear(S.point(b), S.point(p), S.point(q))) return false;
                const Vec3 n0 = normalOf(pt(S, a), pt(S, p), pt(S, q)),
                           n1 = normalOf(pt(S, b), pt(S, p), pt(S, q));
                if (loc.patchSide[f]) {
                    if (angleBetween(n0, n1) > maxTurn) return false;
                } else {
                    // A piece of a mesh face outside the patch may not leave that face's plane (any more
                    // than it already does at a patch vertex).
                    const Vec3& n = loc.planeNormal[f];
                    if (angleBetween(n1, n) > std::max(angleBetween(n0, n), kCoplanar)) return false;
                }
                newMin = std::min(newMin, minAngle(pt(S, b), pt(S, p), pt(S, q)));
            }
            if (newMin < oldMin) return false;
            score = newMin;
            return true;
        };
        // Collapses the candidate edges (a, b), by increasing key, each in the direction that leaves the
        // larger smallest angle around (edges gone or changed by earlier collapses are skipped).
        using Candidates = std::vector<std::pair<double, std::pair<VertexIndex, VertexIndex>>>;
        auto collapseEach = [&](Candidates& cands) {
            std::sort(cands.begin(), cands.end());
            std::size_t done = 0;
            for (const auto& c : cands) {
                progress_.tick();
                const auto [a, b] = c.second;
                if (S.is_removed(a) || S.is_removed(b) || S.halfedge(a, b) == Mesh::null_halfedge()) continue;
                double s1 = -1, s2 = -1;
                const bool ok1 = tryCollapse(a, b, s1), ok2 = tryCollapse(b, a, s2);
                if (!ok1 && !ok2) continue;
                const VertexIndex from = (ok1 && (!ok2 || s1 >= s2)) ? a : b, to = from == a ? b : a;
                collapse(loc, from, to);
                ++done;
            }
            plan.collapses += done;
            return done;
        };
        auto collapsePass = [&] {
            for (int pass = 0; pass < 4; ++pass) {
                const auto near = seamNeighbourhood(loc);
                Candidates cands;
                for (EdgeIndex e : edgesAround(S, near)) {
                    const HalfedgeIndex h = S.halfedge(e);
                    const VertexIndex a = S.source(h), b = S.target(h);
                    const double len = (pt(S, a) - pt(S, b)).norm();
                    if (len < shortEdge) cands.push_back({len, {a, b}});
                }
                if (collapseEach(cands) == 0) break;
            }
        };
        StageClock::lap("optimise:other");
        collapsePass();
        StageClock::lap("optimise:collapse");
        // -- refinement outside the patch: split long edges of the pieces around the seam (the new vertices
        // lie on the old surface: in a face's plane or on a mesh edge), graded from the patch's edge length
        // at the seam outwards, then flip within the faces' planes.
        for (int round = 0; round < 4 && O_.seamGrading > 0; ++round) {
            if (refineOutside(loc) == 0) break;
            flipPass(loc, plan);
        }
        StageClock::lap("optimise:refine");
        collapsePass();
        flipPass(loc, plan);
        StageClock::lap("optimise:collapse+flip");
        // -- smoothing: the vertices added outside the patch move within their face's plane towards the
        // centre of their neighbours where that raises the smallest angle around them.
        for (int pass = 0; pass < 3; ++pass) {
            if (smoothOutside(loc) == 0) break;
            flipPass(loc, plan);
        }
        StageClock::lap("optimise:smooth");
        // -- needles: a face near the seam with a small angle loses its shortest edge when collapsing it
        // (either way, with every check of tryCollapse: no fold, no flip in the view, pieces outside stay
        // in their planes) raises the smallest angle around; then flip again.
        for (int pass = 0; pass < 3; ++pass) {
            const auto near = seamNeighbourhood(loc);
            Candidates cands;
            for (const auto& [ang, f] : thinFaces(loc, near)) {
                const HalfedgeIndex h0 = S.halfedge(f);
                const VertexIndex v[3] = {S.source(h0), S.target(h0), S.target(S.next(h0))};
                int best = 0;
                double bestLen = std::numeric_limits<double>::infinity();
                for (int k = 0; k < 3; ++k) {
                    const double len = (pt(S, v[k]) - pt(S, v[(k + 1) % 3])).norm();
                    if (len < bestLen) {
                        bestLen = len;
                        best = k;
                    }
                }
                cands.push_back({ang, {v[best], v[(best + 1) % 3]}});
            }
            if (collapseEach(cands) == 0) break;
            flipPass(loc, plan);
        }
        StageClock::lap("optimise:needles");
        valencePass(loc, plan);
        StageClock::lap("optimise:valence");
        // -- last smoothing: the free vertices near the seam whose smallest angle around is still small
        // search for a better place (smoothOutside with search; no flips after it, so the valences stay).
        for (int pass = 0; pass < 2; ++pass)
            if (smoothOutside(loc, true) == 0) break;
        StageClock::lap("optimise:search");
    }

    // The smallest angle of the faces (v, p, q) of `ring` (faces `faces`) with v moved from p0 to p1, or -1
    // where one of them would turn over in the view (or, unseen, against its plane) or degenerate, a patch
    // face would turn its normal more than maxNormalChangeDeg, or (with `floors`) a face would fall below
    // its floor. uv: p1 in the view.
    double ringScore(const Local& loc, const std::vector<std::pair<VertexIndex, VertexIndex>>& ring,
                     const std::vector<FaceIndex>& faces, const Vec3& p0, const Vec3& p1, bool floors,
                     Point2& uv) const {
        const Mesh& S = loc.star.S;
        double w;
        if (!V_.project(p1, uv, w)) return -1.0;
        double m = std::numbers::pi;
        for (std::size_t i = 0; i < ring.size(); ++i) {
            const auto [p, q] = ring[i];
            if (!oriented(loc, faces[i], uv, loc.uv[p], loc.uv[q], p1, pt(S, p), pt(S, q)) ||
                CGAL::collinear(toPoint(p1), S.point(p), S.point(q)))
                return -1.0;
            if (loc.patchSide[faces[i]] &&
                angleBetween(normalOf(p0, pt(S, p), pt(S, q)), normalOf(p1, pt(S, p), pt(S, q))) >
                    O_.maxNormalChangeDeg * kDeg)
                return -1.0;
            const double after = minAngle(p1, pt(S, p), pt(S, q));
            if (floors && after < loc.minAllowed[faces[i]]) return -1.0;
            m = std::min(m, after);
        }
        return m;
    }

    // A seam vertex on a mesh edge (a crossing, a snapped patch vertex) slides along that edge towards the
    // centre of its neighbours where that raises the smallest angle around it: the pieces outside stay in
    // their faces' planes; the patch side turns no normal more than maxNormalChangeDeg; no face falls below
    // its floor. With `search`, where the smallest angle around stays below kSearchBelowDeg, the best of
    // kSlideSamples evenly spaced points of the edge is taken when it is better still.
    int slideAlongEdge(Local& loc, VertexIndex v, bool search) {
        Mesh& S = loc.star.S;
        const LVert& l = L_[std::size_t(loc.lid[v])];
        if (l.edgeU < 0) return 0;
        const Vec3 U = L_[std::size_t(l.edgeU)].pos, W = L_[std::size_t(l.edgeW)].pos;
        Vec3 centre(0, 0, 0);
        std::vector<std::pair<VertexIndex, VertexIndex>> ring;
        std::vector<FaceIndex> faces;
        for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
            const FaceIndex f = S.face(g);
            if (f == Mesh::null_face() || loc.star.kept[f]) return 0;
            ring.push_back({S.target(S.next(g)), S.source(g)});
            faces.push_back(f);
            centre += pt(S, S.source(g));
        }
        if (ring.size() < 3) return 0;
        centre /= double(ring.size());
        const double len2 = (W - U).squaredNorm();
        if (!(len2 > 0)) return 0;
        const Vec3 p0 = pt(S, v);
        double oldMin = std::numbers::pi;
        for (const auto& [p, q] : ring)
            oldMin = std::min(oldMin, minAngle(p0, pt(S, p), pt(S, q)));
        // The smallest angle around v moved to U + t (W - U), or -1 where a check fails.
        auto score = [&](double t, Point2& uv) {
            return ringScore(loc, ring, faces, p0, U + t * (W - U), true, uv);
        };
        double bestMin = oldMin, bestT = -1;
        Point2 bestUv;
        auto consider = [&](double t) {
            Point2 uv;
            const double m = score(t, uv);
            if (!(m > bestMin)) return;
            bestMin = m;
            bestT = t;
            bestUv = uv;
        };
        consider(std::clamp((centre - U).dot(W - U) / len2, kSlideEnd, 1.0 - kSlideEnd));
        if (search && bestMin < kSearchBelowDeg * kDeg)
            for (int k = 0; k <= kSlideSamples; ++k)
                consider(kSlideEnd + (1.0 - 2.0 * kSlideEnd) * double(k) / double(kSlideSamples));
        if (bestT < 0) return 0;
        S.point(v) = toPoint(U + bestT * (W - U));
        loc.uv[v] = bestUv;
        return 1;
    }

    // Moves the free vertices near the seam where that raises the smallest angle around them, keeping the
    // surface: a seam vertex on a mesh edge along that edge (slideAlongEdge); a vertex inside one mesh face
    // (pieces of one plane) to its neighbours' centre in that plane. With `search` also, by a compass search
    // for the largest smallest angle: a vertex among nearly coplanar pieces (a smoothly curved part of the
    // mesh) within their mean plane, never farther than kNearPlanarFlipGap × the patch's edge length from
    // the surface before; a vertex on the mesh edge between two planes along that edge's line; and a patch
    // boundary vertex inside a mesh face whose faces, patch side included, all lie in that face's plane (no
    // patch normal turning more than maxNormalChangeDeg, no face below its floor). Every face stays
    // oriented in the view (exact test).
    // Returns how many vertices moved.
    std::size_t smoothOutside(Local& loc, bool search = false) {
        Mesh& S = loc.star.S;
        const double maxTurn = O_.maxNormalChangeDeg * kDeg;
        const auto near = seamNeighbourhood(loc);
        std::vector<std::uint32_t> order(near.begin(), near.end());
        std::sort(order.begin(), order.end());
        std::size_t moved = 0;
        for (std::uint32_t vi : order) {
            progress_.tick();
            const VertexIndex v(vi);
            if (S.is_removed(v) || loc.locked[v] || loc.star.cur[v] != kNone) continue;
            if (S.halfedge(v) == Mesh::null_halfedge()) continue;
            // A seam vertex on a mesh edge slides along it; with `search`, one inside a mesh face (a patch
            // boundary vertex) moves like the points added outside, its patch side included.
            const bool onEdge = loc.lid[v] >= 0 && L_[std::size_t(loc.lid[v])].edgeU >= 0;
            if (onEdge || (loc.lid[v] >= 0 && !search)) {
                moved += slideAlongEdge(loc, v, search);
                continue;
            }
            const bool withPatch = loc.lid[v] >= 0;
            // All faces around: pieces of one mesh face (a Steiner point inside it, not on a mesh edge), or
            // of two (a point on the mesh edge between them: it moves along that edge's line).
            std::vector<Vec3> planes;
            bool outside = true;
            std::vector<std::pair<VertexIndex, VertexIndex>> ring; // (p, q): faces (v, p, q)
            std::vector<FaceIndex> ringFaces;
            Vec3 centre(0, 0, 0);
            for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
                const FaceIndex f = S.face(g);
                if (f == Mesh::null_face() || loc.star.kept[f] || (loc.patchSide[f] && !withPatch)) {
                    outside = false;
                    break;
                }
                const Vec3 n = loc.patchSide[f]
                                   ? normalOf(pt(S, v), pt(S, S.target(S.next(g))), pt(S, S.source(g)))
                                   : loc.planeNormal[f];
                if (std::none_of(planes.begin(), planes.end(),
                                 [&](const Vec3& m) { return angleBetween(n, m) <= kCoplanar; }))
                    planes.push_back(n);
                ring.push_back({S.target(S.next(g)), S.source(g)});
                ringFaces.push_back(f);
                centre += pt(S, S.source(g));
            }
            // Without `search` only a point inside one mesh face moves (to its neighbours' centre).
            if (!outside || ring.size() < 3 || (!search && planes.size() != 1)) continue;
            centre /= double(ring.size());
            const Vec3 p0 = pt(S, v);
            // The directions v may move in: the plane's (the mean plane where the pieces' planes differ by
            // little: a smoothly curved part of the mesh) and, between two planes, the line where they meet.
            Vec3 mean(0, 0, 0);
            double spread = 0;
            for (const Vec3& n : planes) {
                mean += n.normalized();
                for (const Vec3& m : planes)
                    spread = std::max(spread, angleBetween(n, m));
            }
            mean.normalize();
            std::vector<Vec3> dirs;
            if (planes.size() == 1 || spread <= maxTurn) {
                const Vec3 e1 = mean.unitOrthogonal(), e2 = mean.cross(e1);
                for (int k = 0; k < 8; ++k) {
                    const double t = double(k) * std::numbers::pi / 4.0;
                    dirs.push_back(std::cos(t) * e1 + std::sin(t) * e2);
                }
            }
            if (planes.size() == 2 &&
                !withPatch) { // (the patch's planes are not exact: no line between them)
                const Vec3 d = planes[0].cross(planes[1]).normalized();
                if (d.allFinite()) {
                    dirs.push_back(d);
                    dirs.push_back(-d);
                }
            }
            if (dirs.empty()) continue;
            const Vec3 target = centre - mean * mean.dot(centre - p0);
            // How far a point moved to lies from the surface around v before (zero in one plane).
            std::vector<Triangle3> before;
            for (const auto& [p, q] : ring)
                before.emplace_back(toPoint(p0), S.point(p), S.point(q));
            const double maxGap = kNearPlanarFlipGap * h3_;
            auto offSurface = [&](const Vec3& p1) {
                if (planes.size() == 1 && !withPatch) return false;
                double d2 = std::numeric_limits<double>::infinity();
                for (const Triangle3& t : before)
                    d2 = std::min(d2, CGAL::to_double(CGAL::squared_distance(toPoint(p1), t)));
                return !(d2 <= maxGap * maxGap);
            };
            // The smallest angle around v moved to p1, or -1 where a face would turn over in the view (or,
            // unseen, against its plane) or degenerate.
            auto score = [&](const Vec3& p1, Point2& uv) {
                return offSurface(p1) ? -1.0 : ringScore(loc, ring, ringFaces, p0, p1, withPatch, uv);
            };
            double oldMin = std::numbers::pi, nearest = std::numeric_limits<double>::infinity();
            for (const auto& [p, q] : ring) {
                oldMin = std::min(oldMin, minAngle(p0, pt(S, p), pt(S, q)));
                nearest = std::min(nearest, (pt(S, p) - p0).norm());
            }
            Vec3 best = p0;
            Point2 bestUv = loc.uv[v];
            double bestMin = oldMin;
            // Keeps p1 when it beats the best so far.
            auto consider = [&](const Vec3& p1) {
                Point2 uv;
                const double m = score(p1, uv);
                if (!(m > bestMin)) return false;
                best = p1;
                bestUv = uv;
                bestMin = m;
                return true;
            };
            consider(target);
            // With `search`, where the smallest angle around stays below kSearchBelowDeg: a compass search
            // (the step halved when no direction helps) for the position with the largest smallest angle.
            if (search && bestMin < kSearchBelowDeg * kDeg) {
                double step = 0.25 * nearest;
                for (int level = 0, round = 0; level < kSearchLevels && round < kSearchRounds; ++round) {
                    bool improved = false;
                    const Vec3 from = best;
                    for (const Vec3& d : dirs)
                        improved = consider(from + step * d) || improved;
                    if (!improved) {
                        step *= 0.5;
                        ++level;
                    }
                }
            }
            if (!(bestMin > oldMin)) continue;
            S.point(v) = toPoint(best);
            loc.uv[v] = bestUv;
            ++moved;
        }
        return moved;
    }

    std::size_t refineOutside(Local& loc) {
        Mesh& S = loc.star.S;
        const auto near = seamNeighbourhood(loc);
        auto within = near;
        for (EdgeIndex e : edgesAround(S, near))
            for (VertexIndex v : {S.source(S.halfedge(e)), S.target(S.halfedge(e))})
                within.insert(std::uint32_t(v));
        const auto dist = seamDistance(loc, within);
        auto distance = [&](VertexIndex v) {
            auto it = dist.find(std::uint32_t(v));
            return it == dist.end() ? std::numeric_limits<double>::infinity() : it->second;
        };
        std::vector<std::pair<double, EdgeIndex>> cands;
        for (EdgeIndex e : edgesAround(S, near)) {
            const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
            const FaceIndex f = S.face(h), g = S.face(o);
            if (f == Mesh::null_face() || g == Mesh::null_face() || loc.star.kept[f] || loc.star.kept[g])
                continue;
            if (loc.patchSide[f] || loc.patchSide[g]) continue;
            const Vec3 a = pt(S, S.source(h)), b = pt(S, S.target(h));
            const double len = (a - b).norm();
            const double target =
                h3_ + O_.seamGrading * 0.5 * (distance(S.source(h)) + distance(S.target(h)));
            if (len > 4.0 / 3.0 * target) cands.push_back({len, e});
        }
        std::sort(cands.begin(), cands.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
        std::size_t splits = 0;
        for (const auto& [len, e] : cands) {
            progress_.tick();
            if (S.is_removed(e)) continue;
            const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
            const FaceIndex f = S.face(h), g = S.face(o);
            const VertexIndex x = S.source(h), y = S.target(h);
            const Vec3 mid = 0.5 * (pt(S, x) + pt(S, y));
            Point2 uv;
            double w;
            if (!V_.project(mid, uv, w)) continue;
            // The split must leave all four triangles counter-clockwise in the view (pieces of a face the
            // view does not see: oriented like it) ...
            const VertexIndex z = S.target(S.next(h)), u = S.target(S.next(o));
            const Vec3 X = pt(S, x), Y = pt(S, y), Z = pt(S, z), U = pt(S, u);
            if (!oriented(loc, f, loc.uv[x], uv, loc.uv[z], X, mid, Z) ||
                !oriented(loc, f, uv, loc.uv[y], loc.uv[z], mid, Y, Z) ||
                !oriented(loc, g, loc.uv[y], uv, loc.uv[u], Y, mid, U) ||
                !oriented(loc, g, uv, loc.uv[x], loc.uv[u], mid, X, U))
                continue;
            // ... not put the new vertex nearer than a short seam edge to a neighbour of the edge's ends (two
            // vertices that close leave a thin piece no collapse can remove outside the patch) ...
            const double shortEdge = O_.collapseEdgeRatio * h3_;
            bool crowded = false;
            for (VertexIndex end : {x, y})
                for (VertexIndex n : CGAL::vertices_around_target(S.halfedge(end), S))
                    crowded = crowded || (n != x && n != y && (mid - pt(S, n)).norm() < shortEdge);
            if (crowded) continue;
            // ... and not make the smallest angle there worse.
            if (std::min({minAngle(X, mid, Z), minAngle(mid, Y, Z), minAngle(Y, mid, U),
                          minAngle(mid, X, U)}) < 0.99 * std::min(minAngle(X, Y, Z), minAngle(Y, X, U)))
                continue;
            const detail::EdgeSplit split = detail::splitEdge(S, h, toPoint(mid));
            const VertexIndex v = split.vertex;
            loc.uv[v] = uv;
            loc.lid[v] = -1;
            loc.locked[v] = false;
            loc.star.cur[v] = kNone;
            copyFace(loc, f, S.face(split.first));
            copyFace(loc, f, S.face(S.opposite(split.first)));
            copyFace(loc, g, S.face(split.second));
            copyFace(loc, g, S.face(S.opposite(split.second)));
            ++splits;
        }
        return splits;
    }
    static void copyFace(Local& loc, FaceIndex from, FaceIndex to) {
        if (from == to) return;
        loc.star.kept[to] = loc.star.kept[from];
        loc.quality[to] = loc.quality[from];
        loc.scanId[to] = loc.scanId[from];
        loc.patchSide[to] = loc.patchSide[from];
        loc.planeNormal[to] = loc.planeNormal[from];
        loc.minAllowed[to] = loc.minAllowed[from];
        loc.offView[to] = loc.offView[from];
    }

    // A flip of the edge of halfedge h (x → y, faces (x, y, z1) and (y, x, z2) → (x, z2, z1), (z2, y, z1))
    // that the seam optimisation may make: both faces new and near the seam, not a seam edge, no vertex left
    // with fewer than three edges, no edge doubled, every new face oriented as its kind must be (in the view,
    // or in 3D for pieces the view does not see) and not degenerate (exact); on the patch side no normal
    // turns more than maxNormalChangeDeg, outside it the surface stays (see below). Sets the smallest angles
    // before and after, and `nearPlanar` when the flip joins pieces of two nearly coplanar mesh faces.
    bool flipAllowed(const Local& loc, HalfedgeIndex h, const std::unordered_set<std::uint32_t>& near,
                     double& oldMin, double& newMin, bool& nearPlanar) const {
        const Mesh& S = loc.star.S;
        const double maxTurn = O_.maxNormalChangeDeg * kDeg;
        auto isNewFace = [&](FaceIndex f) { return f != Mesh::null_face() && !loc.star.kept[f]; };
        const HalfedgeIndex o = S.opposite(h);
        if (!isNewFace(S.face(h)) || !isNewFace(S.face(o))) return false;
        const VertexIndex x = S.source(h), y = S.target(h), z1 = S.target(S.next(h)),
                          z2 = S.target(S.next(o));
        if (!near.count(std::uint32_t(x)) || !near.count(std::uint32_t(y))) return false;
        if (loc.seam.count(seamKey(x, y)) || !detail::canFlip(S, h)) return false;
        // New faces (x, z2, z1) and (z2, y, z1).
        if (loc.offView[S.face(h)] != loc.offView[S.face(o)] || !oriented(loc, S.face(h), x, z2, z1) ||
            !oriented(loc, S.face(o), z2, y, z1))
            return false;
        if (CGAL::collinear(S.point(x), S.point(z2), S.point(z1)) ||
            CGAL::collinear(S.point(z2), S.point(y), S.point(z1)))
            return false;
        const Vec3 X = pt(S, x), Y = pt(S, y), Z1 = pt(S, z1), Z2 = pt(S, z2);
        const Vec3 o1 = normalOf(X, Y, Z1), o2 = normalOf(Y, X, Z2), n1 = normalOf(X, Z2, Z1),
                   n2 = normalOf(Z2, Y, Z1);
        // On the patch side a flip may not turn a normal more than maxNormalChangeDeg. Outside the patch
        // it may not change the surface: the pieces are coplanar, or they are pieces of one mesh face
        // (tilted only where they reach a patch vertex) and the new ones are tilted no more.
        const bool patchSide = loc.patchSide[S.face(h)];
        if (patchSide != loc.patchSide[S.face(o)]) return false;
        nearPlanar = false;
        const double turn = std::max(
            {angleBetween(o1, n1), angleBetween(o1, n2), angleBetween(o2, n1), angleBetween(o2, n2)});
        if (patchSide) {
            if (turn > maxTurn) return false;
        } else if (turn > kCoplanar) {
            const Vec3 &p1 = loc.planeNormal[S.face(h)], &p2 = loc.planeNormal[S.face(o)];
            bool allowed = false;
            if (angleBetween(p1, p2) <= kCoplanar) {
                const double tilt = std::max(angleBetween(o1, p1), angleBetween(o2, p1));
                allowed = std::max(angleBetween(n1, p1), angleBetween(n2, p1)) <= tilt + kCoplanar &&
                          turn <= maxTurn;
            }
            // Pieces of two mesh faces that are nearly coplanar (a smoothly curved part of the mesh): the
            // flip moves the surface by the gap between the two diagonals, allowed up to a small
            // fraction of the patch's edge length (far below a pixel footprint).
            nearPlanar = !allowed && turn <= maxTurn && segmentGap(X, Y, Z1, Z2) <= kNearPlanarFlipGap * h3_;
            if (!allowed && !nearPlanar) return false;
        }
        oldMin = std::min(minAngle(X, Y, Z1), minAngle(Y, X, Z2));
        newMin = std::min(minAngle(X, Z2, Z1), minAngle(Z2, Y, Z1));
        return true;
    }
    // Flips the edge of h (checked by flipAllowed).
    void flip(Local& loc, HalfedgeIndex h, bool nearPlanar) {
        Mesh& S = loc.star.S;
        const HalfedgeIndex o = S.opposite(h);
        CGAL::Euler::flip_edge(h, S);
        if (nearPlanar) // the new pieces keep their own planes from now on
            for (HalfedgeIndex g : {h, o}) {
                const FaceIndex f = S.face(g);
                const HalfedgeIndex k = S.halfedge(f);
                loc.planeNormal[f] =
                    normalOf(pt(S, S.source(k)), pt(S, S.target(k)), pt(S, S.target(S.next(k)))).normalized();
            }
    }

    // -- flips: raise the smallest angle, valence towards 6
    void flipPass(Local& loc, Plan& plan) {
        Mesh& S = loc.star.S;
        const auto near = seamNeighbourhood(loc);
        auto valenceCost = [&](VertexIndex v, int delta) {
            const int target = S.is_border(v) ? 4 : 6;
            return std::abs(int(S.degree(v)) + delta - target);
        };
        std::deque<EdgeIndex> queue;
        std::unordered_set<std::uint32_t> queued;
        for (EdgeIndex e : edgesAround(S, near)) {
            const HalfedgeIndex h = S.halfedge(e);
            if (near.count(std::uint32_t(S.source(h))) && near.count(std::uint32_t(S.target(h)))) {
                queue.push_back(e);
                queued.insert(std::uint32_t(e));
            }
        }
        std::size_t flips = 0;
        const std::size_t maxFlips = 20 * queue.size() + 100;
        while (!queue.empty() && flips < maxFlips) {
            const EdgeIndex e = queue.front();
            queue.pop_front();
            progress_.tick();
            queued.erase(std::uint32_t(e));
            if (S.is_removed(e)) continue;
            const HalfedgeIndex h = S.halfedge(e), o = S.opposite(h);
            double oldMin = 0, newMin = 0;
            bool nearPlanar = false;
            if (!flipAllowed(loc, h, near, oldMin, newMin, nearPlanar)) continue;
            const VertexIndex x = S.source(h), y = S.target(h), z1 = S.target(S.next(h)),
                              z2 = S.target(S.next(o));
            const int devOld =
                valenceCost(x, 0) + valenceCost(y, 0) + valenceCost(z1, 0) + valenceCost(z2, 0);
            const int devNew =
                valenceCost(x, -1) + valenceCost(y, -1) + valenceCost(z1, 1) + valenceCost(z2, 1);
            // Score: smallest angle in degrees minus 3° per unit of valence deviation.
            const double gain = (newMin - oldMin) / kDeg - 3.0 * double(devNew - devOld);
            if (!(gain > 0.5) || newMin < std::min(oldMin, 20.0 * kDeg)) continue;
            flip(loc, h, nearPlanar);
            ++flips;
            for (HalfedgeIndex g : {S.next(h), S.prev(h), S.next(o), S.prev(o)}) {
                const EdgeIndex ge = S.edge(g);
                if (queued.insert(std::uint32_t(ge)).second) queue.push_back(ge);
            }
        }
        plan.flips += flips;
    }

    // The new faces near the seam (a vertex in `near`) whose smallest angle is below kNeedleDeg, with that
    // angle, smallest first.
    std::vector<std::pair<double, FaceIndex>> thinFaces(const Local& loc,
                                                        const std::unordered_set<std::uint32_t>& near) {
        const Mesh& S = loc.star.S;
        // The faces with a vertex in `near` (found around those vertices, not among all faces of S).
        std::vector<FaceIndex> faces;
        for (std::uint32_t vi : near) {
            const VertexIndex v(vi);
            if (S.is_removed(v) || S.is_isolated(v)) continue;
            for (FaceIndex f : CGAL::faces_around_target(S.halfedge(v), S))
                if (f != Mesh::null_face()) faces.push_back(f);
        }
        std::sort(faces.begin(), faces.end());
        faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
        std::vector<std::pair<double, FaceIndex>> thin;
        for (FaceIndex f : faces) {
            progress_.tick();
            if (loc.star.kept[f]) continue;
            const HalfedgeIndex h0 = S.halfedge(f);
            const VertexIndex v[3] = {S.source(h0), S.target(h0), S.target(S.next(h0))};
            const double ang = minAngle(pt(S, v[0]), pt(S, v[1]), pt(S, v[2]));
            if (ang < kNeedleDeg * kDeg) thin.push_back({ang, f});
        }
        std::sort(thin.begin(), thin.end()); // (angle, face): the same order however the faces were found
        return thin;
    }

    // -- valence: a seam vertex with more than kMaxSeamValence edges loses one by the flip of one of them
    // (every check of flipAllowed) that keeps the smallest angle there at least min(before, 15°) and
    // raises no seam vertex above kMaxSeamValence; the best such flip (largest smallest angle) first.
    void valencePass(Local& loc, Plan& plan) {
        Mesh& S = loc.star.S;
        const auto near = seamNeighbourhood(loc);
        std::unordered_set<std::uint32_t> seamVs;
        for (const auto& [a, b] : loc.seam) {
            seamVs.insert(a);
            seamVs.insert(b);
        }
        // Flips the candidate (flipAllowed) with the largest smallest angle after, above `above` and, when
        // the smallest angle before was larger, at least `floor`; none that raises a seam vertex above
        // kMaxSeamValence. Returns whether it flipped.
        std::size_t flips = 0;
        auto flipBest = [&](const std::vector<HalfedgeIndex>& candidates, double above, double floor) {
            HalfedgeIndex best = Mesh::null_halfedge();
            double bestMin = above;
            bool bestNearPlanar = false;
            for (HalfedgeIndex h : candidates) {
                double oldMin = 0, newMin = 0;
                bool nearPlanar = false;
                if (!flipAllowed(loc, h, near, oldMin, newMin, nearPlanar)) continue;
                if (newMin < std::min(oldMin, floor) || newMin <= bestMin) continue;
                const VertexIndex z1 = S.target(S.next(h)), z2 = S.target(S.next(S.opposite(h)));
                if ((seamVs.count(std::uint32_t(z1)) && S.degree(z1) >= kMaxSeamValence) ||
                    (seamVs.count(std::uint32_t(z2)) && S.degree(z2) >= kMaxSeamValence))
                    continue;
                best = h;
                bestMin = newMin;
                bestNearPlanar = nearPlanar;
            }
            if (best == Mesh::null_halfedge()) return false;
            flip(loc, best, bestNearPlanar);
            ++flips;
            return true;
        };
        std::vector<std::uint32_t> order(seamVs.begin(), seamVs.end());
        std::sort(order.begin(), order.end());
        for (std::uint32_t vi : order) {
            const VertexIndex v(vi);
            for (int guard = 0; guard < 4; ++guard) {
                progress_.tick();
                if (S.is_removed(v) || S.halfedge(v) == Mesh::null_halfedge() ||
                    S.degree(v) <= kMaxSeamValence)
                    break;
                const auto around = CGAL::halfedges_around_target(S.halfedge(v), S);
                if (!flipBest({around.begin(), around.end()}, -1.0, kValenceFlipMinDeg * kDeg)) break;
            }
        }
        // A seam vertex with fewer than kMinSeamValence edges gains one by the flip of the edge opposite it
        // in one of its faces (every check of flipAllowed; the smallest angle there at least min(before,
        // 15°); the edge's ends keep kMinSeamValence edges when on the seam, 3 otherwise); the best first.
        for (std::uint32_t vi : order) {
            const VertexIndex v(vi);
            progress_.tick();
            if (S.is_removed(v) || S.halfedge(v) == Mesh::null_halfedge() || S.is_border(v) ||
                S.degree(v) >= kMinSeamValence)
                continue;
            std::vector<HalfedgeIndex> opposite;
            for (HalfedgeIndex g : CGAL::halfedges_around_target(S.halfedge(v), S)) {
                const HalfedgeIndex h = S.next(S.next(g)); // the side of g's face across from v
                bool keeps = !S.is_border(S.opposite(h));
                for (VertexIndex end : {S.source(h), S.target(h)})
                    keeps =
                        keeps && S.degree(end) > (seamVs.count(std::uint32_t(end)) ? kMinSeamValence : 3u);
                if (keeps) opposite.push_back(h);
            }
            flipBest(opposite, -1.0, kValenceFlipMinDeg * kDeg);
        }
        // Faces near the seam with a small angle: the flip of one of their edges that raises the smallest
        // angle there most (valence aside, but raising no seam vertex above kMaxSeamValence).
        for (const auto& [ang, f] : thinFaces(loc, near)) {
            progress_.tick();
            if (S.is_removed(f)) continue;
            const HalfedgeIndex h0 = S.halfedge(f);
            if (std::abs(minAngle(pt(S, S.source(h0)), pt(S, S.target(h0)), pt(S, S.target(S.next(h0)))) -
                         ang) > 1e-12)
                continue; // changed by an earlier flip
            const auto sides = CGAL::halfedges_around_face(h0, S);
            flipBest({sides.begin(), sides.end()}, ang + 0.5 * kDeg, 0.0);
        }
        plan.flips += flips;
    }
    bool seamVertex(const Local& loc, VertexIndex v) const {
        const std::uint32_t i = std::uint32_t(v);
        auto it = loc.seam.lower_bound({i, 0});
        if (it != loc.seam.end() && it->first == i) return true;
        for (const auto& e : loc.seam)
            if (e.second == i) return true;
        return false;
    }
    // Collapses edge (from, to) so that `to` survives with its position and data.
    void collapse(Local& loc, VertexIndex from, VertexIndex to) {
        Mesh& S = loc.star.S;
        const HalfedgeIndex h = S.halfedge(from, to);
        const EdgeIndex e = S.edge(h);
        const VertexIndex v0 = S.source(S.halfedge(e)), v1 = S.target(S.halfedge(e));
        const VertexIndex kept = CGAL::Euler::collapse_edge(e, S);
        (void)kept;
        if (v1 != to) {
            // The descriptor of `from` survived: give it the data of `to`.
            S.point(v1) = S.point(to);
            loc.lid[v1] = loc.lid[to];
            loc.uv[v1] = loc.uv[to];
            loc.locked[v1] = loc.locked[to];
            loc.star.cur[v1] = loc.star.cur[to];
        }
        std::set<std::pair<std::uint32_t, std::uint32_t>> seam;
        for (auto [a, b] : loc.seam) {
            if (a == std::uint32_t(v0)) a = std::uint32_t(v1);
            if (b == std::uint32_t(v0)) b = std::uint32_t(v1);
            if (a != b) seam.insert(std::minmax(a, b));
        }
        loc.seam.swap(seam);
    }

    // The faces that could intersect each other: new faces are a height field in the view (checked face
    // by face), so only the seam neighbourhood, the kept faces around, and new faces overlapping those in
    // the view need the 3D test.
    std::vector<FaceIndex> intersectionCandidates(Local& loc) {
        Mesh& S = loc.star.S;
        std::unordered_set<std::uint32_t> near;
        {
            const int rings = O_.seamRings + 2;
            std::vector<VertexIndex> ring;
            for (const auto& [a, b] : loc.seam)
                for (std::uint32_t v : {a, b})
                    if (near.insert(v).second) ring.push_back(VertexIndex(v));
            for (int r = 0; r < rings; ++r) {
                std::vector<VertexIndex> next;
                for (VertexIndex v : ring)
                    for (VertexIndex w : CGAL::vertices_around_target(S.halfedge(v), S))
                        if (near.insert(std::uint32_t(w)).second) next.push_back(w);
                ring.swap(next);
            }
        }
        auto faceBox = [&](FaceIndex f) {
            CGAL::Bbox_2 b;
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                b += loc.uv[v].bbox();
            return b;
        };
        std::vector<FaceIndex> out, kept;
        for (FaceIndex f : S.faces())
            if (loc.star.kept[f]) kept.push_back(f);
        BucketGrid keptGrid(4.0 * h2_, S.num_faces());
        for (FaceIndex f : kept)
            keptGrid.insert(int(std::uint32_t(f)), faceBox(f));
        for (FaceIndex f : S.faces()) {
            bool take = loc.star.kept[f];
            if (!take)
                for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                    if (near.count(std::uint32_t(v))) take = true;
            if (!take) {
                const CGAL::Bbox_2 b = faceBox(f);
                keptGrid.query(b, [&](int g) {
                    if (!take && CGAL::do_overlap(b, faceBox(FaceIndex(std::uint32_t(g))))) take = true;
                });
            }
            if (take) out.push_back(f);
        }
        return out;
    }

    bool validate(Local& loc, const std::set<std::pair<std::uint32_t, std::uint32_t>>& bordersBefore,
                  Attempt& a) {
        Mesh& S = loc.star.S;
        std::vector<int> bad;
        auto badFace = [&](FaceIndex f) {
            Point2 c(0, 0);
            double x = 0, y = 0;
            for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S)) {
                x += loc.uv[v].x() / 3.0;
                y += loc.uv[v].y() / 3.0;
            }
            c = Point2(x, y);
            addNear(bad, c);
        };
        // Faces: not degenerate, facing the camera, no needles.
        bool needles = false;
        for (FaceIndex f : S.faces()) {
            progress_.tick();
            if (loc.star.kept[f]) continue;
            const HalfedgeIndex h = S.halfedge(f);
            const VertexIndex p = S.source(h), q = S.target(h), r = S.target(S.next(h));
            if (CGAL::collinear(S.point(p), S.point(q), S.point(r)) || !oriented(loc, f, p, q, r)) {
                badFace(f);
            } else if (minAngle(pt(S, p), pt(S, q), pt(S, r)) < loc.minAllowed[f]) {
                badFace(f);
                needles = true;
            }
        }
        if (!bad.empty() && !needles)
            return fail(a, "it would create degenerate or back-facing faces", std::move(bad));
        if (!bad.empty()) return fail(a, "it would create needle-like faces at its seam", std::move(bad));
        // Vertices: manifold (one umbrella) and no new border.
        std::vector<int> incoming(S.num_vertices(), 0);
        for (HalfedgeIndex h : S.halfedges())
            ++incoming[std::uint32_t(S.target(h))];
        for (VertexIndex v : S.vertices()) {
            if (S.halfedge(v) == Mesh::null_halfedge() || !loc.star.isFull(v)) continue;
            int n = 0, borders = 0;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S.halfedge(v), S)) {
                ++n;
                borders += S.is_border(h);
            }
            if (n != incoming[std::uint32_t(v)] || borders > 1) {
                addNear(bad, loc.uv[v]);
            }
        }
        if (!bad.empty()) return fail(a, "it would create a non-manifold vertex", std::move(bad));
        for (FaceIndex f : S.faces())
            if (!loc.star.kept[f])
                for (VertexIndex v : CGAL::vertices_around_face(S.halfedge(f), S))
                    if (loc.star.cur[v] == kNone && S.is_border(v)) badFace(f);
        const auto bordersAfter = bordersAround(loc);
        if (bordersAfter != bordersBefore) {
            // Locate the difference (a hole of the mesh under the patch, an edge left dangling).
            for (const auto* set : {&bordersAfter, &bordersBefore})
                for (const auto& e : *set)
                    if (!(set == &bordersAfter ? bordersBefore : bordersAfter).count(e)) {
                        Point2 uv;
                        double w;
                        if (e.first != kNone && e.second != kNone &&
                            V_.project(0.5 * (toVec(M_.point(VertexIndex(e.first))) +
                                              toVec(M_.point(VertexIndex(e.second)))),
                                       uv, w))
                            addNear(bad, uv);
                    }
        }
        if (!bad.empty() || bordersAfter != bordersBefore)
            return fail(a, "it would open or close a hole in the mesh", std::move(bad));
        // No new self-intersections among the local faces.
        StageClock::lap("validate:faces+vertices");
        std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
        const auto candidates = intersectionCandidates(loc);
        StageClock::lap("validate:candidates");
        progress_.tick(candidates.size());
        PMP::self_intersections(candidates, S, std::back_inserter(pairs));
        for (const auto& [f, g] : pairs) {
            if (!loc.star.kept[f]) badFace(f);
            if (!loc.star.kept[g]) badFace(g);
        }
        if (!bad.empty()) return fail(a, "it would make the mesh intersect itself", std::move(bad));
        if (O_.failValidationForTesting) return fail(a, "its final check was forced to fail for testing");
        return true;
    }

    // An order of the new faces of S in which each is added next to what is already there: breadth first
    // from the faces next to kept faces (the hole's border) across S's edges.
    static std::vector<std::size_t> growthOrderIn(const Mesh& S, const std::vector<FaceIndex>& sfaces,
                                                  const Local& loc) {
        // Position of each face of S in sfaces (kAbsent: not there).
        constexpr std::size_t kAbsent = std::numeric_limits<std::size_t>::max();
        std::vector<std::size_t> index(S.num_faces(), kAbsent);
        for (std::size_t i = 0; i < sfaces.size(); ++i)
            index[std::size_t(sfaces[i])] = i;
        std::vector<char> done(sfaces.size(), 0);
        std::vector<std::size_t> order;
        order.reserve(sfaces.size());
        std::deque<std::size_t> queue;
        for (std::size_t i = 0; i < sfaces.size(); ++i)
            for (HalfedgeIndex h : CGAL::halfedges_around_face(S.halfedge(sfaces[i]), S)) {
                const FaceIndex g = S.face(S.opposite(h));
                // Next to a face that exists before the additions (kept, or left unchanged).
                if (!done[i] &&
                    (g == Mesh::null_face() || loc.star.kept[g] || index[std::size_t(g)] == kAbsent)) {
                    done[i] = 1;
                    queue.push_back(i);
                }
            }
        auto drain = [&] {
            while (!queue.empty()) {
                const std::size_t i = queue.front();
                queue.pop_front();
                order.push_back(i);
                for (HalfedgeIndex h : CGAL::halfedges_around_face(S.halfedge(sfaces[i]), S)) {
                    const FaceIndex g = S.face(S.opposite(h));
                    if (g == Mesh::null_face() || loc.star.kept[g]) continue;
                    const std::size_t j = index[std::size_t(g)];
                    if (j != kAbsent && !done[j]) {
                        done[j] = 1;
                        queue.push_back(j);
                    }
                }
            }
        };
        drain();
        for (std::size_t i = 0; i < sfaces.size(); ++i)
            if (!done[i]) {
                done[i] = 1;
                queue.push_back(i);
                drain();
            }
        return order;
    }

    bool extractPlan(Local& loc, Attempt& a) {
        Mesh& S = loc.star.S;
        Plan& plan = a.plan;
        // Faces that come out exactly as they were stay in the mesh untouched (same index).
        std::map<std::array<std::uint32_t, 3>, FaceIndex> byCorners;
        auto corners = [](std::array<std::uint32_t, 3> c) {
            std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
            return c;
        };
        for (FaceIndex f : replaced_) {
            const auto vs = faceVertices(f);
            byCorners[corners({std::uint32_t(vs[0]), std::uint32_t(vs[1]), std::uint32_t(vs[2])})] = f;
        }
        std::unordered_set<std::uint32_t> unchanged;
        // Vertices: current ones stay themselves, new ones are numbered in order of use.
        std::unordered_map<std::uint32_t, std::uint32_t> freshIndex;
        std::vector<std::array<VertexIndex, 3>> faces;
        std::vector<FaceIndex> sfaces;
        for (FaceIndex f : S.faces())
            if (!loc.star.kept[f]) {
                const HalfedgeIndex h = S.halfedge(f);
                const std::array<VertexIndex, 3> fv{S.source(h), S.target(h), S.target(S.next(h))};
                const std::array<std::uint32_t, 3> c{loc.star.cur[fv[0]], loc.star.cur[fv[1]],
                                                     loc.star.cur[fv[2]]};
                if (c[0] != kNone && c[1] != kNone && c[2] != kNone) {
                    auto it = byCorners.find(corners(c));
                    if (it != byCorners.end()) {
                        unchanged.insert(std::uint32_t(it->second));
                        continue;
                    }
                }
                faces.push_back(fv);
                sfaces.push_back(f);
            }
        for (FaceIndex f : replaced_)
            if (!unchanged.count(std::uint32_t(f))) plan.removed.push_back(f);
        std::unordered_set<std::uint32_t> reused;
        // Order faces for growth in the rehearsal mesh: the star as copied (same star, same removals).
        Star& rehearsal = loc.pristine;
        for (const auto& fv : faces)
            for (VertexIndex v : fv) {
                const std::uint32_t c = loc.star.cur[v];
                if (c != kNone) {
                    if (reused.insert(c).second) plan.reused.push_back(VertexIndex(c));
                } else if (!freshIndex.count(std::uint32_t(v))) {
                    freshIndex[std::uint32_t(v)] = std::uint32_t(plan.freshPositions.size());
                    plan.freshPositions.push_back(pt(S, v));
                }
            }
        // Face order: growth order over the faces expressed in the rehearsal mesh after the removals.
        std::vector<std::array<PlanVertex, 3>> pf;
        for (const auto& fv : faces) {
            std::array<PlanVertex, 3> p;
            for (int k = 0; k < 3; ++k) {
                const VertexIndex v = fv[std::size_t(k)];
                const std::uint32_t c = loc.star.cur[v];
                p[std::size_t(k)] =
                    c != kNone ? PlanVertex{c, false} : PlanVertex{freshIndex.at(std::uint32_t(v)), true};
            }
            pf.push_back(p);
        }
        StageClock::lap("plan");
        // Rehearse: add fresh vertices, remove the replaced faces, add the faces in growth order.
        std::vector<VertexIndex> fresh;
        for (const Vec3& p : plan.freshPositions)
            fresh.push_back(rehearsal.S.add_vertex(toPoint(p)));
        std::unordered_set<std::uint32_t> keep;
        for (VertexIndex v : plan.reused)
            keep.insert(std::uint32_t(rehearsal.fromCurrent.at(std::uint32_t(v))));
        for (FaceIndex f : plan.removed)
            removeFaceKeeping(rehearsal.S, rehearsal.faceFromCurrent.at(std::uint32_t(f)),
                              [&](VertexIndex v) { return keep.count(std::uint32_t(v)) > 0; });
        std::vector<std::array<VertexIndex, 3>> rf;
        for (const auto& p : pf) {
            std::array<VertexIndex, 3> r;
            for (int k = 0; k < 3; ++k)
                r[std::size_t(k)] = p[std::size_t(k)].fresh
                                        ? fresh[p[std::size_t(k)].index]
                                        : rehearsal.fromCurrent.at(p[std::size_t(k)].index);
            rf.push_back(r);
        }
        const auto order = growthOrderIn(S, sfaces, loc);
        StageClock::lap("rehearsal:prepare");
        progress_.step(8, 8);
        for (std::size_t i : order) {
            progress_.tick();
            if (rehearsal.S.add_face(rf[i][0], rf[i][1], rf[i][2]) == Mesh::null_face())
                return fail(a, "internal error: the stitch could not be rehearsed");
        }
        StageClock::lap("rehearsal:add_face");
        for (std::size_t i : order) {
            plan.faces.push_back(pf[i]);
            plan.quality.push_back(loc.quality[sfaces[i]]);
            plan.scanId.push_back(loc.scanId[sfaces[i]]);
        }
        // Seam figures (after a refill, the seam's faces and vertices are the fill's).
        plan.seamEdges = loc.seam.size();
        std::unordered_set<std::uint32_t> seamVerts;
        for (const auto& [p, q] : loc.seam) {
            plan.seamLength += (pt(S, VertexIndex(p)) - pt(S, VertexIndex(q))).norm();
            seamVerts.insert(p);
            seamVerts.insert(q);
        }
        if (loc.refilled || loc.remeshed) {
            plan.seamEdges = loc.seamLineEdges;
            plan.seamLength = loc.seamLineLength;
        }
        for (std::uint32_t v : seamVerts)
            if (loc.star.isFull(VertexIndex(v))) plan.seamValences.push_back(S.degree(VertexIndex(v)));
        for (std::size_t i = 0; i < faces.size(); ++i) {
            const auto& fv = faces[i];
            if (!seamVerts.count(std::uint32_t(fv[0])) && !seamVerts.count(std::uint32_t(fv[1])) &&
                !seamVerts.count(std::uint32_t(fv[2])))
                continue;
            plan.seamFaceMinAngles.push_back(minAngle(pt(S, fv[0]), pt(S, fv[1]), pt(S, fv[2])) / kDeg);
        }
        return true;
    }

    // ---- inputs
    const Mesh& M_;
    const PatchData& P_;
    const View& V_;
    const StitchOptions& O_;
    std::span<const std::uint32_t> ids_;
    const std::vector<int>& faces_;
    bool curHasQuality_, curHasScanId_;
    ComponentProgress& progress_;
    bool refill_ = O_.refillSeam; // v2 strip refill (off for the retry after a failed refill)
    bool remesh_ = O_.remeshSeam; // v2 band remesh (off for the retry after a worse or failed one)
    Mesh::Property_map<FaceIndex, float> curQuality_;
    Mesh::Property_map<FaceIndex, std::int32_t> curScanId_;

    // ---- component
    struct PEdge {
        int a, b;     // patch vertices, interior on the left of a → b
        int opposite; // third vertex of the patch triangle on this edge
        std::vector<std::pair<double, int>> splits;
        std::vector<int> line;
    };
    struct REdge {
        int u, w; // local ids of the mesh edge's halfedge source and target
        EdgeIndex edge;
        std::vector<std::pair<double, int>> splits;
        std::vector<int> line;
    };
    std::vector<int> compVerts_;                            // vertices of the component, sorted
    std::unordered_map<int, std::vector<int>> vertexFaces_; // faces around each boundary vertex
    std::unordered_set<int> boundary_;
    std::vector<PEdge> pedges_;
    std::unordered_map<std::uint64_t, int> pedgeIndex_;
    std::unordered_map<int, double> snapRadius_;
    double h2_ = 0, h3_ = 0;
    double margin_ = 0; // largest snapping distance in the view
    CGAL::Bbox_2 compBox_;
    BucketGrid compGrid_;

    // ---- current mesh
    IndexMap<VProj> vcache_;
    IndexMap<char> accept_; // bool (a char: vector<bool> has no addressable elements)
    bool fallbackBuilt_ = false;
    std::vector<FaceIndex> fallback_;
    BucketGrid fallbackGrid_;
    std::vector<FaceIndex> region_;   // faces re-triangulated in the view (near the seam)
    std::vector<FaceIndex> interior_; // faces under the patch, removed whole
    IndexMap<int> regionIndex_;
    BucketGrid regionGrid_;

    // ---- local problem
    std::vector<LVert> L_;
    std::unordered_map<std::uint32_t, int> lidOfCurrent_;
    std::unordered_map<int, int> lidOfPatch_;
    std::vector<REdge> redges_;
    std::unordered_map<std::uint32_t, int> redgeIndex_;
    std::vector<std::pair<int, int>> subEdges_;
    std::unordered_set<std::uint64_t> regionSub_, patchSub_;
    std::vector<FaceIndex> replaced_;
    std::vector<LFace> newFaces_;
    std::map<std::uint32_t, int> outerSplits_; // face outside the region → the region edge of it split
};

// ---------------------------------------------------------------------------------------------------
PatchData readPatch(const Mesh& patch, const View& view, std::size_t& dropped) {
    PatchData P;
    std::unordered_map<std::uint32_t, int> index;
    for (VertexIndex v : patch.vertices()) {
        const Vec3 p = toVec(patch.point(v));
        if (!p.allFinite()) throw InvalidInputError("The patch has a vertex with a non-finite coordinate.");
        index[std::uint32_t(v)] = int(P.pos.size());
        P.pos.push_back(p);
        Point2 uv;
        double w = 0;
        if (!view.project(p, uv, w)) uv = Point2(std::numeric_limits<double>::quiet_NaN(), 0);
        P.uv.push_back(uv);
    }
    auto q = patch.property_map<FaceIndex, float>(props::faceQuality);
    auto s = patch.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    P.hasQuality = q.second;
    P.hasScanId = s.second;
    for (FaceIndex f : patch.faces()) {
        std::array<int, 3> t;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(patch.halfedge(f), patch)) {
            if (k == 3) throw InvalidInputError("The patch has a face that is not a triangle.");
            t[std::size_t(k++)] = index.at(std::uint32_t(v));
        }
        if (k != 3) throw InvalidInputError("The patch has a face that is not a triangle.");
        const Point2 &a = P.uv[std::size_t(t[0])], &b = P.uv[std::size_t(t[1])], &c = P.uv[std::size_t(t[2])];
        if (std::isnan(a.x()) || std::isnan(b.x()) || std::isnan(c.x()) || !leftTurn(a, b, c)) {
            ++dropped;
            continue;
        }
        P.tri.push_back(t);
        P.face.push_back(std::uint32_t(f));
        P.quality.push_back(q.second ? q.first[f] : kInputFaceQuality);
        P.scanId.push_back(s.second ? s.first[f] : -1);
    }
    return P;
}

// Components of patch faces connected through vertices, largest first.
std::vector<std::vector<int>> components(const PatchData& P, const std::vector<int>& faces) {
    detail::DisjointSets sets(P.uv.size());
    auto find = [&](int x) { return int(sets.find(std::size_t(x))); };
    for (int f : faces) {
        const auto& t = P.tri[std::size_t(f)];
        sets.unite(std::size_t(t[0]), std::size_t(t[1]));
        sets.unite(std::size_t(t[0]), std::size_t(t[2]));
    }
    std::unordered_map<int, std::size_t> which;
    std::vector<std::vector<int>> out;
    for (int f : faces) {
        const int r = find(P.tri[std::size_t(f)][0]);
        auto [it, fresh] = which.try_emplace(r, out.size());
        if (fresh) out.emplace_back();
        out[it->second].push_back(f);
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const auto& x, const auto& y) { return x.size() > y.size(); });
    return out;
}

} // namespace

StitchReport stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                         const StitchOptions& options, std::span<const std::uint32_t> faceIds,
                         const Progress& progress, std::vector<std::uint8_t>* stitchedPatchFaces) {
    return detail::stitchPatch(current, patch, scanCamera, options, faceIds, progress, {},
                               stitchedPatchFaces);
}

StitchReport detail::stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                                 const StitchOptions& options, std::span<const std::uint32_t> faceIds,
                                 const Progress& progress, const BeforeStitchEdit& beforeEdit,
                                 std::vector<std::uint8_t>* stitchedPatchFaces) {
    const auto start = std::chrono::steady_clock::now();
    StageClock::start();
    if (stitchedPatchFaces) stitchedPatchFaces->assign(patch.num_faces(), 0);
    scanCamera.validate();
    if (patch.number_of_faces() == 0) throw InvalidInputError("The patch has no faces.");
    if (!faceIds.empty() && faceIds.size() != std::size_t(scanCamera.width) * std::size_t(scanCamera.height))
        throw InvalidInputError(
            "The ID buffer has " + std::to_string(faceIds.size()) +
            " pixels but the scan camera's image has " +
            std::to_string(std::size_t(scanCamera.width) * std::size_t(scanCamera.height)) + ".");
    options.validate();

    const View view(scanCamera);
    StitchReport report;
    std::size_t dropped = 0;
    const PatchData P = readPatch(patch, view, dropped);
    if (dropped > 0)
        report.skipped.push_back(std::to_string(dropped) +
                                 " patch faces were behind the camera or not facing it and were left out.");
    report.patchFacesTrimmed += dropped;

    std::vector<int> all(P.tri.size());
    for (std::size_t i = 0; i < all.size(); ++i)
        all[i] = int(i);
    struct Work {
        std::vector<int> faces;
        int name;   // number of the original component (1-based)
        int rounds; // trim rounds used
    };
    std::deque<Work> work;
    std::vector<std::size_t> componentFaces; // faces of each original component
    for (auto& c : components(P, all)) {
        componentFaces.push_back(c.size());
        work.push_back({std::move(c), int(componentFaces.size()), 0});
    }
    const int componentCount = int(componentFaces.size());
    std::map<int, std::string> firstReason; // per original component: the first reason a piece was dropped
    std::set<int> stitched;                 // original components with at least one piece glued in
    auto drop = [&](const Work& w, const std::string& why) {
        report.patchFacesTrimmed += w.faces.size();
        firstReason.try_emplace(w.name, why);
    };

    bool propsReady = false;
    std::size_t seamFacesAbove25 = 0, seamFacesAbove30 = 0, seamValence5To7 = 0;
    const double totalFaces = double(std::max<std::size_t>(P.tri.size(), 1));
    std::size_t facesDone = dropped; // faces stitched, trimmed or dropped so far
    double lastFraction = 0;         // reported fractions never go back
    while (!work.empty()) {
        // Cancellation points: between components and trim rounds, and inside a component's computation
        // (ComponentProgress), never inside an application.
        lastFraction = std::max(lastFraction, std::min(1.0, double(facesDone) / totalFaces));
        progress.report(lastFraction, "stitch");
        Work w = std::move(work.front());
        work.pop_front();
        if (w.faces.size() < options.minComponentFaces) {
            drop(w, w.rounds == 0
                        ? "it has fewer than " + std::to_string(options.minComponentFaces) + " faces"
                        : "what trimming left of it was too small");
            continue;
        }
        const bool curQ = current.property_map<FaceIndex, float>(props::faceQuality).second;
        const bool curS = current.property_map<FaceIndex, std::int32_t>(props::faceScanId).second;
        ComponentProgress componentProgress(progress, lastFraction, double(facesDone) / totalFaces,
                                            double(facesDone + w.faces.size()) / totalFaces);
        ComponentStitcher stitcher(current, P, view, options, faceIds, w.faces, curQ, curS,
                                   componentProgress);
        Attempt a;
        try {
            a = stitcher.run(); // never touches `current`
        } catch (const CGAL::Failure_exception& e) {
            a.reason = "an internal geometric check failed (" + std::string(e.what()) + ")";
        } catch (const std::logic_error& e) {
            a.reason = "an internal consistency check failed (" + std::string(e.what()) + ")";
        }
        if (!a.ok) {
            // Trim the faces around the problem and retry what is left (it may fall apart).
            std::unordered_set<int> bad(a.bad.begin(), a.bad.end());
            std::vector<int> rest;
            for (int f : w.faces) {
                const auto& t = P.tri[std::size_t(f)];
                if (!bad.count(t[0]) && !bad.count(t[1]) && !bad.count(t[2])) rest.push_back(f);
            }
            if (rest.size() == w.faces.size() || w.rounds >= options.maxTrimRounds) {
                drop(w, a.reason);
                continue;
            }
            report.patchFacesTrimmed += w.faces.size() - rest.size();
            firstReason.try_emplace(w.name, a.reason);
            for (auto& c : components(P, rest))
                work.push_front({std::move(c), w.name, w.rounds + 1});
            continue;
        }
        // Apply: every check has passed on the local copy and the rehearsal succeeded.
        StageClock::lap("other");
        if (beforeEdit) {
            std::vector<VertexIndex> used(a.plan.reused);
            for (const auto& face : a.plan.faces)
                for (const PlanVertex& v : face)
                    if (!v.fresh) used.push_back(VertexIndex(v.index));
            beforeEdit(current, a.plan.removed, used);
        }
        if (!propsReady) {
            if (P.hasQuality)
                current.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality);
            if (P.hasScanId) current.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1);
            propsReady = true;
        }
        auto q = current.property_map<FaceIndex, float>(props::faceQuality);
        auto s = current.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const Plan& plan = a.plan;
        const bool applied = replay(
            current, plan, [](VertexIndex v) { return v; }, [](FaceIndex f) { return f; },
            [&](std::size_t i, FaceIndex f) {
                if (q.second) q.first[f] = plan.quality[i];
                if (s.second) s.first[f] = plan.scanId[i];
            });
        if (!applied) throw Error("Internal error: a rehearsed stitch could not be applied to the mesh.");
        StageClock::lap("apply");
        stitched.insert(w.name);
        if (stitchedPatchFaces)
            for (int f : w.faces)
                (*stitchedPatchFaces)[P.face[std::size_t(f)]] = 1;
        facesDone += w.faces.size();
        ++report.piecesStitched;
        report.facesRemoved += plan.removed.size();
        report.facesAdded += plan.faces.size();
        report.seamEdges += plan.seamEdges;
        report.seamLength += plan.seamLength;
        report.collapses += plan.collapses;
        report.flips += plan.flips;
        for (double ang : plan.seamFaceMinAngles) {
            report.seamMinAngleDeg = std::min(report.seamMinAngleDeg, ang);
            seamFacesAbove25 += ang >= 25.0;
            seamFacesAbove30 += ang >= 30.0;
        }
        for (std::size_t k : plan.seamValences) {
            if (report.seamValenceHistogram.size() <= k) report.seamValenceHistogram.resize(k + 1, 0);
            ++report.seamValenceHistogram[k];
            seamValence5To7 += k >= 5 && k <= 7;
        }
        report.seamVertices += plan.seamValences.size();
        report.seamFaces += plan.seamFaceMinAngles.size();
    }
    report.componentsStitched = int(stitched.size());
    for (int c = 1; c <= componentCount; ++c) {
        if (stitched.count(c)) continue;
        ++report.componentsSkipped;
        report.skipped.push_back("Patch component " + std::to_string(c) + " (" +
                                 std::to_string(componentFaces[std::size_t(c - 1)]) +
                                 " faces) was not stitched: " + firstReason[c] + ".");
    }
    report.seamFracMinAngleAbove25 =
        report.seamFaces ? double(seamFacesAbove25) / double(report.seamFaces) : 1.0;
    report.seamFracMinAngleAbove30 =
        report.seamFaces ? double(seamFacesAbove30) / double(report.seamFaces) : 1.0;
    report.seamFracValence5To7 =
        report.seamVertices ? double(seamValence5To7) / double(report.seamVertices) : 1.0;
    if (report.componentsStitched == 0)
        throw InvalidInputError(
            "No part of the patch could be stitched" +
            (componentCount > 1 ? " (" + std::to_string(componentCount) + " components)" : std::string()) +
            ": " + (firstReason.empty() ? std::string("it is empty") : firstReason.begin()->second) + ".");
    if (options.collectGarbage) current.collect_garbage();
    StageClock::lap("other");
    StageClock::print();
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

} // namespace fss
