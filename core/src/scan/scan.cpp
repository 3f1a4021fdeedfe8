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
    const Camera& camera = referenceBuffers.camera;
    camera.validate();
    const int w = camera.width, h = camera.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    if (referenceBuffers.depth.size() != n || referenceBuffers.faceId.size() != n)
        throw InvalidInputError("The scan buffers hold " + std::to_string(referenceBuffers.depth.size()) +
                                " depth and " + std::to_string(referenceBuffers.faceId.size()) +
                                " face-id values instead of " + std::to_string(n) + " for a " +
                                std::to_string(w) + "x" + std::to_string(h) + " camera.");
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

} // namespace fss
