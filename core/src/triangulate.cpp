#include "fss/triangulate.h"

#include "fss/error.h"
#include "fss/scan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace fss {
namespace {

using Point2 = Kernel::Point_2;
using Triangle = std::array<std::uint32_t, 3>; // sample indices, counter-clockwise as seen by the camera

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

enum class Verdict { Keep, Flipped, BackFacing, LongEdge, Grazing };

struct JudgeLimits {
    double maxEdgeFootprints;
    double maxAngle;    // radians
    double cosMaxAngle; // cos(maxAngle)
};

Verdict judge(const SampleGrid& grid, const Triangle& t, CGAL::Orientation gridOrientation, const Viewer& viewer,
              const JudgeLimits& limits) {
    if (screenOrientation(grid, t) != gridOrientation) return Verdict::Flipped;
    const Sample& a = grid.samples[t[0]];
    const Sample& b = grid.samples[t[1]];
    const Sample& c = grid.samples[t[2]];
    const Eigen::Vector3d centroid = (a.point + b.point + c.point) / 3.0;
    const Eigen::Vector3d toViewer = viewer.towards(centroid);
    const Eigen::Vector3d normal = (b.point - a.point).cross(c.point - a.point);
    if (!(normal.dot(toViewer) > 0)) return Verdict::BackFacing;
    for (const Sample* s : {&a, &b, &c})
        if (s->normal.squaredNorm() > 0 && !(s->normal.dot(viewer.towards(s->point)) > 0))
            return Verdict::BackFacing;
    for (auto [u, v] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}}) {
        const double limit = limits.maxEdgeFootprints * std::min(double(u->footprint), double(v->footprint));
        // Squared lengths: no square root in the innermost test.
        if (!(limit >= 0 && (u->point - v->point).squaredNorm() <= limit * limit)) return Verdict::LongEdge;
    }
    for (const Sample* s : {&a, &b, &c})
        if (double(s->samplingAngle) > limits.maxAngle) return Verdict::Grazing;
    if (normal.normalized().dot(toViewer.normalized()) < limits.cosMaxAngle) return Verdict::Grazing;
    return Verdict::Keep;
}

// Removes triangles until every vertex has a single fan (the largest one is kept; ties keep the fan
// with the lowest triangle index). Returns the number of pinched vertices found.
std::size_t makeVerticesManifold(std::vector<Triangle>& triangles, std::vector<bool>& alive,
                                 std::size_t sampleCount, std::size_t& removedTriangles) {
    // Triangles incident to each sample (compressed rows).
    std::vector<std::uint32_t> offset(sampleCount + 1, 0);
    for (const Triangle& t : triangles)
        for (std::uint32_t v : t)
            ++offset[v + 1];
    for (std::size_t i = 0; i < sampleCount; ++i)
        offset[i + 1] += offset[i];
    std::vector<std::uint32_t> incident(offset.back());
    {
        std::vector<std::uint32_t> fill(offset.begin(), offset.end() - 1);
        for (std::uint32_t ti = 0; ti < triangles.size(); ++ti)
            for (std::uint32_t v : triangles[ti])
                incident[fill[v]++] = ti;
    }
    std::vector<std::uint32_t> work;
    std::vector<bool> queued(sampleCount, false);
    for (std::uint32_t v = 0; v < sampleCount; ++v)
        if (offset[v + 1] - offset[v] > 1) work.push_back(v), queued[v] = true;

    std::size_t pinched = 0;
    std::vector<std::uint32_t> fan, component;
    while (!work.empty()) {
        const std::uint32_t v = work.back();
        work.pop_back();
        queued[v] = false;
        fan.clear();
        for (std::uint32_t k = offset[v]; k < offset[v + 1]; ++k)
            if (alive[incident[k]]) fan.push_back(incident[k]);
        // A grid vertex lies in at most the six grid triangles around it, which form one closed fan:
        // all six alive means manifold (the common interior case, skipped without the search below).
        if (fan.size() < 2 || fan.size() == 6) continue;
        // Connected components of the triangles around v: two are adjacent when they share an edge at v,
        // i.e. a vertex other than v.
        component.assign(fan.size(), std::uint32_t(-1));
        std::uint32_t components = 0;
        for (std::size_t s = 0; s < fan.size(); ++s) {
            if (component[s] != std::uint32_t(-1)) continue;
            component[s] = components;
            for (bool grown = true; grown;) {
                grown = false;
                for (std::size_t i = 0; i < fan.size(); ++i) {
                    if (component[i] != components) continue;
                    for (std::size_t j = 0; j < fan.size(); ++j) {
                        if (component[j] != std::uint32_t(-1)) continue;
                        bool shares = false;
                        for (std::uint32_t x : triangles[fan[i]])
                            if (x != v && std::find(triangles[fan[j]].begin(), triangles[fan[j]].end(), x) !=
                                              triangles[fan[j]].end())
                                shares = true;
                        if (shares) component[j] = components, grown = true;
                    }
                }
            }
            ++components;
        }
        if (components < 2) continue;
        ++pinched;
        std::vector<std::size_t> size(components, 0);
        std::vector<std::uint32_t> lowest(components, std::uint32_t(-1));
        for (std::size_t i = 0; i < fan.size(); ++i) {
            ++size[component[i]];
            lowest[component[i]] = std::min(lowest[component[i]], fan[i]);
        }
        std::uint32_t keep = 0;
        for (std::uint32_t k = 1; k < components; ++k)
            if (size[k] > size[keep] || (size[k] == size[keep] && lowest[k] < lowest[keep])) keep = k;
        for (std::size_t i = 0; i < fan.size(); ++i) {
            if (component[i] == keep) continue;
            alive[fan[i]] = false;
            ++removedTriangles;
            for (std::uint32_t x : triangles[fan[i]])
                if (x != v && !queued[x]) work.push_back(x), queued[x] = true;
        }
    }
    return pinched;
}

} // namespace

Patch triangulateGrid(const SampleGrid& grid, const TriangulateOptions& options) {
    if (grid.rows < 0 || grid.cols < 0 ||
        grid.samples.size() != std::size_t(grid.rows) * std::size_t(grid.cols))
        throw InvalidInputError("The sample grid holds " + std::to_string(grid.samples.size()) +
                                " samples instead of its " + std::to_string(grid.rows) + "x" +
                                std::to_string(grid.cols) + ".");
    if (!(options.maxEdgeFootprints > 0))
        throw InvalidInputError("The triangulation's maximum edge length of " +
                                std::to_string(options.maxEdgeFootprints) + " footprints is not positive.");
    if (!(options.maxSamplingAngleDeg > 0 && options.maxSamplingAngleDeg <= 90))
        throw InvalidInputError("The triangulation's maximum sampling angle of " +
                                std::to_string(options.maxSamplingAngleDeg) +
                                " degrees is outside the range (0, 90].");

    Patch patch;
    patch.rows = grid.rows;
    patch.cols = grid.cols;
    patch.scanId = grid.scanId;
    patch.vertexOfSample.assign(grid.samples.size(), Mesh::null_vertex());
    TriangulateReport& report = patch.report;

    // Candidates: both triangles of every quad with four usable corners, split along (r,c)–(r+1,c+1),
    // in the vertex order that is counter-clockwise on the screen for a regular grid.
    std::vector<Triangle> candidates;
    std::size_t rightTurns = 0, leftTurns = 0;
    for (int r = 0; r + 1 < grid.rows; ++r) {
        for (int c = 0; c + 1 < grid.cols; ++c) {
            const auto i00 = std::uint32_t(grid.index(r, c)), i01 = std::uint32_t(grid.index(r, c + 1)),
                       i10 = std::uint32_t(grid.index(r + 1, c)),
                       i11 = std::uint32_t(grid.index(r + 1, c + 1));
            if (!usable(grid.samples[i00]) || !usable(grid.samples[i01]) || !usable(grid.samples[i10]) ||
                !usable(grid.samples[i11]))
                continue;
            ++report.quads;
            for (const Triangle& t : {Triangle{i00, i10, i11}, Triangle{i00, i11, i01}}) {
                candidates.push_back(t);
                const CGAL::Orientation o = screenOrientation(grid, t);
                rightTurns += (o == CGAL::RIGHT_TURN);
                leftTurns += (o == CGAL::LEFT_TURN);
            }
        }
    }
    // A fishbone grid may be mirrored on the screen: its majority orientation is the grid's, and the
    // vertex order is reversed so that the faces still face the camera.
    const bool mirrored = leftTurns > rightTurns;
    if (mirrored)
        for (Triangle& t : candidates)
            std::swap(t[1], t[2]);

    std::vector<Triangle> triangles;
    triangles.reserve(candidates.size());
    const Viewer viewer(grid.camera);
    const double maxAngle = options.maxSamplingAngleDeg * std::numbers::pi / 180.0;
    const JudgeLimits limits{options.maxEdgeFootprints, maxAngle, std::cos(maxAngle)};
    for (const Triangle& t : candidates) {
        switch (judge(grid, t, CGAL::RIGHT_TURN, viewer, limits)) {
        case Verdict::Keep:
            triangles.push_back(t);
            break;
        case Verdict::Flipped:
            ++report.flipped;
            break;
        case Verdict::BackFacing:
            ++report.backFacing;
            break;
        case Verdict::LongEdge:
            ++report.longEdges;
            break;
        case Verdict::Grazing:
            ++report.grazing;
            break;
        }
    }

    std::vector<bool> alive(triangles.size(), true);
    report.nonManifoldVertices =
        makeVerticesManifold(triangles, alive, grid.samples.size(), report.nonManifoldTriangles);

    Mesh& mesh = patch.mesh;
    {
        std::size_t faces = 0;
        for (bool a : alive)
            faces += a ? 1 : 0;
        // Euler: about two faces per vertex and three edges per face pair in a grid patch.
        mesh.reserve(Mesh::size_type(faces / 2 + 2 * std::size_t(grid.cols + grid.rows) + 4),
                     Mesh::size_type(faces * 3 / 2 + std::size_t(grid.cols + grid.rows) + 4),
                     Mesh::size_type(faces));
    }
    auto gridIndex = mesh.add_property_map<VertexIndex, GridIndex>(props::vertexGridIndex, GridIndex{}).first;
    auto quality = mesh.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality).first;
    auto scanId = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
    // Vertices in order of first use, as Euler-style add_face would create them.
    std::vector<std::uint32_t> sampleOf; // sample of each patch vertex
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        if (!alive[k]) continue;
        for (std::uint32_t i : triangles[k]) {
            VertexIndex& v = patch.vertexOfSample[i];
            if (v != Mesh::null_vertex()) continue;
            const Eigen::Vector3d& p = grid.samples[i].point;
            v = mesh.add_vertex(Point3(p.x(), p.y(), p.z()));
            gridIndex[v] = {std::int32_t(i / std::size_t(grid.cols)), std::int32_t(i % std::size_t(grid.cols))};
            sampleOf.push_back(i);
        }
    }
    // The halfedge structure directly (Surface_mesh::add_face searches each new edge around its vertex):
    // every triangle edge joins two grid neighbours, so an edge is found in O(1) at slot 3·(patch vertex
    // of its smaller sample) + (horizontal, vertical or diagonal).
    auto fail = [](std::uint32_t sample) {
        return Error("Internal error: the grid triangulation produced a non-manifold patch at sample " +
                     std::to_string(sample) + ".");
    };
    const auto cols = std::uint32_t(grid.cols);
    std::vector<HalfedgeIndex> edgeSlot(3 * sampleOf.size());
    auto slotOf = [&](std::uint32_t i, std::uint32_t j) -> HalfedgeIndex& {
        const std::uint32_t lo = std::min(i, j), d = std::max(i, j) - lo;
        const std::size_t type = d == 1 ? 0 : d == cols ? 1 : d == cols + 1 ? 2 : 3;
        if (type == 3) throw fail(lo); // not grid neighbours: cannot happen for grid triangles
        return edgeSlot[3 * std::size_t(patch.vertexOfSample[lo].idx()) + type];
    };
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        if (!alive[k]) continue;
        const Triangle& t = triangles[k];
        const FaceIndex f = mesh.add_face();
        std::array<HalfedgeIndex, 3> h;
        for (std::size_t j = 0; j < 3; ++j) {
            const std::uint32_t from = t[j], to = t[(j + 1) % 3];
            HalfedgeIndex& slot = slotOf(from, to);
            if (slot == HalfedgeIndex()) {
                slot = mesh.add_edge();
                mesh.set_target(slot, patch.vertexOfSample[to]);
                mesh.set_target(mesh.opposite(slot), patch.vertexOfSample[from]);
                h[j] = slot;
            } else {
                h[j] = mesh.opposite(slot); // the other face's halfedge runs to → from
                if (mesh.target(h[j]) != patch.vertexOfSample[to] || mesh.face(h[j]) != Mesh::null_face())
                    throw fail(from);
            }
        }
        mesh.set_halfedge(f, h[0]);
        for (std::size_t j = 0; j < 3; ++j) {
            mesh.set_face(h[j], f);
            mesh.set_next(h[j], h[(j + 1) % 3]);
            mesh.set_halfedge(mesh.target(h[j]), h[j]);
        }
        quality[f] = triangleQuality(grid.samples[t[0]], grid.samples[t[1]], grid.samples[t[2]]);
        scanId[f] = grid.scanId;
    }
    // Border halfedges follow each other around the patch's boundary; a border vertex points to its
    // incoming one. Vertex-manifold: at most one border halfedge leaves each vertex.
    std::vector<HalfedgeIndex> borderFrom(sampleOf.size());
    std::vector<HalfedgeIndex> borders;
    for (const HalfedgeIndex slot : edgeSlot) {
        if (slot == HalfedgeIndex()) continue;
        for (const HalfedgeIndex b : {slot, mesh.opposite(slot)}) {
            if (mesh.face(b) != Mesh::null_face()) continue;
            HalfedgeIndex& out = borderFrom[mesh.source(b).idx()];
            if (out != HalfedgeIndex()) throw fail(sampleOf[mesh.source(b).idx()]);
            out = b;
            borders.push_back(b);
        }
    }
    for (const HalfedgeIndex b : borders) {
        const VertexIndex end = mesh.target(b);
        if (borderFrom[end.idx()] == HalfedgeIndex()) throw fail(sampleOf[end.idx()]);
        mesh.set_next(b, borderFrom[end.idx()]);
        mesh.set_halfedge(end, b);
    }
    report.faces = mesh.number_of_faces();
    report.vertices = mesh.number_of_vertices();
    return patch;
}

} // namespace fss
