#include "fss/scan_pipeline.h"

#include "fss/error.h"

#include <chrono>

namespace fss {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

} // namespace

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
    result.grid = sampleRegularGrid(referenceBuffers, reference, workspace, params.scan);
    result.timings.sample = secondsSince(t);
    result.counts.covered = result.grid.hitCount();
    result.counts.frontFacing = result.grid.admissibleCount();
    if (result.counts.frontFacing == 0)
        throw InvalidInputError("The scan camera sees only the back of the surface; it is probably inside the mesh.");

    t = Clock::now();
    if (params.lasso) applyLasso(result.grid, *params.lasso);
    result.timings.lasso = secondsSince(t);
    result.counts.afterLasso = result.grid.admissibleCount();
    if (result.counts.afterLasso == 0)
        throw InvalidInputError("The lasso selects no part of the visible surface.");

    progress.report(0.6, "quality mask");
    t = Clock::now();
    if (!currentIsReference) applyQualityMask(result.grid, current, result.currentBuffers, params.quality);
    result.timings.qualityMask = secondsSince(t);
    result.counts.afterQuality = result.grid.admissibleCount();

    progress.report(0.7, "morphology");
    t = Clock::now();
    applyMorphology(result.grid, {.radius = params.erodeRadius, .dilateRadius = params.dilateRadius},
                    workspace);
    result.timings.morphology = secondsSince(t);
    result.counts.afterMorphology = result.grid.validCount();

    progress.report(0.8, "triangulate");
    t = Clock::now();
    result.patch = triangulateGrid(result.grid, params.triangulate, workspace);
    result.timings.triangulate = secondsSince(t);
    if (result.patch.mesh.number_of_faces() == 0) {
        if (result.counts.afterQuality == 0)
            throw InvalidInputError("Every sample of this scan is worse than the mesh already there, so nothing "
                                    "would change (use force-replace to override).");
        throw InvalidInputError("Nothing is left to triangulate after the masks; enlarge the lasso or reduce the "
                                "erosion.");
    }
    result.timings.total = secondsSince(start);
    progress.report(1.0, "done");
    return result;
}

} // namespace fss
