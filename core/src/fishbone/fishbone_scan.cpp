#include "fss/fishbone_scan.h"

#include "fss/camera_projector.h"
#include "fss/error.h"
#include "fss/mask_triangulate.h"

#include "base/parallel_rows.h"
#include "fishbone/crease_backbone.h"
#include "fishbone/crease_index.h"
#include "fishbone/fishbone_options.h"
#include "fishbone/lasso_clip.h"
#include "mesh/features.h"

#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <utility>

namespace fss {
namespace {

using detail::CreaseIndex;
using detail::CreaseSegment;
using detail::visibleCreases;

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string fmt(double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3g", x);
    return buf;
}

std::string point(const Eigen::Vector2d& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.1f, %.1f)", p.x(), p.y());
    return buf;
}

/// Rays through sub-pixel screen positions with the inverse view-projection computed once (Camera::ray
/// rebuilds and inverts the matrices per call). Same formula as Camera::ray.
struct RayFactory {
    Eigen::Matrix4d inverse;
    const Camera& camera;
    explicit RayFactory(const Camera& c) : inverse(c.viewProjectionMatrix().inverse()), camera(c) {}
    Eigen::Vector3d unproject(double sx, double sy, double depth) const {
        const Eigen::Vector4d ndc(2.0 * sx / camera.width - 1.0, 1.0 - 2.0 * sy / camera.height,
                                  2.0 * depth - 1.0, 1.0);
        const Eigen::Vector4d w = inverse * ndc;
        return w.head<3>() / w.w();
    }
    Ray operator()(double sx, double sy) const {
        const Eigen::Vector3d a = unproject(sx, sy, 0.0), b = unproject(sx, sy, 1.0);
        return Ray{camera.parallel ? a : camera.eye, (b - a).normalized()};
    }
};

} // namespace

// ---- FishboneCache --------------------------------------------------------------------------------------

FishboneCache::FishboneCache() = default;
FishboneCache::~FishboneCache() = default;
FishboneCache::FishboneCache(FishboneCache&&) noexcept = default;
FishboneCache& FishboneCache::operator=(FishboneCache&&) noexcept = default;

bool FishboneCache::holds(const Mesh& reference) const {
    return mesh_ == &reference && vertices_ == reference.number_of_vertices() &&
           faces_ == reference.number_of_faces();
}

void FishboneCache::bind(const Mesh& reference) {
    if (holds(reference)) return;
    clear();
    mesh_ = &reference;
    vertices_ = reference.number_of_vertices();
    faces_ = reference.number_of_faces();
}

bool FishboneCache::hasCurvature(const Mesh& reference) const {
    return holds(reference) && curvature_;
}

bool FishboneCache::hasRayCaster(const Mesh& reference) const {
    return holds(reference) && caster_;
}

const CurvatureField& FishboneCache::curvature(const Mesh& reference, const CurvatureOptions& options,
                                               const Progress& progress) {
    if (holds(reference) && curvature_) return *curvature_;
    const auto t = Clock::now();
    CurvatureField field = estimateCurvature(reference, options, progress);
    bind(reference);
    curvature_ = std::move(field);
    curvatureSeconds_ = secondsSince(t);
    return *curvature_;
}

const RayCaster& FishboneCache::rayCaster(const Mesh& reference) {
    if (holds(reference) && caster_) return *caster_;
    const auto t = Clock::now();
    auto caster = std::make_unique<RayCaster>(reference);
    bind(reference);
    caster_ = std::move(caster);
    rayCasterSeconds_ = secondsSince(t);
    return *caster_;
}

const std::vector<EdgeIndex>& FishboneCache::creaseEdges(const Mesh& reference, double minDihedralDeg) {
    if (holds(reference) && creases_ && creaseAngleDeg_ == minDihedralDeg) return *creases_;
    const std::vector<char> sharp = detail::sharpEdges(reference, minDihedralDeg);
    std::vector<EdgeIndex> edges;
    for (EdgeIndex e : reference.edges())
        if (sharp[e.idx()]) edges.push_back(e);
    bind(reference);
    creases_ = std::move(edges);
    creaseAngleDeg_ = minDihedralDeg;
    return *creases_;
}

void FishboneCache::clear() {
    creases_.reset();
    mesh_ = nullptr;
    vertices_ = faces_ = 0;
    curvature_.reset();
    caster_.reset();
    curvatureSeconds_ = rayCasterSeconds_ = 0;
}

FishboneOptions FishboneParams::defaultTracing() {
    FishboneOptions o;
    o.backboneTracing.lowAnisotropy = LowAnisotropyPolicy::ContinueStraight;
    o.ribTracing.lowAnisotropy = LowAnisotropyPolicy::ContinueStraight;
    // The backbone: half-pixel RK4 steps; the field is bilinear per pixel, so the integration error stays
    // far below its interpolation error, at half the cost of the streamline default (0.25).
    o.backboneTracing.step = 0.5;
    // The ribs, most of a fishbone scan's cost (issue 5: at most twice a regular scan of as many samples):
    // whole-pixel steps, whose RK4 stages still sample the field every half pixel. On a smooth field (the
    // 100k-face torus of bench_fishbone) the rib vertices stay within 0.03 px (median 1e-4 px) of ribs
    // traced with 1/16-pixel steps. The turn limit per step: at a seam of the line field a longer step takes
    // more of the turn at once, so 10° would end ribs earlier than with half-pixel steps and 20° (the same
    // radius of curvature) later; 12° keeps them as long (fandisk bench scene: 11 732 rib samples and 7 826
    // patch faces against 11 764 and 8 136).
    o.ribTracing.step = 1.0;
    o.ribTracing.maxTurnDeg = 12.0;
    // Rib trimming (minRibGap, maxRibTurnDeg, stopRibsAtCreases, issue 20) stays off by default until it is
    // measured together with the stitch: turned on, it broke the seam and property tests of the merge.
    return o;
}

// ---- Ray casting ----------------------------------------------------------------------------------------

// Faces a hinted ray cast walks over the surface before it tries the neighbouring pixels' faces.
constexpr int kMaxWalkSteps = 24;

SampleGrid rayCastFishbone(const FishboneGrid& fishbone, const FrameBuffers& referenceBuffers,
                           const Mesh& reference, const RayCaster& caster, const ScanOptions& options,
                           const LocalSearchOptions& search, std::size_t* hintHits) {
    const Camera& camera = referenceBuffers.camera;
    const int w = camera.width, h = camera.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    if (referenceBuffers.faceId.size() != n)
        throw InvalidInputError("The scan buffers hold " + std::to_string(referenceBuffers.faceId.size()) +
                                " face ids instead of " + std::to_string(n) + ".");
    SampleGrid grid(fishbone.rows, fishbone.cols);
    grid.camera = camera;
    grid.scanId = options.scanId;
    const RayFactory rays(camera);
    const CameraProjector projector(camera);
    // Rows (ribs) in blocks, one per thread (parallel.h): every rib vertex is cast on its own.
    const int blocks = detail::rowBlocks(fishbone.rows, 8);
    std::vector<std::size_t> localHits(static_cast<std::size_t>(blocks), 0);
    detail::parallelRows(fishbone.rows, blocks, [&](int block, int rowBegin, int rowEnd) {
        std::size_t& local = localHits[std::size_t(block)];
        for (int r = rowBegin; r < rowEnd; ++r)
            for (int c = 0; c < fishbone.cols; ++c) {
                Sample& s = grid.at(r, c);
                if (!fishbone.isPresent(r, c)) continue;
                const Eigen::Vector2d& p = fishbone.at(r, c);
                s.screen = p;
                const FaceIndex hint = idBufferHint(referenceBuffers, reference, p);
                const Ray ray = rays(p.x(), p.y());
                if (hint != Mesh::null_face() && !search.verifyUnoccluded) {
                    // The ID buffer's first guess, as a triangular-lattice scan finds its samples (scan.h).
                    if (const auto found =
                            hitFromIdBuffer(referenceBuffers, reference, hint, ray, p, kMaxWalkSteps)) {
                        if (found->onHint) ++local;
                        setSampleOnSurface(s, reference, projector, found->face, found->point, options);
                        continue;
                    }
                }
                const SurfacePoint hit = caster.intersect(ray, hint, search);
                if (!hit) continue;
                if (hint != Mesh::null_face() && hit.face == hint) ++local;
                setSampleOnSurface(s, reference, projector, hit.face, hit.point, options);
            }
    });
    const std::size_t local = std::accumulate(localHits.begin(), localHits.end(), std::size_t(0));
    if (hintHits) *hintHits = local;
    return grid;
}

// ---- The scan -------------------------------------------------------------------------------------------

namespace {

// FishboneOptions::surfaceLength on the sampling image: a screen point's surface point is where its viewing
// ray hits the reference (RayCaster with the ID buffer's face under it as the hint, as the rib vertices are
// cast); a segment's length is the distance of its ends' surface points in pixel footprints there (the unit
// of the triangulation's edge limit). An end on the background: the screen length (both: 0, which the
// resampling skips).
std::function<double(const Eigen::Vector2d&, const Eigen::Vector2d&)>
surfaceMetric(const FrameBuffers& buffers, const RayCaster& caster, const LocalSearchOptions& search) {
    auto rays = std::make_shared<RayFactory>(buffers.camera);
    auto onSurface = [&buffers, &caster, &search,
                      rays](const Eigen::Vector2d& q) -> std::optional<Eigen::Vector3d> {
        const int x = int(std::floor(q.x())), y = int(std::floor(q.y()));
        if (!q.allFinite() || x < 0 || y < 0 || x >= buffers.width() || y >= buffers.height() ||
            !buffers.covered(x, y))
            return std::nullopt;
        const SurfacePoint hit =
            caster.intersect((*rays)(q.x(), q.y()), FaceIndex(buffers.faceAt(x, y)), search);
        if (!hit) return std::nullopt;
        return hit.point;
    };
    return [onSurface, &buffers](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        const std::optional<Eigen::Vector3d> pa = onSurface(a), pb = onSurface(b);
        if (!pa || !pb) return pa || pb ? (b - a).norm() : 0.0;
        const double footprint = buffers.camera.pixelFootprint(0.5 * (*pa + *pb));
        return footprint > 0 ? (*pb - *pa).norm() / footprint : (b - a).norm();
    };
}

// A closed fishbone grid (n rows that wrap) unrolled for the masks and the triangulation: the last p rows,
// the n rows, then rows 0 … p again, so that the morphology sees every row's true neighbours and the quads
// between the last and the first row are triangulated (padded row p + n repeats row 0).
FishboneGrid unrollClosedGrid(const FishboneGrid& g, int p) {
    FishboneGrid out = g;
    out.closed = false;
    out.rows = g.rows + 2 * p + 1;
    out.screen.resize(std::size_t(out.rows) * std::size_t(g.cols));
    out.present.resize(out.screen.size());
    for (int r = 0; r < out.rows; ++r) {
        const int from = ((r - p) % g.rows + g.rows) % g.rows;
        std::copy_n(g.screen.begin() + std::ptrdiff_t(g.index(from, 0)), g.cols,
                    out.screen.begin() + std::ptrdiff_t(out.index(r, 0)));
        std::copy_n(g.present.begin() + std::ptrdiff_t(g.index(from, 0)), g.cols,
                    out.present.begin() + std::ptrdiff_t(out.index(r, 0)));
    }
    return out;
}

// The patch of an unrolled closed grid (unrollClosedGrid): its faces between padded rows p and p + n, with
// row p + n (the repeat of row 0) merged into row p, so the grid closes without a seam; the grid cropped to
// the n rows. Samples of equal screen positions are cast, masked and triangulated alike, so the merged
// rows are the same vertices; a face that would make the patch non-manifold is left out (counted as a
// non-manifold triangle).
void closeUnrolledPatch(Patch& patch, SampleGrid& grid, int n, int p) {
    const Mesh& in = patch.mesh;
    const auto [inIndex, hasIndex] = in.property_map<VertexIndex, GridIndex>(props::vertexGridIndex);
    const auto [inQuality, hasQuality] = in.property_map<FaceIndex, float>(props::faceQuality);
    const auto [inScan, hasScan] = in.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    if (!hasIndex) return;
    Mesh out;
    auto outIndex = out.add_property_map<VertexIndex, GridIndex>(props::vertexGridIndex).first;
    auto outQuality = out.add_property_map<FaceIndex, float>(props::faceQuality, 0.0f).first;
    auto outScan = out.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    const int cols = grid.cols;
    std::vector<VertexIndex> made(std::size_t(n) * std::size_t(cols), Mesh::null_vertex());
    auto vertexOf = [&](VertexIndex v) {
        const GridIndex g = inIndex[v];
        const int row = g.row - p == n ? 0 : g.row - p;
        VertexIndex& m = made[std::size_t(row) * std::size_t(cols) + std::size_t(g.col)];
        if (m == Mesh::null_vertex()) {
            m = out.add_vertex(in.point(v));
            outIndex[m] = GridIndex{row, g.col};
        }
        return m;
    };
    std::size_t refused = 0;
    for (FaceIndex f : in.faces()) {
        std::array<VertexIndex, 3> v{};
        int k = 0;
        bool core = true;
        for (VertexIndex x : CGAL::vertices_around_face(in.halfedge(f), in)) {
            const int row = inIndex[x].row;
            core = core && row >= p && row <= p + n;
            v[std::size_t(k++)] = x;
        }
        if (!core || k != 3) continue;
        const FaceIndex g = out.add_face(vertexOf(v[0]), vertexOf(v[1]), vertexOf(v[2]));
        if (g == Mesh::null_face()) {
            ++refused;
            continue;
        }
        if (hasQuality) outQuality[g] = inQuality[f];
        if (hasScan) outScan[g] = inScan[f];
    }
    for (VertexIndex v : out.vertices())
        if (out.is_isolated(v)) out.remove_vertex(v);
    out.collect_garbage();
    patch.mesh = std::move(out);
    patch.rows = n;
    patch.vertexOfSample.assign(std::size_t(n) * std::size_t(cols), Mesh::null_vertex());
    const auto index = patch.mesh.property_map<VertexIndex, GridIndex>(props::vertexGridIndex).first;
    for (VertexIndex v : patch.mesh.vertices())
        patch.vertexOfSample[std::size_t(index[v].row) * std::size_t(cols) + std::size_t(index[v].col)] = v;
    patch.report.faces = patch.mesh.number_of_faces();
    patch.report.nonManifoldTriangles += refused;
    SampleGrid cropped(n, cols);
    cropped.camera = grid.camera;
    cropped.scanId = grid.scanId;
    std::copy_n(grid.samples.begin() + std::ptrdiff_t(grid.index(p, 0)), std::size_t(n) * std::size_t(cols),
                cropped.samples.begin());
    grid = std::move(cropped);
}

// The samples of grid column \p column cast again without the ID buffer's hint (RayCaster::intersect, the
// true first hit): a crease backbone's samples lie on the crease, within a pixel of the surface beyond it
// wherever the crease is on a silhouette, and the hinted cast found that surface there (fandisk +x: backbone
// samples 6.5 h off their crease points on average, 16.8 h at worst; now 0.004 h).
void castColumnUnhinted(SampleGrid& grid, int column, const Mesh& reference, const RayCaster& caster,
                        const ScanOptions& options) {
    const CameraProjector projector(grid.camera);
    for (int r = 0; r < grid.rows; ++r) {
        Sample& s = grid.at(r, column);
        if (!s.hit) continue;
        const SurfacePoint hit = caster.intersect(grid.camera.ray(s.screen.x(), s.screen.y()));
        if (hit) setSampleOnSurface(s, reference, projector, hit.face, hit.point, options);
    }
}

// The backbone traced along the principal direction through the seed (through the visible \p creases'
// attraction), cut at creases when asked (\p stops); \p k only for the positions in error messages.
Backbone seedBackbone(const DirectionField& backboneField, const FishboneParams& fb,
                      const FishboneOptions& options, const CreaseIndex& creases,
                      const std::function<const CreaseIndex&()>& stops, int k) {
    const std::optional<DirectionSample> at = backboneField.sample(*fb.seed, Eigen::Vector2d(1, 0));
    if (!at || at->anisotropy < fb.minSeedAnisotropy)
        throw InvalidInputError("The fishbone seed " + point(double(k) * *fb.seed) +
                                " lies on a flat or isotropic region where no principal direction is "
                                "defined; pick a point on a curved feature.");
    FishboneOptions backboneOptions = options;
    if (!creases.empty())
        backboneOptions.backboneTracing.attractor = [&](const Eigen::Vector2d& q,
                                                        const Eigen::Vector2d& heading) {
            return creases.nearestAlong(q, heading);
        };
    Backbone traced = traceBackbone(backboneField, *fb.seed, backboneOptions);
    if (options.stopBackboneAtCreases && fb.creaseAngleDeg > 0) stops().cutBackbone(traced);
    if (traced.samples.size() < 2)
        throw InvalidInputError("The fishbone backbone has fewer than two samples; pick a point on a longer "
                                "feature or reduce h.");
    return traced;
}

// Fewer rib vertices than twice the rows: what makes a crease grid fall back to the traced backbone.
bool tooFewRibVertices(const FishboneGrid& grid) {
    return grid.presentCount() < 2 * std::size_t(grid.rows);
}

// trimRibs for the fishbone scan. Straight ribs (a crease backbone's) converge on a crease's concave side and
// fan out on its convex side: they are always trimmed where their quads get thinner than 1:1.5 (whose
// triangles keep 33.7°) or where neighbours come closer than h/2 (the options' own bounds when tighter).
// Fewer rib vertices left than rows: a crease on the silhouette whose one visible side is seen so obliquely
// that its ribs are foreshortened below 1:1.5 on the screen and trimmed away (the creased ring's ridge from
// 75° above: 107 rows, 13 rib vertices left). The straight ribs step h footprints on the surface, so their
// quads are square there: trimmed again with the aspect on the surface (\p surface), they stay (an aspect on
// the surface for every crease grid shrinks the patch of fandisk -z). Returns the vertices removed.
std::size_t trimScanRibs(
    FishboneGrid& grid, const Backbone& backbone, const FishboneOptions& options, bool straight,
    const std::function<std::function<double(const Eigen::Vector2d&, const Eigen::Vector2d&)>()>& surface) {
    FishboneOptions trim = options;
    if (straight) {
        trim.minRibGap = std::max(trim.minRibGap, 0.5);
        trim.maxRibAspect = trim.maxRibAspect >= 1 ? std::min(trim.maxRibAspect, 1.5) : 1.5;
    }
    const FishboneGrid untrimmed = straight ? grid : FishboneGrid{};
    const std::size_t removed = trimRibs(grid, backbone, trim); // as automaticFishbone
    if (!straight || !tooFewRibVertices(grid) || trim.surfaceLength) return removed;
    grid = untrimmed;
    trim.surfaceLength = surface();
    return trimRibs(grid, backbone, trim);
}

// What the crease backbone and its ribs need (FishboneOptions::creaseBackbone; crease_backbone.h).
detail::CreaseBackboneInput creaseInput(const Mesh& reference, const FishboneParams& fb,
                                        const FishboneOptions& options, const FrameBuffers& buffers,
                                        FishboneCache& cache) {
    detail::CreaseBackboneInput in;
    in.mesh = &reference;
    in.creaseEdges = &cache.creaseEdges(reference, fb.creaseAngleDeg);
    in.caster = &cache.rayCaster(reference);
    in.camera = buffers.camera;
    in.spacing = options.spacing;
    in.snapDistance = 3.0;
    in.maxLength = options.backboneTracing.maxLength;
    in.ribMaxLength = options.ribTracing.maxLength;
    return in;
}

// Key-rib mode: every picked key-rib traced at its nearest backbone sample, every drawn one as drawn, blended
// into one grid (keyRibFishbone). \p k is the sampling factor, only for the positions in error messages.
FishboneGrid keyRibGrid(const DirectionField& ribField, const Backbone& backbone, const FishboneParams& fb,
                        const FishboneOptions& options, int k, int W, int H) {
    auto shown = [k](const Eigen::Vector2d& p) { return point(double(k) * p); };
    const double h = options.spacing;
    std::vector<KeyRib> keys;
    std::vector<std::uint8_t> used(backbone.samples.size(), 0);
    auto twoOnOne = [](const std::string& what) {
        return InvalidInputError("Two key-ribs fall on the same backbone sample (" + what +
                                 "); place them farther apart.");
    };
    auto claim = [&](std::size_t row, const std::string& what) {
        if (used[row]) throw twoOnOne(what);
        used[row] = 1;
    };
    std::vector<double> positions; // of the continuous key-ribs (FishboneOptions::continuousKeyRibs)
    for (const Eigen::Vector2d& p : fb.keyRibs) {
        const BackbonePoint at = backbone.nearestPoint(p);
        const std::size_t row = backbone.nearestSample(p);
        const double d = options.continuousKeyRibs ? at.distance : (backbone.samples[row] - p).norm();
        if (d > 2 * h)
            throw InvalidInputError("The key-rib point " + shown(p) + " lies " + fmt(k * d) +
                                    " pixels from the backbone, farther than 2h = " + fmt(2 * k * h) + ".");
        if (!options.continuousKeyRibs) {
            claim(row, shown(p));
            keys.push_back(KeyRib{row, traceRib(ribField, backbone, row, options)});
            continue;
        }
        for (double q : positions)
            if (std::abs(q - at.position) < 0.5) throw twoOnOne("less than h/2 apart along it, " + shown(p));
        used[row] = 1;
        positions.push_back(at.position);
        keys.push_back(tracedKeyRib(ribField, backbone, p, options));
    }
    for (const Polyline2& drawn : fb.drawnKeyRibs) {
        KeyRib key = drawnKeyRib(backbone, drawn, options);
        claim(key.row, "a drawn key-rib");
        keys.push_back(std::move(key));
    }
    return keyRibFishbone(backbone, std::move(keys), options, W, H);
}

// The half-ribs clipped at the lasso (FishboneOptions::clipRibsAtLasso): the number of vertices dropped.
std::size_t clipAtLasso(FishboneScanResult& result, const ScanParams& params) {
    return detail::clipRibsAtLasso(result.fishbone, *params.lasso, 0.5);
}

// Rib ends whose quads make thin triangles peeled (FishboneOptions::peelRibEndsDeg), inside the lasso (the
// mask drops the same samples again).
void peelRibEnds(FishboneScanResult& result, const ScanParams& params, const FishboneOptions& options) {
    if (!(options.peelRibEndsDeg > 0)) return;
    if (params.lasso) applyLasso(result.grid, *params.lasso);
    result.counts.peeled =
        detail::peelSliverRibEnds(result.grid, result.fishbone.backboneColumn, options.peelRibEndsDeg, 3);
}

// The scan on its sampling image: \p params and \p fb are already scaled to it (and validated); \p k is
// the sampling factor, only for the positions in error messages (which the user gave in scan pixels).
FishboneScanResult scanOnSamplingImage(const Mesh& reference, MeshRenderer& referenceRenderer,
                                       const Mesh& current, MeshRenderer& currentRenderer,
                                       const ScanParams& params, const FishboneParams& fb,
                                       FishboneCache& cache, const Progress& progress, int k,
                                       Clock::time_point start) {
    auto shown = [k](const Eigen::Vector2d& p) { return point(double(k) * p); };
    const double h = fb.spacing;
    const bool drawnBackbone = !fb.drawnBackbone.empty();
    const std::size_t keyRibCount = fb.keyRibs.size() + fb.drawnKeyRibs.size();
    const bool keyRibMode = keyRibCount > 0;

    FishboneScanResult result;
    FishboneOptions options = fb.tracing;
    options.spacing = h;
    // Unbounded tracing: a backbone at most the image diagonal long each way, a rib half at most half of it
    // (a line field can close on itself, and a rib circling a feature many times is no sampling grid).
    const double diagonal = std::hypot(double(params.camera.width), double(params.camera.height));
    if (!std::isfinite(options.backboneTracing.maxLength)) options.backboneTracing.maxLength = diagonal;
    if (!std::isfinite(options.ribTracing.maxLength)) options.ribTracing.maxLength = 0.5 * diagonal;

    // Per-reference precomputation (cached by the caller).
    progress.report(0.0, "curvature");
    const bool needFields = !drawnBackbone || !keyRibMode || !fb.keyRibs.empty();
    const CurvatureField* curvature = nullptr;
    if (needFields) {
        const bool cached = cache.hasCurvature(reference);
        curvature = &cache.curvature(reference, {}, progress);
        if (!cached) result.timings.curvature = cache.curvatureSeconds();
    }
    const bool casterCached = cache.hasRayCaster(reference);
    const RayCaster& caster = cache.rayCaster(reference);
    if (!casterCached) result.timings.rayCasterBuild = cache.rayCasterSeconds();

    progress.report(0.1, "render reference");
    auto t = Clock::now();
    FrameBuffers referenceBuffers = referenceRenderer.render(params.camera);
    result.timings.renderReference = secondsSince(t);
    if (referenceBuffers.coveredCount() == 0)
        throw InvalidInputError("The scan camera sees no part of the mesh.");
    const int W = referenceBuffers.width(), H = referenceBuffers.height();

    const bool currentIsReference = (&current == &reference);
    if (!currentIsReference) {
        progress.report(0.2, "render current");
        t = Clock::now();
        result.currentBuffers = currentRenderer.render(referenceBuffers.camera);
        result.timings.renderCurrent = secondsSince(t);
    } else {
        result.currentBuffers = std::move(referenceBuffers); // one render serves both, without a copy
    }
    const FrameBuffers& buffers = currentIsReference ? result.currentBuffers : referenceBuffers;

    // Direction fields: the backbone's (traced backbone) and the ribs' (automatic or traced key-ribs).
    progress.report(0.3, "direction field");
    t = Clock::now();
    DirectionField backboneField, ribField;
    const bool tracedBackbone = !drawnBackbone, tracedRibs = !keyRibMode || !fb.keyRibs.empty();
    if (tracedBackbone) {
        const int sx = int(std::floor(fb.seed->x())), sy = int(std::floor(fb.seed->y()));
        if (!buffers.covered(sx, sy))
            throw InvalidInputError("The fishbone seed " + shown(*fb.seed) +
                                    " lies on the background; pick a point on the surface.");
    }
    // Lazy fields: a tile of pixels is computed when the backbone or a rib first comes near it, so the cost
    // follows the area the fishbone covers (the backbone's field is needed only along the backbone).
    if (tracedBackbone) backboneField = lazyDirectionField(reference, *curvature, buffers, {fb.direction});
    if (tracedRibs)
        ribField = lazyDirectionField(reference, *curvature, buffers, {otherDirection(fb.direction)});
    result.timings.directionField = secondsSince(t);

    progress.report(0.4, "tracing");
    t = Clock::now();
    // The visible creases, made once when needed: for the backbone's crease following and issue 20's stops.
    std::optional<CreaseIndex> creaseIndex, stopIndex;
    auto index = [&](std::optional<CreaseIndex>& i, const RayCaster* rays) -> const CreaseIndex& {
        if (!i) {
            std::vector<CreaseSegment> segments;
            if (fb.creaseAngleDeg > 0)
                segments =
                    visibleCreases(reference, cache.creaseEdges(reference, fb.creaseAngleDeg), buffers, rays);
            i.emplace(std::move(segments), fb.creaseSnapRadius, W, H);
        }
        return *i;
    };
    auto visible = [&]() -> const CreaseIndex& { return index(creaseIndex, nullptr); };
    auto stops = [&]() -> const CreaseIndex& { return index(stopIndex, &caster); };
    Backbone backbone;
    std::optional<detail::CreaseBackbone> onCrease; // the backbone along a crease (creaseBackbone)
    if (!drawnBackbone && options.creaseBackbone && fb.creaseAngleDeg > 0)
        onCrease = detail::creaseBackbone(creaseInput(reference, fb, options, buffers, cache), *fb.seed);
    auto traceSeedBackbone = [&] { return seedBackbone(backboneField, fb, options, visible(), stops, k); };
    if (drawnBackbone) {
        backbone = fss::drawnBackbone(fb.drawnBackbone, options);
    } else if (onCrease) {
        backbone = onCrease->backbone;
        if (options.stopBackboneAtCreases && fb.creaseAngleDeg > 0) stops().cutBackbone(backbone);
    } else {
        backbone = traceSeedBackbone();
    }
    if (backbone.samples.size() < 2)
        throw InvalidInputError("The fishbone backbone has fewer than two samples; pick a point on a longer "
                                "feature or reduce h.");
    if (options.isotropicRibs) options.surfaceLength = surfaceMetric(buffers, caster, fb.raycast);
    bool straight = false;
    if (!keyRibMode) {
        for (;;) {
            // The ribs are independent streamlines, traced on the scan threads (the grid is the same for any
            // thread count).
            // On a crease (and not cut by stopBackboneAtCreases): straight ribs perpendicular to it in 3D.
            straight = onCrease && onCrease->backbone.samples.size() == backbone.samples.size();
            result.fishbone = assembleFishboneGrid(
                backbone,
                straight ? detail::creaseRibs(creaseInput(reference, fb, options, buffers, cache), *onCrease)
                         : traceAllRibs(ribField, backbone, options),
                h, W, H);
            result.counts.trimmed = trimScanRibs(result.fishbone, backbone, options, straight,
                                                 [&] { return surfaceMetric(buffers, caster, fb.raycast); });
            if (!straight || !tooFewRibVertices(result.fishbone)) break;
            onCrease.reset();
            backbone = traceSeedBackbone();
        }
    } else {
        result.fishbone = keyRibGrid(ribField, backbone, fb, options, k, W, H);
    }
    // The straight ribs of a crease backbone always stop at the next crease (sparing the one they leave).
    if ((options.stopRibsAtCreases || straight) && fb.creaseAngleDeg > 0)
        result.counts.creaseStopped =
            stops().stopRibsAtCreases(result.fishbone, options.spareFollowedCrease || straight);
    if (options.clipRibsAtLasso && params.lasso) result.counts.lassoClipped = clipAtLasso(result, params);
    result.timings.tracing = secondsSince(t);
    result.counts.directionPixels = backboneField.computedPixels() + ribField.computedPixels();
    result.counts.rows = result.fishbone.rows;
    result.counts.cols = result.fishbone.cols;
    result.counts.ribVertices = result.fishbone.presentCount();

    progress.report(0.6, "ray casting");
    t = Clock::now();
    // A closed grid is cast, masked and triangulated unrolled (unrollClosedGrid), then closed again.
    const bool closedGrid = result.fishbone.closed;
    const int pad = std::max(0, params.erodeRadius) +
                    std::max(0, params.dilateRadius < 0 ? params.erodeRadius : params.dilateRadius) + 1;
    result.grid =
        rayCastFishbone(closedGrid ? unrollClosedGrid(result.fishbone, pad) : result.fishbone, buffers,
                        reference, caster, params.scan, fb.raycast, &result.counts.onHintFace);
    if (straight)
        castColumnUnhinted(result.grid, result.fishbone.backboneColumn, reference, caster, params.scan);
    // Sampling quality as on the scan image (its pixel footprint, 1/k of the sampling image's), so that the
    // quality mask ranks a fishbone patch the same whatever k is. The footprints stay the sampling camera's
    // (the triangulation's edge limits are in them).
    if (k > 1)
        for (Sample& s : result.grid.samples)
            if (s.hit) s.quality /= float(k);
    result.timings.rayCasting = secondsSince(t);
    result.counts.covered = result.grid.hitCount();
    result.counts.frontFacing = result.grid.admissibleCount();
    if (result.counts.frontFacing == 0)
        throw InvalidInputError("No rib vertex of the fishbone lands on the front of the surface.");

    peelRibEnds(result, params, options);
    MaskStages stages;
    if (params.lasso) stages.lasso = &*params.lasso;
    if (!currentIsReference) {
        stages.current = &current;
        stages.currentBuffers = &result.currentBuffers;
    }
    stages.quality = params.quality;
    stages.morphology = {.radius = params.erodeRadius, .dilateRadius = params.dilateRadius};
    stages.triangulate = params.triangulate;
    stages.triangulate.maxEdgeFootprints *= std::max(1.0, h);
    stages.triangulate.minTriangleAngleDeg =
        std::max(stages.triangulate.minTriangleAngleDeg, options.minFaceAngleDeg);
    stages.triangulate.minComponentFaces =
        std::max(stages.triangulate.minComponentFaces, options.minComponentFaces);
    stages.atLasso = {0.7, "masks"};
    stages.atQuality = stages.atMorphology = {};
    stages.atTriangulate = {0.85, "triangulate"};
    stages.lassoSelectsNothing = "The lasso selects no part of the fishbone grid.";
    stages.nothingLeft = "Nothing is left to triangulate after the masks; enlarge the lasso, reduce the "
                         "erosion or reduce h.";
    MaskedPatch masked = maskAndTriangulate(result.grid, stages, progress);
    result.patch = std::move(masked.patch);
    if (closedGrid) closeUnrolledPatch(result.patch, result.grid, result.fishbone.rows, pad);
    result.counts.afterLasso = masked.counts.afterLasso;
    result.counts.afterQuality = masked.counts.afterQuality;
    result.counts.afterMorphology = masked.counts.afterMorphology;
    result.timings.masks = masked.timings.lasso + masked.timings.qualityMask + masked.timings.morphology;
    result.timings.triangulate = masked.timings.triangulate;
    result.timings.total = secondsSince(start);
    return result;
}

} // namespace

int fishboneSamplingFactor(const Camera& scan, const FishboneParams& fb) {
    const int W = scan.width, H = scan.height;
    const double h = fb.spacing;
    detail::validateSamplingFactor(scan, fb);
    if (fb.samplingFactor > 0) return fb.samplingFactor;
    if (!(h >= 2) || W <= 0 || H <= 0) return 1;
    for (int k = int(std::min({std::floor(h), double(W), double(H)})); k > 1; --k)
        if (W % k == 0 && H % k == 0) return k;
    return 1;
}

Camera fishboneSamplingCamera(const Camera& scan, const FishboneParams& fb) {
    const int k = fishboneSamplingFactor(scan, fb);
    Camera c = scan;
    c.width /= k;
    c.height /= k;
    return c;
}

FishboneScanResult scanFishbonePatch(const Mesh& reference, MeshRenderer& referenceRenderer,
                                     const Mesh& current, MeshRenderer& currentRenderer,
                                     const ScanParams& params, const FishboneParams& fb, FishboneCache& cache,
                                     const Progress& progress) {
    const auto start = Clock::now();
    params.validate();
    fb.validate(params.camera);

    const int k = fishboneSamplingFactor(params.camera, fb);
    FishboneScanResult result;
    if (k == 1) {
        result = scanOnSamplingImage(reference, referenceRenderer, current, currentRenderer, params, fb,
                                     cache, progress, 1, start);
    } else {
        // Everything the user gave in pixels of the scan image, in pixels of the sampling image.
        const double s = 1.0 / k;
        ScanParams sp = params;
        sp.camera.width /= k; // fishboneSamplingCamera, with the k already chosen
        sp.camera.height /= k;
        if (sp.lasso)
            for (Eigen::Vector2d& q : sp.lasso->points)
                q *= s;
        FishboneParams f = fb;
        if (f.seed) *f.seed *= s;
        f.spacing *= s;
        for (Eigen::Vector2d& q : f.keyRibs)
            q *= s;
        for (Polyline2& c : f.drawnKeyRibs)
            for (Eigen::Vector2d& q : c)
                q *= s;
        for (Eigen::Vector2d& q : f.drawnBackbone)
            q *= s;
        // The tracing steps are pixels of the sampling image (the direction field's own resolution), as for
        // any scan of that size; lengths and the crease snap radius are the user's, in scan pixels (a
        // radius of 1.5 sampling pixels pulls a backbone on fandisk at 128² onto neighbouring creases).
        f.creaseSnapRadius *= s;
        for (StreamlineOptions* o : {&f.tracing.backboneTracing, &f.tracing.ribTracing}) {
            o->maxLength *= s;
            if (o->insideRegion)
                o->insideRegion = [inside = o->insideRegion, k](const Eigen::Vector2d& q) {
                    return inside(k * q);
                };
            if (o->attractor)
                o->attractor = [attract = o->attractor, k,
                                s](const Eigen::Vector2d& q,
                                   const Eigen::Vector2d& d) -> std::optional<Eigen::Vector2d> {
                    if (const std::optional<Eigen::Vector2d> a = attract(k * q, d)) return s * *a;
                    return std::nullopt;
                };
        }
        result = scanOnSamplingImage(reference, referenceRenderer, current, currentRenderer, sp, f, cache,
                                     progress, k, start);
        // The traced grid back in pixels of the scan image (the widget draws it over the view).
        for (Eigen::Vector2d& q : result.fishbone.screen)
            q *= double(k);
        result.fishbone.spacing *= double(k);
        result.timings.total = secondsSince(start);
    }
    result.samplingFactor = k;
    progress.report(1.0, "done");
    return result;
}

} // namespace fss
