// scanPatch's lattices (issue #20): the triangular and adaptive lattices against the pixel grid, the lattice
// warped to the surface, the relaxation of a patch on its reference, and criterion A (mean smallest angle,
// share below 30 deg, interior valence, Hausdorff) over CGAL's meshes from the standard views.
#include "fss/error.h"
#include "fss/metrics.h"
#include "fss/raycast.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"
#include "test_data.h"
#include "test_mesh.h"

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

// ---- Lattices (issue #20) -------------------------------------------------------------------------------

namespace {

struct LatticeFigures {
    double meanMinAngle = 0, below30 = 0, valence6 = 0, hausdorff = 0, area = 0;
    std::size_t faces = 0;
    fss::Mesh patch;
    std::string worst; // FSS_WORST: where the patch is farthest from the reference
};

// The lattice options of a scan; by default those of ScanParams{}, which are the command line's and the scan
// panel's (fss-remesh scan: adaptive lattice, mask 35°, warped, no quad-angle bound, no relaxation).
struct LatticeSetting {
    fss::Lattice lattice = fss::ScanOptions{}.lattice;
    double minLatticeAngleDeg = fss::ScanOptions{}.minLatticeAngleDeg;
    double minQuadAngleDeg = fss::TriangulateOptions{}.minQuadAngleDeg;
    int relaxIterations = fss::ScanParams{}.relaxIterations;
    bool warpToSurface = fss::ScanOptions{}.warpToSurface;
};

LatticeFigures latticeScan(const fss::Mesh& ref, fss::MeshRenderer& renderer, fss::StandardView view, int res,
                           const LatticeSetting& setting) {
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(view, fss::boundingBox(ref), res, res);
    params.scan.lattice = setting.lattice;
    params.scan.minLatticeAngleDeg = setting.minLatticeAngleDeg;
    params.triangulate.minQuadAngleDeg = setting.minQuadAngleDeg;
    params.relaxIterations = setting.relaxIterations;
    params.scan.warpToSurface = setting.warpToSurface;
    fss::ScanResult r = fss::scanPatch(ref, renderer, ref, renderer, params);
    const fss::Metrics m = fss::computeMetrics(r.patch.mesh, {.selfIntersections = false, .reference = &ref});
    LatticeFigures out{m.meanMinAngleDeg,
                       m.fracMinAngleBelow30,
                       m.fracValence6Interior,
                       *m.hausdorffToRefRel,
                       m.area,
                       m.faces,
                       std::move(r.patch.mesh),
                       {}};
    if (std::getenv("FSS_WORST")) { // the face farthest from the reference (centroid and edge midpoints)
        const fss::RayCaster caster(ref);
        const fss::Mesh& pm = out.patch;
        const auto gi = pm.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
        double worst = -1;
        std::string where;
        for (const auto f : pm.faces()) {
            std::array<Eigen::Vector3d, 3> p;
            std::array<fss::VertexIndex, 3> vs;
            int k = 0;
            for (const auto v : CGAL::vertices_around_face(pm.halfedge(f), pm)) {
                vs[std::size_t(k)] = v;
                p[std::size_t(k++)] = Eigen::Vector3d(pm.point(v).x(), pm.point(v).y(), pm.point(v).z());
            }
            double d = 0; // at the points of a 6-fold subdivision of the face (28 points)
            for (int i = 0; i <= 6; ++i)
                for (int j = 0; i + j <= 6; ++j)
                    d = std::max(
                        d, caster
                               .closestPoint(
                                   (double(i) * p[0] + double(j) * p[1] + double(6 - i - j) * p[2]) / 6.0)
                               .distance);
            if (d <= worst) continue;
            worst = d;
            const fss::Sample& s0 = r.grid.at(gi[vs[0]].row, gi[vs[0]].col);
            double longest = 0;
            for (int i = 0; i < 3; ++i)
                longest = std::max(longest, (p[std::size_t(i)] - p[std::size_t((i + 1) % 3)]).norm());
            // Around the face: the lattice's 3D edges (a and b) within 3 rows and columns in footprints,
            // and the lattice steps to the nearest sample not in the patch.
            double around = 0;
            int aroundCount = 0, toBorder = 99;
            const int r0 = gi[vs[0]].row, c0 = gi[vs[0]].col;
            for (int dr = -6; dr <= 6; ++dr)
                for (int dc = -6; dc <= 6; ++dc) {
                    const int rr = r0 + dr, cc = c0 + dc;
                    if (rr < 0 || cc < 0 || rr + 1 >= r.grid.rows || cc + 1 >= r.grid.cols) continue;
                    const fss::Sample& s = r.grid.at(rr, cc);
                    if (!s.valid) {
                        toBorder = std::min(toBorder, std::max(std::abs(dr), std::abs(dc)));
                        continue;
                    }
                    if (std::abs(dr) > 3 || std::abs(dc) > 3) continue;
                    for (const fss::Sample* t : {&r.grid.at(rr, cc + 1), &r.grid.at(rr + 1, cc + 1)})
                        if (t->valid) {
                            around += (t->point - s.point).norm() / double(s.footprint);
                            ++aroundCount;
                        }
                }
            char buf[300];
            std::snprintf(
                buf, sizeof buf,
                "worst face %.2e of diag at screen (%.0f, %.0f) lattice (%d, %d): longest edge %.2f "
                "footprints (mean edge within 3: %.2f), %d steps from the patch border, sampling "
                "angle %.0f deg, faces %u %u %u",
                d / fss::boundingBox(ref).diagonal().norm(), s0.screen.x(), s0.screen.y(), r0, c0,
                longest / double(s0.footprint), aroundCount ? around / aroundCount : 0.0, toBorder,
                double(s0.samplingAngle) * 180 / std::numbers::pi, unsigned(s0.face),
                unsigned(r.grid.at(gi[vs[1]].row, gi[vs[1]].col).face),
                unsigned(r.grid.at(gi[vs[2]].row, gi[vs[2]].col).face));
            where = buf;
        }
        out.worst = where;
    }
    return out;
}

LatticeFigures latticeScan(const fss::Mesh& ref, fss::MeshRenderer& renderer, fss::StandardView view, int res,
                           fss::Lattice lattice) {
    // The settings issue 20 measured first (not the defaults): sliver quads dropped, six relaxation sweeps.
    return latticeScan(
        ref, renderer, view, res,
        LatticeSetting{
            .lattice = lattice, .minLatticeAngleDeg = 0, .minQuadAngleDeg = 20, .relaxIterations = 6});
}

// The share of \p ref's area within 0.5 % of its bounding-box diagonal of one of \p patches (measured at
// the reference's face centroids, weighted by face area).
double unionCoverage(const fss::Mesh& ref, const std::vector<const fss::Mesh*>& patches) {
    std::vector<fss::RayCaster> casters;
    for (const fss::Mesh* p : patches)
        if (p->number_of_faces() > 0) casters.emplace_back(*p);
    const double tol = 0.005 * fss::boundingBox(ref).diagonal().norm();
    double covered = 0, total = 0;
    for (const fss::FaceIndex f : ref.faces()) {
        const auto h = ref.halfedge(f);
        const auto& x = ref.point(ref.source(h));
        const auto& y = ref.point(ref.target(h));
        const auto& z = ref.point(ref.target(ref.next(h)));
        const double area = std::sqrt(CGAL::cross_product(y - x, z - x).squared_length()) / 2;
        const Eigen::Vector3d c((x.x() + y.x() + z.x()) / 3, (x.y() + y.y() + z.y()) / 3,
                                (x.z() + y.z() + z.z()) / 3);
        total += area;
        for (const fss::RayCaster& caster : casters)
            if (caster.closestPoint(c).distance <= tol) {
                covered += area;
                break;
            }
    }
    return total > 0 ? covered / total : 0;
}

// How far the umbrella step of a relaxation (mesh/relax.h: each interior vertex towards its neighbours'
// centroid) would move the vertices of \p m: the mean distance to the centroid over the mean edge length.
// On an affine image of the valence-6 lattice every interior vertex *is* its neighbours' centroid (the
// neighbours come in opposite pairs ±a, ±b, ±(a + b)), so only the curvature of the surface and the
// variation of the slant across the patch give it something to do.
double umbrellaShare(const fss::Mesh& m) {
    double moves = 0, edges = 0;
    std::size_t nv = 0, ne = 0;
    for (const auto e : m.edges()) {
        edges += std::sqrt(CGAL::squared_distance(m.point(m.vertex(e, 0)), m.point(m.vertex(e, 1))));
        ++ne;
    }
    for (const auto v : m.vertices()) {
        if (m.is_border(v)) continue;
        double x = 0, y = 0, z = 0;
        int k = 0;
        for (const auto w : CGAL::vertices_around_target(m.halfedge(v), m)) {
            x += m.point(w).x();
            y += m.point(w).y();
            z += m.point(w).z();
            ++k;
        }
        if (k == 0) continue;
        const auto& p = m.point(v);
        moves += std::sqrt((x / k - p.x()) * (x / k - p.x()) + (y / k - p.y()) * (y / k - p.y()) +
                           (z / k - p.z()) * (z / k - p.z()));
        ++nv;
    }
    return nv && ne ? (moves / double(nv)) / (edges / double(ne)) : 0;
}

fss::Lattice latticeFromEnv(const char* name, fss::Lattice fallback) {
    const char* v = std::getenv(name);
    if (!v) return fallback;
    const std::string s = v;
    return s == "square"     ? fss::Lattice::Square
           : s == "adaptive" ? fss::Lattice::Adaptive
                             : fss::Lattice::Triangular;
}

double numberFromEnv(const char* name, double fallback) {
    const char* v = std::getenv(name);
    return v ? std::atof(v) : fallback;
}

} // namespace

// The triangular lattice (the default) against the square pixel lattice on one iso scan of fandisk: rounder
// triangles, the same regularity, no larger distance to the reference.
TEST(ScanPipeline, TriangularLatticeMakesRounderTrianglesThanThePixelGrid) {
    const fss::Mesh ref = fss::test::loadMesh("fandisk.off");
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(ref);
    // The default is the adaptive lattice with the lattice-angle mask at 35° (issue 20).
    EXPECT_EQ(fss::ScanParams{}.scan.lattice, fss::Lattice::Adaptive);
    EXPECT_EQ(fss::ScanParams{}.scan.minLatticeAngleDeg, 35.0);
    const auto tri = latticeScan(ref, renderer, fss::StandardView::Iso, 256, fss::Lattice::Triangular);
    const auto sq = latticeScan(ref, renderer, fss::StandardView::Iso, 256, fss::Lattice::Square);
    std::printf("fandisk iso 256²: triangular mean min angle %.1f°, %.1f %% < 30°, valence 6 %.3f, Hausdorff "
                "%.2e (%zu faces); square %.1f°, %.1f %%, %.3f, %.2e (%zu faces)\n",
                tri.meanMinAngle, 100 * tri.below30, tri.valence6, tri.hausdorff, tri.faces, sq.meanMinAngle,
                100 * sq.below30, sq.valence6, sq.hausdorff, sq.faces);
    // Measured (issue #20 report): 36.4° against 29.9°, 1.2 % against 63.7 % below 30°, Hausdorff 1.84e-3
    // against 2.16e-3 (2.43e-3 before the edge limit scaled with the lattice's screen edges, scanPatch).
    EXPECT_GE(tri.meanMinAngle, sq.meanMinAngle + 5);
    EXPECT_LE(tri.below30, 0.1 * sq.below30);
    EXPECT_GE(tri.valence6, 0.98);
    EXPECT_LE(tri.hausdorff, sq.hausdorff);
}

// The adaptive lattice with the lattice-angle mask at 35° (issue #20), warped to the surface (the defaults)
// on the view where the screen lattice fails worst, fandisk from the iso view: the criterion of the issue
// (mean smallest angle ≥ 50°, ≤ 2 % below 30°, interior valence 6) with most of the square lattice's patch
// area kept (the warp's gain: without it 54.8° on 0.63 of the area, with it 52.3° on 0.96).
TEST(ScanPipeline, AdaptiveLatticeWithTheAngleMaskMakesRoundTrianglesOnFandiskIso) {
    const fss::Mesh ref = fss::test::loadMesh("fandisk.off");
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(ref);
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(ref), 256, 256);
    const fss::ScanResult adaptive = fss::scanPatch(ref, renderer, ref, renderer, params); // the defaults
    params.scan.lattice = fss::Lattice::Square;
    params.scan.minLatticeAngleDeg = 0;
    const fss::ScanResult square = fss::scanPatch(ref, renderer, ref, renderer, params);
    const fss::Metrics a = fss::computeMetrics(adaptive.patch.mesh, {.selfIntersections = false});
    const fss::Metrics s = fss::computeMetrics(square.patch.mesh, {.selfIntersections = false});
    std::printf(
        "fandisk iso 256²: adaptive, warped, mask 35°: mean smallest angle %.1f°, %.1f %% < 30°, valence 6 "
        "%.3f, area %.2f of the square lattice's; square: %.1f°, %.1f %%\n",
        a.meanMinAngleDeg, 100 * a.fracMinAngleBelow30, a.fracValence6Interior, a.area / s.area,
        s.meanMinAngleDeg, 100 * s.fracMinAngleBelow30);
    EXPECT_LT(adaptive.counts.wellShaped, adaptive.counts.frontFacing); // the mask dropped the slanted part
    EXPECT_GE(a.meanMinAngleDeg, 50.0);                                 // measured 52.3° (warped)
    EXPECT_LE(a.fracMinAngleBelow30, 0.02);                             // measured 0.0 %
    EXPECT_GE(a.fracValence6Interior, 0.98);
    // Measured 0.96 with the warp (0.63 without, when the bound was 0.5): raised to what the warp keeps.
    EXPECT_GE(a.area, 0.85 * s.area);
}

// The lattice warped to the surface (ScanOptions::warpToSurface, issue #20) on a sphere seen from the
// front: one affine lattice is equilateral only where the sphere is seen at the lattice's tilt (here
// frontally), the 35° mask then drops the ring beyond about 50° of slant; the warped lattice is equilateral
// on the surface under every sample, so the mask keeps most of the visible hemisphere with round triangles,
// the same interior valence 6 and the surface sampled at the same spacing.
TEST(ScanPipeline, LatticeWarpedToTheSurfaceKeepsRoundTrianglesOnASphere) {
    const fss::Mesh ref = fss::shapes::icosphere(5);
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(ref);
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(fss::StandardView::PosZ, fss::boundingBox(ref), 128, 128);
    params.scan.warpToSurface = false; // the plain affine lattice on purpose (the warp is the default)
    const fss::ScanResult affine = fss::scanPatch(ref, renderer, ref, renderer, params);
    params.scan.warpToSurface = true;
    const fss::ScanResult warped = fss::scanPatch(ref, renderer, ref, renderer, params);
    const fss::Metrics a =
        fss::computeMetrics(affine.patch.mesh, {.selfIntersections = false, .reference = &ref});
    const fss::Metrics w =
        fss::computeMetrics(warped.patch.mesh, {.selfIntersections = false, .reference = &ref});
    std::printf(
        "sphere +z 128²: affine lattice: area %.3f, mean smallest angle %.1f°, %.1f %% < 30°, valence 6 "
        "%.3f, Hausdorff %.2e; warped: area %.3f, %.1f°, %.1f %%, %.3f, %.2e\n",
        a.area, a.meanMinAngleDeg, 100 * a.fracMinAngleBelow30, a.fracValence6Interior, *a.hausdorffToRefRel,
        w.area, w.meanMinAngleDeg, 100 * w.fracMinAngleBelow30, w.fracValence6Interior, *w.hausdorffToRefRel);
    // The visible hemisphere has area 2π; a cap up to the slant θ has 2π(1 − cos θ). Measured: area 2.31 ->
    // 3.99 (the cap to 55° -> to 76°), mean smallest angle 50.4° -> 53.9°, 0 % below 30°, Hausdorff 1.56e-4
    // -> 1.00e-4; with session 16's faster fit area 3.86, 54.8°, 0 %, Hausdorff 1.14e-4 (the bounds hold).
    EXPECT_GE(w.area, 1.5 * a.area);
    EXPECT_GE(w.area, 2 * std::numbers::pi * (1 - std::cos(65 * std::numbers::pi / 180)));
    EXPECT_GE(w.meanMinAngleDeg, 50.0);
    EXPECT_LE(w.fracMinAngleBelow30, 0.02);
    EXPECT_GE(w.fracValence6Interior, 0.98);
    EXPECT_LE(*w.hausdorffToRefRel, 1.5 * *a.hausdorffToRefRel);
}

namespace {

// Criterion A of issue #20 over single 256² scans, a lattice setting against the square pixel lattice (no
// mask, no quad bound, no relaxation) from the same view: per view the figures, then which views fail each
// part (mean smallest angle ≥ 50°, ≤ 2 % below 30°, interior valence-6 share not lower by more than 0.01,
// Hausdorff distance to the reference not larger than the square lattice's). Entries are "mesh.off" (the
// seven standard views, and the share of the reference covered by their patches together) or
// "mesh.off:view" (that view only). FSS_LATTICE_VIEW (iso, +x, ...) scans one view only; FSS_WORST describes
// where each patch is farthest from the reference.
struct CriterionA {
    int scans = 0;
    // "mesh view figure" of the views failing each part; nothing: views without a patch (square has one)
    std::vector<std::string> mean, below30, valence, hausdorff, nothing;
    double worstMean = 90, worstBelow = 0, worstValence = 1, worstHausdorffRatio = 0;
};

CriterionA latticeTable(const std::vector<std::string>& entries, const LatticeSetting& setting) {
    const LatticeSetting square{
        .lattice = fss::Lattice::Square, .minLatticeAngleDeg = 0, .minQuadAngleDeg = 0, .relaxIterations = 0};
    const fss::StandardView views[] = {
        fss::StandardView::Iso,  fss::StandardView::PosX, fss::StandardView::NegX, fss::StandardView::PosY,
        fss::StandardView::NegY, fss::StandardView::PosZ, fss::StandardView::NegZ};
    const char* viewNames[] = {"iso", "+x", "-x", "+y", "-y", "+z", "-z"};
    CriterionA a;
    double sumMean = 0, sumCov = 0;
    std::printf(
        "%-14s %-4s | new: mean<  <30%%  val6   hausd    cov  umb%% | sq: mean<  <30%%  val6   hausd\n",
        "mesh", "view");
    for (const std::string& entry : entries) {
        const std::size_t colon = entry.find(':');
        const std::string name = entry.substr(0, colon);
        const char* env = std::getenv("FSS_LATTICE_VIEW");
        const std::string only = colon != std::string::npos ? entry.substr(colon + 1) : env ? env : "";
        const fss::Mesh ref = fss::test::loadMesh(name);
        fss::CpuMeshRenderer renderer;
        renderer.setMesh(ref);
        std::vector<LatticeFigures> mine, theirs;
        for (int v = 0; v < 7; ++v) {
            if (!only.empty() && only != viewNames[v]) continue;
            // A view where one lattice leaves nothing (seen edge-on, or only from behind): without a patch
            // from the setting while the square lattice has one, the view fails; without a square patch the
            // setting's is judged on its angles only.
            LatticeFigures tri, sq;
            std::string noTri, noSq;
            try {
                tri = latticeScan(ref, renderer, views[v], 256, setting);
            } catch (const fss::InvalidInputError& e) {
                noTri = e.what();
            }
            try {
                sq = latticeScan(ref, renderer, views[v], 256, square);
            } catch (const fss::InvalidInputError& e) {
                noSq = e.what();
            }
            if (!noTri.empty()) {
                std::printf("%-14s %-4s | new: %s%s\n", name.c_str(), viewNames[v], noTri.c_str(),
                            noSq.empty() ? "  FAIL (the square lattice has a patch)" : " (square too)");
                if (noSq.empty()) a.nothing.push_back(name + " " + viewNames[v]);
                continue;
            }
            if (!noSq.empty()) {
                std::printf("%-14s %-4s | square: %s\n", name.c_str(), viewNames[v], noSq.c_str());
                sq.valence6 = 0;
                sq.hausdorff = std::numeric_limits<double>::infinity();
            }
            const double cov = sq.area > 0 ? tri.area / sq.area : 0;
            // Planar views give distances of rounding size (1e-16): those count as 1e-6 of the diagonal.
            const double ratio = std::max(tri.hausdorff, 1e-6) / std::max(sq.hausdorff, 1e-6);
            const double dv = tri.valence6 - sq.valence6;
            const auto fail = [&](std::vector<std::string>& list, bool failed, double figure) {
                if (!failed) return "";
                char buf[96];
                std::snprintf(buf, sizeof buf, "%s %s %.3g", name.c_str(), viewNames[v], figure);
                list.push_back(buf);
                return "  FAIL";
            };
            std::printf(
                "%-14s %-4s | %9.1f %5.1f %6.3f %8.2e %5.2f %5.1f | %8.1f %5.1f %6.3f %8.2e%s%s%s%s\n",
                name.c_str(), viewNames[v], tri.meanMinAngle, 100 * tri.below30, tri.valence6, tri.hausdorff,
                cov, 100 * umbrellaShare(tri.patch), sq.meanMinAngle, 100 * sq.below30, sq.valence6,
                sq.hausdorff, fail(a.mean, tri.meanMinAngle < 50, tri.meanMinAngle),
                fail(a.below30, tri.below30 > 0.02, 100 * tri.below30), fail(a.valence, dv < -0.01, dv),
                fail(a.hausdorff, ratio > 1, ratio));
            if (!tri.worst.empty())
                std::printf("    new %s\n    sq  %s\n", tri.worst.c_str(), sq.worst.c_str());
            a.worstMean = std::min(a.worstMean, tri.meanMinAngle);
            a.worstBelow = std::max(a.worstBelow, tri.below30);
            a.worstValence = std::min(a.worstValence, dv);
            a.worstHausdorffRatio = std::max(a.worstHausdorffRatio, ratio);
            sumMean += tri.meanMinAngle;
            sumCov += cov;
            ++a.scans;
            mine.push_back(std::move(tri));
            theirs.push_back(std::move(sq));
        }
        if (mine.size() < 7) continue;
        std::vector<const fss::Mesh*> pa, pb;
        for (std::size_t k = 0; k < mine.size(); ++k) {
            pa.push_back(&mine[k].patch);
            pb.push_back(&theirs[k].patch);
        }
        std::printf("%-14s union of the 7 views covers %.1f %% of the reference (square lattice: %.1f %%)\n",
                    name.c_str(), 100 * unionCoverage(ref, pa), 100 * unionCoverage(ref, pb));
    }
    const auto list = [](const std::vector<std::string>& l) {
        std::string s;
        for (const std::string& x : l)
            s += (s.empty() ? "" : ", ") + x;
        return s;
    };
    std::printf(
        "%d scans; mean of means %.1f°, mean coverage %.2f; worst: mean smallest angle %.1f°, %.1f %% "
        "below 30°, valence-6 change %+.3f, Hausdorff ratio to square %.2f\n"
        "failing mean >= 50°: %zu (%s)\nfailing <= 2 %% below 30°: %zu (%s)\n"
        "failing valence 6 unchanged: %zu (%s)\nfailing Hausdorff <= square: %zu (%s)\n"
        "no patch where the square lattice has one: %zu (%s)\n",
        a.scans, a.scans ? sumMean / a.scans : 0, a.scans ? sumCov / a.scans : 0, a.worstMean,
        100 * a.worstBelow, a.worstValence, a.worstHausdorffRatio, a.mean.size(), list(a.mean).c_str(),
        a.below30.size(), list(a.below30).c_str(), a.valence.size(), list(a.valence).c_str(),
        a.hausdorff.size(), list(a.hausdorff).c_str(), a.nothing.size(), list(a.nothing).c_str());
    return a;
}

// \p scans views judged, each failing no part of criterion A unless \p known lists it ("hausdorff part.off
// iso": the part, the mesh and the view).
void expectCriterionA(const CriterionA& a, int scans, const std::vector<std::string>& known = {}) {
    EXPECT_EQ(a.scans, scans);
    const std::pair<const char*, const std::vector<std::string>*> parts[] = {{"mean", &a.mean},
                                                                             {"below30", &a.below30},
                                                                             {"valence", &a.valence},
                                                                             {"hausdorff", &a.hausdorff},
                                                                             {"nothing", &a.nothing}};
    for (const auto& [part, failures] : parts)
        for (const std::string& f : *failures) { // "mesh view figure"
            const std::string key = std::string(part) + " " + f.substr(0, f.find(' ', f.find(' ') + 1));
            EXPECT_NE(std::find(known.begin(), known.end(), key), known.end())
                << "criterion A, part " << part << ", fails on " << f;
        }
}

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    for (std::size_t at = 0; at < s.size();) {
        const std::size_t end = std::min(s.find(',', at), s.size());
        out.push_back(s.substr(at, end - at));
        at = end + 1;
    }
    return out;
}

} // namespace

// FSS_LONG_TESTS=1: the table above over FSS_LATTICE_MESHES (comma-separated entries) with a setting from
// the environment, each default the product's (LatticeSetting): FSS_LATTICE = triangular | adaptive | square,
// FSS_MIN_LATTICE_ANGLE (degrees), FSS_MIN_QUAD_ANGLE, FSS_RELAX (sweeps), FSS_WARP (1 | 0).
TEST(ScanPipeline, LatticeTableOverCgalMeshesLong) {
    if (!fss::test::longTests()) GTEST_SKIP() << "set FSS_LONG_TESTS=1";
    const char* list = std::getenv("FSS_LATTICE_MESHES");
    const LatticeSetting d;
    const LatticeSetting setting{.lattice = latticeFromEnv("FSS_LATTICE", d.lattice),
                                 .minLatticeAngleDeg =
                                     numberFromEnv("FSS_MIN_LATTICE_ANGLE", d.minLatticeAngleDeg),
                                 .minQuadAngleDeg = numberFromEnv("FSS_MIN_QUAD_ANGLE", d.minQuadAngleDeg),
                                 .relaxIterations = int(numberFromEnv("FSS_RELAX", d.relaxIterations)),
                                 .warpToSurface = numberFromEnv("FSS_WARP", d.warpToSurface ? 1 : 0) != 0};
    const CriterionA a =
        latticeTable(splitList(list ? list : "fandisk.off,bull.off,eight.off,femur.off"), setting);
    EXPECT_GE(a.worstMean, 50.0);
    EXPECT_LE(a.worstBelow, 0.02);
    EXPECT_GE(a.worstValence, -0.01);
    EXPECT_LE(a.worstHausdorffRatio, 1.0);
}

// The wide set of issue #20 criterion A (session 18): 46 meshes none of the lattice work was tuned on, CAD
// parts, scans, open meshes, tiny and large ones.
constexpr const char* kWideList =
    "ALSTOM_TEST4.off,mech-holes-shark.off,rotor_small.off,cube-meshed.off,part.off,cylinder_locally_refined."
    "off,turbine.off,cheese.off,handle.off,tripod.off,cross.off,u.off,b9_mesh.off,helmet.off,boeing.off,"
    "bunny00.off,armadillo.off,diplodocus.off,man.off,bear.off,ChineseDragon-10kv.off,lion-head.off,knot2."
    "off,bones.off,blobby_3cc.off,head.off,oblong.off,retinal.off,refined_elephant.off,polygon_mesh.off,"
    "ellipe0.003.off,larger_sphere.off,elephant-with-holes.off,holes.off,three_peaks.off,horizons.off,patch-"
    "01.off,mesh_with_border.off,plane.off,mask_cone.off,nefertiti.off,cube.off,octahedron.off,icosahedron."
    "off,star.off,tetrahedron.off";

// FSS_LONG_TESTS=1: criterion A at the product's defaults on every view of kWideList (CPU renderer).
// 282 views with a patch (of 322: the rest show nothing or only the back of the surface with either
// lattice; session 18 wrote 291, but its own binary gives 282 — measured again in session 19), none with
// more than 2 % below 30°, valence 6 unchanged on all. Session 18 (warp fit turned towards the affine
// lattice): 23 views below a mean smallest angle of 50°, 10 with a larger Hausdorff distance than the square
// lattice. Session 19 (ScanOptions::warpFollowsFit, tuned on octahedron +z, ALSTOM_TEST4 +y, polygon_mesh +x
// and part iso): 8 and 8; fixed: the octahedron's six axis views (47.9–48.0° -> 50.2°), polygon_mesh's four,
// part iso, cheese iso, b9_mesh ±y, blobby_3cc +x, three_peaks iso (mean) and ALSTOM_TEST4 ±y,
// mech-holes-shark iso, blobby_3cc +x, oblong -y (Hausdorff); made worse: icosahedron iso (50.6° -> 49.3°),
// mech-holes-shark +y, man iso, elephant-with-holes +z (Hausdorff ratios 0.67–0.85 -> 1.01–1.05). Criterion
// A is NOT met on the views of kOpenViews (13 views): the test fails on any other view failing a part, and
// prints which of these still fail.
//  - mean smallest angle 40.6–49.4° on 8 views: patch-01 ±y and mesh_with_border +y are edge-on views where
//    the square lattice leaves nothing; icosahedron iso: five faces meet at each apex (angle sum 300°) and
//    the warp now keeps 2.05 of the square lattice's area (was 1.66), more of it slanted; man -z, bones +x,
//    blobby_3cc -x, three_peaks -y (47.9–49.4°, up 0.2–1.5° from session 18) not analysed further. Six
//    relaxation sweeps (ScanParams::relaxIterations) raise them by 0.0–1.2° (bones +x to 50.1°) but make the
//    Hausdorff distance worse on 6 of the 16 views: the relaxation stays off.
//    Session 21 tried those sweeps with a move refused when it raises the largest distance to the reference
//    of its ring's face centroids and edge midpoints: +0.0–0.8° on 12 of these views, none reaching 50°
//    (bones +x 49.4 -> 49.8°, man -z 48.8 -> 49.2°, blobby_3cc -x 48.5 -> 48.9°, 12 sweeps as 6), the
//    Hausdorff distance unchanged on the Hausdorff views but blobby_3cc -x 4.69e-4 -> 5.26e-4: not kept.
//  - Hausdorff distance worse than the square lattice's on 8 views, ratio 1.01–1.13, boeing ±y 94–97 (the
//    square's triangles lie in the planar faces seen face-on: 3e-16; the warped patch covers 21–23 times
//    their area). FSS_WORST on mech-holes-shark -y, man iso, elephant-with-holes +z, u -y: the farthest face
//    1–2 lattice steps from the patch border, edges 1.0–1.5 footprints (the square's farthest faces 1.4–2.4),
//    where the patch ends at a crease or fold. Session 21 (scanPatch drops the warped patch's border faces
//    farther than 0.2 footprints from the reference, two rings): mech-holes-shark -y 1.13 -> 0.53, man iso
//    1.01 -> 0.38, elephant-with-holes +z 1.01 -> 0.68 (now pass); mech-holes-shark +y (1.05), u -y (1.05),
//    oblong +y (1.03) unchanged: the bound does not reach their farthest faces (oblong's 2 steps in,
//    sampling angle 69°); 0.05 of the longest edge fixes shark +y but takes bull +x 0.80 -> 0.53 of the
//    square's area.
constexpr const char* kOpenViews[] = {"mean man.off -z",
                                      "mean bones.off +x",
                                      "mean blobby_3cc.off -x",
                                      "mean three_peaks.off -y",
                                      "mean patch-01.off +y",
                                      "mean patch-01.off -y",
                                      "mean mesh_with_border.off +y",
                                      "mean icosahedron.off iso",
                                      "hausdorff mech-holes-shark.off +y",
                                      "hausdorff u.off -y",
                                      "hausdorff boeing.off +y",
                                      "hausdorff boeing.off -y",
                                      "hausdorff oblong.off +y"};

TEST(ScanPipeline, CriterionAAtTheDefaultsOnUntunedMeshesLong) {
    if (!fss::test::longTests()) GTEST_SKIP() << "set FSS_LONG_TESTS=1";
    expectCriterionA(latticeTable(splitList(kWideList), LatticeSetting{}), 282,
                     std::vector<std::string>(std::begin(kOpenViews), std::end(kOpenViews)));
}

// Criterion A at the product's defaults on five views of small meshes of the wide set (a CAD part, a
// sphere, an open mesh with holes, a terrain, a part with holes), each against the square lattice's
// Hausdorff distance measured here. Session 18 (the CPU renderer, as here): rotor_small -x 58.3°, 0 % < 30°,
// Hausdorff 2.27e-4 (square 5.41e-4); larger_sphere iso 54.2°, 0 %, 1.71e-4 (3.82e-4); holes +x 56.1°, 0 %,
// 4.05e-4 (5.76e-4). Session 19 adds two views that failed the mean smallest angle with the session 17 fit
// and pass with the warp following the fit (ScanOptions::warpFollowsFit; neither was tuned on):
// three_peaks iso 49.0° -> 53.6° (Hausdorff 4.70e-4, square 6.22e-4), cheese iso 48.5° -> 52.7° (1.14e-3,
// square 2.44e-3).
TEST(ScanPipeline, CriterionAAtTheDefaultsOnFiveUntunedViews) {
    expectCriterionA(latticeTable({"rotor_small.off:-x", "larger_sphere.off:iso", "holes.off:+x",
                                   "three_peaks.off:iso", "cheese.off:iso"},
                                  LatticeSetting{}),
                     5);
}

// The patch relaxation (ScanParams::relaxIterations, mesh/relax.h): the same connectivity and border,
// every vertex on the reference on the same side of every crease, no face turned away from the camera,
// a smallest angle and a mean smallest angle no lower than without it.
TEST(ScanPipeline, RelaxationMovesVerticesOnTheReferenceOnly) {
    const fss::Mesh ref = fss::test::loadMesh("fandisk.off");
    fss::CpuMeshRenderer renderer;
    renderer.setMesh(ref);
    fss::ScanParams params;
    params.camera = fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(ref), 128, 128);
    // On the pixel lattice, where the relaxation has the most to do and the bounds below were measured (on
    // the default adaptive lattice six sweeps move the mean smallest angle 55.01° -> 55.06° at a Hausdorff
    // cost of 1.215e-3 -> 1.688e-3, issue #20 report: the relaxation stays off by default).
    params.scan.lattice = fss::Lattice::Square;
    params.scan.minLatticeAngleDeg = 0;
    params.relaxIterations = 0;
    const fss::ScanResult plain = fss::scanPatch(ref, renderer, ref, renderer, params);
    params.relaxIterations = 6;
    const fss::ScanResult relaxed = fss::scanPatch(ref, renderer, ref, renderer, params);
    const fss::Mesh &a = plain.patch.mesh, &b = relaxed.patch.mesh;
    ASSERT_EQ(a.number_of_vertices(), b.number_of_vertices());
    ASSERT_EQ(a.number_of_faces(), b.number_of_faces());
    for (auto h : a.halfedges())
        ASSERT_EQ(a.target(h), b.target(h));
    const fss::RayCaster caster(ref);
    const double scale = fss::boundingBox(ref).diagonal().norm();
    std::size_t moved = 0;
    for (auto v : b.vertices()) {
        const auto& p = a.point(v);
        const auto& q = b.point(v);
        if (a.is_border(v)) {
            EXPECT_EQ(p, q);
            continue;
        }
        if (p == q) continue;
        ++moved;
        const Eigen::Vector3d pe(p.x(), p.y(), p.z()), qe(q.x(), q.y(), q.z());
        const fss::SurfacePoint onRef = caster.closestPoint(qe);
        EXPECT_LE(onRef.distance, 1e-9 * scale);
        // The same side of every crease: the reference normal under the vertex turned by less than 35°.
        auto normalAt = [&](fss::FaceIndex f) {
            const auto h = ref.halfedge(f);
            const auto& x = ref.point(ref.source(h));
            const auto& y = ref.point(ref.target(h));
            const auto& z = ref.point(ref.target(ref.next(h)));
            const auto n = CGAL::cross_product(y - x, z - x);
            return Eigen::Vector3d(n.x(), n.y(), n.z()).normalized();
        };
        EXPECT_GT(normalAt(onRef.face).dot(normalAt(caster.closestPoint(pe).face)),
                  std::cos(35.0 * std::numbers::pi / 180))
            << "vertex " << v;
    }
    const fss::Metrics ma = fss::computeMetrics(a, {.selfIntersections = false, .reference = &ref});
    const fss::Metrics mb = fss::computeMetrics(b, {.selfIntersections = true, .reference = &ref});
    std::printf("fandisk iso 128²: %zu of %zu interior vertices moved; mean smallest angle %.2f° -> %.2f°, "
                "below 30° %.2f %% -> %.2f %%, smallest %.2f° -> %.2f°, Hausdorff %.3e -> %.3e\n",
                moved, ma.interiorVertices, ma.meanMinAngleDeg, mb.meanMinAngleDeg,
                100 * ma.fracMinAngleBelow30, 100 * mb.fracMinAngleBelow30, ma.minAngleDeg, mb.minAngleDeg,
                *ma.hausdorffToRefRel, *mb.hausdorffToRefRel);
    EXPECT_GT(moved, ma.interiorVertices / 10);
    EXPECT_GE(mb.minAngleDeg, ma.minAngleDeg);
    EXPECT_GE(mb.meanMinAngleDeg, ma.meanMinAngleDeg);
    EXPECT_EQ(mb.selfIntersections.value_or(1), 0u);
    // Measured: 2.91e-3 -> 3.73e-3 (+28 %, still below a pixel footprint): the relaxation costs distance
    // to the reference (issue #20 report); this bound records it.
    EXPECT_LE(*mb.hausdorffToRefRel, 1.35 * *ma.hausdorffToRefRel);
    EXPECT_EQ(mb.fracValence6Interior, ma.fracValence6Interior);
    // Every face still faces the camera.
    const Eigen::Vector3d eye = params.camera.eye;
    for (auto f : b.faces()) {
        const auto h = b.halfedge(f);
        const auto& x = b.point(b.source(h));
        const auto& y = b.point(b.target(h));
        const auto& z = b.point(b.target(b.next(h)));
        const auto n = CGAL::cross_product(y - x, z - x);
        const Eigen::Vector3d ne(n.x(), n.y(), n.z()), toEye = eye - Eigen::Vector3d(x.x(), x.y(), x.z());
        EXPECT_GT(ne.dot(toEye), 0) << "face " << f;
    }
}
