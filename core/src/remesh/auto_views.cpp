// The views of auto v1 and v2 (auto_remesh.h steps 2-3): the greedy Gauss-map view plan, the parallel
// cameras that frame them and the partition of the surface among them. Split from auto_remesh.cpp.
#include "remesh/auto_face_geometry.h"
#include "remesh/auto_v2.h"

#include "fss/frame_buffers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace fss::detail {
namespace {

using autoview::FaceGeometry;
using autoview::faceGeometry;

/// Evenly spread unit directions (Fibonacci sphere), after the six axis directions.
std::vector<Eigen::Vector3d> candidateDirections(int n) {
    std::vector<Eigen::Vector3d> dirs = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = golden * i;
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    return dirs;
}

} // namespace

/// A parallel camera looking along −\p from (the eye on the \p from side) that frames \p points (plus
/// \p margin world units on each side) with square pixels of side \p footprint. The image is enlarged by
/// raising the footprint when it would exceed Camera::kMaxResolution.
Camera frameParallelView(const Eigen::Vector3d& from, const std::vector<Eigen::Vector3d>& points,
                         double footprint, double margin) {
    const Eigen::Vector3d w = -from.normalized(); // view direction
    const Eigen::Vector3d up0 = std::abs(w.z()) > 0.9 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 1);
    const Eigen::Vector3d right = w.cross(up0).normalized();
    const Eigen::Vector3d up = right.cross(w).normalized();
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300, z0 = 1e300, z1 = -1e300;
    for (const Eigen::Vector3d& p : points) {
        const double x = p.dot(right), y = p.dot(up), z = p.dot(w);
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
        z0 = std::min(z0, z), z1 = std::max(z1, z);
    }
    x0 -= margin, x1 += margin, y0 -= margin, y1 += margin;
    const double ext = std::max({x1 - x0, y1 - y0, footprint});
    const double f = std::max(footprint, ext / (Camera::kMaxResolution - 4));
    Camera cam;
    cam.parallel = true;
    cam.width = std::clamp(int(std::ceil((x1 - x0) / f)) + 2, 16, Camera::kMaxResolution);
    cam.height = std::clamp(int(std::ceil((y1 - y0) / f)) + 2, 16, Camera::kMaxResolution);
    cam.parallelScale = 0.5 * cam.height * f;
    const Eigen::Vector3d centre = right * (0.5 * (x0 + x1)) + up * (0.5 * (y0 + y1)) + w * (0.5 * (z0 + z1));
    const double depth = std::max(z1 - z0, ext) + margin;
    cam.focal = centre;
    cam.eye = centre - w * depth;
    cam.up = up;
    cam.nearPlane = 0.01 * depth;
    cam.farPlane = 10 * depth;
    return cam;
}

/// The partition of the reference surface among the initial views: label[f] is the view whose scan owns
/// reference face f (−1: no view sees it well enough; the follow-up views handle those faces).
///
/// Each face starts with the view that sees it most frontally among the views in which it is visible
/// (its centroid not behind the depth buffer) at a sampling angle ≤ maxAngle. The labelling is then
/// smoothed by iterated conditional modes on a Potts energy, Σ_f area_f·(1/cos θ_fl − 1) +
/// β·Σ_{shared edges} length·[labels differ], which shortens the borders between regions, and connected
/// pieces of a label smaller than minIslandArea are merged into the neighbouring label they share the
/// longest border with (when that view sees all of them). Few compact regions: few seams.
std::vector<int> partitionSurface(const Mesh& reference, const std::vector<FrameBuffers>& views,
                                  double maxAngleDeg, double beta, double minIslandArea, int rounds) {
    const std::size_t nf = reference.number_of_faces() + reference.number_of_removed_faces();
    const std::size_t nv = views.size();
    const double cosMin = std::cos(maxAngleDeg * std::numbers::pi / 180.0);
    std::vector<FaceGeometry> geo(nf);
    for (FaceIndex f : reference.faces())
        geo[f.idx()] = faceGeometry(reference, f);
    // cost[f·nv + v]: data term of label v at face f, infinity when v may not own f.
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> cost(nf * nv, inf);
    for (std::size_t v = 0; v < nv; ++v) {
        const FrameBuffers& fb = views[v];
        const Camera& cam = fb.camera;
        const Eigen::Vector3d toEye = -cam.viewDirection();
        for (FaceIndex f : reference.faces()) {
            const FaceGeometry& g = geo[f.idx()];
            const double c = g.normal.dot(toEye);
            if (g.area <= 0 || c < cosMin) continue;
            const Eigen::Vector3d s = cam.project(g.centroid);
            const int px = int(std::floor(s.x())), py = int(std::floor(s.y()));
            if (px < 0 || py < 0 || px >= fb.width() || py >= fb.height()) continue;
            bool visible = fb.faceAt(px, py) == std::uint32_t(f.idx());
            if (!visible && fb.covered(px, py)) {
                // The face is thinner than a pixel or its centroid falls next to its pixels: compare depths,
                // with a tolerance of the depth a surface at this angle spans within a pixel or two.
                const Eigen::Vector3d p = cam.unprojectPixelCentre(px, py, fb.depthAt(px, py));
                const double footprint = cam.pixelFootprint(p);
                const double tan = std::sqrt(std::max(0.0, 1.0 - c * c)) / c;
                visible = cam.viewDepth(g.centroid) <= cam.viewDepth(p) + footprint * (1.0 + 2.0 * tan);
            }
            if (visible) cost[f.idx() * nv + v] = g.area * (1.0 / c - 1.0);
        }
    }
    std::vector<int> label(nf, -1);
    for (FaceIndex f : reference.faces()) {
        double best = inf;
        for (std::size_t v = 0; v < nv; ++v)
            if (cost[f.idx() * nv + v] < best) best = cost[f.idx() * nv + v], label[f.idx()] = int(v);
    }
    auto edgeLength = [&](HalfedgeIndex h) {
        return (toEigen(reference.point(reference.target(h))) - toEigen(reference.point(reference.source(h))))
            .norm();
    };
    // Iterated conditional modes.
    std::vector<double> border(nv);
    for (int round = 0; round < rounds; ++round) {
        std::size_t changed = 0;
        for (FaceIndex f : reference.faces()) {
            if (label[f.idx()] < 0) continue;
            std::fill(border.begin(), border.end(), 0.0);
            double total = 0;
            for (HalfedgeIndex h : CGAL::halfedges_around_face(reference.halfedge(f), reference)) {
                const FaceIndex o = reference.face(reference.opposite(h));
                const double len = edgeLength(h);
                total += len;
                if (o != Mesh::null_face() && label[o.idx()] >= 0) border[std::size_t(label[o.idx()])] += len;
            }
            int best = label[f.idx()];
            double bestCost = inf;
            for (std::size_t v = 0; v < nv; ++v) {
                const double c = cost[f.idx() * nv + v] + beta * (total - border[v]);
                if (c < bestCost) bestCost = c, best = int(v);
            }
            if (best != label[f.idx()]) label[f.idx()] = best, ++changed;
        }
        if (changed == 0) break;
    }
    // Islands: connected pieces of one label with a small area join their longest-bordering neighbour.
    for (int round = 0; round < 4; ++round) {
        std::size_t merged = 0;
        std::vector<char> seen(nf, 0);
        for (FaceIndex f : reference.faces()) {
            if (seen[f.idx()] || label[f.idx()] < 0) continue;
            const int l = label[f.idx()];
            std::vector<FaceIndex> piece{f}, stack{f};
            seen[f.idx()] = 1;
            double area = 0;
            std::fill(border.begin(), border.end(), 0.0);
            while (!stack.empty()) {
                const FaceIndex g = stack.back();
                stack.pop_back();
                area += geo[g.idx()].area;
                for (HalfedgeIndex h : CGAL::halfedges_around_face(reference.halfedge(g), reference)) {
                    const FaceIndex o = reference.face(reference.opposite(h));
                    if (o == Mesh::null_face()) continue;
                    if (label[o.idx()] == l) {
                        if (!seen[o.idx()]) seen[o.idx()] = 1, stack.push_back(o), piece.push_back(o);
                    } else if (label[o.idx()] >= 0) {
                        border[std::size_t(label[o.idx()])] += edgeLength(h);
                    }
                }
            }
            if (area >= minIslandArea) continue;
            std::vector<std::size_t> order(nv);
            for (std::size_t v = 0; v < nv; ++v)
                order[v] = v;
            std::sort(order.begin(), order.end(),
                      [&](std::size_t a, std::size_t b) { return border[a] > border[b]; });
            for (std::size_t v : order) {
                if (border[v] <= 0) break;
                const bool allSeen = std::all_of(piece.begin(), piece.end(),
                                                 [&](FaceIndex g) { return cost[g.idx() * nv + v] < inf; });
                if (!allSeen) continue;
                for (FaceIndex g : piece)
                    label[g.idx()] = int(v);
                ++merged;
                break;
            }
        }
        if (merged == 0) break;
    }
    return label;
}

std::vector<Eigen::Vector3d> planViews(const Mesh& reference, double servedAngleDeg, double minAreaFraction,
                                       int maxViews) {
    const double servedCos = std::cos(servedAngleDeg * std::numbers::pi / 180.0);
    double area = 0;
    for (FaceIndex f : reference.faces())
        area += faceGeometry(reference, f).area;
    const std::vector<Eigen::Vector3d> candidates = candidateDirections(600);
    std::vector<double> binArea(candidates.size(), 0);
    std::vector<Eigen::Vector3d> binNormalSum(candidates.size(), Eigen::Vector3d::Zero());
    for (FaceIndex f : reference.faces()) {
        const FaceGeometry g = faceGeometry(reference, f);
        if (g.area <= 0) continue;
        std::size_t best = 0;
        double bestDot = -2;
        for (std::size_t i = 0; i < candidates.size(); ++i) {
            const double d = candidates[i].dot(g.normal);
            if (d > bestDot) bestDot = d, best = i;
        }
        binArea[best] += g.area;
        binNormalSum[best] += g.area * g.normal;
    }
    std::vector<Eigen::Vector3d> binNormal(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
        binNormal[i] =
            binNormalSum[i].norm() > 0 ? Eigen::Vector3d(binNormalSum[i].normalized()) : candidates[i];
    std::vector<char> served(candidates.size(), 0);
    auto servedArea = [&](const Eigen::Vector3d& d) {
        double a = 0;
        for (std::size_t b = 0; b < candidates.size(); ++b)
            if (!served[b] && binArea[b] > 0 && binNormal[b].dot(d) >= servedCos) a += binArea[b];
        return a;
    };
    std::vector<Eigen::Vector3d> views;
    while (int(views.size()) < maxViews) {
        double bestArea = 0;
        Eigen::Vector3d bestDir;
        for (const Eigen::Vector3d& d : candidates) {
            const double a = servedArea(d);
            if (a > bestArea * 1.0001) bestArea = a, bestDir = d;
        }
        if (bestArea < minAreaFraction * area) break;
        // Centre the view on what it serves (a single plane gets an exactly frontal view).
        Eigen::Vector3d mean(0, 0, 0);
        for (std::size_t b = 0; b < candidates.size(); ++b)
            if (!served[b] && binArea[b] > 0 && binNormal[b].dot(bestDir) >= servedCos)
                mean += binNormalSum[b];
        if (mean.norm() > 0 && servedArea(mean.normalized()) >= 0.95 * bestArea) bestDir = mean.normalized();
        for (std::size_t b = 0; b < candidates.size(); ++b)
            if (binArea[b] > 0 && binNormal[b].dot(bestDir) >= servedCos) served[b] = 1;
        views.push_back(bestDir);
    }
    return views;
}

} // namespace fss::detail
