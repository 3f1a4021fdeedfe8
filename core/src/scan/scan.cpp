#include "fss/scan.h"

#include "fss/camera_projector.h"
#include "fss/error.h"

#include "base/huge_pages.h"
#include "base/parallel_rows.h"
#include "scan/scan_geometry.h"
#include "scan/scan_workspace_impl.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fss {
namespace {

using detail::checkBuffers;
using detail::FaceGeometry;
using detail::faceGeometry;
using detail::kDegToRad;
using detail::planeFromScreen;
using detail::toEigen;

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

// Smallest angle (degrees) of the triangle with edge vectors u, v, u + v.
double smallestAngleDeg(const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    double l[3] = {u.squaredNorm(), v.squaredNorm(), (u + v).squaredNorm()};
    std::sort(l, l + 3);
    if (!(l[0] > 0)) return 0.0;
    const double c = (l[1] + l[2] - l[0]) / (2.0 * std::sqrt(l[1] * l[2]));
    return std::acos(std::clamp(c, -1.0, 1.0)) / kDegToRad;
}

} // namespace

double latticeAngleOnPlane(const CameraProjector& camera, const Eigen::Vector3d& point,
                           const Eigen::Vector3d& normal, const LatticeBasis& basis) {
    Eigen::Matrix2d m;
    if (!planeFromScreen(camera, point, normal, m)) return 0.0;
    return smallestAngleDeg(m * basis.a, m * basis.b);
}

LatticeBasis chooseAdaptiveLattice(const FrameBuffers& referenceBuffers, const Mesh& reference,
                                   double spacing, double countFromDeg) {
    checkBuffers(referenceBuffers);
    const Camera& camera = referenceBuffers.camera;
    const CameraProjector projector(camera);
    const int w = camera.width, h = camera.height;
    // A fixed subsample of the covered front-facing pixels: the inverse screen Jacobian of each.
    const int stride = std::max(1, int(std::ceil(std::sqrt(double(w) * double(h) / 3000.0))));
    std::vector<Eigen::Matrix2d> planes;
    const std::size_t faceCount = reference.number_of_faces() + reference.number_of_removed_faces();
    for (int y = stride / 2; y < h; y += stride)
        for (int x = stride / 2; x < w; x += stride) {
            const std::uint32_t id = referenceBuffers.faceAt(x, y);
            if (id == FrameBuffers::kNoFace || id >= faceCount || reference.is_removed(FaceIndex(id)) ||
                reference.degree(FaceIndex(id)) != 3)
                continue;
            const FaceGeometry g = faceGeometry(reference, FaceIndex(id));
            const auto [point, ray] =
                projector.unprojectPixelCentreWithRay(x, y, referenceBuffers.depthAt(x, y));
            if (!(g.normal.squaredNorm() > 0) || !(g.normal.dot(ray.direction) < 0)) continue;
            Eigen::Matrix2d m;
            if (planeFromScreen(projector, point, g.normal, m)) planes.push_back(m);
        }
    auto rotation = [](double deg) {
        const double t = deg * kDegToRad;
        Eigen::Matrix2d r;
        r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
        return r;
    };
    LatticeBasis best;
    best.a = {spacing, 0};
    best.b = spacing * Eigen::Vector2d(-0.5, std::sqrt(3.0) / 2.0);
    double bestScore = 0;
    bool any = false;
    for (int tilt = 0; tilt <= 60; tilt += 10)
        for (int dir = 0; dir < (tilt == 0 ? 1 : 12); ++dir)
            for (int turn = 0; turn < 8; ++turn) {
                const Eigen::Matrix2d rd = rotation(15.0 * dir);
                const Eigen::Matrix2d k =
                    rd * Eigen::Vector2d(1.0, std::cos(tilt * kDegToRad)).asDiagonal() * rd.transpose();
                const Eigen::Matrix2d rt = rotation(7.5 * turn);
                LatticeBasis c;
                c.a = spacing * k * rt * Eigen::Vector2d(1, 0);
                c.b = spacing * k * rt * Eigen::Vector2d(-0.5, std::sqrt(3.0) / 2.0);
                double score = 0;
                for (const Eigen::Matrix2d& m : planes) {
                    const double g = smallestAngleDeg(m * c.a, m * c.b);
                    if (g >= countFromDeg) score += g - 30.0;
                }
                if (!any || score > bestScore + 1e-9 * (1 + std::abs(bestScore))) {
                    any = true;
                    bestScore = score;
                    best = c;
                }
            }
    return best;
}

std::size_t applyLatticeAngleMask(SampleGrid& grid, double minAngleDeg, bool localBasis) {
    if (!(minAngleDeg > 0) || grid.rows < 2 || grid.cols < 2) return 0;
    const Eigen::Vector2d o = grid.at(0, 0).screen;
    LatticeBasis basis;
    basis.a = grid.at(0, 1).screen - o;
    basis.b = grid.at(1, 1).screen - o - basis.a;
    const CameraProjector projector(grid.camera);
    std::size_t masked = 0;
    for (int r = 0; r < grid.rows; ++r)
        for (int c = 0; c < grid.cols; ++c) {
            Sample& s = grid.at(r, c);
            if (!s.admissible) continue;
            if (localBasis) { // the triangle (r, c), (r, c + 1), (r + 1, c + 1), or the one before at the end
                const int r0 = std::min(r, grid.rows - 2), c0 = std::min(c, grid.cols - 2);
                basis.a = grid.at(r0, c0 + 1).screen - grid.at(r0, c0).screen;
                basis.b = grid.at(r0 + 1, c0 + 1).screen - grid.at(r0, c0 + 1).screen;
            }
            if (latticeAngleOnPlane(projector, s.point, s.normal, basis) >= minAngleDeg) continue;
            s.admissible = s.valid = false;
            ++masked;
        }
    return masked;
}

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

namespace {

// Keeps of the warped lattice \p positions (rows × cols, row-major) the rectangle of rows and columns whose
// samples fall in the w × h image and two more around it (the lattice-angle mask reads a sample's next row
// and column): the samples beyond miss the image, and the warp's margin (sampleLattice) doubles the
// lattice, so every later stage would visit twice the samples for the same patch.
void cropToImage(std::vector<Eigen::Vector2d>& positions, int w, int h, int& rows, int& cols) {
    int r0 = rows, r1 = -1, c0 = cols, c1 = -1;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const Eigen::Vector2d& p = positions[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
            if (!(p.x() >= 0 && p.x() < w && p.y() >= 0 && p.y() < h)) continue;
            r0 = std::min(r0, r);
            r1 = std::max(r1, r);
            c0 = std::min(c0, c);
            c1 = std::max(c1, c);
        }
    if (r1 < 0) return; // nothing in the image: the lattice as it is
    constexpr int kMargin = 2;
    r0 = std::max(0, r0 - kMargin);
    c0 = std::max(0, c0 - kMargin);
    r1 = std::min(rows - 1, r1 + kMargin);
    c1 = std::min(cols - 1, c1 + kMargin);
    const int newCols = c1 - c0 + 1;
    std::size_t at = 0; // rows only move forward: in place
    for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c)
            positions[at++] = positions[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
    positions.resize(at);
    rows = r1 - r0 + 1;
    cols = newCols;
}

} // namespace

SampleGrid sampleLattice(const FrameBuffers& referenceBuffers, const Mesh& reference,
                         ScanWorkspace& workspace, const ScanOptions& options, const Progress& progress) {
    const double spacing = latticeSpacingPixels(referenceBuffers.camera, options);
    if (options.lattice == Lattice::Square && spacing == 1.0)
        return sampleRegularGrid(referenceBuffers, reference, workspace, options, progress);
    checkBuffers(referenceBuffers);
    const Camera& camera = referenceBuffers.camera;
    const int w = camera.width, h = camera.height;
    // Sample (r, c) at origin + c·a + r·b. The triangular lattice is stored sheared (see scan.h):
    // x = x0 + (c − r/2)·s, y = y0 + r·(√3/2)·s; the square one x = x0 + c·s, y = y0 + r·s.
    Eigen::Vector2d origin, a, b;
    int rows = 0, cols = 0;
    std::vector<Eigen::Vector2d> warped; // ScanOptions::warpToSurface: every sample's screen position
    if (options.lattice == Lattice::Adaptive) {
        const LatticeBasis basis =
            chooseAdaptiveLattice(referenceBuffers, reference, spacing,
                                  options.minLatticeAngleDeg > 0 ? options.minLatticeAngleDeg : 35.0);
        a = basis.a;
        b = basis.b;
        // The lattice coordinates of the image's corners bound the rows and columns that cover it.
        Eigen::Matrix2d m;
        m.col(0) = a;
        m.col(1) = b;
        const Eigen::Matrix2d inv = m.inverse();
        const Eigen::Vector2d centre(0.5 * w, 0.5 * h);
        double cMin = 0, cMax = 0, rMin = 0, rMax = 0;
        for (const Eigen::Vector2d& corner :
             {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)}) {
            const Eigen::Vector2d cr = inv * (corner - centre);
            cMin = std::min(cMin, cr.x());
            cMax = std::max(cMax, cr.x());
            rMin = std::min(rMin, cr.y());
            rMax = std::max(rMax, cr.y());
        }
        // A warped lattice may gather its rows and columns where the surface is slanted: a margin of a
        // quarter of them on each side keeps the image covered (samples outside it miss).
        const double margin = options.warpToSurface ? 0.25 : 0.0;
        const double c0 = std::floor(cMin - margin * (cMax - cMin)),
                     r0 = std::floor(rMin - margin * (rMax - rMin));
        cols = int(std::ceil(cMax + margin * (cMax - cMin)) - c0) + 1;
        rows = int(std::ceil(rMax + margin * (rMax - rMin)) - r0) + 1;
        origin = centre + c0 * a + r0 * b;
        if (options.warpToSurface) {
            warped = warpLatticeToSurface(referenceBuffers, reference, spacing, basis, origin, rows, cols,
                                          options.warpFollowsFit);
            cropToImage(warped, w, h, rows, cols);
        }
    } else {
        const bool triangular = options.lattice == Lattice::Triangular;
        const double shear = triangular ? 0.5 : 0.0;
        const double dy = triangular ? spacing * std::sqrt(3.0) / 2.0 : spacing;
        rows = std::max(1, int(std::floor(double(h) / dy)));
        const int rowLength = std::max(1, int(std::floor(double(w) / spacing)));
        origin = {(double(w) - double(rowLength - 1) * spacing) / 2.0,
                  (double(h) - double(rows - 1) * dy) / 2.0};
        cols = rowLength + int(std::ceil(shear * double(rows - 1))) + (triangular ? 1 : 0);
        a = {spacing, 0};
        b = {-shear * spacing, dy};
    }
    const bool adaptive = options.lattice == Lattice::Adaptive;
    const double shear = -b.x() / spacing, dy = b.y();
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
                    s.screen = !warped.empty() ? warped[std::size_t(r) * std::size_t(cols) + std::size_t(c)]
                               : adaptive
                                   ? Eigen::Vector2d(origin + double(c) * a + double(r) * b)
                                   : Eigen::Vector2d(origin.x() + (double(c) - shear * double(r)) * spacing,
                                                     origin.y() + double(r) * dy);
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
