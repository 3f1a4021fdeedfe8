#include "fss/auto_remesh.h"

#include "mesh/features.h"
#include "mesh/local_ops.h"
#include "remesh/auto_face_geometry.h"
#include "remesh/auto_v2.h"
#include "remesh/crease_snap.h"
#include "remesh/join_regions.h"
#include "remesh/seam_relax.h"

#include "fss/error.h"
#include "fss/fishbone_scan.h"
#include "fss/mask.h"
#include "fss/mask_triangulate.h"
#include "fss/scan.h"
#include "fss/scan_pipeline.h"
#include "fss/triangulate.h"

#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_set>

namespace fss {
namespace {

using detail::toEigen;
using detail::autoview::FaceGeometry;
using detail::autoview::faceGeometry;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The scan id map of \p mesh, created with −1 when absent.
Mesh::Property_map<FaceIndex, std::int32_t> scanIds(Mesh& mesh) {
    return mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
}

struct Coverage {
    double scanned = 0, total = 0;
    std::size_t inputFaces = 0;
    double fraction() const { return total > 0 ? scanned / total : 0; }
};

Coverage measureCoverage(Mesh& mesh) {
    auto ids = scanIds(mesh);
    Coverage c;
    for (FaceIndex f : mesh.faces()) {
        const double a = faceGeometry(mesh, f).area;
        c.total += a;
        if (ids[f] >= 0)
            c.scanned += a;
        else
            ++c.inputFaces;
    }
    return c;
}

double minCornerAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    auto angle = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
        const Eigen::Vector3d u = q - p, v = r - p;
        return std::atan2(u.cross(v).norm(), u.dot(v));
    };
    return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

/// Flips edges between two nearly coplanar faces (normals within \p maxDihedralDeg) where the flip raises
/// the smaller of the two faces' smallest angles, for faces with a smallest angle under \p belowDeg: the
/// slivers that seams leave. A flip is done only when the new edge does not exist yet, both end vertices keep
/// valence ≥ 3 (canFlip), and both new faces keep the orientation of the old ones (normals within
/// maxDihedralDeg): connectivity stays manifold and the surface moves nowhere (the quad is flat to within the
/// dihedral limit).
std::size_t flipSlivers(Mesh& mesh, double belowDeg, double maxDihedralDeg, int rounds) {
    const double below = belowDeg * std::numbers::pi / 180.0;
    const double cosDihedral = std::cos(maxDihedralDeg * std::numbers::pi / 180.0);
    std::size_t flips = 0;
    for (int round = 0; round < rounds; ++round) {
        std::size_t flipsThisRound = 0;
        for (EdgeIndex e : mesh.edges()) {
            const HalfedgeIndex h = mesh.halfedge(e), o = mesh.opposite(h);
            if (!detail::canFlip(mesh, h)) continue;
            const VertexIndex va = mesh.source(h), vb = mesh.target(h);
            const VertexIndex vc = mesh.target(mesh.next(h)), vd = mesh.target(mesh.next(o));
            const Eigen::Vector3d a = toEigen(mesh.point(va)), b = toEigen(mesh.point(vb));
            const Eigen::Vector3d c = toEigen(mesh.point(vc)), d = toEigen(mesh.point(vd));
            const double before = std::min(minCornerAngle(a, b, c), minCornerAngle(b, a, d));
            if (before >= below) continue;
            const Eigen::Vector3d n1 = (b - a).cross(c - a), n2 = (a - b).cross(d - b);
            if (n1.norm() == 0 || n2.norm() == 0 || n1.normalized().dot(n2.normalized()) < cosDihedral)
                continue;
            // After the flip: faces (c, a, d) and (d, b, c).
            const Eigen::Vector3d m1 = (a - c).cross(d - c), m2 = (b - d).cross(c - d);
            if (m1.norm() == 0 || m2.norm() == 0) continue;
            const Eigen::Vector3d n = (n1.normalized() + n2.normalized()).normalized();
            if (m1.normalized().dot(n) < cosDihedral || m2.normalized().dot(n) < cosDihedral) continue;
            const double after = std::min(minCornerAngle(c, a, d), minCornerAngle(d, b, c));
            if (after <= before + 1e-6) continue;
            CGAL::Euler::flip_edge(h, mesh);
            ++flipsThisRound;
        }
        flips += flipsThisRound;
        if (flipsThisRound == 0) break;
    }
    return flips;
}

/// Resamples a screen polyline so that consecutive points are at least \p minGap pixels apart.
Polyline2 thinPolyline(const Polyline2& in, double minGap) {
    Polyline2 out;
    for (const Eigen::Vector2d& p : in)
        if (out.empty() || (p - out.back()).norm() >= minGap) out.push_back(p);
    if (out.size() >= 2 && (in.back() - out.back()).norm() > 1e-9) out.back() = in.back();
    return out;
}

/// A band-shaped lasso of half width \p halfWidth pixels around the screen polyline \p line.
Lasso bandLasso(const Polyline2& line, double halfWidth) {
    Lasso lasso;
    const std::size_t n = line.size();
    std::vector<Eigen::Vector2d> left, right;
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d a = line[i == 0 ? 0 : i - 1], b = line[i + 1 == n ? n - 1 : i + 1];
        Eigen::Vector2d t = b - a;
        if (t.norm() < 1e-12) t = Eigen::Vector2d(1, 0);
        t.normalize();
        const Eigen::Vector2d nrm(-t.y(), t.x());
        // Extend the ends along the line by a little so the band covers the end samples.
        Eigen::Vector2d p = line[i];
        if (i == 0) p -= t * (0.5 * halfWidth);
        if (i + 1 == n) p += t * (0.5 * halfWidth);
        left.push_back(p + nrm * halfWidth);
        right.push_back(p - nrm * halfWidth);
    }
    lasso.points = left;
    lasso.points.insert(lasso.points.end(), right.rbegin(), right.rend());
    return lasso;
}

/// Pixels of \p buffers (rendered from \p current) within \p radius pixels (Chebyshev) of a pixel that shows
/// a face of \p current left from the input (props::faceScanId < 0); all false when no pixel shows one.
std::vector<char> pixelsNearInputFaces(Mesh& current, const FrameBuffers& buffers, int radius) {
    auto ids = scanIds(current);
    const int W = buffers.width(), H = buffers.height();
    std::vector<char> near(buffers.faceId.size(), 0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const std::uint32_t f = buffers.faceAt(x, y);
            if (f == FrameBuffers::kNoFace || ids[FaceIndex(f)] >= 0) continue;
            for (int dy = std::max(-radius, -y); dy <= radius && y + dy < H; ++dy)
                for (int dx = std::max(-radius, -x); dx <= radius && x + dx < W; ++dx)
                    near[buffers.index(x + dx, y + dy)] = 1;
        }
    return near;
}

/// The regular scan of autoRemesh: scanPatch's stages, with the quality mask overridden (samples
/// re-admitted) where the current mesh shows an input face within \p fillRadius pixels.
struct RegularScan {
    Patch patch;
    FrameBuffers currentBuffers;
    Camera camera;
};

RegularScan regularScan(const Mesh& reference, MeshRenderer& referenceRenderer, Mesh& current,
                        MeshRenderer& currentRenderer, const Camera& camera, std::int32_t scanId,
                        int fillRadius, double maxSamplingAngleDeg, const AutoOptions& options) {
    const FrameBuffers ref = referenceRenderer.render(camera);
    if (ref.coveredCount() == 0) throw InvalidInputError("The view sees no part of the mesh.");
    RegularScan out;
    out.currentBuffers = currentRenderer.render(ref.camera);
    out.camera = ref.camera;
    ScanOptions so;
    so.scanId = scanId;
    SampleGrid grid = sampleRegularGrid(ref, reference, so);
    std::vector<char> admissibleBefore;
    if (fillRadius >= 0) {
        admissibleBefore.resize(grid.samples.size());
        for (std::size_t i = 0; i < grid.samples.size(); ++i)
            admissibleBefore[i] = grid.samples[i].admissible;
    }
    // Keep each view to the part of the surface it sees well: its patch boundary then runs where the current
    // mesh is a clean height field in the view (no silhouettes or occlusion contours), which the stitcher
    // needs.
    const double maxAngle = maxSamplingAngleDeg * std::numbers::pi / 180.0;
    for (Sample& s : grid.samples)
        if (s.admissible && s.samplingAngle > maxAngle) s.admissible = s.valid = false;
    MaskStages stages;
    stages.current = &current;
    stages.currentBuffers = &out.currentBuffers;
    stages.quality.margin = options.qualityMargin;
    std::vector<char> readmit;
    if (fillRadius >= 0) {
        // Pixels that show an input face of the current mesh, dilated by fillRadius: their samples come
        // back after the quality mask.
        readmit = pixelsNearInputFaces(current, out.currentBuffers, fillRadius);
        for (std::size_t i = 0; i < grid.samples.size(); ++i)
            readmit[i] = readmit[i] && admissibleBefore[i];
        stages.readmit = &readmit;
    }
    stages.morphology = {.radius = options.morphologyRadius, .dilateRadius = options.morphologyRadius};
    stages.atQuality = stages.atMorphology = stages.atTriangulate = {};
    stages.nothingBetter = stages.nothingLeft =
        "No sample of the view is better than the mesh already there.";
    out.patch = maskAndTriangulate(grid, stages).patch;
    return out;
}

/// The scan of one region of the partition: the samples of \p ref (the reference rendered from the view)
/// on faces the view owns, plus a margin of \p marginPx pixels around them (so that the patch overlaps its
/// neighbours and the stitch has something to zipper), replacing whatever the current mesh has there.
///
/// With \p restrictTo (one flag per pixel), only samples on flagged pixels are kept: the fill pass uses it
/// to rescan, on the same pixel grid, the parts of a region still left from the input.
Patch regionScan(const Mesh& reference, const FrameBuffers& ref, const std::vector<int>& owner, int view,
                 std::int32_t scanId, int marginPx, double marginMaxAngleDeg, int morphologyRadius,
                 const std::vector<char>* restrictTo = nullptr) {
    ScanOptions so;
    so.scanId = scanId;
    SampleGrid grid = sampleRegularGrid(ref, reference, so);
    const int W = grid.cols, H = grid.rows;
    std::vector<char> own(grid.samples.size(), 0);
    for (std::size_t i = 0; i < grid.samples.size(); ++i) {
        const Sample& s = grid.samples[i];
        own[i] = s.admissible && s.face != Sample::kNoFace && owner[s.face] == view;
    }
    // The margin stays on the surface around the region (reference faces within 3·marginPx vertex rings of
    // it): dilating on the screen alone would also reach across occlusion contours onto other sheets.
    std::vector<char> nearRegion(owner.size(), 0);
    for (FaceIndex f : reference.faces())
        if (owner[f.idx()] == view) nearRegion[f.idx()] = 1;
    for (int ring = 0; ring < 3 * marginPx; ++ring) {
        std::vector<char> vertexNear(reference.number_of_vertices() + reference.number_of_removed_vertices(),
                                     0);
        for (FaceIndex f : reference.faces())
            if (nearRegion[f.idx()])
                for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
                    vertexNear[v.idx()] = 1;
        for (FaceIndex f : reference.faces())
            for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
                if (vertexNear[v.idx()]) nearRegion[f.idx()] = 1;
    }
    const float maxAngle = float(marginMaxAngleDeg * std::numbers::pi / 180.0);
    std::vector<char> keep(own);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (!own[grid.index(y, x)]) continue;
            for (int dy = -marginPx; dy <= marginPx; ++dy)
                for (int dx = -marginPx; dx <= marginPx; ++dx) {
                    if (!grid.inside(y + dy, x + dx)) continue;
                    const std::size_t j = grid.index(y + dy, x + dx);
                    const Sample& s = grid.samples[j];
                    if (s.admissible && s.samplingAngle <= maxAngle && s.face != Sample::kNoFace &&
                        nearRegion[s.face])
                        keep[j] = 1;
                }
        }
    for (std::size_t i = 0; i < grid.samples.size(); ++i)
        if (!keep[i] || (restrictTo && !(*restrictTo)[i]))
            grid.samples[i].admissible = grid.samples[i].valid = false;
    MaskStages stages; // no lasso, no quality mask: the region replaces whatever is there
    stages.morphology = {.radius = morphologyRadius, .dilateRadius = morphologyRadius};
    stages.atQuality = stages.atMorphology = stages.atTriangulate = {};
    stages.nothingBetter = stages.nothingLeft = "The view owns no part of the surface.";
    return maskAndTriangulate(grid, stages).patch;
}

} // namespace

namespace detail {

std::size_t flipSliverFaces(Mesh& mesh, double belowDeg, double maxDihedralDeg, int rounds) {
    return flipSlivers(mesh, belowDeg, maxDihedralDeg, rounds);
}

} // namespace detail

double edgeLengthForVertexCount(double area, std::size_t vertices) {
    if (!(area > 0) || !std::isfinite(area)) throw InvalidInputError("The surface area must be positive.");
    if (vertices == 0) throw InvalidInputError("The target vertex count must be positive.");
    return std::sqrt(area / (double(vertices) * std::sqrt(3.0) / 2.0));
}

double detail::targetEdgeLength(double area, const AutoOptions& options, std::size_t inputVertices) {
    if (options.edgeLength > 0) return options.edgeLength;
    return edgeLengthForVertexCount(area,
                                    options.targetVertices > 0 ? options.targetVertices : inputVertices);
}

AutoResult autoRemesh(const Mesh& reference, const AutoOptions& options, const Progress& progress) {
    const auto start = Clock::now();
    if (reference.number_of_faces() == 0) throw InvalidInputError("The mesh to remesh has no faces.");
    if (!CGAL::is_triangle_mesh(reference))
        throw InvalidInputError("The mesh to remesh is not a triangle mesh.");
    options.validate();
    if (options.engine == AutoEngine::V2) return detail::autoRemeshV2(reference, options, progress);

    AutoResult result;
    // Reference geometry: per-face normals and areas, bounding box.
    std::vector<FaceGeometry> faces;
    std::vector<Eigen::Vector3d> corners;
    faces.reserve(reference.number_of_faces());
    for (FaceIndex f : reference.faces()) {
        faces.push_back(faceGeometry(reference, f));
        result.area += faces.back().area;
    }
    if (!(result.area > 0)) throw InvalidInputError("The mesh to remesh has no area.");
    const Eigen::AlignedBox3d box = boundingBox(reference);
    for (int i = 0; i < 8; ++i)
        corners.push_back(box.corner(Eigen::AlignedBox3d::CornerType(i)));
    result.edgeLength = detail::targetEdgeLength(result.area, options, reference.number_of_vertices());
    const double L = result.edgeLength;
    const double footprint = L * options.footprintRatio;

    auto makeRenderer = [&]() -> std::unique_ptr<MeshRenderer> {
        if (options.renderer) return options.renderer();
        return std::make_unique<CpuMeshRenderer>();
    };
    std::unique_ptr<MeshRenderer> referenceRenderer = makeRenderer();
    std::unique_ptr<MeshRenderer> currentRenderer = makeRenderer();
    referenceRenderer->setMesh(reference);
    Mesh current = reference;
    scanIds(current);
    currentRenderer->setMesh(current);

    std::int32_t nextScanId = 0;

    // Runs one stitch of a patch; on failure the mesh is unchanged and the step says why.
    auto stitchInto = [&](AutoStep& step, const Mesh& patch, const Camera& camera,
                          const std::vector<std::uint32_t>& faceIds) {
        auto t = Clock::now();
        try {
            const StitchReport r = stitchPatch(current, patch, camera, options.stitch, faceIds);
            step.stitched = true;
            step.facesAdded = r.facesAdded;
            step.facesRemoved = r.facesRemoved;
            step.patchFacesTrimmed = r.patchFacesTrimmed;
            if (!r.skipped.empty()) step.note = r.skipped.front();
            currentRenderer->setMesh(current);
        } catch (const CancelledError&) {
            throw;
        } catch (const Error& e) {
            step.note = e.what();
        }
        result.stitchSeconds += secondsSince(t);
    };
    auto finishStep = [&](AutoStep& step, Clock::time_point t0) {
        step.seconds = secondsSince(t0);
        step.coverageAfter = measureCoverage(current).fraction();
        (step.stitched ? result.scansStitched : result.scansSkipped)++;
        result.steps.push_back(std::move(step));
    };
    auto budgetLeft = [&]() { return int(result.steps.size()) < options.maxViews; };

    // 1. Feature lines with fishbone grids.
    if (options.fishbone) {
        progress.report(0.0, "fishbone");
        auto t = Clock::now();
        const std::vector<detail::CreaseChain> chains =
            detail::creaseChains(reference, detail::sharpEdges(reference, options.featureAngleDeg), 40.0);
        result.featureChains = chains.size();
        result.planSeconds += secondsSince(t);
        FishboneCache cache;
        const double h = 4.0; // rib and backbone spacing in pixels
        std::size_t done = 0;
        for (const detail::CreaseChain& chain : chains) {
            ++done;
            if (!budgetLeft()) break;
            if (chain.length < options.minFeatureLength * L || chain.bisector.norm() == 0) continue;
            progress.report(0.3 * double(done) / double(chains.size()), "fishbone");
            const auto t0 = Clock::now();
            AutoStep step;
            step.kind = AutoStep::Kind::Fishbone;
            step.scanId = nextScanId++;
            try {
                ScanParams params;
                params.camera = detail::frameParallelView(chain.bisector, chain.points, footprint / h,
                                                          (options.fishboneBandWidth + 3) * L);
                params.erodeRadius = params.dilateRadius = options.morphologyRadius;
                params.scan.scanId = step.scanId;
                params.quality.margin = options.qualityMargin;
                Polyline2 line;
                for (const Eigen::Vector3d& p : chain.points) {
                    const Eigen::Vector3d s = params.camera.project(p);
                    line.emplace_back(s.x(), s.y());
                }
                line = thinPolyline(line, 1.0);
                if (line.size() < 2) continue;
                params.lasso = bandLasso(line, options.fishboneBandWidth * h);
                FishboneParams fb;
                fb.drawnBackbone = line;
                fb.direction = PrincipalDirection::Min;
                // A whole number of spacings along the line, so that both of its ends (corners) are sampled.
                double screenLength = 0;
                for (std::size_t i = 1; i < line.size(); ++i)
                    screenLength += (line[i] - line[i - 1]).norm();
                fb.spacing = screenLength / std::max(1.0, std::round(screenLength / h));
                fb.spacing = std::clamp(fb.spacing, 0.75 * h, 1.5 * h);
                // Ribs traced on every pixel: the finest alignment with the feature (with the automatic
                // sampling image fandisk's auto run keeps 1 % less of its area and 1 % fewer valence-6
                // vertices; these scans are few, so their render cost hardly counts).
                fb.samplingFactor = 1;
                // The paper's grid as before issue 20's defaults: auto's own figures were measured with it,
                // and a drawn backbone along a crease chain has no loop to close; the sliver bound and the
                // small-part drop of the fishbone scan are left to auto's own clean-up.
                fb.tracing.closeLoops = false;
                fb.tracing.minFaceAngleDeg = 0;
                fb.tracing.minComponentFaces = 0;
                fb.tracing.peelRibEndsDeg = 0; // session 20's rib-end peel likewise
                step.camera = params.camera;
                auto ts = Clock::now();
                FishboneScanResult scan = scanFishbonePatch(reference, *referenceRenderer, current,
                                                            *currentRenderer, params, fb, cache);
                result.scanSeconds += secondsSince(ts);
                step.patchFaces = scan.patch.mesh.number_of_faces();
                stitchInto(step, scan.patch.mesh, scan.grid.camera, scan.currentBuffers.faceId);
            } catch (const CancelledError&) {
                throw;
            } catch (const Error& e) {
                step.note = e.what();
            }
            finishStep(step, t0);
        }
    }

    // 2. The initial views: greedy cover of the Gauss map, normals binned on a fine set of directions.
    progress.report(0.3, "plan");
    auto tPlan = Clock::now();
    const std::vector<Eigen::Vector3d> views =
        detail::planViews(reference, options.servedAngleDeg, options.minViewAreaFraction, options.maxViews);
    result.planSeconds += secondsSince(tPlan);

    // The partition of the surface among the views: each region is scanned once, by its own view.
    tPlan = Clock::now();
    std::vector<FrameBuffers> viewBuffers;
    for (const Eigen::Vector3d& d : views) {
        progress.report(0.3, "plan");
        viewBuffers.push_back(
            referenceRenderer->render(detail::frameParallelView(d, corners, footprint, 2 * L)));
    }
    const std::vector<int> owner =
        detail::partitionSurface(reference, viewBuffers, options.maxSamplingAngleDeg,
                                 options.partitionSmoothing * L, options.minRegionArea * L * L, 30);
    result.planSeconds += secondsSince(tPlan);

    // Pass 0 scans each view's region; the fill passes then let each view rescan, on the same pixel grid as
    // its first patch, the parts of its region (and margin) still left from the input, where the stitch
    // trimmed its first patch.
    for (int pass = 0; pass <= options.regionFillPasses; ++pass)
        for (std::size_t i = 0; i < views.size() && budgetLeft(); ++i) {
            if (pass > 0 && measureCoverage(current).fraction() >= options.coverageGoal) break;
            progress.report(0.3 + 0.4 * double(pass * views.size() + i) /
                                      double((options.regionFillPasses + 1) * views.size()),
                            "scan " + std::to_string(i + 1) + "/" + std::to_string(views.size()));
            const auto t0 = Clock::now();
            AutoStep step;
            step.kind = pass == 0 ? AutoStep::Kind::Initial : AutoStep::Kind::RegionFill;
            step.camera = viewBuffers[i].camera;
            try {
                auto ts = Clock::now();
                const FrameBuffers currentBuffers = currentRenderer->render(step.camera);
                std::vector<char> nearInput;
                if (pass > 0) {
                    nearInput = pixelsNearInputFaces(current, currentBuffers, options.regionMarginPx + 1);
                    if (std::find(nearInput.begin(), nearInput.end(), 1) == nearInput.end()) continue;
                }
                step.scanId = nextScanId++;
                const Patch patch =
                    regionScan(reference, viewBuffers[i], owner, int(i), step.scanId, options.regionMarginPx,
                               options.regionMarginMaxSamplingAngleDeg, options.morphologyRadius,
                               pass > 0 ? &nearInput : nullptr);
                result.scanSeconds += secondsSince(ts);
                step.patchFaces = patch.mesh.number_of_faces();
                stitchInto(step, patch.mesh, step.camera, currentBuffers.faceId);
            } catch (const CancelledError&) {
                throw;
            } catch (const Error& e) {
                step.note = e.what();
            }
            finishStep(step, t0);
        }

    // 3. Follow-up views aimed at the regions still left from the input.
    for (int round = 0; round < options.followUpRounds && budgetLeft(); ++round) {
        if (measureCoverage(current).fraction() >= options.coverageGoal) break;
        progress.report(0.7 + 0.3 * double(round) / double(options.followUpRounds), "follow-up");
        auto t = Clock::now();
        auto ids = scanIds(current);
        // Connected regions of input faces (through edges).
        struct Region {
            std::vector<FaceIndex> faces;
            double area = 0;
            Eigen::Vector3d normalSum{0, 0, 0};
        };
        std::vector<Region> regions;
        for (std::vector<FaceIndex>& faces :
             detail::faceComponents(current, [&](FaceIndex f) { return ids[f] < 0; })) {
            Region r;
            for (FaceIndex g : faces) {
                const FaceGeometry fg = faceGeometry(current, g);
                r.area += fg.area;
                r.normalSum += fg.area * fg.normal;
            }
            r.faces = std::move(faces);
            regions.push_back(std::move(r));
        }
        std::sort(regions.begin(), regions.end(),
                  [](const Region& a, const Region& b) { return a.area > b.area; });
        result.planSeconds += secondsSince(t);
        int scansThisRound = 0;
        const double coverageBefore = measureCoverage(current).fraction();
        for (const Region& region : regions) {
            if (!budgetLeft() || scansThisRound >= 12) break;
            if (region.area < 0.5 * L * L) break;
            // The region may have been covered by an earlier follow-up of this round.
            auto idsNow = scanIds(current);
            std::unordered_set<std::uint32_t> members;
            std::vector<Eigen::Vector3d> pts;
            for (FaceIndex f : region.faces) {
                if (!current.is_removed(f) && idsNow[f] < 0) {
                    members.insert(std::uint32_t(f.idx()));
                    for (VertexIndex v : CGAL::vertices_around_face(current.halfedge(f), current))
                        pts.push_back(toEigen(current.point(v)));
                }
            }
            if (members.empty()) continue;
            t = Clock::now();
            Eigen::Vector3d n = region.normalSum.norm() > 0.3 * region.area
                                    ? Eigen::Vector3d(region.normalSum.normalized())
                                    : faceGeometry(current, region.faces[0]).normal;
            if (n.norm() == 0) continue;
            // Candidate directions around the region's mean normal; the one that sees most of it wins.
            const Eigen::Vector3d a =
                std::abs(n.x()) < 0.9 ? Eigen::Vector3d(1, 0, 0) : Eigen::Vector3d(0, 1, 0);
            const Eigen::Vector3d u = n.cross(a).normalized(), v = n.cross(u);
            std::vector<Eigen::Vector3d> dirs{n};
            for (double tilt : {25.0, 50.0})
                for (int k = 0; k < 6; ++k) {
                    const double phi = k * std::numbers::pi / 3.0 + (tilt > 30 ? std::numbers::pi / 6 : 0);
                    const double th = tilt * std::numbers::pi / 180.0;
                    dirs.push_back(std::cos(th) * n + std::sin(th) * (std::cos(phi) * u + std::sin(phi) * v));
                }
            Camera best;
            double bestSeen = 0;
            for (const Eigen::Vector3d& d : dirs) {
                Camera cam = detail::frameParallelView(d, pts, footprint, 4 * L);
                try {
                    const FrameBuffers fb = currentRenderer->render(cam);
                    double seenPx = 0;
                    for (std::uint32_t id : fb.faceId)
                        if (id != FrameBuffers::kNoFace && members.count(id)) seenPx += 1;
                    seenPx *= 1.0 - 0.3 * (1.0 - d.dot(n)); // prefer frontal views on a tie
                    if (seenPx > bestSeen) bestSeen = seenPx, best = fb.camera;
                } catch (const CancelledError&) {
                    throw;
                } catch (const Error&) {
                }
            }
            result.planSeconds += secondsSince(t);
            if (bestSeen < 1) continue;
            const auto t0 = Clock::now();
            AutoStep step;
            step.kind = AutoStep::Kind::FollowUp;
            step.scanId = nextScanId++;
            step.camera = best;
            try {
                auto ts = Clock::now();
                RegularScan scan =
                    regularScan(reference, *referenceRenderer, current, *currentRenderer, best, step.scanId,
                                2 + options.morphologyRadius, options.followUpMaxSamplingAngleDeg, options);
                result.scanSeconds += secondsSince(ts);
                step.patchFaces = scan.patch.mesh.number_of_faces();
                stitchInto(step, scan.patch.mesh, scan.camera, scan.currentBuffers.faceId);
            } catch (const CancelledError&) {
                throw;
            } catch (const Error& e) {
                step.note = e.what();
            }
            finishStep(step, t0);
            ++scansThisRound;
        }
        if (scansThisRound == 0 || measureCoverage(current).fraction() <= coverageBefore + 1e-6) break;
    }

    if (options.flipSliversBelowDeg > 0) {
        auto t = Clock::now();
        result.sliverFlips = flipSlivers(current, options.flipSliversBelowDeg, 20.0, 8);
        result.stitchSeconds += secondsSince(t);
    }
    current.collect_garbage();
    // The seams are relaxed, the creases recovered where the scans bevelled them, and the seams relaxed
    // again around the crease vertices (which the relaxation now keeps as feature vertices).
    auto relax = [&] {
        if (options.seamRelaxRounds <= 0) return;
        auto t = Clock::now();
        detail::SeamRelaxOptions ro;
        ro.rounds = options.seamRelaxRounds;
        ro.edgeLength = L;
        ro.minAngleDeg = options.seamRelaxMinAngleDeg;
        ro.maxNormalChangeDeg = options.stitch.maxNormalChangeDeg;
        ro.featureAngleDeg = options.featureAngleDeg;
        ro.collapses = options.seamRelaxCollapses;
        const detail::SeamRelaxReport rr = detail::relaxSeams(current, reference, ro);
        result.seamFlips += rr.flips;
        result.seamCollapses += rr.collapses;
        result.seamMoves += rr.moves;
        result.seamRelaxDiscarded = result.seamRelaxDiscarded || rr.reverted;
        result.stitchSeconds += secondsSince(t);
    };
    progress.report(0.99, "relax");
    relax();
    if (options.creaseSnapRounds > 0) {
        auto t = Clock::now();
        detail::CreaseSnapOptions co;
        co.edgeLength = L;
        co.creaseAngleDeg = options.featureAngleDeg;
        co.minAngleDeg = options.stitch.minAngleFloorDeg;
        co.rounds = options.creaseSnapRounds;
        const detail::CreaseSnapReport cr = detail::snapToCreases(current, reference, co);
        result.creaseSnaps = cr.snaps;
        result.creaseSplits = cr.splits;
        result.creaseFlips = cr.flips;
        result.creaseRemovals = cr.removals;
        result.creaseRepairs = cr.repairs;
        result.stitchSeconds += secondsSince(t);
        if (cr.snaps + cr.splits + cr.flips + cr.removals + cr.repairs > 0) relax();
        if (auto [onCrease, have] = current.property_map<VertexIndex, bool>(detail::kOnCreaseProperty); have)
            current.remove_property_map(onCrease);
    }
    progress.report(1.0, "done");
    const Coverage c = measureCoverage(current);
    result.coverage = c.fraction();
    result.inputFacesLeft = c.inputFaces;
    result.inputAreaLeft = c.total - c.scanned;
    result.mesh = std::move(current);
    result.seconds = secondsSince(start);
    return result;
}

} // namespace fss
