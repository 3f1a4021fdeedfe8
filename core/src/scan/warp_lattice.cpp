#include "fss/scan.h"

#include "fss/camera_projector.h"

#include "base/parallel_rows.h"
#include "scan/scan_geometry.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <vector>

// The adaptive lattice warped to the surface (ScanOptions::warpToSurface, issue #20): per-pixel bases
// equilateral on the surface, fitted by least squares on a coarse grid of the lattice.

namespace fss {
namespace {

using detail::faceGeometry;
using detail::FaceGeometry;
using detail::kDegToRad;
using detail::planeFromScreen;

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
                    Eigen::Matrix2d& local, Eigen::Matrix2d& toTangent) {
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
    toTangent = mf;
    return true;
}

// The wanted basis of every pixel and its weight (warpLatticeToSurface); outside the image the affine
// basis with a small weight.
struct WantedBases {
    int width, height;
    const Eigen::Matrix2d& affine;
    const std::vector<Eigen::Matrix2d>& wanted;
    const std::vector<double>& weight;
    // Per pixel with weight 1: the screen-to-tangent map in footprints (surfaceBasisAt's mf), and the
    // equilateral basis and its inverse, for the bases turned towards the fit (ScanOptions::warpFollowsFit).
    const std::vector<Eigen::Matrix2d>& toTangent;
    const Eigen::Matrix2d& equilateral;
    const Eigen::Matrix2d& equilateralInverse;

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

    // The basis at \p p that is equilateral on the surface and turned to be closest to \p fitted (the
    // local step of an as-rigid-as-possible fit) instead of to the affine basis; the affine-closest one
    // where that would turn the lattice over.
    Eigen::Matrix2d towards(const Eigen::Vector2d& p, const Eigen::Matrix2d& fitted, double& wt) const {
        const Eigen::Matrix2d& fixed = at(p, wt);
        if (wt < 1) return fixed;
        const std::size_t i =
            std::size_t(std::floor(p.y())) * std::size_t(width) + std::size_t(std::floor(p.x()));
        const Eigen::Matrix2d& mf = toTangent[i];
        const Eigen::Matrix2d result =
            mf.inverse() * closestOrthogonal(mf * fitted * equilateralInverse) * equilateral;
        if (!result.allFinite() || !(result.determinant() * affine.determinant() > 0)) return fixed;
        return result;
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
                      const WantedBases& field, bool followFit) {
    constexpr double kAnchor = 1e-5;
    constexpr int steps[3][2] = {{0, 1}, {1, 0}, {1, 1}}; // (dr, dc) of the grid's edges a, b, a + b
    const int n = g.size();
    // With followFit, every node's basis (a, b) under the positions phi (central differences, one-sided at
    // the grid's ends), which the wanted bases along its edges are turned towards.
    std::vector<Eigen::Matrix2d> fitted;
    if (followFit) {
        fitted.resize(std::size_t(n));
        const auto node = [&](int r, int c) { return phi.row(r * g.cols + c).transpose(); };
        for (int r = 0; r < g.rows; ++r)
            for (int c = 0; c < g.cols; ++c) {
                const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, g.cols - 1);
                const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, g.rows - 1);
                Eigen::Matrix2d j;
                j.col(0) = (node(r, c1) - node(r, c0)) / double(g.k * (c1 - c0));
                j.col(1) = (node(r1, c) - node(r0, c)) / double(g.k * (r1 - r0));
                fitted[std::size_t(r * g.cols + c)] = j;
            }
    }
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
                    const Eigen::Matrix2d edgeFit =
                        followFit ? Eigen::Matrix2d(0.5 * (fitted[std::size_t(i)] + fitted[std::size_t(j)]))
                                  : Eigen::Matrix2d::Zero();
                    for (int k = 0; k < g.k; ++k) {
                        const double t = (double(k) + 0.5) / double(g.k);
                        const Eigen::Vector2d p = ((1 - t) * phi.row(i) + t * phi.row(j)).transpose();
                        double wk = 0;
                        const Eigen::Matrix2d m = followFit ? field.towards(p, edgeFit, wk) : field.at(p, wk);
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

} // namespace

std::vector<Eigen::Vector2d> warpLatticeToSurface(const FrameBuffers& referenceBuffers, const Mesh& reference,
                                                  double spacing, const LatticeBasis& basis,
                                                  const Eigen::Vector2d& origin, int rows, int cols,
                                                  bool followFit) {
    detail::checkBuffers(referenceBuffers);
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
    std::vector<Eigen::Matrix2d> toTangent(wanted.size(), Eigen::Matrix2d::Identity());
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
                                   equilateral, towardsEquilateral, affine, wanted[i], toTangent[i]))
                    weight[i] = 1.0;
            }
    });
    const Eigen::Matrix2d equilateralInverse = equilateral.inverse();
    const WantedBases field{w, h, affine, wanted, weight, toTangent, equilateral, equilateralInverse};

    // The fit is made on a coarse grid, every kFit-th row and column (the warp is smooth; the solve costs
    // ~1/16 of the fine grid's), and the fine positions interpolated bilinearly in (row, column). Its
    // rounds (the bases re-read under the moved edges) run first on a grid twice as coarse, solved directly
    // (LDLᵀ, the pattern ordered once); the last round, on the kFit grid, starts from that solution
    // interpolated and is solved directly too, on the nodes that matter: the rectangle of rows and columns
    // whose nodes fall in the image, and two more around it (the lattice's margin beyond it only keeps the
    // image covered; those nodes keep the coarser solution). Issue #20: session 16's last round, 50
    // conjugate-gradient steps on the whole kFit grid, stopped far from the solution where the wanted bases
    // change fast (the lattice 1.4–2× too long on the surface there, and its Hausdorff distance worse than
    // the square lattice's in 2 of 70 views: femur +y, pig +y); 500 steps reach the direct solution.
    //
    // With followFit (session 19) the bases are turned towards the fit's own at every round after the
    // first (an as-rigid-as-possible fit: local step = the turn, global step = the solve), and the last
    // rounds run on every 2nd row and column: where the wanted bases jump (a sharp crease, faces slanted
    // in different directions around an apex) the turn of the session 17 fit, fixed by the affine lattice,
    // gave the two sides bases that no continuous lattice joins, and the fit compromised over rows around;
    // bases turned to agree along the crease are joined by a lattice that bends there, which a grid of
    // every 4th row and column blurred over 4–8 rows. Rounds and steps measured on 4 views of issue #20's
    // wide set (octahedron +z, ALSTOM_TEST4 +y, polygon_mesh +x, part iso; DESIGN.md §1, session 19).
    const int kFit = followFit ? 2 : 4, kCoarseRounds = followFit ? 4 : 2, kFineRounds = followFit ? 2 : 1;
    constexpr int kCoarse = 8, kCropMargin = 2;
    const FitGrid coarse(kCoarse, rows, cols), fine(kFit, rows, cols);
    const Eigen::MatrixX2d coarseAnchor = coarse.affinePositions(origin, basis);
    Eigen::MatrixX2d coarsePhi = coarseAnchor;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    for (int round = 0; round < kCoarseRounds; ++round) {
        const FitSystem system = assembleFit(coarse, coarsePhi, coarseAnchor, field, followFit && round > 0);
        if (round == 0) ldlt.analyzePattern(system.matrix);
        ldlt.factorize(system.matrix);
        if (ldlt.info() == Eigen::Success) {
            const Eigen::MatrixX2d x = ldlt.solve(system.rhs);
            if (x.allFinite()) coarsePhi = x;
        }
    }
    Eigen::MatrixX2d phi(fine.size(), 2);
    int r0 = fine.rows, r1 = -1, c0 = fine.cols, c1 = -1; // the fine nodes in the image
    for (int r = 0; r < fine.rows; ++r)
        for (int c = 0; c < fine.cols; ++c) {
            const Eigen::Vector2d p = coarse.interpolate(coarsePhi, kFit * r, kFit * c);
            phi.row(r * fine.cols + c) = p.transpose();
            if (p.x() >= 0 && p.y() >= 0 && p.x() < w && p.y() < h) {
                r0 = std::min(r0, r);
                r1 = std::max(r1, r);
                c0 = std::min(c0, c);
                c1 = std::max(c1, c);
            }
        }
    if (r1 >= 0) {
        r0 = std::max(0, r0 - kCropMargin);
        c0 = std::max(0, c0 - kCropMargin);
        r1 = std::min(fine.rows - 1, r1 + kCropMargin);
        c1 = std::min(fine.cols - 1, c1 + kCropMargin);
        // The crop as a grid of its own (node (r, c) of it is fine node (r0 + r, c0 + c)).
        FitGrid crop(kFit, 2, 2);
        crop.rows = r1 - r0 + 1;
        crop.cols = c1 - c0 + 1;
        Eigen::MatrixX2d cropPhi(crop.size(), 2), cropAnchor(crop.size(), 2);
        for (int r = 0; r < crop.rows; ++r)
            for (int c = 0; c < crop.cols; ++c) {
                cropPhi.row(r * crop.cols + c) = phi.row((r0 + r) * fine.cols + c0 + c);
                cropAnchor.row(r * crop.cols + c) =
                    (origin + double(kFit * (c0 + c)) * basis.a + double(kFit * (r0 + r)) * basis.b)
                        .transpose();
            }
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct;
        for (int round = 0; round < kFineRounds; ++round) {
            const FitSystem system = assembleFit(crop, cropPhi, cropAnchor, field, followFit);
            if (round == 0) direct.analyzePattern(system.matrix);
            direct.factorize(system.matrix);
            if (direct.info() == Eigen::Success) {
                const Eigen::MatrixX2d x = direct.solve(system.rhs);
                if (x.allFinite()) cropPhi = x;
            }
        }
        for (int r = 0; r < crop.rows; ++r)
            for (int c = 0; c < crop.cols; ++c)
                phi.row((r0 + r) * fine.cols + c0 + c) = cropPhi.row(r * crop.cols + c);
    }
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            out[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = fine.interpolate(phi, r, c);
    return out;
}

} // namespace fss
