#include "fss/raycast.h"

#include "fss/camera_projector.h"
#include "fss/error.h"

#include "mesh/local_closest_point.h"
#include "mesh/triangle_geometry.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_set>
#include <vector>

namespace fss {
namespace {

using detail::toEigen;

using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Traits = CGAL::AABB_traits<Kernel, Primitive>;
using Tree = CGAL::AABB_tree<Traits>;

Point3 toPoint(const Eigen::Vector3d& v) {
    return {v.x(), v.y(), v.z()};
}

Kernel::Ray_3 toCgalRay(const Ray& ray) {
    return {toPoint(ray.origin), Kernel::Vector_3(ray.direction.x(), ray.direction.y(), ray.direction.z())};
}

Kernel::Triangle_3 triangleOf(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    return {mesh.point(mesh.source(h)), mesh.point(mesh.target(h)), mesh.point(mesh.target(mesh.next(h)))};
}

// Ray parameter of a ray/triangle intersection result (a point, or a segment when the ray lies in the
// triangle's plane: its entry point is the nearer end).
template <class Variant> double hitParameter(const Variant& v, const Ray& ray, Eigen::Vector3d& point) {
    if (const Point3* p = boost::get<Point3>(&v)) {
        point = toEigen(*p);
    } else if (const Kernel::Segment_3* s = boost::get<Kernel::Segment_3>(&v)) {
        const Eigen::Vector3d a = toEigen(s->source()), b = toEigen(s->target());
        point = (a - ray.origin).dot(ray.direction) <= (b - ray.origin).dot(ray.direction) ? a : b;
    } else {
        return std::numeric_limits<double>::infinity();
    }
    return std::max(0.0, (point - ray.origin).dot(ray.direction));
}

// The faces within `rings` vertex rings of `centre` (centre first).
void collectRings(const Mesh& mesh, FaceIndex centre, int rings, std::vector<FaceIndex>& out,
                  std::unordered_set<std::uint32_t>& seen) {
    out.clear();
    seen.clear();
    out.push_back(centre);
    seen.insert(std::uint32_t(centre.idx()));
    std::size_t begin = 0;
    for (int ring = 0; ring < rings; ++ring) {
        const std::size_t end = out.size();
        for (std::size_t i = begin; i < end; ++i) {
            for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(out[i]), mesh)) {
                for (FaceIndex g : CGAL::faces_around_target(h, mesh)) {
                    if (g == Mesh::null_face()) continue;
                    if (seen.insert(std::uint32_t(g.idx())).second) out.push_back(g);
                }
            }
        }
        begin = end;
    }
}

void requireFace(const Mesh& mesh, FaceIndex f, const char* what) {
    if (f == Mesh::null_face() || std::size_t(f.idx()) >= mesh.num_faces() || mesh.is_removed(f))
        throw InvalidInputError(std::string("The ") + what + " " + std::to_string(std::size_t(f.idx())) +
                                " is not a face of the mesh.");
}

} // namespace

struct RayCaster::Impl {
    const Mesh* mesh = nullptr;
    Tree tree;
};

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
    impl_->mesh = &mesh;
    for (FaceIndex f : mesh.faces())
        if (mesh.degree(f) != 3)
            throw InvalidInputError("Face " + std::to_string(std::size_t(f.idx())) +
                                    " of the mesh is not a triangle, so it cannot be ray cast.");
    for (VertexIndex v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
            throw InvalidInputError("Vertex " + std::to_string(std::size_t(v.idx())) +
                                    " of the mesh has a non-finite coordinate.");
    }
    if (mesh.number_of_faces() == 0) return;
    impl_->tree.insert(faces(mesh).first, faces(mesh).second, mesh);
    // Build eagerly: CGAL builds lazily inside const queries otherwise, which is not thread-safe.
    impl_->tree.build();
    impl_->tree.accelerate_distance_queries();
}

RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

const Mesh& RayCaster::mesh() const {
    return *impl_->mesh;
}

SurfacePoint RayCaster::intersect(const Ray& ray) const {
    SurfacePoint result;
    if (impl_->tree.empty()) return result;
    const auto hit = impl_->tree.first_intersection(toCgalRay(ray));
    if (!hit) return result;
    result.distance = hitParameter(hit->first, ray, result.point);
    result.face = hit->second;
    return result;
}

SurfacePoint RayCaster::intersect(const Ray& ray, FaceIndex hint, const LocalSearchOptions& options) const {
    if (hint == Mesh::null_face() || impl_->tree.empty()) return intersect(ray);
    const Mesh& mesh = *impl_->mesh;
    requireFace(mesh, hint, "hint face");
    std::vector<FaceIndex> candidates;
    std::unordered_set<std::uint32_t> seen;
    collectRings(mesh, hint, std::max(0, options.rings), candidates, seen);
    const Kernel::Ray_3 cgalRay = toCgalRay(ray);
    SurfacePoint best;
    best.distance = std::numeric_limits<double>::infinity();
    for (FaceIndex f : candidates) {
        const auto hit = CGAL::intersection(cgalRay, triangleOf(mesh, f));
        if (!hit) continue;
        Eigen::Vector3d p;
        const double t = hitParameter(*hit, ray, p);
        if (t < best.distance) best = {f, p, t};
    }
    if (!best) return intersect(ray);
    if (options.verifyUnoccluded && best.distance > 0) {
        const Eigen::Vector3d end = ray.origin + best.distance * (1.0 - 1e-7) * ray.direction;
        if (impl_->tree.do_intersect(Kernel::Segment_3(toPoint(ray.origin), toPoint(end))))
            return intersect(ray);
    }
    return best;
}

SurfacePoint RayCaster::closestPoint(const Eigen::Vector3d& p) const {
    SurfacePoint result;
    if (impl_->tree.empty()) return result;
    const auto [q, f] = impl_->tree.closest_point_and_primitive(toPoint(p));
    result.face = f;
    result.point = toEigen(q);
    result.distance = (result.point - p).norm();
    return result;
}

Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    // Voronoi regions of the corners, then the edges, then the interior (Ericson 5.1.5).
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Eigen::Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return a + v * ab;
    }
    const Eigen::Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        return a + w * ac;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + w * (c - b);
    }
    const double denom = va + vb + vc;
    if (!(std::abs(denom) > 0)) {
        // Degenerate triangle that slipped through the region tests: best of the three edges.
        Eigen::Vector3d best = a;
        for (auto [u, w] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
            const Eigen::Vector3d e = w - u;
            const double len2 = e.squaredNorm();
            const double t = len2 > 0 ? std::clamp((p - u).dot(e) / len2, 0.0, 1.0) : 0.0;
            const Eigen::Vector3d q = u + t * e;
            if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
        }
        return best;
    }
    const double v = vb / denom, w = vc / denom;
    return a + ab * v + ac * w;
}

namespace {

// Faces of a local search, deduplicated with a small open-addressing set that is cleared by bumping a
// generation stamp: no allocation per query once the scratch has grown (one per thread).
class LocalFaceSet {
public:
    void clear() {
        faces.clear();
        if (++generation_ == 0) { // wrapped: forget every stamp
            std::fill(stamp_.begin(), stamp_.end(), 0u);
            generation_ = 1;
        }
    }
    // Adds f unless present; true when it was added.
    bool insert(FaceIndex f) {
        if (2 * (faces.size() + 1) > slot_.size()) grow();
        const std::uint32_t id = std::uint32_t(f.idx());
        const std::size_t mask = slot_.size() - 1;
        for (std::size_t i = hash(id) & mask;; i = (i + 1) & mask) {
            if (stamp_[i] != generation_) {
                stamp_[i] = generation_;
                slot_[i] = id;
                faces.push_back(f);
                return true;
            }
            if (slot_[i] == id) return false;
        }
    }
    std::vector<FaceIndex> faces;

private:
    static std::size_t hash(std::uint32_t id) { return std::size_t(id * 2654435761u); }
    void grow() {
        const std::vector<FaceIndex> kept = faces;
        const std::size_t size = std::max<std::size_t>(64, 2 * slot_.size());
        slot_.assign(size, 0);
        stamp_.assign(size, 0);
        generation_ = 1;
        faces.clear();
        for (FaceIndex f : kept)
            insert(f);
    }
    std::vector<std::uint32_t> slot_, stamp_;
    std::uint32_t generation_ = 1;
};

// collectRings with the scratch set (same faces in the same order).
void collectRingsInto(const Mesh& mesh, FaceIndex centre, int rings, LocalFaceSet& set) {
    set.clear();
    set.insert(centre);
    std::size_t begin = 0;
    for (int ring = 0; ring < rings; ++ring) {
        const std::size_t end = set.faces.size();
        for (std::size_t i = begin; i < end; ++i) {
            for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(set.faces[i]), mesh)) {
                for (FaceIndex g : CGAL::faces_around_target(h, mesh)) {
                    if (g != Mesh::null_face()) set.insert(g);
                }
            }
        }
        begin = end;
    }
}

Eigen::Vector3d closestOnFace(const Mesh& mesh, FaceIndex f, const Eigen::Vector3d& p) {
    const HalfedgeIndex h = mesh.halfedge(f);
    return closestPointOnTriangle(p, toEigen(mesh.point(mesh.source(h))), toEigen(mesh.point(mesh.target(h))),
                                  toEigen(mesh.point(mesh.target(mesh.next(h)))));
}

} // namespace

SurfacePoint closestPointNear(const Mesh& mesh, const Eigen::Vector3d& p, FaceIndex hint,
                              const LocalSearchOptions& options) {
    requireFace(mesh, hint, "hint face");
    SurfacePoint best;
    // Fast path: p on the hint face itself (the sample's own face in the quality mask). The walk visits
    // the hint first and only replaces it by a strictly closer face, so at distance 0 it returns the hint.
    {
        const Eigen::Vector3d q = closestOnFace(mesh, hint, p);
        const double d = (q - p).norm();
        if (d == 0) return {hint, q, d};
    }
    thread_local LocalFaceSet candidates;
    best.distance = std::numeric_limits<double>::infinity();
    FaceIndex centre = hint;
    constexpr int kMaxRecentring = 16;
    for (int iteration = 0; iteration <= kMaxRecentring; ++iteration) {
        collectRingsInto(mesh, centre, std::max(0, options.rings), candidates);
        for (FaceIndex f : candidates.faces) {
            const Eigen::Vector3d q = closestOnFace(mesh, f, p);
            const double d = (q - p).norm();
            if (d < best.distance) best = {f, q, d};
        }
        if (best.face == centre) break;
        centre = best.face;
    }
    return best;
}

const std::vector<FaceIndex>& detail::LocalClosestPoint::ringsOf(FaceIndex centre) {
    const std::size_t i = std::size_t(centre.idx());
    if (rings_.size() < mesh_->num_faces()) rings_.resize(mesh_->num_faces());
    if (rings_[i].empty()) {
        thread_local LocalFaceSet set;
        collectRingsInto(*mesh_, centre, std::max(0, options_.rings), set);
        rings_[i] = set.faces;
    }
    return rings_[i];
}

SurfacePoint detail::LocalClosestPoint::operator()(const Eigen::Vector3d& p, FaceIndex hint) {
    requireFace(*mesh_, hint, "hint face");
    {
        const Eigen::Vector3d q = closestOnFace(*mesh_, hint, p);
        const double d = (q - p).norm();
        if (d == 0) return {hint, q, d};
    }
    if (measured_.size() < mesh_->num_faces()) measured_.resize(mesh_->num_faces(), 0u);
    if (spheres_.size() < mesh_->num_faces()) {
        const std::size_t from = spheres_.size();
        spheres_.resize(mesh_->num_faces());
        for (std::size_t i = from; i < spheres_.size(); ++i) {
            const FaceIndex f(static_cast<std::uint32_t>(i));
            if (mesh_->is_removed(f)) {
                spheres_[i] = Eigen::Vector4d(0, 0, 0, std::numeric_limits<double>::infinity());
                continue;
            }
            const HalfedgeIndex h = mesh_->halfedge(f);
            const Eigen::Vector3d a = toEigen(mesh_->point(mesh_->source(h))),
                                  b = toEigen(mesh_->point(mesh_->target(h))),
                                  c = toEigen(mesh_->point(mesh_->target(mesh_->next(h))));
            const Eigen::Vector3d m = (a + b + c) / 3.0;
            const double r = std::max({(a - m).norm(), (b - m).norm(), (c - m).norm()});
            spheres_[i] = Eigen::Vector4d(m.x(), m.y(), m.z(), r);
        }
    }
    if (++query_ == 0) { // wrapped: forget every stamp
        std::fill(measured_.begin(), measured_.end(), 0u);
        query_ = 1;
    }
    SurfacePoint best;
    best.distance = std::numeric_limits<double>::infinity();
    FaceIndex centre = hint;
    constexpr int kMaxRecentring = 16; // as closestPointNear
    for (int iteration = 0; iteration <= kMaxRecentring; ++iteration) {
        for (FaceIndex f : ringsOf(centre)) {
            std::uint32_t& stamp = measured_[std::size_t(f.idx())];
            if (stamp == query_) continue;
            stamp = query_;
            // No point of f is nearer than its sphere: skip it where that is clearly farther than the best
            // (the margin dwarfs the rounding of both distances, so no face that could win is skipped).
            const Eigen::Vector4d& s = spheres_[std::size_t(f.idx())];
            const double toCentre = (p - s.head<3>()).norm();
            if (toCentre - s.w() > best.distance + 1e-9 * (toCentre + s.w() + s.head<3>().norm())) continue;
            const Eigen::Vector3d q = closestOnFace(*mesh_, f, p);
            const double d = (q - p).norm();
            if (d < best.distance) best = {f, q, d};
        }
        if (best.face == centre || !best) break;
        centre = best.face;
    }
    return best;
}

FrameBuffers rasterizeOnCpu(const Mesh& mesh, const Camera& camera, const Progress& progress) {
    camera.validate();
    const RayCaster caster(mesh);
    return rasterizeOnCpu(caster, camera, progress);
}

FrameBuffers rasterizeOnCpu(const RayCaster& caster, const Camera& camera, const Progress& progress) {
    camera.validate();
    FrameBuffers buffers;
    buffers.camera = camera;
    const std::size_t n = std::size_t(camera.width) * std::size_t(camera.height);
    buffers.depth.assign(n, 1.0f);
    buffers.faceId.assign(n, FrameBuffers::kNoFace);
    const CameraProjector projector(camera);
    for (int y = 0; y < camera.height; ++y) {
        progress.report(double(y) / camera.height, "Ray casting");
        for (int x = 0; x < camera.width; ++x) {
            const double sx = x + 0.5, sy = y + 0.5;
            // Start on the near plane: what GL's near clipping leaves visible.
            Ray ray = projector.ray(sx, sy);
            ray.origin = projector.unproject(sx, sy, 0.0);
            const SurfacePoint hit = caster.intersect(ray);
            if (!hit) continue;
            const double depth = projector.project(hit.point).z();
            if (!(depth <= 1.0)) continue;
            buffers.depth[buffers.index(x, y)] = float(std::clamp(depth, 0.0, 1.0));
            buffers.faceId[buffers.index(x, y)] = std::uint32_t(hit.face.idx());
        }
    }
    progress.report(1.0, "Ray casting");
    return buffers;
}

} // namespace fss
