#pragma once
/// \file raycast.h
/// Ray casting on a triangle mesh: the first surface point hit by a viewing ray and the closest surface
/// point to a query point. Used by the fishbone scan (rib vertex → ray → sample, DESIGN.md §1), by the
/// sampling-quality mask (sample → closest face of the current mesh) and as a CPU reference rasterizer
/// producing the same FrameBuffers as the GPU rasterizer (tests, machines without OpenGL).
///
/// RayCaster keeps a CGAL AABB tree of the mesh; this file's .cpp is the only translation unit (besides
/// metrics.cpp) that includes the AABB tree headers, so the rest of FSS compiles fast.

#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/progress.h"

#include <Eigen/Core>

#include <memory>

namespace fss {

/// A point on the mesh surface with the face it lies on. `face == Mesh::null_face()` means "none".
struct SurfacePoint {
    FaceIndex face = Mesh::null_face();
    Eigen::Vector3d point{0, 0, 0};
    /// Ray hits: ray parameter t ≥ 0 of the hit (the distance from the ray origin, directions are unit).
    /// Closest-point queries: the Euclidean distance from the query point.
    double distance = 0;

    explicit operator bool() const { return face != Mesh::null_face(); }
};

/// Options of the hinted (local-search-first) queries.
struct LocalSearchOptions {
    /// The faces within this many vertex rings around the hint face are searched first (0 = the hint face
    /// only, 1 = every face sharing a vertex with it, ...).
    int rings = 2;
    /// Hinted ray queries only: also check with the AABB tree that nothing occludes the local hit (one
    /// segment query from the ray origin to just before the hit). Off by default: a hint taken from the ID
    /// buffer under the ray is the visible face except within a pixel of occlusion boundaries.
    bool verifyUnoccluded = false;
};

/// First-hit ray queries and closest-point queries on one triangle mesh (CGAL AABB tree, exact predicates
/// for the ray/triangle decisions, double constructions).
///
/// The mesh is referenced, not copied: it must outlive the RayCaster and must not be modified while the
/// RayCaster exists. Queries are const and thread-safe. Building costs O(n log n) for n faces.
class RayCaster {
public:
    /// Builds the AABB tree of \p mesh (including the accelerator of closest-point queries).
    /// \pre every face of \p mesh is a triangle. An empty mesh is allowed (every query misses).
    /// \throw InvalidInputError when a face is not a triangle or a vertex is not finite.
    explicit RayCaster(const Mesh& mesh);
    ~RayCaster();
    RayCaster(RayCaster&&) noexcept;
    RayCaster& operator=(RayCaster&&) noexcept;
    RayCaster(const RayCaster&) = delete;
    RayCaster& operator=(const RayCaster&) = delete;

    const Mesh& mesh() const;

    /// First intersection of \p ray (t ≥ 0) with the surface. A ray lying in a triangle's plane hits at its
    /// entry point. Returns an empty SurfacePoint on a miss.
    SurfacePoint intersect(const Ray& ray) const;

    /// First intersection of \p ray, searching the faces around \p hint first (fishbone sampling: the face
    /// of the ID buffer under the rib vertex is the first guess). When one of the faces within
    /// `options.rings` vertex rings of \p hint is hit, the nearest such hit is returned (verified
    /// unoccluded when `options.verifyUnoccluded`); otherwise, or when \p hint is null, the AABB tree
    /// answers (same result as intersect(ray)).
    /// \pre \p hint is null or a face of mesh().
    SurfacePoint intersect(const Ray& ray, FaceIndex hint, const LocalSearchOptions& options = {}) const;

    /// Closest point of the surface to \p p (AABB tree). Empty result for an empty mesh.
    SurfacePoint closestPoint(const Eigen::Vector3d& p) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Closest point to \p p on the faces of \p mesh near \p hint, without any acceleration structure (the
/// sampling-quality mask runs it on the *current* mesh, which changes with every scan, so building a tree
/// would cost the whole mesh per scan). It walks: the faces within `options.rings` vertex rings of the
/// current best face are searched, and the search re-centres on the best face until it no longer
/// changes (at most 16 re-centrings), so it follows the surface downhill to a local minimum of the
/// distance. Cost O(rings² · iterations). `options.verifyUnoccluded` is ignored.
/// \pre \p hint is a face of \p mesh (not removed); every face is a triangle.
/// \throw InvalidInputError when \p hint is not a face of \p mesh.
SurfacePoint closestPointNear(const Mesh& mesh, const Eigen::Vector3d& p, FaceIndex hint,
                              const LocalSearchOptions& options = {});

/// Closest point to \p p on the triangle (a, b, c) (Ericson, *Real-Time Collision Detection*, 5.1.5);
/// works for degenerate triangles too.
Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// CPU reference rasterizer: the FrameBuffers a GPU render of \p mesh from \p camera gives, by casting
/// the ray through every pixel centre (x+½, y+½). A ray starts on the near plane (GL near clipping); the
/// pixel gets the face of the first hit and its window depth Camera::project(hit).z; hits beyond the far
/// plane and misses leave the background (depth 1, FrameBuffers::kNoFace). Which of two faces sharing an
/// edge a ray exactly through that edge reports is unspecified (as on a GPU). About 0.1–0.3 s per 256²
/// view of a 10k–100k face mesh on one core.
/// \pre camera.validate() passes.
/// \throw InvalidInputError from Camera::validate() or RayCaster; CancelledError through \p progress
///        (reported once per image row).
FrameBuffers rasterizeOnCpu(const Mesh& mesh, const Camera& camera, const Progress& progress = {});

/// As above with an existing RayCaster (several views of one mesh build the tree once).
FrameBuffers rasterizeOnCpu(const RayCaster& caster, const Camera& camera, const Progress& progress = {});

} // namespace fss
