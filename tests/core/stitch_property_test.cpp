// Stitching property test (issue #4): on CGAL sample meshes, hundreds of random scans, each scanned from the
// reference, masked against the current mesh and stitched into it (chained). After EVERY stitch the
// invariants of DESIGN.md §5 are checked independently of the stitcher's own checks and of StitchReport:
//  - valid halfedge structure, triangles only, no isolated or non-manifold vertices, no two edges joining
//    the same two vertices (edge-manifold), consistent orientation (a closed mesh keeps a positive volume);
//  - a closed mesh stays closed; the number of boundary loops is unchanged;
//  - no self-intersections: CGAL::Polygon_mesh_processing::does_self_intersect on every face that changed
//    and every face whose bounding box meets one of them (the mesh was free of intersections before, so a
//    new intersecting pair contains a changed face); the whole mesh is checked by does_self_intersect
//    every kFullCheckEvery scans and at the end;
//  - no degenerate faces (exact collinearity test);
//  - faces outside the seam neighbourhood unchanged: every face index live before and after keeps its
//    vertices and their points unless it is "changed"; every changed or removed face of the mesh before the
//    stitch lies within StitchOptions::seamRings vertex rings of a face that touches the patch's footprint
//    (its projection covers a pixel of the patch's sample mask dilated by one pixel, or one of its vertices
//    projects into such a pixel);
//  - Hausdorff distance to the reference within one pixel footprint, both directions, sampled:
//    current → reference at the three corners, the three edge midpoints and the centroid of every face
//    the stitch added; reference → current at the corners and centroid of every reference face within
//    two footprints of the changed region's bounding box. The bound at a point on (or nearest to) a
//    current-mesh face made by scan s is scan s's pixel footprint there (Camera::pixelFootprint); a face
//    still carrying the input's scan id −1 lies on the input surface, bound 1e-9 of the bounding box
//    diagonal. The whole mesh is measured both ways at the end.
// A scan that produces no patch (the view misses the visible surface, every sample is worse than the mesh)
// does not count; a patch that cannot be stitched at all (InvalidInputError) is allowed, counted, must leave
// the mesh bit for bit unchanged, and most patches must stitch. Seeds are fixed and printed on failure.
#include "fss/camera_projector.h"
#include "fss/error.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"
#include "fss/stitch.h"
#include "fss/triangulate.h"

#include "stitch_helpers.h"
#include "stitch_property_diag.h"
#include "stitch_property_setup.h"
#include "test_data.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh/IO/OFF.h>
#include <CGAL/box_intersection_d.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <unordered_map>
#include <unordered_set>

namespace PMP = CGAL::Polygon_mesh_processing;
using fss::Camera;
using fss::FaceIndex;
using fss::HalfedgeIndex;
using fss::Mesh;
using fss::Point3;
using fss::VertexIndex;
using Vec3 = Eigen::Vector3d;

namespace {

constexpr int kFullCheckEvery = 25;

using stitch_property_setup::randomSetup;
using stitch_property_setup::ScanSetup;
using stitch_property_setup::ZBufferRenderer;
using stitch_test_helpers::boundaryLoops;
using stitch_test_helpers::degenerateFaces;
using stitch_test_helpers::nonManifoldVertices;
using stitch_test_helpers::vec;

using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<fss::Kernel, Primitive>>;

// Two edges joining the same pair of vertices (the surface would be non-manifold along that edge).
std::size_t duplicateEdges(const Mesh& m) {
    std::unordered_set<std::uint64_t> seen;
    std::size_t n = 0;
    for (auto e : m.edges()) {
        std::uint32_t a = std::uint32_t(m.vertex(e, 0)), b = std::uint32_t(m.vertex(e, 1));
        if (a > b) std::swap(a, b);
        if (!seen.insert((std::uint64_t(a) << 32) | b).second) ++n;
    }
    return n;
}

std::array<VertexIndex, 3> corners(const Mesh& m, FaceIndex f) {
    const HalfedgeIndex h = m.halfedge(f);
    return {m.source(h), m.target(h), m.target(m.next(h))};
}

// Face f of a live in both meshes with the same vertices (same cyclic order) at the same points?
bool sameFace(const Mesh& a, const Mesh& b, FaceIndex f) {
    if (std::size_t(f) >= b.num_faces() || b.is_removed(f)) return false;
    auto ca = corners(a, f), cb = corners(b, f);
    for (int r = 0; r < 3; ++r) {
        bool same = true;
        for (int k = 0; k < 3 && same; ++k) {
            const VertexIndex va = ca[std::size_t(k)], vb = cb[std::size_t((k + r) % 3)];
            same = va == vb && a.point(va) == b.point(vb);
        }
        if (same) return true;
    }
    return false;
}

void expectBitIdentical(const Mesh& a, const Mesh& b) {
    ASSERT_EQ(a.num_vertices(), b.num_vertices());
    ASSERT_EQ(a.num_halfedges(), b.num_halfedges());
    ASSERT_EQ(a.num_faces(), b.num_faces());
    ASSERT_EQ(a.number_of_removed_faces(), b.number_of_removed_faces());
    for (std::size_t i = 0; i < a.num_vertices(); ++i) {
        const VertexIndex v(static_cast<std::uint32_t>(i));
        ASSERT_EQ(a.is_removed(v), b.is_removed(v));
        ASSERT_EQ(a.point(v), b.point(v));
        ASSERT_EQ(a.halfedge(v), b.halfedge(v));
    }
    for (std::size_t i = 0; i < a.num_halfedges(); ++i) {
        const HalfedgeIndex h(static_cast<std::uint32_t>(i));
        ASSERT_EQ(a.next(h), b.next(h));
        ASSERT_EQ(a.target(h), b.target(h));
        ASSERT_EQ(a.face(h), b.face(h));
    }
}

using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, FaceIndex>;
Box faceBox(const Mesh& m, FaceIndex f) {
    CGAL::Bbox_3 b;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
        b += m.point(v).bbox();
    return Box(b, f);
}

// Faces of m whose bounding boxes meet the bounding box of one of `changed` (changed ones included).
std::vector<FaceIndex> facesNear(const Mesh& m, const std::vector<FaceIndex>& changed) {
    std::vector<Box> a, b;
    for (FaceIndex f : changed)
        a.push_back(faceBox(m, f));
    for (FaceIndex f : m.faces())
        b.push_back(faceBox(m, f));
    std::set<FaceIndex> out(changed.begin(), changed.end());
    CGAL::box_intersection_d(a.begin(), a.end(), b.begin(), b.end(),
                             [&](const Box&, const Box& y) { out.insert(y.info()); });
    return {out.begin(), out.end()};
}

// ---- footprint of the patch in the scan's image
struct Footprint {
    int W = 0, H = 0;
    std::vector<char> mask; // pixels of patch samples, dilated by one pixel
    bool at(int x, int y) const { return x >= 0 && y >= 0 && x < W && y < H && mask[std::size_t(y * W + x)]; }
};

// The pixel of each patch vertex is the one it projects into: a grid index is a pixel only on the square
// pixel lattice, and the default lattice (issue #20) is not one.
Footprint footprintOf(const fss::Patch& patch, const Camera& cam) {
    Footprint fp;
    fp.W = cam.width;
    fp.H = cam.height;
    std::vector<char> raw(std::size_t(fp.W) * std::size_t(fp.H), 0);
    for (auto v : patch.mesh.vertices()) {
        const auto& p = patch.mesh.point(v);
        const Eigen::Vector3d s = cam.project(Eigen::Vector3d(p.x(), p.y(), p.z()));
        const int x = int(std::floor(s.x())), y = int(std::floor(s.y()));
        if (x >= 0 && y >= 0 && x < fp.W && y < fp.H) raw[std::size_t(y * fp.W + x)] = 1;
    }
    fp.mask.assign(raw.size(), 0);
    for (int y = 0; y < fp.H; ++y)
        for (int x = 0; x < fp.W; ++x) {
            if (!raw[std::size_t(y * fp.W + x)]) continue;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int X = x + dx, Y = y + dy;
                    if (X >= 0 && Y >= 0 && X < fp.W && Y < fp.H) fp.mask[std::size_t(Y * fp.W + X)] = 1;
                }
        }
    return fp;
}

// Does face f of m touch the footprint in the view (a vertex in a footprint pixel, or a footprint pixel
// centre inside its projection)?
bool touchesFootprint(const Mesh& m, FaceIndex f, const Camera& cam, const Footprint& fp) {
    Vec3 s[3];
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
        const Vec3 p = vec(m.point(v));
        if (cam.viewDepth(p) <= 0) return false;
        s[k] = cam.project(p);
        if (fp.at(int(std::floor(s[k].x())), int(std::floor(s[k].y())))) return true;
        ++k;
    }
    const double area =
        (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[1].y() - s[0].y()) * (s[2].x() - s[0].x());
    if (area == 0) return false;
    const int x0 = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
    const int x1 = std::min(fp.W - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
    const int y1 = std::min(fp.H - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            if (!fp.at(x, y)) continue;
            const double px = x + 0.5, py = y + 0.5;
            bool in = true;
            for (int i = 0; i < 3 && in; ++i) {
                const Vec3 &p = s[(i + 1) % 3], &q = s[(i + 2) % 3];
                in = ((q.x() - p.x()) * (py - p.y()) - (q.y() - p.y()) * (px - p.x())) / area >= 0;
            }
            if (in) return true;
        }
    return false;
}

// ---- one mesh
struct Case {
    const char* file;
    std::uint32_t seed;
    int patches; // scans that produce a patch
    int maxRes;
    // Issue 19's bound asserted on this mesh: every face a stitch created has a smallest angle of at least
    // this (degrees; faces at a thin input angle exempt). 0: measured and printed only (not met there yet).
    double createdMinDeg = 0;
};

struct Figures {
    int attempts = 0, noPatch = 0, stitched = 0, refused = 0;
    double worstToRef = 0, worstFromRef = 0; // Hausdorff / footprint
    std::size_t facesStart = 0, facesEnd = 0;
    double stitchSeconds = 0, scanSeconds = 0, checkSeconds = 0;
    std::map<std::string, int> reasons; // why patches were refused
    // Seam figures over all stitches (see the loop).
    double seamMinAngle = 180;
    std::size_t seamFaces = 0, seamFacesAbove30 = 0, seamVertices = 0, seamValence5To7 = 0;
    int stitchesSeamAbove20 = 0;
    // Issue 19's figures on the faces each stitch created (see the loop).
    double createdMinAngle = 180, worstStitchFrac30 = 1;
    std::size_t createdFaces = 0, createdAbove30 = 0, createdExempt = 0;
    int stitchesCreatedAbove20 = 0, stitchesCreated98Above30 = 0, stitchesValence90 = 0;
    int stitchesAllFour =
        0; // >= 20 deg, >= 98 % >= 30 deg, >= 90 % valence 5-7, Hausdorff within a footprint
};

double seamAngleDeg(const Vec3& a, const Vec3& b, const Vec3& c) {
    const std::array<Vec3, 3> p{a, b, c};
    double best = 180;
    for (std::size_t i = 0; i < 3; ++i) {
        const Vec3 u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
        best = std::min(best, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / std::numbers::pi);
    }
    return best;
}

class StitchProperty : public ::testing::TestWithParam<Case> {};

TEST_P(StitchProperty, ChainedRandomScansKeepEveryInvariant) {
    const Case& cs = GetParam();
    Mesh ref;
    if (std::string(cs.file) == "shape:torus") {
        ref = fss::shapes::torus(48, 16, 1.0, 0.35);
    } else if (std::string(cs.file) == "shape:icosphere") {
        ref = fss::shapes::icosphere(3, 1.0);
    } else {
        std::ifstream in(fss::test::meshPath(cs.file));
        ASSERT_TRUE(in && CGAL::IO::read_OFF(in, ref)) << cs.file;
    }
    ASSERT_TRUE(CGAL::is_triangle_mesh(ref));
    const bool closed = CGAL::is_closed(ref);
    const std::size_t loops = boundaryLoops(ref);
    const Eigen::AlignedBox3d box = fss::boundingBox(ref);
    const double diag = box.diagonal().norm();
    const double inputTol = 1e-9 * diag;
    ASSERT_FALSE(PMP::does_self_intersect(ref));
    Tree refTree(faces(ref).first, faces(ref).second, ref);
    refTree.accelerate_distance_queries();
    // Reference sample points (corners and centroids), for reference → current.
    std::vector<Vec3> refPoints;
    for (auto v : ref.vertices())
        refPoints.push_back(vec(ref.point(v)));
    for (auto f : ref.faces()) {
        Vec3 c(0, 0, 0);
        for (auto v : CGAL::vertices_around_face(ref.halfedge(f), ref))
            c += vec(ref.point(v)) / 3.0;
        refPoints.push_back(c);
    }

    ZBufferRenderer refRenderer, curRenderer;
    refRenderer.setMesh(ref);
    Mesh current = ref;
    std::map<std::int32_t, Camera> scanCameras;
    Figures fig;
    fig.facesStart = ref.number_of_faces();
    // FSS_STITCH_PROPERTY_SEED=N shifts every case's seed by N (other scans of the same meshes).
    const std::uint32_t seed = [&] {
        const char* e = std::getenv("FSS_STITCH_PROPERTY_SEED");
        return cs.seed + (e ? std::uint32_t(std::strtoul(e, nullptr, 10)) : 0u);
    }();
    std::mt19937 rng(seed);
    // FSS_STITCH_REFILL=1 measures stitch v2's seam refill (StitchOptions::refillSeam, off by default);
    // FSS_STITCH_REMESH=0 measures without stitch v2's seam band remesh (StitchOptions::remeshSeam, on by
    // default): version 1's seam, for comparison.
    const fss::StitchOptions options = [] {
        fss::StitchOptions o;
        const char* refill = std::getenv("FSS_STITCH_REFILL");
        o.refillSeam = refill && std::string(refill) == "1";
        const char* remesh = std::getenv("FSS_STITCH_REMESH");
        o.remeshSeam = !(remesh && std::string(remesh) == "0");
        return o;
    }();
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::time_point t) {
        return std::chrono::duration<double>(Clock::now() - t).count();
    };

    // Bound of the distance at a point p on / nearest to face f of the current mesh: the pixel footprint
    // at p of the scan that sampled the face's surface (its scan id) and of the scan whose stitch last
    // re-made the face (its seam vertices come from that scan), whichever is larger; inputTol for faces
    // of the input that no stitch has touched.
    // A vertex that a stitch placed on the old surface (a seam crossing on an old edge, a refinement
    // vertex) inherits the bound of the old face it lies on: vertexBound; samples and input vertices lie
    // on the reference (inputTol).
    std::vector<std::int32_t> madeBy(ref.num_faces(), -1);
    std::unordered_map<std::uint32_t, double> vertexBound;
    auto boundAt = [&](const Mesh& m, FaceIndex f, const Vec3& p) {
        auto sid = m.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId);
        const std::int32_t s = sid.second ? sid.first[f] : -1;
        const std::int32_t k = std::size_t(f) < madeBy.size() ? madeBy[std::size_t(f)] : -1;
        double b = inputTol;
        if (s >= 0) b = std::max(b, scanCameras.at(s).pixelFootprint(p));
        if (k >= 0) b = std::max(b, scanCameras.at(k).pixelFootprint(p));
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
            auto it = vertexBound.find(std::uint32_t(v));
            if (it != vertexBound.end()) b = std::max(b, it->second);
        }
        return b;
    };
    // Explains a face that is too far from the reference.
    auto describe = [&](const Mesh& m, FaceIndex f) {
        auto sid = m.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId);
        std::ostringstream os;
        os << " [face " << std::uint32_t(f) << " scan id " << (sid.second ? sid.first[f] : -1)
           << " made by scan " << (std::size_t(f) < madeBy.size() ? madeBy[std::size_t(f)] : -1)
           << "; corners:";
        const auto c = corners(m, f);
        for (int i = 0; i < 3; ++i) {
            const Vec3 p = vec(m.point(c[std::size_t(i)])), q = vec(m.point(c[std::size_t((i + 1) % 3)]));
            os << " (d " << std::sqrt(refTree.squared_distance(m.point(c[std::size_t(i)]))) << ", edge "
               << (q - p).norm() << ", bound " << boundAt(m, f, p) << ")";
        }
        os << "]";
        return os.str();
    };
    auto toReference = [&](const Mesh& m, FaceIndex f, double& worst, std::string& where) {
        const auto c = corners(m, f);
        const Vec3 P[3] = {vec(m.point(c[0])), vec(m.point(c[1])), vec(m.point(c[2]))};
        const Vec3 pts[7] = {P[0],
                             P[1],
                             P[2],
                             0.5 * (P[0] + P[1]),
                             0.5 * (P[1] + P[2]),
                             0.5 * (P[2] + P[0]),
                             (P[0] + P[1] + P[2]) / 3.0};
        for (const Vec3& p : pts) {
            const double d = std::sqrt(refTree.squared_distance(Point3(p.x(), p.y(), p.z())));
            const double r = d / boundAt(m, f, p);
            if (r > worst) {
                worst = r;
                std::ostringstream os;
                os << "point (" << p.transpose() << ") distance " << d << describe(m, f);
                where = os.str();
            }
        }
    };
    auto fromReference = [&](const Mesh& m, Tree& tree, const Vec3& p, double& worst, std::string& where) {
        const auto [q, f] = tree.closest_point_and_primitive(Point3(p.x(), p.y(), p.z()));
        const double d = (vec(q) - p).norm();
        double bound = boundAt(m, f, vec(q));
        if (d > bound) {
            // The nearest face may be one that no scan changed beside a patch that cut a corner of the
            // reference: the bound at p is the largest among the faces within 2d of p.
            std::vector<Primitive::Id> near;
            const double r = 2 * d;
            tree.all_intersected_primitives(
                fss::Kernel::Iso_cuboid_3(p.x() - r, p.y() - r, p.z() - r, p.x() + r, p.y() + r, p.z() + r),
                std::back_inserter(near));
            const Point3 P(p.x(), p.y(), p.z());
            for (FaceIndex g : near) {
                const auto c = corners(m, g);
                const fss::Kernel::Triangle_3 t(m.point(c[0]), m.point(c[1]), m.point(c[2]));
                if (CGAL::squared_distance(P, t) <= r * r)
                    bound = std::max(bound, boundAt(m, g, vec(m.point(c[0]))));
            }
        }
        const double r = d / bound;
        if (r > worst) {
            worst = r;
            std::ostringstream os;
            os << "reference point (" << p.transpose() << ") distance " << d << " to" << describe(m, f);
            where = os.str();
        }
    };

    int scanId = 0;
    // An open surface (head.off) shows its back to about nine random views in ten: up to 12 attempts per
    // patch.
    while (fig.stitched + fig.refused < cs.patches && fig.attempts < 12 * cs.patches) {
        ++fig.attempts;
        const ScanSetup setup = randomSetup(rng, box, cs.maxRes);
        const std::string trace = std::string(cs.file) + " seed " + std::to_string(seed) + " attempt " +
                                  std::to_string(fig.attempts) + " scan id " + std::to_string(scanId + 1) +
                                  ": " + setup.text;
        SCOPED_TRACE(trace);
        fss::ScanParams params;
        params.camera = setup.camera;
        params.lasso = setup.lasso;
        params.erodeRadius = setup.erode;
        params.dilateRadius = setup.dilate;
        params.scan.scanId = scanId + 1;
        params.quality.forceReplace = setup.forceReplace;
        // The square pixel lattice, on which these seeds' figures were measured, unless
        // FSS_PROPERTY_LATTICE=default: on the default adaptive lattice with its 35° mask (issue #20) every
        // invariant holds on the nine meshes, but head.off (seed 5505) gets 7 of 10 random views without a
        // patch and then 1 patch stitched, 2 refused (fewer than 8 faces; needle-like seam faces), failing
        // the majority rule below: the mask leaves small fragments of small oblique scans.
        if (const char* l = std::getenv("FSS_PROPERTY_LATTICE"); !l || std::string(l) != "default") {
            params.scan.lattice = fss::Lattice::Square;
            params.scan.minLatticeAngleDeg = 0;
        }
        auto t = Clock::now();
        curRenderer.setMesh(current);
        fss::ScanResult scan;
        try {
            scan = fss::scanPatch(ref, refRenderer, current, curRenderer, params);
        } catch (const fss::InvalidInputError&) {
            ++fig.noPatch;
            fig.scanSeconds += seconds(t);
            continue;
        }
        fig.scanSeconds += seconds(t);
        ++scanId;
        const Camera cam = scan.grid.camera;
        scanCameras[scanId] = cam;

        const Mesh before = current;
        t = Clock::now();
        fss::StitchReport report;
        try {
            report = fss::stitchPatch(current, scan.patch.mesh, cam, options, scan.currentBuffers.faceId);
            ++fig.stitched;
        } catch (const fss::InvalidInputError& e) {
            fig.stitchSeconds += seconds(t);
            ++fig.refused;
            std::string why = e.what();
            why = why.substr(0, why.find(':'));
            if (why.find("No part") == 0) {
                why = e.what();
                why = why.substr(why.find(':') + 2);
            }
            ++fig.reasons[why];
            expectBitIdentical(current, before);
            if (HasFailure()) return;
            continue;
        }
        fig.stitchSeconds += seconds(t);
        t = Clock::now();

        // Structure.
        ASSERT_TRUE(current.is_valid(false));
        ASSERT_TRUE(CGAL::is_triangle_mesh(current));
        EXPECT_EQ(nonManifoldVertices(current), 0u);
        EXPECT_EQ(duplicateEdges(current), 0u);
        EXPECT_EQ(CGAL::is_closed(current), closed);
        EXPECT_EQ(boundaryLoops(current), loops);
        EXPECT_EQ(degenerateFaces(current), 0u);
        if (closed) {
            EXPECT_GT(PMP::volume(current), 0.0);
        }

        // Changed faces: new indices, or indices whose vertices / points differ; removed ones.
        std::vector<FaceIndex> changedAfter;
        for (auto f : current.faces())
            if (std::size_t(f) >= before.num_faces() || before.is_removed(f) || !sameFace(current, before, f))
                changedAfter.push_back(f);
        std::vector<FaceIndex> changedBefore;
        for (auto f : before.faces())
            if (!sameFace(before, current, f)) changedBefore.push_back(f);
        EXPECT_FALSE(changedAfter.empty());
        // Bounds of the new vertices (before madeBy changes: the old faces' bounds are wanted).
        {
            Tree old(changedBefore.begin(), changedBefore.end(), before);
            std::unordered_map<std::uint32_t, double> bounds;
            for (FaceIndex f : changedAfter)
                for (auto v : CGAL::vertices_around_face(current.halfedge(f), current)) {
                    const bool fresh = std::size_t(v) >= before.num_vertices() || before.is_removed(v) ||
                                       before.point(v) != current.point(v);
                    if (!fresh || bounds.count(std::uint32_t(v))) continue;
                    const Point3& p = current.point(v);
                    double b = inputTol;
                    if (refTree.squared_distance(p) > inputTol * inputTol && !changedBefore.empty()) {
                        std::vector<Primitive::Id> on;
                        const double r = inputTol;
                        old.all_intersected_primitives(fss::Kernel::Iso_cuboid_3(p.x() - r, p.y() - r,
                                                                                 p.z() - r, p.x() + r,
                                                                                 p.y() + r, p.z() + r),
                                                       std::back_inserter(on));
                        if (on.empty()) on.push_back(old.closest_point_and_primitive(p).second);
                        for (FaceIndex g : on)
                            b = std::max(b, boundAt(before, g, vec(p)));
                    }
                    bounds[std::uint32_t(v)] = b;
                }
            for (const auto& [v, b] : bounds)
                vertexBound[v] = b;
        }
        madeBy.resize(current.num_faces(), -1);
        for (FaceIndex f : changedAfter)
            madeBy[std::size_t(f)] = scanId;

        // Seam figures (issue 19), from the mesh alone: seam vertices are the vertices of changed faces
        // that also touch an unchanged face or a face of another scan id (where the patch meets the old
        // mesh, and the rim of the changed region); seam faces are the changed faces with a seam vertex.
        bool angleCriteria = false; // issue 19's three shape criteria on this stitch
        std::string diagCriteria;   // FSS_STITCH_PROPERTY_DIAG=1: the criteria this stitch fails
        {
            auto sid = current.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId);
            std::unordered_set<std::uint32_t> changed;
            for (FaceIndex f : changedAfter)
                changed.insert(std::uint32_t(f));
            std::unordered_set<std::uint32_t> seamVertices;
            for (FaceIndex f : changedAfter)
                for (auto v : CGAL::vertices_around_face(current.halfedge(f), current)) {
                    bool otherScan = false, unchanged = false;
                    for (auto g : CGAL::faces_around_target(current.halfedge(v), current)) {
                        if (g == Mesh::null_face()) continue;
                        unchanged = unchanged || !changed.count(std::uint32_t(g));
                        otherScan = otherScan || (sid.second && sid.first[g] != scanId);
                    }
                    if (unchanged || otherScan) seamVertices.insert(std::uint32_t(v));
                }
            double smallest = 180;
            for (FaceIndex f : changedAfter) {
                const auto c = corners(current, f);
                if (!seamVertices.count(std::uint32_t(c[0])) && !seamVertices.count(std::uint32_t(c[1])) &&
                    !seamVertices.count(std::uint32_t(c[2])))
                    continue;
                const double a = seamAngleDeg(vec(current.point(c[0])), vec(current.point(c[1])),
                                              vec(current.point(c[2])));
                smallest = std::min(smallest, a);
                ++fig.seamFaces;
                fig.seamFacesAbove30 += a >= 30;
            }
            for (std::uint32_t v : seamVertices) {
                const auto d = current.degree(VertexIndex(v));
                ++fig.seamVertices;
                fig.seamValence5To7 += d >= 5 && d <= 7;
            }
            fig.seamMinAngle = std::min(fig.seamMinAngle, smallest);
            fig.stitchesSeamAbove20 += smallest >= 20;

            // Issue 19's figures on every face the stitch created (not the patch's own faces, which are the
            // scan's): smallest angle, share >= 30 deg, and seam vertices of valence 5-7. The issue's
            // exemption, precisely: a created face below 20 deg is exempt (and counted) only when one of its
            // corners is a vertex of the mesh before, not moved, with an angle below 20 deg AT that vertex in
            // one of its faces before the stitch (an input angle smaller than the bound touching the seam);
            // a thin angle elsewhere in a face around it does not exempt.
            std::unordered_map<std::uint32_t, bool> thinBefore;
            auto touchesThinInput = [&](VertexIndex v) {
                if (std::size_t(v) >= before.num_vertices() || before.is_removed(v) ||
                    before.point(v) != current.point(v))
                    return false;
                auto [it, fresh] = thinBefore.try_emplace(std::uint32_t(v), false);
                if (fresh)
                    for (auto h : CGAL::halfedges_around_target(before.halfedge(v), before)) {
                        if (before.is_border(h)) continue;
                        const Vec3 p = vec(before.point(v)), u = vec(before.point(before.source(h))) - p,
                                   w = vec(before.point(before.target(before.next(h)))) - p;
                        if (std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / std::numbers::pi < 20.0)
                            it->second = true;
                    }
                return it->second;
            };
            // Faces the stitch created: changed faces that are not patch faces as the scan made them.
            using Key = std::array<std::array<double, 3>, 3>;
            auto keyOf = [](const Mesh& m, FaceIndex f) {
                const auto c = corners(m, f);
                Key k;
                for (std::size_t i = 0; i < 3; ++i)
                    k[i] = {m.point(c[i]).x(), m.point(c[i]).y(), m.point(c[i]).z()};
                std::sort(k.begin(), k.end());
                return k;
            };
            std::set<Key> patchFaces;
            for (FaceIndex f : scan.patch.mesh.faces())
                patchFaces.insert(keyOf(scan.patch.mesh, f));
            double created = 180;
            FaceIndex worstFace;
            std::size_t n = 0, above30 = 0;
            for (FaceIndex f : changedAfter) {
                if (patchFaces.count(keyOf(current, f))) continue;
                const auto c = corners(current, f);
                const double a = seamAngleDeg(vec(current.point(c[0])), vec(current.point(c[1])),
                                              vec(current.point(c[2])));
                ++n;
                above30 += a >= 30;
                if (a < 20 && (touchesThinInput(c[0]) || touchesThinInput(c[1]) || touchesThinInput(c[2]))) {
                    ++fig.createdExempt;
                    continue;
                }
                if (a < created) worstFace = f;
                created = std::min(created, a);
            }
            const double frac30 = n ? double(above30) / double(n) : 1.0;
            const double fracValence = seamVertices.empty() ? 1.0 : [&] {
                std::size_t good = 0;
                for (std::uint32_t v : seamVertices) {
                    const auto d = current.degree(VertexIndex(v));
                    good += d >= 5 && d <= 7;
                }
                return double(good) / double(seamVertices.size());
            }();
            fig.createdMinAngle = std::min(fig.createdMinAngle, created);
            fig.createdFaces += n;
            fig.createdAbove30 += above30;
            fig.stitchesCreatedAbove20 += created >= 20;
            fig.stitchesCreated98Above30 += frac30 >= 0.98;
            fig.stitchesValence90 += fracValence >= 0.9;
            fig.worstStitchFrac30 = std::min(fig.worstStitchFrac30, frac30);
            angleCriteria = created >= 20 && frac30 >= 0.98 && fracValence >= 0.9;
            if (fss::test::stitchPropertyDiag() && !angleCriteria) {
                std::set<std::array<double, 3>> patchPoints;
                for (auto v : scan.patch.mesh.vertices()) {
                    const Point3& p = scan.patch.mesh.point(v);
                    patchPoints.insert({p.x(), p.y(), p.z()});
                }
                char buf[160];
                std::snprintf(buf, sizeof buf, "%s%s%s", created < 20 ? " min20" : "",
                              frac30 < 0.98 ? " frac30" : "", fracValence < 0.9 ? " valence" : "");
                diagCriteria = buf;
                if (created < 20)
                    fss::test::printWorstCreatedFace(cs.file, scanId, created, before, current, worstFace,
                                                     changed, patchPoints, &cam);
                if (frac30 < 0.98) {
                    std::map<std::string, int> classes;
                    for (FaceIndex f : changedAfter) {
                        if (patchFaces.count(keyOf(current, f))) continue;
                        const auto c = corners(current, f);
                        if (seamAngleDeg(vec(current.point(c[0])), vec(current.point(c[1])),
                                         vec(current.point(c[2]))) >= 30)
                            continue;
                        ++classes[fss::test::classifyCreatedFace(before, current, f, changed, patchPoints,
                                                                 &cam, nullptr)];
                    }
                    std::string list;
                    for (const auto& [k, n] : classes)
                        list += " " + k + ":" + std::to_string(n);
                    std::fprintf(stderr, "diag30 %s stitch %d: %.4f of %zu >= 30;%s\n", cs.file, scanId,
                                 frac30, n, list.c_str());
                }
                if (fracValence < 0.9) {
                    std::map<std::size_t, int> hist;
                    for (std::uint32_t v : seamVertices)
                        ++hist[current.degree(VertexIndex(v))];
                    std::string list;
                    for (const auto& [d, k] : hist)
                        list += " " + std::to_string(d) + ":" + std::to_string(k);
                    std::fprintf(stderr, "diagval %s stitch %d: %.4f of %zu;%s\n", cs.file, scanId,
                                 fracValence, seamVertices.size(), list.c_str());
                }
            }
        }

        // Seam neighbourhood: every changed face of `before` within seamRings vertex rings of a face that
        // touches the patch's footprint.
        {
            const Footprint fp = footprintOf(scan.patch, cam);
            std::unordered_map<std::uint32_t, bool> touches;
            auto touching = [&](FaceIndex f) {
                auto [it, fresh] = touches.try_emplace(std::uint32_t(f), false);
                if (fresh) it->second = touchesFootprint(before, f, cam, fp);
                return it->second;
            };
            std::size_t outside = 0;
            std::string example;
            for (FaceIndex f : changedBefore) {
                std::set<FaceIndex> ring{f}, seen{f};
                bool ok = touching(f);
                for (int r = 0; r < options.seamRings && !ok; ++r) {
                    std::set<FaceIndex> next;
                    for (FaceIndex g : ring)
                        for (auto v : CGAL::vertices_around_face(before.halfedge(g), before))
                            for (auto h : CGAL::faces_around_target(before.halfedge(v), before))
                                if (h != Mesh::null_face() && seen.insert(h).second) next.insert(h);
                    for (FaceIndex g : next)
                        ok = ok || touching(g);
                    ring.swap(next);
                }
                if (!ok) {
                    ++outside;
                    if (example.empty()) example = "face " + std::to_string(std::uint32_t(f));
                }
            }
            EXPECT_EQ(outside, 0u) << "changed faces outside the seam neighbourhood, e.g. " << example
                                   << " of " << changedBefore.size();
        }

        // Self-intersections.
        if (scanId % kFullCheckEvery == 0) {
            EXPECT_FALSE(PMP::does_self_intersect(current));
        } else {
            EXPECT_FALSE(PMP::does_self_intersect(facesNear(current, changedAfter), current));
        }

        // Hausdorff, both directions, in footprints.
        {
            double worst = 0;
            std::string where;
            for (FaceIndex f : changedAfter)
                toReference(current, f, worst, where);
            EXPECT_LE(worst, 1.0) << "current -> reference: " << where;
            fig.worstToRef = std::max(fig.worstToRef, worst);
            const bool toRefOk = worst <= 1.0;

            CGAL::Bbox_3 b;
            double fpMax = 0;
            for (FaceIndex f : changedAfter)
                for (auto v : CGAL::vertices_around_face(current.halfedge(f), current)) {
                    b += current.point(v).bbox();
                    fpMax = std::max(fpMax, cam.pixelFootprint(vec(current.point(v))));
                }
            Tree tree(faces(current).first, faces(current).second, current);
            tree.accelerate_distance_queries();
            worst = 0;
            where.clear();
            const double grow = 2 * fpMax;
            for (const Vec3& p : refPoints)
                if (p.x() >= b.xmin() - grow && p.x() <= b.xmax() + grow && p.y() >= b.ymin() - grow &&
                    p.y() <= b.ymax() + grow && p.z() >= b.zmin() - grow && p.z() <= b.zmax() + grow)
                    fromReference(current, tree, p, worst, where);
            EXPECT_LE(worst, 1.0) << "reference -> current: " << where;
            fig.worstFromRef = std::max(fig.worstFromRef, worst);
            fig.stitchesAllFour += angleCriteria && toRefOk && worst <= 1.0 && !HasFailure();
            if (fss::test::stitchPropertyDiag() && !(angleCriteria && toRefOk && worst <= 1.0))
                std::fprintf(stderr, "fail4 %s stitch %d:%s%s\n", cs.file, scanId, diagCriteria.c_str(),
                             toRefOk && worst <= 1.0 ? "" : " hausdorff");
        }
        fig.checkSeconds += seconds(t);
        if (HasFailure()) {
            std::printf("FAILED at %s\n%zu faces removed, %zu added, %zu seam faces\n", trace.c_str(),
                        report.facesRemoved, report.facesAdded, report.seamFaces);
            return;
        }
    }

    // The whole mesh at the end.
    EXPECT_FALSE(PMP::does_self_intersect(current));
    {
        double worst = 0;
        std::string where;
        for (auto f : current.faces())
            toReference(current, f, worst, where);
        EXPECT_LE(worst, 1.0) << "current -> reference: " << where;
        Tree tree(faces(current).first, faces(current).second, current);
        tree.accelerate_distance_queries();
        double worst2 = 0;
        for (const Vec3& p : refPoints)
            fromReference(current, tree, p, worst2, where);
        EXPECT_LE(worst2, 1.0) << "reference -> current: " << where;
        fig.worstToRef = std::max(fig.worstToRef, worst);
        fig.worstFromRef = std::max(fig.worstFromRef, worst2);
    }
    fig.facesEnd = current.number_of_faces();
    std::printf(
        "%s (seed %u): %d scan attempts, %d without a patch, %d patches stitched, %d refused; faces %zu -> "
        "%zu; worst Hausdorff / footprint: current->reference %.3f, reference->current %.3f; "
        "time scan %.1f s, stitch %.1f s, checks %.1f s\n",
        cs.file, seed, fig.attempts, fig.noPatch, fig.stitched, fig.refused, fig.facesStart, fig.facesEnd,
        fig.worstToRef, fig.worstFromRef, fig.scanSeconds, fig.stitchSeconds, fig.checkSeconds);
    for (const auto& [why, n] : fig.reasons)
        std::printf("  refused %d x: %s\n", n, why.c_str());
    std::printf(
        "  seam: smallest angle %.2f deg; stitches with every seam angle >= 20 deg: %d of %d; seam faces "
        ">= 30 deg: %.4f of %zu; seam vertices of valence 5-7: %.4f of %zu\n",
        fig.seamMinAngle, fig.stitchesSeamAbove20, fig.stitched,
        fig.seamFaces ? double(fig.seamFacesAbove30) / double(fig.seamFaces) : 1.0, fig.seamFaces,
        fig.seamVertices ? double(fig.seamValence5To7) / double(fig.seamVertices) : 1.0, fig.seamVertices);
    std::printf("  created faces: smallest angle %.2f deg (%zu faces < 20 deg at a thin input angle exempt); "
                "stitches with every created angle >= 20 deg: %d of %d; with >= 98 %% of created faces >= 30 "
                "deg: %d of %d (worst %.4f); with >= 90 %% of seam vertices of valence 5-7: %d of %d; "
                "created faces >= 30 deg: %.4f of %zu\n",
                fig.createdMinAngle, fig.createdExempt, fig.stitchesCreatedAbove20, fig.stitched,
                fig.stitchesCreated98Above30, fig.stitched, fig.worstStitchFrac30, fig.stitchesValence90,
                fig.stitched, fig.createdFaces ? double(fig.createdAbove30) / double(fig.createdFaces) : 1.0,
                fig.createdFaces);
    std::printf("  issue 19's seam criterion (all four on one stitch): %d of %d stitches\n",
                fig.stitchesAllFour, fig.stitched);
    EXPECT_GE(fig.createdMinAngle, cs.createdMinDeg) << "a face a stitch created is below issue 19's bound";
    EXPECT_GE(fig.stitched + fig.refused, cs.patches) << "too few scans produced a patch";
    // Most patches stitch (a majority); the refused ones are listed above with their reasons.
    EXPECT_GT(fig.stitched, fig.refused) << "too many patches could not be stitched";
}

// A few scans per mesh by default (the ctest run stays short); FSS_LONG_TESTS=1 runs 200 per mesh,
// FSS_STITCH_PROPERTY_SCANS=N any number.
const int kPatches = [] {
    const char* env = std::getenv("FSS_STITCH_PROPERTY_SCANS");
    if (env) return std::max(1, std::atoi(env));
    return fss::test::longTests() ? 200 : 3;
}();

INSTANTIATE_TEST_SUITE_P(Meshes, StitchProperty,
                         ::testing::Values(Case{"couplingdown.off", 1101u, kPatches, 512},
                                           Case{"elephant.off", 2202u, kPatches, 512},
                                           Case{"fandisk.off", 3303u, kPatches, 512},
                                           Case{"mech-holes-shark.off", 4404u, kPatches, 512},
                                           // with boundary, a coarse CAD part, a decimated organic one
                                           Case{"head.off", 5505u, kPatches, 512},
                                           Case{"part.off", 6606u, kPatches, 512},
                                           Case{"hand.off", 7707u, kPatches, 512},
                                           // analytic shapes (fss::shapes)
                                           Case{"shape:torus", 8818u, kPatches, 512},
                                           // created faces >= 20 deg (measured 30.28 deg at 25 scans)
                                           Case{"shape:icosphere", 9909u, kPatches, 512, 20.0}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                             std::string n = info.param.file;
                             if (n.rfind("shape:", 0) == 0) n = n.substr(6);
                             n = n.substr(0, n.find('.'));
                             std::replace(n.begin(), n.end(), '-', '_');
                             return n;
                         });

} // namespace
