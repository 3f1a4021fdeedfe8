#include "fss/scan.h"

#include "fss/camera_projector.h"
#include "fss/error.h"

#include "base/huge_pages.h"
#include "base/parallel_rows.h"
#include "scan/scan_workspace_impl.h"

#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

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

// The inverse of the screen Jacobian of the plane through \p point with normal \p normal, in an orthonormal
// basis of the plane: screen vector w ↦ tangent coordinates of the plane vector that projects onto w
// (the projection linearised at the point, a step of one pixel footprint). False when seen edge-on.
bool planeFromScreen(const CameraProjector& camera, const Eigen::Vector3d& point,
                     const Eigen::Vector3d& normal, Eigen::Matrix2d& inverse) {
    const Eigen::Vector3d t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
    const double eps = camera.pixelFootprint(point);
    if (!(eps > 0) || !std::isfinite(eps)) return false;
    const Eigen::Vector2d p0 = camera.project(point).head<2>();
    Eigen::Matrix2d j;
    j.col(0) = (camera.project(point + eps * t1).head<2>() - p0) / eps;
    j.col(1) = (camera.project(point + eps * t2).head<2>() - p0) / eps;
    const double det = j.determinant();
    if (!(std::abs(det) > 1e-9 * j.squaredNorm()) || !std::isfinite(det)) return false;
    inverse = j.inverse();
    return true;
}

// The orthogonal matrix closest to \p n (the polar factor U·Vᵀ of its SVD), in closed form: the rotation
// maximising tr(Qᵀn) when det n ≥ 0, else the reflection doing so (a 2 × 2 rotation by t is (cos t, −sin t;
// sin t, cos t), whose trace product is cos t·(n00 + n11) + sin t·(n10 − n01); a reflection (cos t, sin t;
// sin t, −cos t) gives cos t·(n00 − n11) + sin t·(n01 + n10)). Zero for a zero matrix.
Eigen::Matrix2d closestOrthogonal(const Eigen::Matrix2d& n) {
    Eigen::Matrix2d q;
    if (n.determinant() >= 0) {
        const double c = n(0, 0) + n(1, 1), s = n(1, 0) - n(0, 1), len = std::hypot(c, s);
        if (!(len > 0)) return Eigen::Matrix2d::Zero();
        q << c / len, -s / len, s / len, c / len;
    } else {
        const double c = n(0, 0) - n(1, 1), s = n(0, 1) + n(1, 0), len = std::hypot(c, s);
        q << c / len, s / len, s / len, -c / len;
    }
    return q;
}

// \p m with its singular values clamped to at most \p limit, in closed form: m = R(φ)·diag(σ1, σ2)·R(θ) with
// σ1 = p + q, σ2 = p − q (negative when det m < 0), p = |(m00 + m11, m10 − m01)| / 2, q = |(m00 − m11, m10 +
// m01)| / 2; only σ1 can exceed the limit unless both do.
Eigen::Matrix2d withSingularValuesAtMost(const Eigen::Matrix2d& m, double limit) {
    const double e = 0.5 * (m(0, 0) + m(1, 1)), f = 0.5 * (m(0, 0) - m(1, 1)), g = 0.5 * (m(1, 0) + m(0, 1)),
                 h = 0.5 * (m(1, 0) - m(0, 1));
    const double p = std::hypot(e, h), q = std::hypot(f, g);
    const double s1 = p + q, s2 = p - q;
    if (s1 <= limit) return m; // |σ2| ≤ σ1
    const double a1 = std::atan2(g, f), a2 = std::atan2(h, e);
    const double theta = 0.5 * (a2 - a1), phi = 0.5 * (a2 + a1);
    const double t1 = std::min(s1, limit), t2 = std::clamp(s2, -limit, limit);
    const Eigen::Matrix2d u = Eigen::Rotation2Dd(phi).toRotationMatrix(),
                          v = Eigen::Rotation2Dd(theta).toRotationMatrix();
    return u * Eigen::Vector2d(t1, t2).asDiagonal() * v;
}

// The basis warpLatticeToSurface wants at pixel (x, y), which shows face \p face at depth \p depth: the
// one whose triangle is equilateral on the face's plane (\p equilateral mapped by the plane's linearised
// screen map), turned to be closest to the affine lattice's basis \p affine (\p towardsEquilateral =
// affine · equilateral⁻¹). False (and \p local untouched) where the face is back-facing, seen edge-on or
// the basis would turn the lattice over.
bool surfaceBasisAt(const CameraProjector& projector, const Mesh& reference, FaceIndex face, int x, int y,
                    float depth, const Eigen::Matrix2d& equilateral,
                    const Eigen::Matrix2d& towardsEquilateral, const Eigen::Matrix2d& affine,
                    Eigen::Matrix2d& local) {
    const FaceGeometry g = faceGeometry(reference, face);
    const auto [point, ray] = projector.unprojectPixelCentreWithRay(x, y, depth);
    if (!(g.normal.squaredNorm() > 0) || !(g.normal.dot(ray.direction) < 0)) return false;
    Eigen::Matrix2d m; // screen pixels -> tangent coordinates, world units
    if (!planeFromScreen(projector, point, g.normal, m)) return false;
    const double footprint = projector.pixelFootprint(point);
    // In footprints, and no slant beyond 75° (the mask drops what is steeper anyway).
    const Eigen::Matrix2d mf = withSingularValuesAtMost(m / footprint, 1.0 / std::cos(75.0 * kDegToRad));
    // The orthogonal Q closest to mf·K·R (polar decomposition): the wanted basis mf⁻¹·Q·E is then
    // equilateral on the plane and as near the affine one as the plane allows. (Q is a reflection where mf
    // reverses the orientation — the tangent basis's handedness against the screen's — so that the wanted
    // basis keeps the affine one's.)
    const Eigen::Matrix2d q = closestOrthogonal(mf * towardsEquilateral);
    const Eigen::Matrix2d result = mf.inverse() * q * equilateral;
    if (!result.allFinite() || !(result.determinant() * affine.determinant() > 0)) return false;
    local = result;
    return true;
}

// The wanted basis of every pixel and its weight (warpLatticeToSurface); outside the image the affine
// basis with a small weight.
struct WantedBases {
    int width, height;
    const Eigen::Matrix2d& affine;
    const std::vector<Eigen::Matrix2d>& wanted;
    const std::vector<double>& weight;

    const Eigen::Matrix2d& at(const Eigen::Vector2d& p, double& wt) const {
        const int x = int(std::floor(p.x())), y = int(std::floor(p.y()));
        if (x < 0 || y < 0 || x >= width || y >= height) {
            wt = 0.01;
            return affine;
        }
        const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
        wt = weight[i];
        return wanted[i];
    }
};

// The grid of every k-th row and column of a lattice of latticeRows × latticeCols samples, wide enough to
// hold its last row and column; node (r, c) is sample (k·r, k·c), index r·cols + c.
struct FitGrid {
    int k, rows, cols;
    FitGrid(int step, int latticeRows, int latticeCols)
        : k(step), rows((latticeRows - 1 + step - 1) / step + 1),
          cols((latticeCols - 1 + step - 1) / step + 1) {}
    int size() const { return rows * cols; }
    // The nodes of the affine lattice origin + c·a + r·b, one row each.
    Eigen::MatrixX2d affinePositions(const Eigen::Vector2d& origin, const LatticeBasis& basis) const {
        Eigen::MatrixX2d p(size(), 2);
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c)
                p.row(r * cols + c) =
                    (origin + double(k * c) * basis.a + double(k * r) * basis.b).transpose();
        return p;
    }
    // Sample (r, c) of the lattice, bilinear in (row, column) between the nodes \p phi.
    Eigen::Vector2d interpolate(const Eigen::MatrixX2d& phi, int r, int c) const {
        const int i = std::min(r / k, rows - 2), j = std::min(c / k, cols - 2);
        const double u = double(r - k * i) / k, v = double(c - k * j) / k;
        return ((1 - u) * (1 - v) * phi.row(i * cols + j) + (1 - u) * v * phi.row(i * cols + j + 1) +
                u * (1 - v) * phi.row((i + 1) * cols + j) + u * v * phi.row((i + 1) * cols + j + 1))
            .transpose();
    }
};

struct FitSystem {
    Eigen::SparseMatrix<double> matrix;
    Eigen::MatrixX2d rhs;
};

// The normal equations of one round of warpLatticeToSurface's fit on grid \p g: every edge of the grid
// (a, b, a + b in (row, column)) pulled towards the wanted bases read along it under the positions \p phi,
// with their weights, and every node weakly towards \p anchor (keeps the system definite and the grid in
// place). The same pattern for any positions.
FitSystem assembleFit(const FitGrid& g, const Eigen::MatrixX2d& phi, const Eigen::MatrixX2d& anchor,
                      const WantedBases& field) {
    constexpr double kAnchor = 1e-5;
    constexpr int steps[3][2] = {{0, 1}, {1, 0}, {1, 1}}; // (dr, dc) of the grid's edges a, b, a + b
    const int n = g.size();
    std::vector<Eigen::Vector2d> edgeTarget(std::size_t(n) * 3);
    std::vector<double> edgeWeight(std::size_t(n) * 3, 0.0);
    // Every edge's target step and weight (each depends only on the positions: rows of nodes in blocks, one
    // per thread, give the same result for any number of threads), then the system.
    detail::parallelRows(g.rows, detail::rowBlocks(g.rows, 8), [&](int, int rowBegin, int rowEnd) {
        for (int r = rowBegin; r < rowEnd; ++r)
            for (int c = 0; c < g.cols; ++c)
                for (int e = 0; e < 3; ++e) {
                    const int r2 = r + steps[e][0], c2 = c + steps[e][1];
                    if (r2 >= g.rows || c2 >= g.cols) continue;
                    const int i = r * g.cols + c, j = r2 * g.cols + c2;
                    // The wanted bases along the edge, averaged with their weights.
                    Eigen::Matrix2d local = Eigen::Matrix2d::Zero();
                    double wt = 0;
                    for (int k = 0; k < g.k; ++k) {
                        const double t = (double(k) + 0.5) / double(g.k);
                        double wk = 0;
                        const Eigen::Matrix2d& m =
                            field.at(((1 - t) * phi.row(i) + t * phi.row(j)).transpose(), wk);
                        local += wk * m;
                        wt += wk;
                    }
                    local /= wt;
                    // Sample (r, c) sits at o + c·a + r·b: a step of dc columns and dr rows is dc·a + dr·b.
                    const std::size_t at = std::size_t(i) * 3 + std::size_t(e);
                    edgeTarget[at] = double(g.k) * (double(steps[e][1]) * local.col(0) +
                                                    double(steps[e][0]) * local.col(1));
                    edgeWeight[at] = wt / double(g.k);
                }
    });
    // Node (r, c) meets the edges e of itself and of (r, c − 1) (e = 0), (r − 1, c) (e = 1), (r − 1, c − 1)
    // (e = 2): its row of the matrix (a column: the matrix is symmetric) in increasing order of index, and
    // its right-hand side (the edge's target step pulls its end j towards i + step).
    const auto weightOf = [&](int r, int c, int e) {
        return r >= 0 && c >= 0 ? edgeWeight[std::size_t(r * g.cols + c) * 3 + std::size_t(e)] : 0.0;
    };
    FitSystem system;
    system.rhs = kAnchor * anchor;
    system.matrix.resize(n, n);
    system.matrix.reserve(Eigen::VectorXi::Constant(n, 7));
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
            const int i = r * g.cols + c;
            // (dr, dc, edge of the neighbour or of this node) in increasing order of the neighbour's index.
            const double w[6] = {weightOf(r - 1, c - 1, 2), weightOf(r - 1, c, 1), weightOf(r, c - 1, 0),
                                 weightOf(r, c, 0),         weightOf(r, c, 1),     weightOf(r, c, 2)};
            const int at[6] = {i - g.cols - 1, i - g.cols, i - 1, i + 1, i + g.cols, i + g.cols + 1};
            double diagonal = kAnchor;
            for (int k = 0; k < 6; ++k)
                diagonal += w[k];
            for (int k = 0; k < 3; ++k)
                if (w[k] != 0) system.matrix.insert(at[k], i) = -w[k];
            system.matrix.insert(i, i) = diagonal;
            for (int k = 3; k < 6; ++k)
                if (w[k] != 0) system.matrix.insert(at[k], i) = -w[k];
            for (int k = 0; k < 3; ++k) { // edges ending here: from the neighbours before
                const std::size_t e = std::size_t(at[k]) * 3 + std::size_t(2 - k);
                if (w[k] != 0) system.rhs.row(i) += w[k] * edgeTarget[e].transpose();
            }
            for (int k = 0; k < 3; ++k) { // edges starting here
                const std::size_t e = std::size_t(i) * 3 + std::size_t(k);
                if (w[3 + k] != 0) system.rhs.row(i) -= w[3 + k] * edgeTarget[e].transpose();
            }
        }
    system.matrix.makeCompressed();
    return system;
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

std::vector<Eigen::Vector2d> warpLatticeToSurface(const FrameBuffers& referenceBuffers, const Mesh& reference,
                                                  double spacing, const LatticeBasis& basis,
                                                  const Eigen::Vector2d& origin, int rows, int cols) {
    checkBuffers(referenceBuffers);
    std::vector<Eigen::Vector2d> out(std::size_t(std::max(rows, 0)) * std::size_t(std::max(cols, 0)));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            out[std::size_t(r) * std::size_t(cols) + std::size_t(c)] =
                origin + double(c) * basis.a + double(r) * basis.b;
    if (rows < 2 || cols < 2) return out;
    const Camera& camera = referenceBuffers.camera;
    const CameraProjector projector(camera);
    const int w = camera.width, h = camera.height;
    // The wanted basis [a' b'] per pixel (column-major 2 × 2) and its weight.
    Eigen::Matrix2d affine;
    affine.col(0) = basis.a;
    affine.col(1) = basis.b;
    Eigen::Matrix2d equilateral;
    equilateral.col(0) = spacing * Eigen::Vector2d(1, 0);
    equilateral.col(1) = spacing * Eigen::Vector2d(-0.5, std::sqrt(3.0) / 2.0);
    const Eigen::Matrix2d towardsEquilateral = affine * equilateral.inverse(); // K·R of the chosen lattice
    std::vector<Eigen::Matrix2d> wanted(std::size_t(w) * std::size_t(h), affine);
    std::vector<double> weight(wanted.size(), 0.01);
    const std::size_t faceCount = reference.number_of_faces() + reference.number_of_removed_faces();
    // Every pixel's basis depends only on that pixel: rows in blocks, one per thread, give the same result
    // for any number of threads.
    detail::parallelRows(h, detail::rowBlocks(h, 16), [&](int, int rowBegin, int rowEnd) {
        for (int y = rowBegin; y < rowEnd; ++y)
            for (int x = 0; x < w; ++x) {
                const std::uint32_t id = referenceBuffers.faceAt(x, y);
                if (id == FrameBuffers::kNoFace || id >= faceCount || reference.is_removed(FaceIndex(id)) ||
                    reference.degree(FaceIndex(id)) != 3)
                    continue;
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                if (surfaceBasisAt(projector, reference, FaceIndex(id), x, y, referenceBuffers.depthAt(x, y),
                                   equilateral, towardsEquilateral, affine, wanted[i]))
                    weight[i] = 1.0;
            }
    });
    const WantedBases field{w, h, affine, wanted, weight};
    // The fit is made on a coarse grid, every kFit-th row and column (the warp is smooth; the solve costs
    // ~1/16 of the fine grid's), and the fine positions interpolated bilinearly in (row, column). Its
    // rounds (the bases re-read under the moved edges) run first on a grid twice as coarse, solved directly
    // (LDLᵀ, the pattern ordered once); the last round, on the kFit grid, starts from that solution
    // interpolated, and a fixed number of conjugate-gradient steps corrects what the coarser grid could not
    // resolve (issue #20: three rounds on the kFit grid by conjugate gradients to a 1e-7 residual, ~470
    // steps each, cost 0.6 s a scan; this gives the same quality on the tuning meshes, see the report).
    constexpr int kFit = 4, kCoarseRounds = 2, kFineIterations = 50;
    const FitGrid coarse(2 * kFit, rows, cols), fine(kFit, rows, cols);
    const Eigen::MatrixX2d coarseAnchor = coarse.affinePositions(origin, basis);
    Eigen::MatrixX2d coarsePhi = coarseAnchor;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    for (int round = 0; round < kCoarseRounds; ++round) {
        const FitSystem system = assembleFit(coarse, coarsePhi, coarseAnchor, field);
        if (round == 0) ldlt.analyzePattern(system.matrix);
        ldlt.factorize(system.matrix);
        if (ldlt.info() == Eigen::Success) {
            const Eigen::MatrixX2d x = ldlt.solve(system.rhs);
            if (x.allFinite()) coarsePhi = x;
        }
    }
    const Eigen::MatrixX2d anchor = fine.affinePositions(origin, basis);
    Eigen::MatrixX2d phi(fine.size(), 2);
    for (int r = 0; r < fine.rows; ++r)
        for (int c = 0; c < fine.cols; ++c)
            phi.row(r * fine.cols + c) = coarse.interpolate(coarsePhi, kFit * r, kFit * c).transpose();
    {
        const FitSystem system = assembleFit(fine, phi, anchor, field);
        Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
        cg.setMaxIterations(kFineIterations);
        cg.setTolerance(1e-7);
        cg.compute(system.matrix);
        for (int k = 0; k < 2; ++k) {
            const Eigen::VectorXd x = cg.solveWithGuess(system.rhs.col(k), phi.col(k));
            if (x.allFinite()) phi.col(k) = x;
        }
    }
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            out[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = fine.interpolate(phi, r, c);
    return out;
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
        if (options.warpToSurface)
            warped = warpLatticeToSurface(referenceBuffers, reference, spacing, basis, origin, rows, cols);
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
