#include "fss/scan.h"

#include "fss/camera_projector.h"
#include "fss/error.h"

#include "base/huge_pages.h"
#include "base/parallel_rows.h"
#include "scan/scan_workspace_impl.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

namespace fss {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

struct FaceGeometry {
    Eigen::Vector3d a;
    Eigen::Vector3d normal; // unit, or zero for a degenerate face
};

FaceGeometry faceGeometry(const Mesh& mesh, FaceIndex f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    const Eigen::Vector3d a = toEigen(mesh.point(mesh.source(h))), b = toEigen(mesh.point(mesh.target(h))),
                          c = toEigen(mesh.point(mesh.target(mesh.next(h))));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    return {a, len > 0 && std::isfinite(len) ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero()};
}

// Unit vector from the sample towards the viewer along its viewing ray.
Eigen::Vector3d towardsViewer(const CameraProjector& camera, const Eigen::Vector3d& point) {
    if (camera.parallel()) return -camera.viewDirection();
    const Eigen::Vector3d d = camera.eye() - point;
    const double len = d.norm();
    return len > 0 ? Eigen::Vector3d(d / len) : Eigen::Vector3d(-camera.viewDirection());
}

double cosOfLimit(double qualityAngleLimitDeg) {
    return std::cos(std::clamp(qualityAngleLimitDeg, 0.0, 89.9) * kDegToRad);
}

// setSampleOnSurface with the face's geometry and the camera's matrices already at hand.
void setSample(Sample& sample, const CameraProjector& camera, FaceIndex face, const FaceGeometry& g,
               const Eigen::Vector3d& point, double cosLimit) {
    const bool degenerate = !(g.normal.squaredNorm() > 0);
    const double cosAngle =
        degenerate ? 0.0 : std::clamp(g.normal.dot(towardsViewer(camera, point)), -1.0, 1.0);
    const bool frontFacing = !degenerate && cosAngle > 0;
    sample.point = point;
    sample.face = std::uint32_t(face.idx());
    sample.normal = g.normal;
    sample.samplingAngle = float(degenerate ? std::numbers::pi / 2 : std::acos(cosAngle));
    sample.footprint = float(camera.pixelFootprint(point));
    // sampleQuality of the stored (float) angle, with cos of the limit computed once per grid.
    sample.quality =
        float(double(sample.footprint) / std::max(std::cos(double(sample.samplingAngle)), cosLimit));
    sample.hit = true;
    sample.admissible = frontFacing;
    sample.valid = frontFacing;
}

// Walks over the mesh from face \p start towards the ray (a visibility walk in the ray's barycentric
// coordinates): in each face the ray's intersection with the face's plane has barycentric coordinates;
// when one is negative the walk crosses the edge opposite the most negative one. Returns the face the
// ray hits and the hit point, or nothing when the walk reaches a border, a face seen from its other side
// (a silhouette: the visible sheet ends there), a face the ray runs parallel to, or \p maxSteps faces.
std::optional<std::pair<FaceIndex, Eigen::Vector3d>> walkToHit(const Mesh& mesh, FaceIndex start,
                                                               const Ray& ray, int maxSteps) {
    FaceIndex f = start;
    double startSign = 0;
    for (int step = 0; step <= maxSteps; ++step) {
        const HalfedgeIndex h0 = mesh.halfedge(f), h1 = mesh.next(h0);
        const Eigen::Vector3d a = toEigen(mesh.point(mesh.source(h0))),
                              b = toEigen(mesh.point(mesh.target(h0))),
                              c = toEigen(mesh.point(mesh.target(h1)));
        const Eigen::Vector3d e1 = b - a, e2 = c - a, pv = ray.direction.cross(e2);
        const double det = e1.dot(pv);
        if (!(std::abs(det) >= 1e-14 * e1.norm() * e2.norm())) return std::nullopt;
        if (step == 0) startSign = det;
        if ((det > 0) != (startSign > 0)) return std::nullopt;
        const Eigen::Vector3d tv = ray.origin - a, qv = tv.cross(e1);
        const double u = tv.dot(pv) / det, v = ray.direction.dot(qv) / det, w = 1.0 - u - v; // of b, c, a
        constexpr double eps = 1e-12;
        if (u >= -eps && v >= -eps && w >= -eps) {
            const double t = e2.dot(qv) / det;
            if (t < 0) return std::nullopt;
            return std::make_pair(f, Eigen::Vector3d(ray.origin + t * ray.direction));
        }
        // The edge opposite the most negative coordinate: a's is b→c (h1), b's is c→a (h2), c's is a→b (h0).
        const HalfedgeIndex exit = (w <= u && w <= v) ? h1 : (u <= v ? mesh.next(h1) : h0);
        const FaceIndex next = mesh.face(mesh.opposite(exit));
        if (next == Mesh::null_face()) return std::nullopt;
        f = next;
    }
    return std::nullopt;
}

void checkBuffers(const FrameBuffers& referenceBuffers) {
    const Camera& camera = referenceBuffers.camera;
    camera.validate();
    const int w = camera.width, h = camera.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    if (referenceBuffers.depth.size() != n || referenceBuffers.faceId.size() != n)
        throw InvalidInputError("The scan buffers hold " + std::to_string(referenceBuffers.depth.size()) +
                                " depth and " + std::to_string(referenceBuffers.faceId.size()) +
                                " face-id values instead of " + std::to_string(n) + " for a " +
                                std::to_string(w) + "x" + std::to_string(h) + " camera.");
}

} // namespace

float sampleQuality(double footprint, double samplingAngle, double qualityAngleLimitDeg) {
    const double cosLimit = std::cos(std::clamp(qualityAngleLimitDeg, 0.0, 89.9) * kDegToRad);
    return float(footprint / std::max(std::cos(samplingAngle), cosLimit));
}

float triangleQuality(const Sample& a, const Sample& b, const Sample& c) {
    return triangleQuality(a.quality, b.quality, c.quality);
}

float triangleQuality(float qa, float qb, float qc) {
    return float((double(qa) + double(qb) + double(qc)) / 3.0);
}

void setSampleOnSurface(Sample& sample, const Mesh& reference, const Camera& camera, FaceIndex face,
                        const Eigen::Vector3d& point, const ScanOptions& options) {
    setSample(sample, CameraProjector(camera), face, faceGeometry(reference, face), point,
              cosOfLimit(options.qualityAngleLimitDeg));
}

void setSampleOnSurface(Sample& sample, const Mesh& reference, const CameraProjector& camera, FaceIndex face,
                        const Eigen::Vector3d& point, const ScanOptions& options) {
    setSample(sample, camera, face, faceGeometry(reference, face), point,
              cosOfLimit(options.qualityAngleLimitDeg));
}

SampleGrid sampleRegularGrid(const FrameBuffers& referenceBuffers, const Mesh& reference,
                             const ScanOptions& options, const Progress& progress) {
    ScanWorkspace workspace;
    return sampleRegularGrid(referenceBuffers, reference, workspace, options, progress);
}

SampleGrid sampleRegularGrid(const FrameBuffers& referenceBuffers, const Mesh& reference,
                             ScanWorkspace& workspace, const ScanOptions& options, const Progress& progress) {
    checkBuffers(referenceBuffers);
    const Camera& camera = referenceBuffers.camera;
    const int w = camera.width, h = camera.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    // The recycled samples of the workspace, if any: every sample is written below.
    SampleGrid grid;
    grid.rows = h;
    grid.cols = w;
    grid.samples = std::exchange(workspace.impl().samples, {});
    detail::resizeWithHugePages(grid.samples, n);
    grid.camera = camera;
    grid.scanId = options.scanId;
    const CameraProjector projector(camera);
    const double cosLimit = cosOfLimit(options.qualityAngleLimitDeg);
    // Rows in contiguous blocks, one per thread (parallel.h); every sample depends only on its pixel, so
    // the grid is the same for any number of blocks. Block 0 runs on this thread and reports progress.
    std::atomic<bool> stop{false};
    const int blocks = detail::rowBlocks(h, 16);
    detail::parallelRows(h, blocks, [&](int block, int rowBegin, int rowEnd) {
        // Row by row: first the faces the row's pixels show (one entry per run of pixels showing the same
        // face, as neighbouring pixels mostly do), then those faces' checks and geometry — lookups in the
        // reference mesh that do not depend on each other, so the processor overlaps their cache misses —
        // then the samples.
        std::vector<FaceIndex> faces;
        std::vector<FaceGeometry> geometry;
        std::vector<std::uint32_t> runOf(static_cast<std::size_t>(w));
        try {
            for (int r = rowBegin; r < rowEnd && !stop.load(std::memory_order_relaxed); ++r) {
                if (block == 0) progress.report(double(r - rowBegin) / double(rowEnd - rowBegin), "Sampling");
                faces.clear();
                for (int c = 0; c < w; ++c) {
                    const std::uint32_t id = referenceBuffers.faceAt(c, r);
                    if (id == FrameBuffers::kNoFace) continue;
                    if (faces.empty() || faces.back() != FaceIndex(id)) faces.push_back(FaceIndex(id));
                    runOf[std::size_t(c)] = std::uint32_t(faces.size() - 1);
                }
                geometry.resize(faces.size());
                for (std::size_t k = 0; k < faces.size(); ++k) {
                    const FaceIndex f = faces[k];
                    if (std::size_t(f.idx()) >= reference.num_faces() || reference.is_removed(f) ||
                        reference.degree(f) != 3)
                        throw InvalidInputError("The face-id buffer names face " + std::to_string(f.idx()) +
                                                ", which is not a triangle of the reference mesh: the "
                                                "buffers were not rendered from this mesh.");
                    geometry[k] = faceGeometry(reference, f);
                }
                for (int c = 0; c < w; ++c) {
                    Sample& s = grid.at(r, c);
                    const std::uint32_t id = referenceBuffers.faceAt(c, r);
                    if (id == FrameBuffers::kNoFace) {
                        s = Sample{};
                        s.screen = {c + 0.5, r + 0.5};
                        continue;
                    }
                    s.screen = {c + 0.5, r + 0.5};
                    const FaceIndex f(id);
                    const FaceGeometry& g = geometry[runOf[std::size_t(c)]];
                    // The pixel centre at its depth, and the viewing ray through it (s.screen).
                    const auto [unprojected, ray] =
                        projector.unprojectPixelCentreWithRay(c, r, referenceBuffers.depthAt(c, r));
                    // Snap along the viewing ray onto the face's plane (removes depth quantisation).
                    Eigen::Vector3d point = unprojected;
                    const double denom = g.normal.dot(ray.direction);
                    if (g.normal.squaredNorm() > 0 && std::abs(denom) > 1e-12) {
                        const Eigen::Vector3d snapped =
                            ray.origin + (g.normal.dot(g.a - ray.origin) / denom) * ray.direction;
                        const double limit =
                            options.maxSnapFootprints * projector.pixelFootprint(unprojected);
                        if (snapped.allFinite() && (snapped - unprojected).norm() <= limit) point = snapped;
                    }
                    setSample(s, projector, f, g, point, cosLimit);
                }
            }
        } catch (...) {
            stop.store(true, std::memory_order_relaxed); // the other blocks stop early; this one rethrows
            throw;
        }
    });
    progress.report(1.0, "Sampling");
    return grid;
}

double latticeSpacingPixels(const Camera& camera, const ScanOptions& options) {
    if (!(options.spacingWorld > 0)) return options.spacingPixels;
    const double footprint = camera.pixelFootprint(camera.focal);
    const double s = options.spacingWorld / footprint;
    if (!(std::isfinite(s) && s >= 0.25 && s <= 1024))
        throw InvalidInputError("The lattice spacing of " + std::to_string(options.spacingWorld) +
                                " world units is " + std::to_string(s) +
                                " pixels at the camera's focal point; it must be 0.25 to 1024 pixels.");
    return s;
}

FaceIndex idBufferHint(const FrameBuffers& buffers, const Mesh& reference, const Eigen::Vector2d& screen) {
    const int w = buffers.camera.width, h = buffers.camera.height;
    const int px = std::clamp(int(std::floor(screen.x())), 0, w - 1);
    const int py = std::clamp(int(std::floor(screen.y())), 0, h - 1);
    const std::uint32_t id = buffers.faceAt(px, py);
    const std::size_t faceCount = reference.number_of_faces() + reference.number_of_removed_faces();
    return (id != FrameBuffers::kNoFace && id < faceCount) ? FaceIndex(id) : Mesh::null_face();
}

std::optional<IdBufferHit> hitFromIdBuffer(const FrameBuffers& buffers, const Mesh& reference, FaceIndex hint,
                                           const Ray& ray, const Eigen::Vector2d& screen, int maxWalkSteps) {
    // Most rays hit the hint face (a sample lies in the pixel whose centre shows it); the walk tests it
    // first, then moves over the surface towards the ray (faces smaller than a pixel).
    if (const auto walked = walkToHit(reference, hint, ray, maxWalkSteps))
        return IdBufferHit{walked->first, walked->second, walked->first == hint};
    // The faces under the 8 neighbouring pixels (the walk met a border or a silhouette): nearest hit.
    const int w = buffers.camera.width, h = buffers.camera.height;
    const int px = std::clamp(int(std::floor(screen.x())), 0, w - 1);
    const int py = std::clamp(int(std::floor(screen.y())), 0, h - 1);
    const std::size_t faceCount = reference.number_of_faces() + reference.number_of_removed_faces();
    std::optional<IdBufferHit> best;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int x = px + dx, y = py + dy;
            if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= w || y >= h) continue;
            const std::uint32_t nid = buffers.faceAt(x, y);
            if (nid == FrameBuffers::kNoFace || nid >= faceCount || FaceIndex(nid) == hint) continue;
            if (const auto q = walkToHit(reference, FaceIndex(nid), ray, 0);
                q &&
                (!best || (q->second - ray.origin).squaredNorm() < (best->point - ray.origin).squaredNorm()))
                best = IdBufferHit{FaceIndex(nid), q->second, false};
        }
    return best;
}

SampleGrid sampleLattice(const FrameBuffers& referenceBuffers, const Mesh& reference,
                         ScanWorkspace& workspace, const ScanOptions& options, const Progress& progress) {
    const double spacing = latticeSpacingPixels(referenceBuffers.camera, options);
    if (options.lattice == Lattice::Square && spacing == 1.0)
        return sampleRegularGrid(referenceBuffers, reference, workspace, options, progress);
    checkBuffers(referenceBuffers);
    const Camera& camera = referenceBuffers.camera;
    const int w = camera.width, h = camera.height;
    const bool triangular = options.lattice == Lattice::Triangular;
    // The sheared lattice (see scan.h): x = x0 + (c − shear·r)·s, y = y0 + r·dy.
    const double shear = triangular ? 0.5 : 0.0;
    const double dy = triangular ? spacing * std::sqrt(3.0) / 2.0 : spacing;
    const int rows = std::max(1, int(std::floor(double(h) / dy)));
    const int rowLength = std::max(1, int(std::floor(double(w) / spacing)));
    const double y0 = (double(h) - double(rows - 1) * dy) / 2.0;
    const double x0 = (double(w) - double(rowLength - 1) * spacing) / 2.0;
    const int cols = rowLength + int(std::ceil(shear * double(rows - 1))) + (triangular ? 1 : 0);
    SampleGrid grid;
    grid.rows = rows;
    grid.cols = cols;
    grid.samples = std::exchange(workspace.impl().samples, {});
    detail::resizeWithHugePages(grid.samples, std::size_t(rows) * std::size_t(cols));
    grid.camera = camera;
    grid.scanId = options.scanId;
    const CameraProjector projector(camera);
    const double cosLimit = cosOfLimit(options.qualityAngleLimitDeg);
    constexpr int kMaxWalkSteps = 24; // as the fishbone scan's
    std::atomic<bool> stop{false};
    const int blocks = detail::rowBlocks(rows, 16);
    detail::parallelRows(rows, blocks, [&](int block, int rowBegin, int rowEnd) {
        try {
            for (int r = rowBegin; r < rowEnd && !stop.load(std::memory_order_relaxed); ++r) {
                if (block == 0) progress.report(double(r - rowBegin) / double(rowEnd - rowBegin), "Sampling");
                for (int c = 0; c < cols; ++c) {
                    Sample& s = grid.at(r, c);
                    s = Sample{};
                    s.screen = {x0 + (double(c) - shear * double(r)) * spacing, y0 + double(r) * dy};
                    if (!(s.screen.x() >= 0 && s.screen.x() < w && s.screen.y() >= 0 && s.screen.y() < h))
                        continue;
                    const std::uint32_t id = referenceBuffers.faceAt(int(s.screen.x()), int(s.screen.y()));
                    if (id == FrameBuffers::kNoFace) continue;
                    const FaceIndex f(id);
                    if (std::size_t(id) >= reference.num_faces() || reference.is_removed(f) ||
                        reference.degree(f) != 3)
                        throw InvalidInputError("The face-id buffer names face " + std::to_string(id) +
                                                ", which is not a triangle of the reference mesh: the "
                                                "buffers were not rendered from this mesh.");
                    const Ray ray = projector.ray(s.screen.x(), s.screen.y());
                    const auto hit =
                        hitFromIdBuffer(referenceBuffers, reference, f, ray, s.screen, kMaxWalkSteps);
                    if (!hit) continue;
                    setSample(s, projector, hit->face, faceGeometry(reference, hit->face), hit->point,
                              cosLimit);
                    s.quality = float(double(s.quality) * spacing);
                }
            }
        } catch (...) {
            stop.store(true, std::memory_order_relaxed);
            throw;
        }
    });
    progress.report(1.0, "Sampling");
    return grid;
}

} // namespace fss
