#include "fss/scan_pipeline.h"

#include "fss/error.h"
#include "fss/mask_triangulate.h"
#include "fss/raycast.h"

#include "mesh/relax.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace fss {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

void reportAt(const Progress& progress, const ProgressMark& mark) {
    if (!mark.stage.empty()) progress.report(mark.fraction, mark.stage);
}

// The patch's interior vertices relaxed on the reference (mesh/relax.h), each starting from its sample's
// reference face and footprint.
void relaxPatch(Patch& patch, const SampleGrid& grid, const Mesh& reference, const ScanParams& params) {
    Mesh& mesh = patch.mesh;
    const auto [gridIndex, found] = mesh.property_map<VertexIndex, GridIndex>(props::vertexGridIndex);
    if (!found) return;
    std::vector<VertexIndex> vertices;
    std::vector<FaceIndex> hints;
    std::vector<double> footprints;
    for (VertexIndex v : mesh.vertices()) {
        if (mesh.is_border(v)) continue;
        const GridIndex g = gridIndex[v];
        const Sample& s = grid.at(g.row, g.col);
        if (s.face == Sample::kNoFace) continue;
        vertices.push_back(v);
        hints.push_back(FaceIndex(s.face));
        footprints.push_back(double(s.footprint));
    }
    detail::RelaxOptions options;
    options.iterations = params.relaxIterations;
    detail::relaxOnReference(mesh, reference, vertices, hints, footprints, options, &grid.camera);
}

// The longest screen edge, in pixels, of the grid triangles of a lattice other than the square pixel
// lattice (sampleLattice: sample (r, c) at o + c·a + r·b, triangles with the edges a, b, a + b), relative to
// the square pixel lattice's (√2, its diagonal); 1 for the square lattice and grids of fewer than 2×2.
double edgeLimitScale(const SampleGrid& grid, const ScanOptions& options) {
    const Lattice lattice = options.lattice;
    if (lattice == Lattice::Square || grid.rows < 2 || grid.cols < 2) return 1.0;
    // A lattice warped to the surface has edges of about one spacing on the surface wherever it is slanted
    // (measured 0.99–1.07 footprints around the worst faces of the 70 views of the issue #20 table); its
    // screen edges say nothing. Its limit: 1.65 spacings (scale 0.55 of 3 footprints), about what the
    // square lattice's 3 footprints leave over its own diagonal on a surface slanted by 45° (√3 footprints).
    // The triangular lattice's 2.12 (scale 1/√2) let through faces 1.7–2.1 spacings long beside a
    // silhouette or where the fit stretches the lattice: they made the Hausdorff distance worse than the
    // square lattice's (elk +z: 1.64e-3 against 1.56e-3; 0.87e-3 with this limit, coverage 0.99 -> 0.98).
    if (lattice == Lattice::Adaptive && options.warpToSurface) return 0.55;
    const Eigen::Vector2d a = grid.at(0, 1).screen - grid.at(0, 0).screen;
    const Eigen::Vector2d b = grid.at(1, 1).screen - grid.at(0, 1).screen;
    return std::max({a.norm(), b.norm(), (a + b).norm()}) / std::sqrt(2.0);
}

// The border faces of the patch farther from the reference than \p chordFootprints of their corners'
// smallest pixel footprint (the largest distance of the centroid and the edge midpoints, closestPointNear
// from a corner's sample face): their border corners' samples lose `valid`. Returns whether any did.
bool maskFarBorderFaces(const Patch& patch, SampleGrid& grid, const Mesh& reference, double chordFootprints) {
    const Mesh& mesh = patch.mesh;
    const auto [gridIndex, found] = mesh.property_map<VertexIndex, GridIndex>(props::vertexGridIndex);
    if (!found || !(chordFootprints > 0)) return false;
    std::vector<std::size_t> drop;
    for (FaceIndex f : mesh.faces()) {
        bool border = false;
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
            border = border || mesh.is_border(mesh.opposite(h));
        if (!border) continue;
        std::array<Eigen::Vector3d, 3> p;
        std::array<VertexIndex, 3> vs;
        FaceIndex hint;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            const auto& q = mesh.point(v);
            vs[std::size_t(k)] = v;
            p[std::size_t(k++)] = Eigen::Vector3d(q.x(), q.y(), q.z());
            const Sample& s = grid.at(gridIndex[v].row, gridIndex[v].col);
            if (hint == FaceIndex() && s.face != Sample::kNoFace) hint = FaceIndex(s.face);
        }
        if (hint == FaceIndex()) continue;
        double d = closestPointNear(reference, (p[0] + p[1] + p[2]) / 3.0, hint).distance;
        for (std::size_t i = 0; i < 3; ++i)
            d = std::max(d, closestPointNear(reference, 0.5 * (p[i] + p[(i + 1) % 3]), hint).distance);
        double footprint = std::numeric_limits<double>::infinity();
        for (VertexIndex v : vs)
            footprint = std::min(footprint, double(grid.at(gridIndex[v].row, gridIndex[v].col).footprint));
        if (!(d > chordFootprints * footprint)) continue;
        for (VertexIndex v : vs)
            if (mesh.is_border(v))
                drop.push_back(std::size_t(gridIndex[v].row) * std::size_t(grid.cols) +
                               std::size_t(gridIndex[v].col));
    }
    for (std::size_t i : drop)
        grid.samples[i].valid = grid.samples[i].admissible = false;
    return !drop.empty();
}

} // namespace

MaskedPatch maskAndTriangulate(SampleGrid& grid, const MaskStages& stages, const Progress& progress) {
    ScanWorkspace workspace;
    return maskAndTriangulate(grid, stages, workspace, progress);
}

MaskedPatch maskAndTriangulate(SampleGrid& grid, const MaskStages& stages, ScanWorkspace& workspace,
                               const Progress& progress) {
    MaskedPatch result;
    reportAt(progress, stages.atLasso);
    auto t = Clock::now();
    if (stages.lasso) applyLasso(grid, *stages.lasso);
    result.timings.lasso = secondsSince(t);
    result.counts.afterLasso = grid.admissibleCount();
    if (stages.lasso && result.counts.afterLasso == 0) throw InvalidInputError(stages.lassoSelectsNothing);

    reportAt(progress, stages.atQuality);
    t = Clock::now();
    if (stages.current) {
        if (!stages.currentBuffers)
            throw InvalidInputError(
                "The quality mask needs the current mesh's buffers from the scan camera.");
        applyQualityMask(grid, *stages.current, *stages.currentBuffers, stages.quality);
    }
    if (stages.readmit) {
        const std::vector<char>& readmit = *stages.readmit;
        if (readmit.size() != grid.samples.size())
            throw InvalidInputError("The re-admission mask has " + std::to_string(readmit.size()) +
                                    " flags for " + std::to_string(grid.samples.size()) + " samples.");
        for (std::size_t i = 0; i < grid.samples.size(); ++i)
            if (readmit[i]) grid.samples[i].admissible = grid.samples[i].valid = true;
    }
    result.timings.qualityMask = secondsSince(t);
    result.counts.afterQuality = grid.admissibleCount();

    reportAt(progress, stages.atMorphology);
    t = Clock::now();
    applyMorphology(grid, stages.morphology, workspace);
    result.timings.morphology = secondsSince(t);
    result.counts.afterMorphology = grid.validCount();

    reportAt(progress, stages.atTriangulate);
    t = Clock::now();
    result.patch = triangulateGrid(grid, stages.triangulate, workspace);
    result.timings.triangulate = secondsSince(t);
    if (result.patch.mesh.number_of_faces() == 0)
        throw InvalidInputError(result.counts.afterQuality == 0 ? stages.nothingBetter : stages.nothingLeft);
    return result;
}

ScanResult scanPatch(const Mesh& reference, MeshRenderer& referenceRenderer, const Mesh& current,
                     MeshRenderer& currentRenderer, const ScanParams& params, const Progress& progress) {
    ScanWorkspace workspace;
    return scanPatch(reference, referenceRenderer, current, currentRenderer, params, workspace, progress);
}

ScanResult scanPatch(const Mesh& reference, MeshRenderer& referenceRenderer, const Mesh& current,
                     MeshRenderer& currentRenderer, const ScanParams& params, ScanWorkspace& workspace,
                     const Progress& progress) {
    const auto start = Clock::now();
    params.validate();

    ScanResult result;
    progress.report(0.0, "render reference");
    auto t = Clock::now();
    const FrameBuffers referenceBuffers = referenceRenderer.render(params.camera);
    result.timings.renderReference = secondsSince(t);
    result.counts.pixels = std::size_t(referenceBuffers.width()) * std::size_t(referenceBuffers.height());
    if (referenceBuffers.coveredCount() == 0)
        throw InvalidInputError("The scan camera sees no part of the mesh.");

    const bool currentIsReference = (&current == &reference);
    if (!currentIsReference) {
        progress.report(0.2, "render current");
        t = Clock::now();
        // The same camera, with the clipping range the reference render used, so pixels correspond.
        result.currentBuffers = currentRenderer.render(referenceBuffers.camera);
        result.timings.renderCurrent = secondsSince(t);
    } else {
        result.currentBuffers = referenceBuffers;
    }

    progress.report(0.4, "sample");
    t = Clock::now();
    result.grid = sampleLattice(referenceBuffers, reference, workspace, params.scan);
    result.timings.sample = secondsSince(t);
    result.counts.covered = result.grid.hitCount();
    result.counts.frontFacing = result.grid.admissibleCount();
    if (result.counts.frontFacing == 0)
        throw InvalidInputError(
            "The scan camera sees only the back of the surface; it is probably inside the mesh.");
    applyLatticeAngleMask(result.grid, params.scan.minLatticeAngleDeg,
                          params.scan.warpToSurface && params.scan.lattice == Lattice::Adaptive);
    result.counts.wellShaped = result.grid.admissibleCount();

    MaskStages stages;
    if (params.lasso) stages.lasso = &*params.lasso;
    if (!currentIsReference) {
        stages.current = &current;
        stages.currentBuffers = &result.currentBuffers;
    }
    stages.quality = params.quality;
    stages.morphology = {.radius = params.erodeRadius, .dilateRadius = params.dilateRadius};
    stages.triangulate = params.triangulate;
    // The edge limit is in pixel footprints; the lattice's edges are `spacing` pixels long.
    stages.triangulate.maxEdgeFootprints *= std::max(1.0, latticeSpacingPixels(params.camera, params.scan));
    // And no looser than on the pixel lattice relative to the triangles' screen size (issue #20): the
    // triangular and adaptive lattices' edges are at most 1 px on the screen against the pixel lattice's
    // √2 px diagonal, so the same limit in footprints let through their triangles stretched 2–3 times more
    // in depth (across occlusion boundaries and at grazing slants): those made the adaptive lattice's
    // Hausdorff distance worse than the square lattice's in 9 of 65 views (issue #20 report).
    stages.triangulate.maxEdgeFootprints *= edgeLimitScale(result.grid, params.scan);
    MaskedPatch masked = maskAndTriangulate(result.grid, stages, workspace, progress);
    result.patch = std::move(masked.patch);
    // A warped lattice's patch where it ends at a crease or a fold: its border faces 1–2 lattice steps
    // from there bridge the crease and lie farther from the reference than the square lattice's faces
    // (issue #20, criterion A, Hausdorff part). Those farther than 0.2 footprints are dropped, two rings.
    if (params.scan.lattice == Lattice::Adaptive && params.scan.warpToSurface) {
        for (int pass = 0; pass < 2 && maskFarBorderFaces(result.patch, result.grid, reference, 0.2); ++pass)
            result.patch = triangulateGrid(result.grid, stages.triangulate, workspace);
    }
    result.counts.afterLasso = masked.counts.afterLasso;
    result.counts.afterQuality = masked.counts.afterQuality;
    result.counts.afterMorphology = masked.counts.afterMorphology;
    result.timings.lasso = masked.timings.lasso;
    result.timings.qualityMask = masked.timings.qualityMask;
    result.timings.morphology = masked.timings.morphology;
    result.timings.triangulate = masked.timings.triangulate;
    if (params.relaxIterations > 0) {
        t = Clock::now();
        relaxPatch(result.patch, result.grid, reference, params);
        result.timings.relax = secondsSince(t);
    }
    result.timings.total = secondsSince(start);
    progress.report(1.0, "done");
    return result;
}

} // namespace fss
