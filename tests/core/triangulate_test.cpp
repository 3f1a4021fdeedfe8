// Grid triangulation: exact counts and valences on full grids, each rejection rule on hand-made grids
// with known answers, non-manifold fixing, and real scans of CGAL's fandisk and bunny (valid patch,
// valence 6 inside, no edge across a silhouette, Hausdorff distance to the reference, lasso subsets).
#include "fss/error.h"
#include "fss/mask.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/shapes.h"
#include "fss/triangulate.h"

#include "test_data.h"

#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

using fss::Camera;
using fss::Mesh;
using fss::Patch;
using fss::SampleGrid;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Vector3d toEigen(const fss::Point3& p) {
    return {p.x(), p.y(), p.z()};
}

// A frontal parallel camera looking down −z at the plane z = 0, `cols` × `rows` pixels, 0.1 per pixel.
Camera frontal(int cols, int rows) {
    Camera cam;
    cam.parallel = true;
    cam.eye = {0, 0, 10};
    cam.focal = {0, 0, 0};
    cam.up = {0, 1, 0};
    cam.width = cols;
    cam.height = rows;
    cam.parallelScale = 0.05 * rows;
    cam.nearPlane = 1;
    cam.farPlane = 100;
    return cam;
}

// Hand-made grid on the plane z = 0 (or at depth `depthOf(r, c)` below it), every sample valid where
// `pattern(r, c)` holds; samples sit on their pixel centres.
template <class Pattern> SampleGrid handMadeGrid(int rows, int cols, Pattern pattern) {
    SampleGrid g(rows, cols);
    g.camera = frontal(cols, rows);
    g.scanId = 3;
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            fss::Sample& s = g.at(r, c);
            s.screen = {c + 0.5, r + 0.5};
            const Eigen::Vector3d onPlane = g.camera.unproject(c + 0.5, r + 0.5, 0.5);
            s.point = {onPlane.x(), onPlane.y(), 0.0};
            s.normal = {0, 0, 1};
            s.footprint = float(g.camera.pixelFootprint(s.point));
            s.samplingAngle = 0;
            s.quality = s.footprint;
            s.hit = true;
            s.admissible = s.valid = pattern(r, c);
        }
    }
    return g;
}

SampleGrid fullGrid(int rows, int cols) {
    return handMadeGrid(rows, cols, [](int, int) { return true; });
}

// Every vertex has a single fan: the halfedges around it (circulator) are all the halfedges into it.
std::size_t nonManifoldVertices(const Mesh& m) {
    std::map<std::size_t, std::size_t> incoming;
    for (auto h : m.halfedges())
        ++incoming[std::size_t(m.target(h).idx())];
    std::size_t bad = 0;
    for (auto v : m.vertices()) {
        std::size_t around = 0, borders = 0;
        for (auto h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
            ++around;
            borders += m.is_border(h);
        }
        if (around != incoming[std::size_t(v.idx())] || borders > 1) ++bad;
    }
    return bad;
}

struct Valences {
    std::size_t interior = 0, six = 0;
};

Valences interiorValences(const Mesh& m) {
    Valences v;
    for (auto x : m.vertices()) {
        if (m.is_border(x)) continue;
        ++v.interior;
        v.six += (m.degree(x) == 6);
    }
    return v;
}

// Every face is counter-clockwise as seen by the camera (its normal points towards the viewer).
std::size_t facesAwayFromCamera(const Patch& p, const Camera& cam) {
    std::size_t away = 0;
    for (auto f : p.mesh.faces()) {
        auto h = p.mesh.halfedge(f);
        const Eigen::Vector3d a = toEigen(p.mesh.point(p.mesh.source(h))),
                              b = toEigen(p.mesh.point(p.mesh.target(h))),
                              c = toEigen(p.mesh.point(p.mesh.target(p.mesh.next(h))));
        const Eigen::Vector3d toViewer =
            cam.parallel ? Eigen::Vector3d(-cam.viewDirection()) : Eigen::Vector3d(cam.eye - a);
        away += !((b - a).cross(c - a).dot(toViewer) > 0);
    }
    return away;
}

} // namespace

TEST(Triangulate, FullGridGivesValenceSix) {
    for (auto [rows, cols] : {std::pair{2, 2}, std::pair{7, 5}, std::pair{24, 31}}) {
        const SampleGrid g = fullGrid(rows, cols);
        const Patch p = fss::triangulateGrid(g);
        EXPECT_EQ(p.mesh.number_of_faces(), std::size_t(2 * (rows - 1) * (cols - 1)));
        EXPECT_EQ(p.mesh.number_of_vertices(), std::size_t(rows * cols));
        EXPECT_EQ(p.report.quads, std::size_t((rows - 1) * (cols - 1)));
        EXPECT_EQ(p.report.faces, p.mesh.number_of_faces());
        EXPECT_TRUE(CGAL::is_valid_polygon_mesh(p.mesh));
        const Valences v = interiorValences(p.mesh);
        EXPECT_EQ(v.interior, std::size_t((rows - 2) * (cols - 2)));
        EXPECT_EQ(v.six, v.interior);
        EXPECT_EQ(facesAwayFromCamera(p, g.camera), 0u);
        // Properties: grid index per vertex, quality and scan id per face.
        auto gi = p.mesh.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex);
        auto q = p.mesh.property_map<fss::FaceIndex, float>(fss::props::faceQuality);
        auto id = p.mesh.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
        ASSERT_TRUE(gi.second && q.second && id.second);
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) {
                const auto vx = p.vertexAt(r, c);
                ASSERT_NE(vx, Mesh::null_vertex());
                EXPECT_EQ(gi.first[vx], (fss::GridIndex{r, c}));
                EXPECT_EQ(toEigen(p.mesh.point(vx)), g.at(r, c).point);
            }
        for (auto f : p.mesh.faces()) {
            EXPECT_FLOAT_EQ(q.first[f], 0.1f);
            EXPECT_EQ(id.first[f], 3);
        }
    }
}

TEST(Triangulate, CornerTouchingQuadsAreMadeManifold) {
    // Two quads, (0,0) and (1,1), touching at sample (1,1) along the split diagonal: both triangles of
    // each quad meet there, two fans of two; the later quad is removed.
    {
        const Patch p = fss::triangulateGrid(
            handMadeGrid(3, 3, [](int r, int c) { return !(r == 0 && c == 2) && !(r == 2 && c == 0); }));
        EXPECT_EQ(p.report.quads, 2u);
        EXPECT_EQ(p.report.nonManifoldVertices, 1u);
        EXPECT_EQ(p.report.nonManifoldTriangles, 2u);
        EXPECT_EQ(p.mesh.number_of_faces(), 2u);
        EXPECT_NE(p.vertexAt(0, 0), Mesh::null_vertex());
        EXPECT_EQ(p.vertexAt(2, 2), Mesh::null_vertex());
        EXPECT_EQ(nonManifoldVertices(p.mesh), 0u);
        EXPECT_TRUE(CGAL::is_valid_polygon_mesh(p.mesh));
    }
    // Quads (0,1) and (1,0) touch at (1,1) across the other diagonal: only one triangle of each contains
    // it, two fans of one; one triangle goes.
    {
        const Patch p = fss::triangulateGrid(
            handMadeGrid(3, 3, [](int r, int c) { return !(r == 0 && c == 0) && !(r == 2 && c == 2); }));
        EXPECT_EQ(p.report.quads, 2u);
        EXPECT_EQ(p.report.nonManifoldVertices, 1u);
        EXPECT_EQ(p.report.nonManifoldTriangles, 1u);
        EXPECT_EQ(p.mesh.number_of_faces(), 3u);
        EXPECT_EQ(nonManifoldVertices(p.mesh), 0u);
        EXPECT_TRUE(CGAL::is_valid_polygon_mesh(p.mesh));
    }
    // A random 70 % pattern is full of pinched corners: the result is manifold and valid, and every
    // candidate triangle is either a face or counted as removed.
    {
        std::mt19937 rng(11);
        std::vector<bool> on(40 * 40);
        for (std::size_t i = 0; i < on.size(); ++i)
            on[i] = rng() % 10 < 7;
        const Patch p =
            fss::triangulateGrid(handMadeGrid(40, 40, [&](int r, int c) { return bool(on[r * 40 + c]); }));
        EXPECT_GT(p.report.nonManifoldVertices, 10u);
        EXPECT_EQ(nonManifoldVertices(p.mesh), 0u);
        EXPECT_TRUE(CGAL::is_valid_polygon_mesh(p.mesh));
        EXPECT_EQ(p.report.faces + p.report.nonManifoldTriangles, 2 * p.report.quads);
    }
}

TEST(Triangulate, DepthStepIsCut) {
    // Columns 0–4 at z = 0, columns 5–9 at z = −10 footprints: the quads between columns 4 and 5 span the
    // step, both of their triangles go (2 per row of quads); everything else stays.
    SampleGrid g = fullGrid(6, 10);
    for (int r = 0; r < 6; ++r)
        for (int c = 5; c < 10; ++c)
            g.at(r, c).point.z() = -10 * 0.1;
    const Patch p = fss::triangulateGrid(g);
    EXPECT_EQ(p.report.longEdges, 2u * 5u);
    EXPECT_EQ(p.mesh.number_of_faces(), 2u * 5u * 8u);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(p.mesh));
    // A step of 2 footprints: the crossing edges span √5 ≈ 2.24 and √6 ≈ 2.45 footprints, within the
    // default limit of 3; a limit of 2 cuts them again.
    for (int r = 0; r < 6; ++r)
        for (int c = 5; c < 10; ++c)
            g.at(r, c).point.z() = -2 * 0.1;
    EXPECT_EQ(fss::triangulateGrid(g).report.longEdges, 0u);
    EXPECT_EQ(fss::triangulateGrid(g, {.maxEdgeFootprints = 2.0}).report.longEdges, 2u * 5u);
}

TEST(Triangulate, GrazingFlippedAndBackFacingTrianglesGo) {
    {
        // One sample seen at 85°: its 6 triangles go (corner test), nothing else.
        SampleGrid g = fullGrid(5, 5);
        g.at(2, 2).samplingAngle = float(85 * kDeg);
        const Patch p = fss::triangulateGrid(g);
        EXPECT_EQ(p.report.grazing, 6u);
        EXPECT_EQ(p.mesh.number_of_faces(), 32u - 6u);
        EXPECT_EQ(fss::triangulateGrid(g, {.maxSamplingAngleDeg = 86}).report.grazing, 0u);
    }
    {
        // 2×3 samples; sample (0,1) moved on the screen to the right of (0,2): exactly one triangle,
        // (0,1)–(1,2)–(0,2), turns clockwise on the screen (hand-computed).
        SampleGrid g = fullGrid(2, 3);
        g.at(0, 1).screen = {3.5, 0.5};
        g.at(0, 1).point = g.camera.unproject(3.5, 0.5, 0.5);
        g.at(0, 1).point.z() = 0;
        const Patch p = fss::triangulateGrid(g, {.maxEdgeFootprints = 10});
        EXPECT_EQ(p.report.flipped, 1u);
        EXPECT_EQ(p.mesh.number_of_faces(), 3u);
    }
    {
        // A mirrored grid (columns run right to left, as a fishbone grid may): nothing is flipped, the
        // vertex order is reversed so that every face still faces the camera.
        SampleGrid g = fullGrid(4, 6);
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 6; ++c) {
                g.at(r, c).screen = {5.5 - c, r + 0.5};
                g.at(r, c).point = g.camera.unproject(5.5 - c, r + 0.5, 0.5);
                g.at(r, c).point.z() = 0;
            }
        const Patch p = fss::triangulateGrid(g);
        EXPECT_EQ(p.report.flipped, 0u);
        EXPECT_EQ(p.mesh.number_of_faces(), 30u);
        EXPECT_EQ(facesAwayFromCamera(p, g.camera), 0u);
    }
    {
        // Reference normals facing away from the viewer in one row of samples: the triangles touching it go.
        SampleGrid g = fullGrid(5, 5);
        for (int c = 0; c < 5; ++c)
            g.at(4, c).normal = {0, 0, -1};
        const Patch p = fss::triangulateGrid(g);
        EXPECT_EQ(p.report.backFacing, 8u);
        EXPECT_EQ(p.mesh.number_of_faces(), 24u);
    }
    EXPECT_THROW(fss::triangulateGrid(fullGrid(3, 3), {.maxEdgeFootprints = 0}), fss::InvalidInputError);
    EXPECT_THROW(fss::triangulateGrid(fullGrid(3, 3), {.maxSamplingAngleDeg = 95}), fss::InvalidInputError);
    SampleGrid broken = fullGrid(3, 3);
    broken.samples.pop_back();
    EXPECT_THROW(fss::triangulateGrid(broken), fss::InvalidInputError);
}

namespace {

struct RealScan {
    Mesh reference;
    Camera camera;
    SampleGrid grid; // after morphology
    Patch patch;
    double rasterSeconds = 0;
};

RealScan scanMesh(const std::string& name) {
    RealScan s;
    if (!CGAL::IO::read_polygon_mesh(fss::test::meshPath(name).string(), s.reference))
        throw std::runtime_error("cannot read " + name);
    Eigen::AlignedBox3d box;
    for (auto v : s.reference.vertices())
        box.extend(toEigen(s.reference.point(v)));
    s.camera = Camera::standardView(fss::StandardView::Iso, box, 256, 256);
    const fss::RayCaster caster(s.reference);
    const auto t0 = std::chrono::steady_clock::now();
    const fss::FrameBuffers fb = fss::rasterizeOnCpu(caster, s.camera);
    s.rasterSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    s.grid = fss::sampleRegularGrid(fb, s.reference, {.scanId = 1});
    fss::applyMorphology(s.grid);
    s.patch = fss::triangulateGrid(s.grid);
    return s;
}

void checkRealPatch(const RealScan& s, const std::string& name) {
    const Mesh& m = s.patch.mesh;
    const auto& r = s.patch.report;
    std::printf("%s: raster %.3f s, %zu valid samples, %zu quads -> %zu faces; dropped: %zu long edges, %zu "
                "grazing, %zu flipped, %zu back-facing, %zu non-manifold (%zu vertices)\n",
                name.c_str(), s.rasterSeconds, s.grid.validCount(), r.quads, r.faces, r.longEdges, r.grazing,
                r.flipped, r.backFacing, r.nonManifoldTriangles, r.nonManifoldVertices);
    ASSERT_GT(m.number_of_faces(), 10000u);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_EQ(nonManifoldVertices(m), 0u);
    EXPECT_EQ(facesAwayFromCamera(s.patch, s.camera), 0u);
    const Valences v = interiorValences(m);
    EXPECT_GE(double(v.six), 0.98 * double(v.interior));
    EXPECT_EQ(v.six, v.interior); // a grid patch: an interior vertex has all six triangles
    // No edge longer than 3 pixel footprints (footprints recomputed from the camera).
    double worstEdge = 0;
    for (auto e : m.edges()) {
        const Eigen::Vector3d a = toEigen(m.point(m.vertex(e, 0))), b = toEigen(m.point(m.vertex(e, 1)));
        worstEdge = std::max(worstEdge, (a - b).norm() /
                                            std::min(s.camera.pixelFootprint(a), s.camera.pixelFootprint(b)));
    }
    EXPECT_LE(worstEdge, 3.0 * (1 + 1e-6));
    // Hausdorff distance patch → reference over the vertices and face centroids.
    const fss::RayCaster caster(s.reference);
    Eigen::AlignedBox3d box;
    for (auto x : s.reference.vertices())
        box.extend(toEigen(s.reference.point(x)));
    const double diagonal = box.diagonal().norm();
    double hausdorff = 0;
    for (auto x : m.vertices())
        hausdorff = std::max(hausdorff, caster.closestPoint(toEigen(m.point(x))).distance);
    const double vertexHausdorff = hausdorff;
    for (auto f : m.faces()) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (auto x : CGAL::vertices_around_face(m.halfedge(f), m))
            c += toEigen(m.point(x));
        hausdorff = std::max(hausdorff, caster.closestPoint(c / 3.0).distance);
    }
    std::printf("%s: worst edge %.3f footprints, Hausdorff %.3g %% of the diagonal (vertices %.3g %%)\n",
                name.c_str(), worstEdge, 100 * hausdorff / diagonal, 100 * vertexHausdorff / diagonal);
    EXPECT_LE(vertexHausdorff, 1e-9 * diagonal); // samples lie on the reference
    EXPECT_LE(hausdorff, 0.0025 * diagonal);
}

} // namespace

// A quad whose 3D corner angle falls below minQuadAngleDeg loses both triangles (issue #20): a full grid
// sheared on the screen and on the plane (sample (r, c) at x = c + t·r) has parallelogram quads with the
// corner angles atan(1/t) and 180° minus it.
TEST(Triangulate, SliverQuadsAreDropped) {
    constexpr double t = 5.0;
    SampleGrid g = handMadeGrid(6, 40, [](int, int) { return true; });
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
            fss::Sample& s = g.at(r, c);
            s.screen.x() = c + 0.5 + t * r - 12;
            const Eigen::Vector3d onPlane = g.camera.unproject(s.screen.x(), s.screen.y(), 0.5);
            s.point = {onPlane.x(), onPlane.y(), 0.0};
        }
    const double angle = std::atan2(1.0, t) / kDeg; // 11.3°
    const std::size_t quads = 5 * 39;
    for (double bound : {0.0, angle - 0.5, angle + 0.5}) {
        SCOPED_TRACE(bound);
        const Patch p = fss::triangulateGrid(g, {.maxEdgeFootprints = 10, .minQuadAngleDeg = bound});
        EXPECT_EQ(p.report.quads, quads);
        EXPECT_EQ(p.report.sliverQuads, bound > angle ? 2 * quads : 0u);
        EXPECT_EQ(p.mesh.number_of_faces(), bound > angle ? 0u : 2 * quads);
    }
    EXPECT_THROW(fss::triangulateGrid(g, {.minQuadAngleDeg = 90}), fss::InvalidOptionError);
}

// A quad with right corners but a thin triangle loses both triangles under minTriangleAngleDeg (issue #20),
// not under minQuadAngleDeg: a full grid stretched along x by a = 3 on the plane and on the screen has
// rectangles whose triangles have the smallest angle atan(1/3) = 18.43°.
TEST(Triangulate, QuadsWithThinTrianglesAreDropped) {
    constexpr double a = 3.0;
    SampleGrid g = handMadeGrid(6, 40, [](int, int) { return true; });
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
            fss::Sample& s = g.at(r, c);
            s.screen.x() = a * c + 0.5;
            const Eigen::Vector3d onPlane = g.camera.unproject(s.screen.x(), s.screen.y(), 0.5);
            s.point = {onPlane.x(), onPlane.y(), 0.0};
        }
    const double angle = std::atan2(1.0, a) / kDeg;
    const std::size_t quads = 5 * 39;
    for (double bound : {0.0, angle - 0.5, angle + 0.5}) {
        SCOPED_TRACE(bound);
        const Patch p = fss::triangulateGrid(g, {.maxEdgeFootprints = 10, .minTriangleAngleDeg = bound});
        EXPECT_EQ(p.report.quads, quads);
        EXPECT_EQ(p.report.sliverQuads, bound > angle ? 2 * quads : 0u);
        EXPECT_EQ(p.mesh.number_of_faces(), bound > angle ? 0u : 2 * quads);
    }
    // The corner bound alone keeps them all (every corner is 90°).
    EXPECT_EQ(
        fss::triangulateGrid(g, {.maxEdgeFootprints = 10, .minQuadAngleDeg = 45}).mesh.number_of_faces(),
        2 * quads);
    EXPECT_THROW(fss::triangulateGrid(g, {.minTriangleAngleDeg = 60}), fss::InvalidOptionError);
}

// minComponentFaces drops the connected parts with fewer faces: a 6 × 15 grid without columns 10 and 11
// has a part of 9 × 5 quads (90 triangles) and one of 2 × 5 quads (20 triangles).
TEST(Triangulate, SmallPartsAreDropped) {
    const SampleGrid g = handMadeGrid(6, 15, [](int, int c) { return c != 10 && c != 11; });
    for (const int bound : {0, 20, 21, 91}) {
        SCOPED_TRACE(bound);
        const Patch p = fss::triangulateGrid(g, {.minComponentFaces = bound});
        const std::size_t dropped = bound > 90 ? 110 : bound > 20 ? 20 : 0;
        EXPECT_EQ(p.report.smallParts, dropped);
        EXPECT_EQ(p.mesh.number_of_faces(), 110 - dropped);
    }
    EXPECT_THROW(fss::triangulateGrid(g, {.minComponentFaces = -1}), fss::InvalidOptionError);
}

TEST(Triangulate, IsoScanOfFandisk) {
    const RealScan s = scanMesh("fandisk.off");
    checkRealPatch(s, "fandisk");
}

TEST(Triangulate, IsoScanOfBunnyWithLasso) {
    const RealScan s = scanMesh("bunny00.off");
    checkRealPatch(s, "bunny00");

    // A lasso (a concave arrow-like polygon across the middle) gives a strict subset of the full patch.
    const fss::FrameBuffers fb = fss::rasterizeOnCpu(s.reference, s.camera);
    SampleGrid lassoed = fss::sampleRegularGrid(fb, s.reference, {.scanId = 1});
    const fss::Lasso lasso{{{60, 60}, {200, 80}, {130, 128}, {210, 190}, {70, 200}}};
    EXPECT_GT(fss::applyLasso(lassoed, lasso), 0u);
    fss::applyMorphology(lassoed);
    const Patch sub = fss::triangulateGrid(lassoed);
    EXPECT_GT(sub.mesh.number_of_faces(), 1000u);
    EXPECT_LT(sub.mesh.number_of_faces(), s.patch.mesh.number_of_faces());
    auto gi = sub.mesh.property_map<fss::VertexIndex, fss::GridIndex>(fss::props::vertexGridIndex).first;
    for (auto v : sub.mesh.vertices()) {
        const fss::GridIndex g = gi[v];
        const auto full = s.patch.vertexAt(g.row, g.col);
        ASSERT_NE(full, Mesh::null_vertex());
        EXPECT_EQ(sub.mesh.point(v), s.patch.mesh.point(full));
        EXPECT_TRUE(fss::insideLasso(lasso, s.grid.at(g.row, g.col).screen));
    }
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(sub.mesh));
    EXPECT_EQ(nonManifoldVertices(sub.mesh), 0u);
}
