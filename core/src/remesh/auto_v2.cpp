// auto v2 (issue 23, auto_remesh.h AutoEngine::V2): the regions of the partition are sampled once each with
// the triangular lattice and joined in one pass, so that the cost does not grow as views × stitch.
//
//  1. Views: auto v1's greedy Gauss-map plan (planViews) and its partition of the surface (partitionSurface,
//     most frontal unoccluded view, Potts-smoothed), plus views aimed at the faces no view owns (their mean
//     normal), after which the partition is recomputed with all views.
//  2. Each region is sampled with the triangular lattice (sampleLattice) at a world spacing chosen so that
//     every region gets the vertex density of a regular triangulation at the target edge length (a region
//     seen at a mean cos θ is sampled at L·sqrt(cos θ)); only the samples on the region's own faces are kept
//     (no margin), triangulated on the lattice. The regions are independent: they are sampled in parallel
//     (parallelItems) from buffers rendered beforehand on one thread, and merged in view order, so the
//     result is the same for any thread count.
//  3. One join: the patches are put into one mesh, with the faces of the reference no patch reaches (centroid
//     farther than L from every patch vertex: thin pieces the opening removed, regions whose patch failed,
//     faces no view sees) as a region of their own, left from the input (scan id -1; the coverage says how
//     much). The gaps between them (about one lattice spacing wide, along the partition borders) are closed
//     by an advancing front over the boundary edges, a zipper in the manner of Turk & Levoy's zippering of
//     range images: each boundary edge takes as third corner the boundary vertex in front of it that sees it
//     under the largest angle (the Delaunay choice), best triangles first, only faces whose centroid lies
//     within L/4 of the reference; Surface_mesh::add_face refuses whatever would make the mesh non-manifold.
//     CGAL's hole filling closes what is left (junctions of three regions), on an open reference only the
//     cycles that do not run along its own boundary (ReferenceBorder).
//  4. Seam relaxation and crease recovery once, as v1 ends (seam_relax.h, crease_snap.h), then the repair of
//     the faces below 20° (sliver_repair.h; FSS_AUTO_V2_SLIVERS=1 prints where they lie before and after).
//  5. Validation (validateJoin): as many boundary loops and connected components as the reference and the
//     same Euler characteristic (genus), a vertex count within 10 % of the target (else parts went
//     unsampled), closed when the reference is, no pinched vertex, no degenerate face, every vertex and face
//     centroid within 1.5 L of the reference, no self-intersection.
// FSS_AUTO_V2_DEBUG=1 in the environment prints the stages' figures to stderr. A result that fails is dropped
// and v1 runs instead (AutoResult::engineNote). The advancing front is our own: CGAL's hole filling works on
// one boundary cycle at a time, and the gaps between patches are one multiply-connected region bounded by
// many cycles.
#include "remesh/auto_v2.h"

#include "base/parallel_rows.h"
#include "remesh/crease_snap.h"
#include "remesh/join_regions.h"
#include "remesh/seam_relax.h"
#include "remesh/sliver_repair.h"

#include "fss/error.h"
#include "fss/mask.h"
#include "fss/mask_triangulate.h"
#include "fss/metrics.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/scan_workspace.h"
#include <CGAL/Polygon_mesh_processing/border.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace fss::detail {
namespace {
namespace v2 {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The lattice spacing is this fraction of the spacing that gives a regular triangulation's vertex density:
/// the join adds no vertex and the seam relaxation collapses a few (measured: fandisk, bunny00 4-6 % short
/// of the target at 1).
constexpr double kDensity = 0.97;

/// Largest distance of the result's vertices and face centroids from the reference, in edge lengths: the
/// lattice's samples lie on it and the crease recovery's bevels within L/2; measured on blade 0.7 L (its
/// thin rims), rotor_small's cap across a handle 5 L.
constexpr double kMaxDistance = 1.5;

/// Largest distance of a vertex or face centroid of the reference from the result, in edge lengths: the
/// result's border on an open reference lies up to a lattice spacing inside the reference's own (the
/// patches keep only the samples on their region's faces).
constexpr double kMaxDistanceFromInput = 1.5;

/// Rounds of the join that turn the reference's faces around what the join left wrong into input faces
/// (autoRemeshV2, step 3).
constexpr int kWidenRounds = 3;

/// The opening of the regions' samples (radius 1), with what it removes on thin parts put back: the samples
/// it removes, in connected pieces (8-neighbours in the grid), are kept again when a piece has at least
/// \p minPiece samples (a strip of a thin part: a leg, a trunk, an ear seen from the side) and dropped when
/// it is smaller (single samples, one-sample spikes, which the join cannot close cleanly). The result is the
/// grid's admissible and valid flags. Returns the samples put back.
std::size_t openKeepingThinParts(SampleGrid& grid, std::size_t minPiece, ScanWorkspace& workspace) {
    const std::size_t n = grid.samples.size();
    std::vector<char> before(n, 0);
    for (std::size_t i = 0; i < n; ++i)
        before[i] = grid.samples[i].valid;
    applyMorphology(grid, {.radius = 1, .dilateRadius = 1}, workspace);
    std::vector<char> removed(n, 0);
    for (std::size_t i = 0; i < n; ++i)
        removed[i] = before[i] && !grid.samples[i].valid;
    std::size_t restored = 0;
    std::vector<std::size_t> piece, stack;
    for (std::size_t start = 0; start < n; ++start) {
        if (removed[start] != 1) continue;
        piece.clear();
        stack.assign(1, start);
        removed[start] = 2;
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            piece.push_back(i);
            const int r = int(i / std::size_t(grid.cols)), c = int(i % std::size_t(grid.cols));
            for (int dr = -1; dr <= 1; ++dr)
                for (int dc = -1; dc <= 1; ++dc) {
                    if (!grid.inside(r + dr, c + dc)) continue;
                    const std::size_t j = grid.index(r + dr, c + dc);
                    if (removed[j] == 1) removed[j] = 2, stack.push_back(j);
                }
        }
        if (piece.size() < minPiece) continue;
        for (std::size_t i : piece)
            grid.samples[i].valid = true;
        restored += piece.size();
    }
    for (Sample& s : grid.samples)
        s.admissible = s.valid;
    return restored;
}

/// The patch of region \p view: the triangular lattice at \p spacing world units, only the samples on the
/// faces the view owns, triangulated.
Patch regionPatch(const Mesh& reference, const FrameBuffers& buffers, const std::vector<int>& owner, int view,
                  double spacing, std::size_t minThinPiece, std::string* debug = nullptr) {
    ScanOptions so;
    so.scanId = view;
    so.lattice = Lattice::Triangular;
    so.spacingWorld = spacing;
    so.minLatticeAngleDeg = 0; // the partition already gave each face its most frontal view
    ScanWorkspace workspace;
    SampleGrid grid = sampleLattice(buffers, reference, workspace, so);
    std::size_t hits = 0, admissible = 0, own = 0;
    for (Sample& s : grid.samples) {
        hits += s.hit;
        admissible += s.admissible;
        if (s.admissible && (s.face == Sample::kNoFace || owner[s.face] != view))
            s.admissible = s.valid = false;
        own += s.admissible;
    }
    MaskStages stages;
    // The opening (radius 1) removes single samples and one-sample spikes, which the join cannot close
    // cleanly (measured on elephant: without it 1168 intersecting face pairs after the join, 79 with it).
    std::size_t thin = 0;
    if (minThinPiece > 0) {
        thin = openKeepingThinParts(grid, minThinPiece, workspace);
        stages.morphology = {.radius = 0, .dilateRadius = 0};
    } else {
        stages.morphology = {.radius = 1, .dilateRadius = 1};
    }
    stages.atQuality = stages.atMorphology = stages.atTriangulate = {};
    stages.nothingBetter = stages.nothingLeft = "The view owns no part of the surface.";
    MaskedPatch out = maskAndTriangulate(grid, stages, workspace);
    if (debug)
        *debug = "hits " + std::to_string(hits) + " admissible " + std::to_string(admissible) + " own " +
                 std::to_string(own) + " thin " + std::to_string(thin) + " morph " +
                 std::to_string(out.counts.afterMorphology) + " verts " +
                 std::to_string(out.patch.mesh.number_of_vertices()) + " long " +
                 std::to_string(out.patch.report.longEdges) + " graz " +
                 std::to_string(out.patch.report.grazing) + " back " +
                 std::to_string(out.patch.report.backFacing) + " flip " +
                 std::to_string(out.patch.report.flipped);
    return std::move(out.patch);
}

/// Faces of \p reference no view owns, in connected pieces (through edges), largest area first.
struct Unowned {
    std::vector<FaceIndex> faces;
    double area = 0;
    Eigen::Vector3d normalSum{0, 0, 0};
};

std::vector<Unowned> unownedPieces(const Mesh& reference, const std::vector<int>& owner) {
    std::vector<Unowned> out;
    for (std::vector<FaceIndex>& faces :
         faceComponents(reference, [&](FaceIndex f) { return owner[f.idx()] < 0; })) {
        Unowned piece;
        for (FaceIndex g : faces) {
            const double a = faceArea(reference, g);
            piece.area += a;
            piece.normalSum += a * faceNormal(reference, g);
        }
        piece.faces = std::move(faces);
        out.push_back(std::move(piece));
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const Unowned& a, const Unowned& b) { return a.area > b.area; });
    return out;
}

} // namespace v2
} // namespace

std::string validateJoin(const Mesh& mesh, const JoinTarget& target, bool knownFree, bool* freeAfter) {
    MetricsOptions mo;
    mo.selfIntersections = !knownFree;
    Metrics m = computeMetrics(mesh, mo);
    if (knownFree) m.selfIntersections = 0;
    // PMP::self_intersections reports a degenerate face f as (f, f), which computeMetrics counts in
    // degenerateFaces only: free means neither.
    if (freeAfter)
        *freeAfter = knownFree || (m.selfIntersections == std::size_t(0) && m.degenerateFaces == 0);
    if (mesh.number_of_faces() == 0) return "the joined mesh has no face";
    if (m.boundaryLoops != target.boundaryLoops)
        return "the joined mesh has " + std::to_string(m.boundaryLoops) + " boundary loops, the input " +
               std::to_string(target.boundaryLoops);
    if (m.components != target.components)
        return "the joined mesh has " + std::to_string(m.components) + " connected components, the input " +
               std::to_string(target.components);
    if (target.eulerCharacteristic) {
        const long euler = long(m.vertices) - long(m.edges) + long(m.faces);
        if (euler != *target.eulerCharacteristic)
            return "the joined mesh has Euler characteristic " + std::to_string(euler) + ", the input " +
                   std::to_string(*target.eulerCharacteristic);
    }
    // Parts of the surface no region sampled are bridged by the hole filling: far fewer vertices than a
    // regular triangulation of the whole surface means parts of it were cut off.
    if (std::abs(double(m.vertices) - target.vertices) > 0.1 * target.vertices)
        return "the joined mesh has " + std::to_string(m.vertices) + " vertices against the " +
               std::to_string(std::llround(target.vertices)) +
               " of the target: parts of the surface were not sampled";
    if (target.closed && !m.closed)
        return "the joined mesh has " + std::to_string(m.boundaryEdges) + " boundary edges left";
    if (m.nonManifoldVertices > 0)
        return "the joined mesh has " + std::to_string(m.nonManifoldVertices) + " pinched vertices";
    if (m.degenerateFaces > 0)
        return "the joined mesh has " + std::to_string(m.degenerateFaces) + " degenerate faces";
    if (target.reference) {
        double far = 0;
        for (VertexIndex v : mesh.vertices())
            far = std::max(far, target.reference->closestPoint(at(mesh, v)).distance);
        for (FaceIndex f : mesh.faces()) {
            Eigen::Vector3d c(0, 0, 0);
            for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
                c += at(mesh, v) / 3.0;
            far = std::max(far, target.reference->closestPoint(c).distance);
        }
        if (far > target.maxDistance)
            return "the joined mesh lies up to " + std::to_string(far / target.maxDistance) +
                   " times the allowed distance from the input";
    }
    if (target.inputSamples && !target.inputSamples->empty()) {
        const RayCaster onMesh(mesh);
        double far = 0;
        for (const Eigen::Vector3d& p : *target.inputSamples)
            far = std::max(far, onMesh.closestPoint(p).distance);
        if (far > target.maxDistanceFromInput)
            return "the joined mesh leaves parts of the input uncovered, up to " +
                   std::to_string(far / target.maxDistanceFromInput) + " times the allowed distance from it";
    }
    if (m.selfIntersections.value_or(0) > 0)
        return "the joined mesh intersects itself (" + std::to_string(*m.selfIntersections) + " face pairs)";
    return {};
}

std::vector<Eigen::Vector3d> inputSamples(const Mesh& reference) {
    std::vector<Eigen::Vector3d> out;
    out.reserve(reference.number_of_vertices() + reference.number_of_faces());
    for (VertexIndex v : reference.vertices())
        out.push_back(at(reference, v));
    for (FaceIndex f : reference.faces()) {
        Eigen::Vector3d c(0, 0, 0);
        for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
            c += at(reference, v) / 3.0;
        out.push_back(c);
    }
    return out;
}

AutoResult autoRemeshV2(const Mesh& reference, const AutoOptions& options, const Progress& progress) {
    using namespace v2;
    const auto start = Clock::now();
    AutoResult result;
    result.engineUsed = AutoEngine::V2;
    std::vector<Eigen::Vector3d> corners;
    for (FaceIndex f : reference.faces())
        result.area += faceArea(reference, f);
    if (!(result.area > 0)) throw InvalidInputError("The mesh to remesh has no area.");
    const Eigen::AlignedBox3d box = boundingBox(reference);
    for (int i = 0; i < 8; ++i)
        corners.push_back(box.corner(Eigen::AlignedBox3d::CornerType(i)));
    result.edgeLength = detail::targetEdgeLength(result.area, options, reference.number_of_vertices());
    const double L = result.edgeLength;
    // Pixels finer than the lattice: the ID buffer then places the lattice's samples and decides the
    // partition's visibility at a fraction of an edge length.
    const double footprint = 0.5 * L;
    bool closedInput = true;
    for (HalfedgeIndex h : reference.halfedges())
        if (reference.is_border(h)) closedInput = false;

    // 1. Views and the partition.
    progress.report(0.0, "plan");
    auto t = Clock::now();
    std::unique_ptr<MeshRenderer> renderer =
        options.renderer ? options.renderer() : std::make_unique<CpuMeshRenderer>();
    renderer->setMesh(reference);
    std::vector<FrameBuffers> buffers;
    for (const Eigen::Vector3d& d :
         planViews(reference, options.servedAngleDeg, options.minViewAreaFraction, options.maxViews)) {
        progress.report(0.05, "plan");
        buffers.push_back(renderer->render(frameParallelView(d, corners, footprint, 2 * L)));
    }
    const double beta = options.partitionSmoothing * L, minIsland = options.minRegionArea * L * L;
    std::vector<int> owner =
        partitionSurface(reference, buffers, options.maxSamplingAngleDeg, beta, minIsland, 30);
    for (int round = 0; round < 2 && int(buffers.size()) < options.maxViews; ++round) {
        const std::vector<Unowned> pieces = unownedPieces(reference, owner);
        std::size_t added = 0;
        for (const Unowned& piece : pieces) {
            if (piece.area < 0.5 * L * L || int(buffers.size()) >= options.maxViews || added >= 12) break;
            if (piece.normalSum.norm() < 1e-3 * piece.area) continue;
            std::vector<Eigen::Vector3d> pts;
            for (FaceIndex f : piece.faces)
                for (VertexIndex v : CGAL::vertices_around_face(reference.halfedge(f), reference))
                    pts.push_back(at(reference, v));
            progress.report(0.1, "plan");
            buffers.push_back(
                renderer->render(frameParallelView(piece.normalSum.normalized(), pts, footprint, 4 * L)));
            ++added;
        }
        if (added == 0) break;
        owner =
            partitionSurface(reference, buffers, options.followUpMaxSamplingAngleDeg, beta, minIsland, 30);
    }
    result.planSeconds = since(t);

    // 2. The regions, sampled in parallel. Spacing per region: the vertex density of a regular
    // triangulation at L on the surface (a lattice cell seen at angle θ covers 1/cos θ of its screen area).
    t = Clock::now();
    const std::size_t nv = buffers.size();
    std::vector<double> cosArea(nv, 0), regionArea(nv, 0);
    std::vector<Eigen::Vector3d> viewDirections;
    for (const FrameBuffers& b : buffers)
        viewDirections.push_back(b.camera.viewDirection());
    std::vector<Patch> patches(nv);
    std::size_t minThinPiece = 0;
    if (const char* env = std::getenv("FSS_AUTO_V2_THIN")) minThinPiece = std::size_t(std::atoi(env));
    std::vector<std::string> notes(nv), dbg(nv);
    progress.report(0.2, "scan");
    for (FaceIndex f : reference.faces()) {
        const int o = owner[f.idx()];
        if (o < 0) continue;
        const double a = faceArea(reference, f);
        regionArea[std::size_t(o)] += a;
        cosArea[std::size_t(o)] +=
            a * std::max(0.0, -faceNormal(reference, f).dot(viewDirections[std::size_t(o)]));
    }
    parallelItems(nv, 1, [&](std::size_t i) {
        if (regionArea[i] <= 0) {
            notes[i] = "The view owns no part of the surface.";
            return;
        }
        const double c = std::clamp(cosArea[i] / regionArea[i], 0.5, 1.0);
        try {
            patches[i] = regionPatch(reference, buffers[i], owner, int(i), kDensity * L * std::sqrt(c),
                                     minThinPiece, &dbg[i]);
        } catch (const Error& e) {
            notes[i] = e.what();
        }
    });
    result.scanSeconds = since(t);
    if (std::getenv("FSS_AUTO_V2_DEBUG"))
        for (std::size_t i = 0; i < nv; ++i)
            std::fprintf(stderr, "v2 region %zu: area %.4f expected %.0f verts, cos %.2f: %s\n", i,
                         regionArea[i], regionArea[i] / (std::sqrt(3.0) / 2 * L * L),
                         regionArea[i] > 0 ? cosArea[i] / regionArea[i] : 0.0,
                         dbg[i].empty() ? notes[i].c_str() : dbg[i].c_str());

    // 3. One join.
    progress.report(0.5, "join");
    t = Clock::now();
    Mesh current;
    for (std::size_t i = 0; i < nv; ++i) {
        AutoStep step;
        step.kind = AutoStep::Kind::Initial;
        step.camera = buffers[i].camera;
        step.scanId = std::int32_t(i);
        step.patchFaces = patches[i].mesh.number_of_faces();
        step.facesAdded = step.patchFaces;
        step.stitched = step.patchFaces > 0;
        step.note = notes[i];
        if (step.stitched) appendPatch(current, patches[i].mesh);
        (step.stitched ? result.scansStitched : result.scansSkipped)++;
        result.steps.push_back(std::move(step));
    }
    if (current.number_of_faces() == 0) throw InvalidInputError("No view of auto v2 sees the surface.");
    const bool debug = std::getenv("FSS_AUTO_V2_DEBUG") != nullptr;
    // Two ways to join; the first whose result passes validateJoin is kept (else the first): the faces no
    // region sampled kept as a region of their own, joined in one pass (JoinStyle::InputRegions), then
    // session 15's join (JoinStyle::TwoPasses), which bridges those parts with the hole filling.
    const std::vector<char> unsampled = unsampledFaces(reference, patches, L);
    const char* widenEnv = std::getenv("FSS_AUTO_V2_WIDEN");
    const bool widen = widenEnv && std::string(widenEnv) == "1";
    const ReferenceBorder border = closedInput ? ReferenceBorder{} : referenceBorder(reference, L);
    patches.clear();
    const RayCaster caster(reference);
    const std::vector<Eigen::Vector3d> samples = inputSamples(reference);
    MetricsOptions referenceTopology;
    referenceTopology.selfIntersections = false;
    const Metrics referenceMetrics = computeMetrics(reference, referenceTopology);
    const JoinTarget target{.closed = closedInput,
                            .components = referenceMetrics.components,
                            .boundaryLoops = referenceMetrics.boundaryLoops,
                            .vertices = result.area / (std::sqrt(3.0) / 2.0 * L * L),
                            .eulerCharacteristic = long(referenceMetrics.vertices) -
                                                   long(referenceMetrics.edges) +
                                                   long(referenceMetrics.faces),
                            .reference = &caster,
                            .maxDistance = kMaxDistance * L,
                            .inputSamples = &samples,
                            .maxDistanceFromInput = kMaxDistanceFromInput * L};
    // The join is chosen on its topology only: the hole filling's vertices lie off the reference until the
    // seam relaxation projects them (measured on bunny00: 1.6 L after the join, 0.22 L at the end).
    // The distance from the input too is checked at the end only: with it in the join's choice the widening
    // below ran on bunny00 and left 2 components (measured, session 20).
    JoinTarget joinTarget = target;
    // Whether `current` is known not to intersect itself: the last whole-mesh test (or a stage that keeps
    // a free mesh free) said so of exactly this mesh. Each stage below then skips its own entry test.
    bool currentFree = false;
    joinTarget.reference = nullptr;
    joinTarget.inputSamples = nullptr;
    if (widen) joinTarget.inputSamples = &samples;
    std::vector<char> inputFaces = unsampled;
    {
        // When the repaired join fails validation, the reference's own faces within 2 L of what the join
        // left wrong (faces that intersect, pinch or, closed, a hole the filling cannot close) become input
        // faces, the patch faces near them are removed and the join runs again, up to kWidenRounds times
        // (measured on couplingdown: the repair alone took the join from 3741 faces to 910 in 6 pieces,
        // holes whose filling failed growing by two rings every round).
        Mesh joined;
        // Every way out of the loop keeps the repaired join, whose validation is then roundWhy: it is not
        // run again (measured on bunny00: one whole-mesh validation in four).
        std::string why;
        // Whether `joined` (then `current`) is known not to intersect itself (validateJoin's freeAfter): the
        // stages after the join then skip their whole-mesh entry test.
        bool joinedFree = false;
        for (int round = 0;; ++round) {
            joined = current;
            std::vector<char> widened(inputFaces.size(), 0);
            for (std::size_t i = 0; i < inputFaces.size(); ++i)
                widened[i] = inputFaces[i] && !unsampled[i];
            removePatchFacesNear(joined, reference, widened, L);
            joinRegions(joined, reference, &inputFaces, caster, border, JoinStyle::InputRegions, L,
                        closedInput, debug, 0);
            Mesh repaired = joined;
            repairJoin(repaired, border, closedInput, 4, debug);
            repaired.collect_garbage();
            // Measured on elephant: two input faces no patch reached, each closed on itself by the filling.
            dropSmallPieces(repaired, target.components, 8);
            const std::string roundWhy = validateJoin(repaired, joinTarget, false, &joinedFree);
            if (debug)
                std::fprintf(stderr, "v2: join round %d: %s\n", round,
                             roundWhy.empty() ? "valid" : roundWhy.c_str());
            why = roundWhy;
            if (round == kWidenRounds || !widen || roundWhy.empty()) {
                joined = std::move(repaired);
                break;
            }
            // With FSS_AUTO_V2_WIDEN=1: the reference's faces the repaired join does not cover (centroid
            // farther than L from it) become input faces (measured on mech-holes-shark: the repair's hole
            // around intersecting faces next to a hole of the part merged with the hole's border cycle, which
            // the filling leaves open: a notch 12 L wide, 2.8 L deep).
            std::size_t added = flagUncoveredFaces(reference, repaired, L, inputFaces);
            added += widenInputRegions(reference, joined, closedInput, 2 * L, inputFaces);
            if (debug) std::fprintf(stderr, "v2: widen round %d: %zu input faces more\n", round, added);
            if (added == 0) {
                joined = std::move(repaired);
                break;
            }
            joinedFree = false; // `joined` is the unrepaired join now
        }
        if (debug)
            std::fprintf(stderr, "v2: join with input regions: %s\n", why.empty() ? "valid" : why.c_str());
        if (why.empty()) {
            current = std::move(joined);
            currentFree = joinedFree;
        } else {
            joinRegions(current, reference, nullptr, caster, border, JoinStyle::TwoPasses, L, closedInput,
                        debug, 4);
            const std::string other = validateJoin(current, joinTarget, false, &currentFree);
            if (debug)
                std::fprintf(stderr, "v2: join in two passes: %s\n", other.empty() ? "valid" : other.c_str());
            if (!other.empty()) current = std::move(joined), currentFree = joinedFree;
        }
    }
    if (debug)
        std::fprintf(stderr, "v2: join %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));
    result.stitchSeconds = result.joinSeconds = since(t);

    // 4. Seam relaxation and crease recovery, once.
    progress.report(0.7, "relax");
    t = Clock::now();
    auto relax = [&] {
        if (options.seamRelaxRounds <= 0) return;
        const auto t0 = Clock::now();
        SeamRelaxOptions ro;
        ro.rounds = options.seamRelaxRounds;
        ro.edgeLength = L;
        ro.minAngleDeg = options.seamRelaxMinAngleDeg;
        ro.maxNormalChangeDeg = options.stitch.maxNormalChangeDeg;
        ro.featureAngleDeg = options.featureAngleDeg;
        ro.collapses = options.seamRelaxCollapses;
        ro.knownFree = currentFree;
        const SeamRelaxReport rr = relaxSeams(current, reference, ro);
        currentFree = rr.freeAfter;
        result.seamFlips += rr.flips;
        result.seamCollapses += rr.collapses;
        result.seamMoves += rr.moves;
        result.seamRelaxDiscarded = result.seamRelaxDiscarded || rr.reverted;
        result.relaxSeconds += since(t0);
    };
    if (options.flipSliversBelowDeg > 0) {
        result.sliverFlips = flipSliverFaces(current, options.flipSliversBelowDeg, 20.0, 8);
        if (result.sliverFlips > 0) currentFree = false;
    }
    result.relaxSeconds = since(t);
    relax();
    if (debug)
        std::fprintf(stderr, "v2: relax %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));
    if (options.creaseSnapRounds > 0) {
        const auto t0 = Clock::now();
        CreaseSnapOptions co;
        co.edgeLength = L;
        co.creaseAngleDeg = options.featureAngleDeg;
        co.minAngleDeg = options.stitch.minAngleFloorDeg;
        co.rounds = options.creaseSnapRounds;
        co.knownFree = currentFree;
        const CreaseSnapReport cr = snapToCreases(current, reference, co);
        currentFree = cr.freeAfter;
        result.creaseSnaps = cr.snaps;
        result.creaseSplits = cr.splits;
        result.creaseFlips = cr.flips;
        result.creaseRemovals = cr.removals;
        result.creaseRepairs = cr.repairs;
        result.creaseSeconds = since(t0);
        if (cr.snaps + cr.splits + cr.flips + cr.removals + cr.repairs > 0) relax();
    }
    if (std::getenv("FSS_AUTO_V2_SLIVERS"))
        std::fprintf(stderr, "v2 slivers before repair: %s\n",
                     sliverCensus(current, reference, L, options.featureAngleDeg, 20.0).format().c_str());
    if (options.repairSliversBelowDeg > 0) {
        const auto t0 = Clock::now();
        SliverRepairOptions so;
        so.belowDeg = options.repairSliversBelowDeg;
        so.edgeLength = L;
        so.featureAngleDeg = options.featureAngleDeg;
        so.knownFree = currentFree;
        const SliverRepairReport sr = repairSlivers(current, caster, so);
        currentFree = sr.freeAfter;
        result.sliversBefore = sr.before;
        result.sliversAfter = sr.after;
        result.sliverRepairFlips = sr.flips;
        result.sliverCollapses = sr.collapses;
        result.sliverMoves = sr.moves;
        result.sliverSeconds = since(t0);
        if (debug)
            std::fprintf(
                stderr,
                "v2: slivers %zu -> %zu (%zu flips, %zu collapses, %zu moves, %d sweeps undone), %.3f s\n",
                sr.before, sr.after, sr.flips, sr.collapses, sr.moves, sr.sweepsReverted,
                result.sliverSeconds);
    }
    if (std::getenv("FSS_AUTO_V2_SLIVERS"))
        std::fprintf(stderr, "v2 slivers after repair: %s\n",
                     sliverCensus(current, reference, L, options.featureAngleDeg, 20.0).format().c_str());
    {
        if (auto [onCrease, have] = current.property_map<VertexIndex, bool>(kOnCreaseProperty); have)
            current.remove_property_map(onCrease);
    }
    result.stitchSeconds += since(t);
    if (debug)
        std::fprintf(stderr, "v2: relax + creases %.2f s, %zu vertices\n", since(t),
                     std::size_t(current.number_of_vertices()));

    // 5. Validation; v1 when it fails.
    progress.report(0.95, "validate");
    t = Clock::now();
    const std::string why = validateJoin(current, target, currentFree);
    if (debug) {
        const RayCaster onResult(current);
        double from = 0, to = 0;
        Eigen::Vector3d farPoint(0, 0, 0);
        for (const Eigen::Vector3d& p : samples)
            if (const double d = onResult.closestPoint(p).distance; d > from) from = d, farPoint = p;
        std::fprintf(stderr, "v2: farthest input point (%.4f %.4f %.4f)\n", farPoint.x(), farPoint.y(),
                     farPoint.z());
        for (VertexIndex v : current.vertices())
            to = std::max(to, caster.closestPoint(at(current, v)).distance);
        std::fprintf(stderr, "v2: validation %.2f s (input to result %.3f L, result to input %.3f L): %s\n",
                     since(t), from / L, to / L, why.empty() ? "valid" : why.c_str());
    }
    if (!why.empty() && !options.fallbackToV1) {
        result.engineNote = "auto v2 failed (" + why + ").";
    } else if (!why.empty()) {
        AutoOptions o1 = options;
        o1.engine = AutoEngine::V1;
        AutoResult r = autoRemesh(reference, o1, progress);
        r.engineNote = "auto v2 failed (" + why + "); auto v1 ran instead.";
        r.seconds = since(start);
        return r;
    }
    // Coverage: the share of the reference's area in regions whose patch was made (sampled by a view); the
    // rest is bridged by the join (no face is left from the input in v2).
    {
        const auto [ids, haveIds] = current.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        double scanned = 0, total = 0;
        for (FaceIndex f : current.faces()) {
            const double a = faceArea(current, f);
            total += a;
            if (haveIds && ids[f] >= 0)
                scanned += a;
            else
                ++result.inputFacesLeft;
        }
        // The faces no patch reached are either left from the input (JoinStyle::InputRegions) or bridged by
        // the hole filling (TwoPasses, whose new faces take a neighbour's scan id): not sampled either way.
        double unsampledArea = 0;
        for (FaceIndex f : reference.faces())
            if (inputFaces[f.idx()]) unsampledArea += faceArea(reference, f);
        result.coverage = std::min(total > 0 ? scanned / total : 0.0, 1.0 - unsampledArea / result.area);
        result.inputAreaLeft = total - scanned;
    }
    for (AutoStep& s : result.steps)
        s.coverageAfter = result.coverage;
    progress.report(1.0, "done");
    result.mesh = std::move(current);
    result.seconds = since(start);
    return result;
}

} // namespace fss::detail
