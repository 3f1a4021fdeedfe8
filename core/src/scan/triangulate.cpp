#include "fss/triangulate.h"

#include "fss/error.h"
#include "fss/scan.h"

#include "base/parallel_rows.h"
#include "scan/scan_workspace_impl.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

namespace fss {
namespace {

using Point2 = Kernel::Point_2;
using Triangle = ScanWorkspace::Impl::Triangle; // sample indices, counter-clockwise as seen by the camera

bool usable(const Sample& s) {
    return s.valid && s.hit && s.point.allFinite();
}

// Direction from \p p towards the viewer along its viewing ray, not normalised (its sign tests need no
// length); the view direction's opposite where p is the eye itself.
struct Viewer {
    explicit Viewer(const Camera& camera)
        : eye(camera.eye), back(-camera.viewDirection()), parallel(camera.parallel) {}
    Eigen::Vector3d towards(const Eigen::Vector3d& p) const {
        if (parallel) return back;
        const Eigen::Vector3d d = eye - p;
        return d.squaredNorm() > 0 ? d : back;
    }
    Eigen::Vector3d eye, back;
    bool parallel;
};

// Screen orientation with y pointing down: a triangle that the camera sees counter-clockwise (OpenGL's
// front face, y up) is a right turn in these coordinates.
CGAL::Orientation screenOrientation(const SampleGrid& grid, const Triangle& t) {
    const auto& a = grid.samples[t[0]].screen;
    const auto& b = grid.samples[t[1]].screen;
    const auto& c = grid.samples[t[2]].screen;
    return CGAL::orientation(Point2(a.x(), a.y()), Point2(b.x(), b.y()), Point2(c.x(), c.y()));
}

enum class Verdict { Keep, Flipped, BackFacing, LongEdge, Grazing, SliverQuad };

struct JudgeLimits {
    double maxEdgeFootprints;
    double maxAngle;       // radians
    double cosMaxAngle;    // cos(maxAngle)
    double cosMinQuad;     // cos(minQuadAngleDeg); > 1 when there is no bound
    double cosMinTriangle; // cos(minTriangleAngleDeg); > 1 when there is no bound
};

// Whether the corner angle at \p p between the edges to \p a and \p b is below the bound whose cosine is
// \p cosBound (a degenerate corner counts as below).
bool cornerBelow(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 double cosBound) {
    const Eigen::Vector3d u = a - p, v = b - p;
    const double lu = u.norm(), lv = v.norm();
    return !(lu > 0 && lv > 0) || u.dot(v) > cosBound * lu * lv;
}

// A quad (corners in order around it, the first and third on the diagonal (r, c)–(r+1, c+1)) with a 3D corner
// angle below the quad bound (cos above cosMinQuad), or with a triangle of the split whose 3D angle is
// below the triangle bound (cos above cosMinTriangle).
bool sliverQuad(const SampleGrid& grid, std::array<std::uint32_t, 4> q, double cosMinQuad,
                double cosMinTriangle) {
    auto at = [&](std::size_t k) -> const Eigen::Vector3d& { return grid.samples[q[k % 4]].point; };
    if (cosMinQuad < 1)
        for (std::size_t k = 0; k < 4; ++k)
            if (cornerBelow(at(k), at(k + 1), at(k + 3), cosMinQuad)) return true;
    if (cosMinTriangle < 1)
        for (const std::size_t side : {1, 3}) // the triangles (q0, q1, q2) and (q0, q3, q2)
            if (cornerBelow(at(0), at(side), at(2), cosMinTriangle) ||
                cornerBelow(at(side), at(0), at(2), cosMinTriangle) ||
                cornerBelow(at(2), at(0), at(side), cosMinTriangle))
                return true;
    return false;
}

// Per-sample flags of usableSample (one byte per sample): the tests of judge() that depend on one sample
// only, computed once per sample instead of once per triangle (a sample is a corner of up to six).
constexpr std::uint8_t kUsable = 1, kReferenceBackFacing = 2, kSampleGrazing = 4;

std::uint8_t sampleFlags(const Sample& s, const Viewer& viewer, const JudgeLimits& limits) {
    if (!usable(s)) return 0;
    std::uint8_t f = kUsable;
    if (s.normal.squaredNorm() > 0 && !(s.normal.dot(viewer.towards(s.point)) > 0)) f |= kReferenceBackFacing;
    if (double(s.samplingAngle) > limits.maxAngle) f |= kSampleGrazing;
    return f;
}

// The 3D tests of a candidate whose screen orientation is already known to be the grid's; \p corners are
// the sampleFlags of its three samples, or-ed.
Verdict judge(const SampleGrid& grid, std::uint8_t corners, const Triangle& t, const Viewer& viewer,
              const JudgeLimits& limits) {
    const Sample& a = grid.samples[t[0]];
    const Sample& b = grid.samples[t[1]];
    const Sample& c = grid.samples[t[2]];
    const Eigen::Vector3d centroid = (a.point + b.point + c.point) / 3.0;
    const Eigen::Vector3d toViewer = viewer.towards(centroid);
    const Eigen::Vector3d normal = (b.point - a.point).cross(c.point - a.point);
    if (!(normal.dot(toViewer) > 0)) return Verdict::BackFacing;
    if (corners & kReferenceBackFacing) return Verdict::BackFacing;
    for (auto [u, v] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}}) {
        const double limit = limits.maxEdgeFootprints * std::min(double(u->footprint), double(v->footprint));
        // Squared lengths: no square root in the innermost test.
        if (!(limit >= 0 && (u->point - v->point).squaredNorm() <= limit * limit)) return Verdict::LongEdge;
    }
    if (corners & kSampleGrazing) return Verdict::Grazing;
    if (normal.normalized().dot(toViewer.normalized()) < limits.cosMaxAngle) return Verdict::Grazing;
    return Verdict::Keep;
}

// Removes triangles until every vertex has a single fan (the largest one is kept; ties keep the fan
// with the lowest triangle index), compacting \p triangles to the survivors in their order. Returns the
// number of pinched vertices found. \p triangles are grid triangles in quad order (row-major quads, for
// each quad first {i00, i10, i11} then {i00, i11, i01}, or both with their last two corners swapped when
// \p mirrored), as the candidates are made.
//
// Vertex v = (r, c) lies in at most six grid triangles; in triangle order they are: quad (r−1, c−1) both
// halves, quad (r−1, c) first half, quad (r, c−1) second half, quad (r, c) both halves. So one byte per
// sample — which halves of the quad whose top-left corner it is exist and are still alive — gives each
// vertex's fan in triangle order without an incidence list, and a triangle's rank in that order is
// 2·(top-left sample) + half. The work list is the one an incidence-list version would make: first every
// vertex in two or more triangles, in increasing order, taken from the back (here read lazily, downwards),
// then the vertices of removed triangles pushed on top when not already waiting.
std::size_t makeVerticesManifold(std::vector<Triangle>& triangles, int rows, int cols, bool mirrored,
                                 std::size_t& removedTriangles, ScanWorkspace::Impl& w) {
    if (triangles.empty()) return 0;
    constexpr std::uint8_t kExists[2] = {1, 2}, kAlive[2] = {4, 8};
    const std::size_t sampleCount = std::size_t(rows) * std::size_t(cols);
    const auto ucols = std::uint32_t(cols);
    std::vector<std::uint8_t>& quad = w.quadHalves; // by top-left sample
    quad.assign(sampleCount, 0);
    auto halfOf = [&](const Triangle& t) { return (t[1] == t[0] + ucols || t[2] == t[0] + ucols) ? 0 : 1; };
    for (const Triangle& t : triangles)
        quad[t[0]] |= std::uint8_t(kExists[halfOf(t)] | kAlive[halfOf(t)]);
    // The corners of half h of the quad at top-left sample q, in the triangle's vertex order.
    auto corners = [&](std::uint32_t q, int h) -> Triangle {
        Triangle t = h == 0 ? Triangle{q, q + ucols, q + ucols + 1} : Triangle{q, q + ucols + 1, q + 1};
        if (mirrored) std::swap(t[1], t[2]);
        return t;
    };
    struct Slot {
        std::uint32_t quad;
        int half;
    };
    // The (up to six) triangles around v = (r, c) that exist, alive or all, in triangle order.
    auto fanAt = [&](std::uint32_t v, std::uint32_t r, std::uint32_t c, bool aliveOnly,
                     std::array<Slot, 6>& out) {
        std::size_t n = 0;
        auto take = [&](std::uint32_t q, int h) {
            if (quad[q] & (aliveOnly ? kAlive[h] : kExists[h])) out[n++] = {q, h};
        };
        if (r > 0 && c > 0) take(v - ucols - 1, 0), take(v - ucols - 1, 1);
        if (r > 0) take(v - ucols, 0);
        if (c > 0) take(v - 1, 1);
        take(v, 0), take(v, 1);
        return n;
    };
    auto fanOf = [&](std::uint32_t v, bool aliveOnly, std::array<Slot, 6>& out) {
        return fanAt(v, v / ucols, v % ucols, aliveOnly, out);
    };
    auto initialCount = [&](std::uint32_t v) {
        std::array<Slot, 6> all;
        return fanOf(v, false, all);
    };
    std::vector<std::uint8_t>& pushed = w.pushed; // on the work list above the initial vertices
    pushed.assign(sampleCount, 0);
    std::vector<std::uint32_t>& work = w.work;
    work.clear();
    // Initial vertices not yet taken: those ≤ next (and in two or more triangles); next = (nextRow, nextCol).
    std::int64_t next = std::int64_t(sampleCount) - 1;
    std::uint32_t nextRow = std::uint32_t(rows - 1), nextCol = std::uint32_t(cols - 1);
    auto waiting = [&](std::uint32_t x) {
        return pushed[x] || (std::int64_t(x) <= next && initialCount(x) > 1);
    };

    std::size_t pinched = 0;
    std::array<Slot, 6> fan;
    std::array<Triangle, 6> tri;
    std::array<std::uint32_t, 6> component;
    for (;;) {
        std::uint32_t v = 0;
        if (!work.empty()) {
            v = work.back();
            work.pop_back();
            pushed[v] = 0;
        } else {
            // Down to the next vertex that was initially in two or more triangles (row and column
            // counted along, no division per sample).
            bool found = false;
            while (next >= 0 && !found) {
                found = fanAt(std::uint32_t(next), nextRow, nextCol, false, fan) > 1;
                v = std::uint32_t(next--);
                if (nextCol > 0)
                    --nextCol;
                else
                    nextCol = ucols - 1, --nextRow;
            }
            if (!found) break;
        }
        const std::size_t n = fanOf(v, true, fan);
        // A grid vertex lies in at most the six grid triangles around it, which form one closed fan:
        // all six alive means manifold (the common interior case, skipped without the search below).
        if (n < 2 || n == 6) continue;
        for (std::size_t i = 0; i < n; ++i)
            tri[i] = corners(fan[i].quad, fan[i].half);
        // Connected components of the triangles around v: two are adjacent when they share an edge at v,
        // i.e. a vertex other than v.
        component.fill(std::uint32_t(-1));
        std::uint32_t components = 0;
        for (std::size_t s = 0; s < n; ++s) {
            if (component[s] != std::uint32_t(-1)) continue;
            component[s] = components;
            for (bool grown = true; grown;) {
                grown = false;
                for (std::size_t i = 0; i < n; ++i) {
                    if (component[i] != components) continue;
                    for (std::size_t j = 0; j < n; ++j) {
                        if (component[j] != std::uint32_t(-1)) continue;
                        bool shares = false;
                        for (std::uint32_t x : tri[i])
                            if (x != v && std::find(tri[j].begin(), tri[j].end(), x) != tri[j].end())
                                shares = true;
                        if (shares) component[j] = components, grown = true;
                    }
                }
            }
            ++components;
        }
        if (components < 2) continue;
        ++pinched;
        // Per component: size and lowest rank (2·quad + half, in triangle order).
        std::array<std::size_t, 6> size{};
        std::array<std::uint64_t, 6> lowest;
        lowest.fill(std::uint64_t(-1));
        for (std::size_t i = 0; i < n; ++i) {
            ++size[component[i]];
            lowest[component[i]] =
                std::min(lowest[component[i]], 2 * std::uint64_t(fan[i].quad) + fan[i].half);
        }
        std::uint32_t keep = 0;
        for (std::uint32_t k = 1; k < components; ++k)
            if (size[k] > size[keep] || (size[k] == size[keep] && lowest[k] < lowest[keep])) keep = k;
        for (std::size_t i = 0; i < n; ++i) {
            if (component[i] == keep) continue;
            quad[fan[i].quad] &= std::uint8_t(~kAlive[fan[i].half]);
            ++removedTriangles;
            for (std::uint32_t x : tri[i])
                if (x != v && !waiting(x)) work.push_back(x), pushed[x] = 1;
        }
    }
    if (removedTriangles > 0)
        std::erase_if(triangles, [&](const Triangle& t) { return !(quad[t[0]] & kAlive[halfOf(t)]); });
    return pinched;
}

// Drops the triangles of every connected part with fewer than \p minFaces triangles, keeping the order of
// the others; returns how many were dropped. Once every vertex has a single fan (makeVerticesManifold),
// triangles sharing a vertex are connected through that fan, so the parts are the classes of the samples
// joined by the triangles (union–find on sample indices).
std::size_t dropSmallComponents(std::vector<Triangle>& triangles, std::size_t sampleCount, int minFaces) {
    if (minFaces <= 1 || triangles.empty()) return 0;
    std::vector<std::uint32_t> parent(sampleCount);
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    for (const Triangle& t : triangles)
        for (std::size_t j = 1; j < 3; ++j) {
            const std::uint32_t a = root(t[0]), b = root(t[j]);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    std::vector<std::uint32_t> size(sampleCount, 0);
    for (const Triangle& t : triangles)
        ++size[root(t[0])];
    const std::size_t before = triangles.size();
    std::erase_if(triangles, [&](const Triangle& t) { return size[root(t[0])] < std::uint32_t(minFaces); });
    return before - triangles.size();
}

// True when \p mesh has exactly the properties triangulateGrid gives a patch (so that, emptied and resized,
// it is the same as a new mesh with them).
bool hasPatchPropertiesOnly(const Mesh& mesh) {
    static const Mesh reference = [] {
        Mesh m;
        m.add_property_map<VertexIndex, GridIndex>(props::vertexGridIndex, GridIndex{});
        m.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality);
        m.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1);
        return m;
    }();
    return mesh.properties<VertexIndex>() == reference.properties<VertexIndex>() &&
           mesh.properties<HalfedgeIndex>() == reference.properties<HalfedgeIndex>() &&
           mesh.properties<EdgeIndex>() == reference.properties<EdgeIndex>() &&
           mesh.properties<FaceIndex>() == reference.properties<FaceIndex>() &&
           mesh.property_map<VertexIndex, GridIndex>(props::vertexGridIndex).second &&
           mesh.property_map<FaceIndex, float>(props::faceQuality).second &&
           mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId).second;
}

/// Triangulation stage 1: both triangles of every quad with four usable corners, judged in one pass over the
/// quad rows (in blocks, one per thread); the kept ones in row order, in the grid's orientation. Fills the
/// report's quad and rejection counts, the dense sample qualities (w.sampleQuality) and \p mirrored.
std::vector<Triangle>& judgeQuadTriangles(const SampleGrid& grid, const TriangulateOptions& options,
                                          ScanWorkspace::Impl& w, TriangulateReport& report, bool& mirrored) {
    const Viewer viewer(grid.camera);
    const double maxAngle = options.maxSamplingAngleDeg * std::numbers::pi / 180.0;
    const JudgeLimits limits{
        options.maxEdgeFootprints, maxAngle, std::cos(maxAngle),
        options.minQuadAngleDeg > 0 ? std::cos(options.minQuadAngleDeg * std::numbers::pi / 180.0) : 2.0,
        options.minTriangleAngleDeg > 0 ? std::cos(options.minTriangleAngleDeg * std::numbers::pi / 180.0)
                                        : 2.0};

    // One pass over the quad rows, in blocks, one per thread (parallel.h), with the samples of a quad row
    // in cache: their own tests (sampleFlags, one byte per sample of the two rows at hand: every sample is
    // a corner of up to four quads and six triangles), the candidates — both triangles of every quad with
    // four usable corners, split along (r,c)–(r+1,c+1), in the vertex order that is counter-clockwise on
    // the screen for a regular grid — their exact screen orientation and their 3D tests (judge). Which
    // orientation is the grid's is only known once every candidate is counted: a fishbone grid may be
    // mirrored on the screen, its majority orientation is then the grid's and the vertex order is reversed
    // so that the faces still face the camera (which reverses the exact orientation too). A candidate is
    // judged in the one order in which it is not flipped: as made if it turns right (kept if the grid is
    // not mirrored), reversed if it turns left (kept if the grid is mirrored). The blocks' kept candidates
    // are concatenated in row order, so the result does not depend on the number of blocks.
    // The samples' q go into a dense array for the faces' qualities at the end.
    const std::size_t sampleCount = grid.samples.size();
    std::vector<float>& sampleQuality = w.sampleQuality;
    sampleQuality.resize(sampleCount); // every entry is written below
    const int quadRows = std::max(grid.rows - 1, 0);
    const int blocks = detail::rowBlocks(quadRows, 16);
    using Block = ScanWorkspace::Impl::Block;
    std::vector<Block>& block = w.blocks;
    block.resize(static_cast<std::size_t>(blocks));
    for (Block& b : block) {
        b.candidates.clear();
        b.keptIf.clear();
        b.quads = b.rightTurns = b.leftTurns = 0;
        b.verdicts = {};
        b.top.resize(std::size_t(grid.cols)); // every entry written before it is read
        b.bottom.resize(std::size_t(grid.cols));
    }
    constexpr std::uint8_t kKeptIfNotMirrored = 1, kKeptIfMirrored = 2;
    detail::parallelRows(std::max(quadRows, 1), blocks, [&](int b, int rowBegin, int rowEnd) {
        Block& out = block[std::size_t(b)];
        // This block's sample rows for the dense q: its quad rows' top rows, and the last row for the last.
        const int qualityEnd = rowEnd == std::max(quadRows, 1) ? grid.rows : rowEnd;
        auto flagRow = [&](int r, std::vector<std::uint8_t>& flags) {
            const Sample* row = grid.samples.data() + grid.index(r, 0);
            for (int c = 0; c < grid.cols; ++c)
                flags[std::size_t(c)] = sampleFlags(row[c], viewer, limits);
            if (r >= rowBegin && r < qualityEnd)
                for (int c = 0; c < grid.cols; ++c)
                    sampleQuality[grid.index(r, c)] = row[c].quality;
        };
        if (rowBegin < grid.rows) flagRow(rowBegin, out.bottom);
        for (int r = rowBegin; r < rowEnd && r + 1 < grid.rows; ++r) {
            std::swap(out.top, out.bottom);
            flagRow(r + 1, out.bottom);
            const std::uint8_t* top = out.top.data();
            const std::uint8_t* bottom = out.bottom.data();
            for (int c = 0; c + 1 < grid.cols; ++c) {
                if (!(top[c] & top[c + 1] & bottom[c] & bottom[c + 1] & kUsable)) continue;
                const auto i00 = std::uint32_t(grid.index(r, c)), i01 = std::uint32_t(grid.index(r, c + 1)),
                           i10 = std::uint32_t(grid.index(r + 1, c)),
                           i11 = std::uint32_t(grid.index(r + 1, c + 1));
                ++out.quads;
                const bool sliver =
                    sliverQuad(grid, {i00, i01, i11, i10}, limits.cosMinQuad, limits.cosMinTriangle);
                const std::uint8_t lower = top[c] | bottom[c] | bottom[c + 1],
                                   upper = top[c] | bottom[c + 1] | top[c + 1];
                for (const auto& [t, corners] :
                     {std::pair{Triangle{i00, i10, i11}, lower}, std::pair{Triangle{i00, i11, i01}, upper}}) {
                    const CGAL::Orientation o = screenOrientation(grid, t);
                    out.rightTurns += (o == CGAL::RIGHT_TURN);
                    out.leftTurns += (o == CGAL::LEFT_TURN);
                    // [0]: the verdicts if the grid is not mirrored, [1]: if it is.
                    if (o == CGAL::RIGHT_TURN) {
                        const Verdict v =
                            sliver ? Verdict::SliverQuad : judge(grid, corners, t, viewer, limits);
                        ++out.verdicts[0][std::size_t(v)];
                        ++out.verdicts[1][std::size_t(Verdict::Flipped)];
                        if (v == Verdict::Keep)
                            out.candidates.push_back(t), out.keptIf.push_back(kKeptIfNotMirrored);
                    } else if (o == CGAL::LEFT_TURN) {
                        const Verdict v =
                            sliver ? Verdict::SliverQuad
                                   : judge(grid, corners, Triangle{t[0], t[2], t[1]}, viewer, limits);
                        ++out.verdicts[0][std::size_t(Verdict::Flipped)];
                        ++out.verdicts[1][std::size_t(v)];
                        if (v == Verdict::Keep)
                            out.candidates.push_back(t), out.keptIf.push_back(kKeptIfMirrored);
                    } else {
                        ++out.verdicts[0][std::size_t(Verdict::Flipped)];
                        ++out.verdicts[1][std::size_t(Verdict::Flipped)];
                    }
                }
            }
        }
    });
    std::size_t rightTurns = 0, leftTurns = 0;
    for (const Block& b : block) {
        report.quads += b.quads;
        rightTurns += b.rightTurns;
        leftTurns += b.leftTurns;
    }
    mirrored = leftTurns > rightTurns;
    const std::uint8_t kept = mirrored ? kKeptIfMirrored : kKeptIfNotMirrored;
    std::vector<Triangle>& triangles = w.triangles;
    triangles.clear();
    {
        std::size_t total = 0;
        for (const Block& b : block)
            total += b.candidates.size();
        triangles.reserve(total);
        for (Block& b : block) {
            for (std::size_t k = 0; k < b.candidates.size(); ++k) {
                if (b.keptIf[k] != kept) continue;
                Triangle t = b.candidates[k];
                if (mirrored) std::swap(t[1], t[2]);
                triangles.push_back(t);
            }
            b.candidates.clear();
            b.keptIf.clear();
        }
    }
    for (const Block& b : block) {
        const auto& v = b.verdicts[mirrored ? 1 : 0];
        report.flipped += v[std::size_t(Verdict::Flipped)];
        report.backFacing += v[std::size_t(Verdict::BackFacing)];
        report.longEdges += v[std::size_t(Verdict::LongEdge)];
        report.grazing += v[std::size_t(Verdict::Grazing)];
        report.sliverQuads += v[std::size_t(Verdict::SliverQuad)];
    }

    return triangles;
}

/// Triangulation stage 2: the patch's halfedge structure built directly from \p triangles (grid sample
/// indices), with its points, grid indices, face qualities and scan ids.
void buildPatchMesh(const SampleGrid& grid, const std::vector<Triangle>& triangles, ScanWorkspace::Impl& w,
                    Patch& patch) {
    const std::size_t sampleCount = grid.samples.size();
    const std::vector<float>& sampleQuality = w.sampleQuality;
    // The halfedge structure directly (Surface_mesh::add_face searches each new edge around its vertex,
    // and add_vertex / add_edge / add_face grow every property array one element at a time). Pass 1
    // numbers vertices in order of first use and edges in order of first use by the faces — the numbering
    // Euler-style add_face would give — so the mesh can be sized once; pass 2 fills it. Every triangle
    // edge joins two grid neighbours, so an edge is found in O(1) at slot 3·(patch vertex of its smaller
    // sample) + (horizontal, vertical or diagonal).
    auto fail = [](std::uint32_t sample) {
        return Error("Internal error: the grid triangulation produced a non-manifold patch at sample " +
                     std::to_string(sample) + ".");
    };
    constexpr std::uint32_t kNone = std::uint32_t(-1);
    std::vector<std::uint32_t>& vertexOf = w.vertexOf; // patch vertex of each sample
    vertexOf.assign(sampleCount, kNone);
    std::vector<std::uint32_t>& sampleOf = w.sampleOf; // sample of each patch vertex
    sampleOf.clear();
    std::size_t faceCount = 0;
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        ++faceCount;
        for (std::uint32_t i : triangles[k]) {
            if (vertexOf[i] != kNone) continue;
            vertexOf[i] = std::uint32_t(sampleOf.size());
            sampleOf.push_back(i);
        }
    }
    const auto cols = std::uint32_t(grid.cols);
    std::vector<std::uint32_t>& edgeSlot = w.edgeSlot; // edge index per slot
    edgeSlot.assign(3 * sampleOf.size(), kNone);
    auto slotOf = [&](std::uint32_t i, std::uint32_t j) -> std::uint32_t& {
        const std::uint32_t lo = std::min(i, j), d = std::max(i, j) - lo;
        const std::size_t type = d == 1 ? 0 : d == cols ? 1 : d == cols + 1 ? 2 : 3;
        if (type == 3) throw fail(lo); // not grid neighbours: cannot happen for grid triangles
        return edgeSlot[3 * std::size_t(vertexOf[lo]) + type];
    };
    std::uint32_t edgeCount = 0;
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        const Triangle& t = triangles[k];
        for (std::size_t j = 0; j < 3; ++j) {
            std::uint32_t& slot = slotOf(t[j], t[(j + 1) % 3]);
            if (slot == kNone) slot = edgeCount++;
        }
    }

    Mesh& mesh = patch.mesh;
    // A recycled mesh (one with exactly our properties and nothing removed, ScanWorkspace::recycle) is
    // resized without being emptied first: its arrays keep their memory and their old values, and every
    // value of every element is written below — points, grid indices, vertex, halfedge (target, face,
    // next, prev) and face connectivity, face qualities and scan ids — while its removed flags are all
    // false already. Emptying it first would make resize write every array once more (as much as filling
    // it). Any other mesh is replaced by a new one.
    if (!hasPatchPropertiesOnly(mesh)) mesh = Mesh();
    mesh.resize(Mesh::size_type(sampleOf.size()), Mesh::size_type(edgeCount), Mesh::size_type(faceCount));
    auto gridIndex = mesh.add_property_map<VertexIndex, GridIndex>(props::vertexGridIndex, GridIndex{}).first;
    auto quality = mesh.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality).first;
    auto scanId = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    // The vertices' points, grid indices and vertexOfSample (task 1) and the connectivity and face
    // properties (task 0) write different arrays: two threads fill them at once where there are two.
    auto fillVertices = [&] {
        patch.vertexOfSample.assign(grid.samples.size(), Mesh::null_vertex());
        for (std::uint32_t v = 0; v < sampleOf.size(); ++v) {
            const std::uint32_t i = sampleOf[v];
            const Eigen::Vector3d& p = grid.samples[i].point;
            const VertexIndex vi(v);
            mesh.point(vi) = Point3(p.x(), p.y(), p.z());
            gridIndex[vi] = {std::int32_t(i / std::size_t(grid.cols)),
                             std::int32_t(i % std::size_t(grid.cols))};
            patch.vertexOfSample[i] = vi;
        }
    };
    // An edge's first halfedge (2e) runs the way the first face that used it traverses it; the second
    // face finds it already made and takes the opposite halfedge, which must run the other way round.
    // edgeMade counts the faces of each edge: the opposite halfedge of an edge with one is a border.
    std::vector<std::uint8_t>& edgeMade = w.edgeMade;
    edgeMade.assign(edgeCount, 0);
    auto fillFaces = [&] {
        std::uint32_t faceIndex = 0;
        for (std::size_t k = 0; k < triangles.size(); ++k) {
            const Triangle& t = triangles[k];
            const FaceIndex f(faceIndex++);
            std::array<HalfedgeIndex, 3> h;
            for (std::size_t j = 0; j < 3; ++j) {
                const std::uint32_t from = t[j], to = t[(j + 1) % 3];
                const std::uint32_t e = slotOf(from, to);
                const HalfedgeIndex first(2 * e);
                const VertexIndex toVertex(vertexOf[to]);
                if (!edgeMade[e]) {
                    edgeMade[e] = 1;
                    mesh.set_target(first, toVertex);
                    mesh.set_target(mesh.opposite(first), VertexIndex(vertexOf[from]));
                    mesh.set_face(mesh.opposite(first), Mesh::null_face()); // until a second face takes it
                    h[j] = first;
                } else {
                    h[j] = mesh.opposite(first); // the other face's halfedge runs to → from
                    if (mesh.target(h[j]) != toVertex || mesh.face(h[j]) != Mesh::null_face())
                        throw fail(from);
                    edgeMade[e] = 2;
                }
            }
            mesh.set_halfedge(f, h[0]);
            for (std::size_t j = 0; j < 3; ++j) {
                mesh.set_face(h[j], f);
                mesh.set_next(h[j], h[(j + 1) % 3]);
                mesh.set_halfedge(mesh.target(h[j]), h[j]);
            }
            quality[f] = triangleQuality(sampleQuality[t[0]], sampleQuality[t[1]], sampleQuality[t[2]]);
            scanId[f] = grid.scanId;
        }
    };
    detail::parallelRows(2, std::min(scanThreads(), 2), [&](int, int taskBegin, int taskEnd) {
        for (int task = taskBegin; task < taskEnd; ++task)
            task == 0 ? fillFaces() : fillVertices();
    });
    // Border halfedges follow each other around the patch's boundary; a border vertex points to its
    // incoming one. Vertex-manifold: at most one border halfedge leaves each vertex.
    std::vector<HalfedgeIndex>& borderFrom = w.borderFrom;
    borderFrom.assign(sampleOf.size(), HalfedgeIndex());
    std::vector<HalfedgeIndex>& borders = w.borders;
    borders.clear();
    for (const std::uint32_t e : edgeSlot) {
        if (e == kNone || edgeMade[e] != 1) continue; // the first halfedge (2e) has its face
        const HalfedgeIndex b = mesh.opposite(HalfedgeIndex(2 * e));
        HalfedgeIndex& out = borderFrom[mesh.source(b).idx()];
        if (out != HalfedgeIndex()) throw fail(sampleOf[mesh.source(b).idx()]);
        out = b;
        borders.push_back(b);
    }
    for (const HalfedgeIndex b : borders) {
        const VertexIndex end = mesh.target(b);
        if (borderFrom[end.idx()] == HalfedgeIndex()) throw fail(sampleOf[end.idx()]);
        mesh.set_next(b, borderFrom[end.idx()]);
        mesh.set_halfedge(end, b);
    }
}

} // namespace

Patch triangulateGrid(const SampleGrid& grid, const TriangulateOptions& options) {
    ScanWorkspace workspace;
    return triangulateGrid(grid, options, workspace);
}

Patch triangulateGrid(const SampleGrid& grid, const TriangulateOptions& options, ScanWorkspace& workspace) {
    if (grid.rows < 0 || grid.cols < 0 ||
        grid.samples.size() != std::size_t(grid.rows) * std::size_t(grid.cols))
        throw InvalidInputError("The sample grid holds " + std::to_string(grid.samples.size()) +
                                " samples instead of its " + std::to_string(grid.rows) + "x" +
                                std::to_string(grid.cols) + ".");
    options.validate();

    ScanWorkspace::Impl& w = workspace.impl();
    Patch patch;
    if (w.hasPatch) { // a recycled patch: its arrays are refilled below, every value written
        patch = std::move(w.patch);
        w.patch = Patch();
        w.hasPatch = false;
        patch.report = {};
    }
    patch.rows = grid.rows;
    patch.cols = grid.cols;
    patch.scanId = grid.scanId;
    TriangulateReport& report = patch.report;

    bool mirrored = false;
    std::vector<Triangle>& triangles = judgeQuadTriangles(grid, options, w, report, mirrored);

    report.nonManifoldVertices =
        makeVerticesManifold(triangles, grid.rows, grid.cols, mirrored, report.nonManifoldTriangles, w);

    report.smallParts = dropSmallComponents(triangles, grid.samples.size(), options.minComponentFaces);

    buildPatchMesh(grid, triangles, w, patch);
    const Mesh& mesh = patch.mesh;
    report.faces = mesh.number_of_faces();
    report.vertices = mesh.number_of_vertices();
    return patch;
}

} // namespace fss
