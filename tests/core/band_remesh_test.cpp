// The band remesh of stitch v2 (band_remesh.h, DESIGN.md §6.2) on its own: slivers along a seam become
// well-shaped while creases, planes and the faces outside the band are kept. References are independent:
// signed areas by the shoelace formula, planes and crease lines of known shapes.
#include "stitch/band_remesh.h"
#include "stitch/seam_quality.h"

#include "fss/shapes.h"
#include "mesh/local_ops.h"

#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

namespace {

// A seam-like band of slivers on a planar grid: every edge of row y = 6 split close to its end (as version
// 1's crossings do), so the faces along the row have angles of a few degrees.
struct SliverGrid {
    fss::Mesh mesh = fss::shapes::grid(12, 12, 1.0);
    std::vector<fss::FaceIndex> band;
    fss::Camera camera;
    SliverGrid() {
        std::vector<fss::HalfedgeIndex> row;
        for (fss::EdgeIndex e : mesh.edges()) {
            const fss::HalfedgeIndex h = mesh.halfedge(e);
            const auto a = mesh.point(mesh.source(h)), b = mesh.point(mesh.target(h));
            if (a.y() == 6 && b.y() == 6 && std::min(a.x(), b.x()) >= 2 && std::max(a.x(), b.x()) <= 10)
                row.push_back(h);
        }
        for (fss::HalfedgeIndex h : row) {
            const auto a = mesh.point(mesh.source(h)), b = mesh.point(mesh.target(h));
            fss::detail::splitEdge(mesh, h, a + 0.93 * (b - a));
        }
        for (fss::FaceIndex f : mesh.faces()) {
            double x = 0, y = 0;
            for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
                x += mesh.point(v).x() / 3;
                y += mesh.point(v).y() / 3;
            }
            if (x > 1.5 && x < 10.5 && y > 3.5 && y < 8.5) band.push_back(f);
        }
        camera.eye = {6, 6, 25};
        camera.focal = {6, 6, 0};
        camera.width = camera.height = 256;
    }
};

double smallestAngleOf(const fss::Mesh& m, fss::FaceIndex f) {
    const auto h = m.halfedge(f);
    auto p = [&](fss::VertexIndex v) {
        return Eigen::Vector3d(m.point(v).x(), m.point(v).y(), m.point(v).z());
    };
    return fss::stitch::smallestAngleDeg(p(m.source(h)), p(m.target(h)), p(m.target(m.next(h))));
}

double faceArea(const fss::Mesh& m, fss::FaceIndex f) {
    const auto h = m.halfedge(f);
    const auto a = m.point(m.source(h)), b = m.point(m.target(h)), c = m.point(m.target(m.next(h)));
    return 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x())); // signed, in z = 0
}

} // namespace

// The band remesh on a plane: the slivers are gone (every band face >= 30 deg), every vertex stays in the
// plane, the band's area (shoelace, signed: no face turned over) is what it was, and the faces and vertices
// outside the band are untouched.
TEST(BandRemesh, PlanarSliverBandBecomesWellShaped) {
    SliverGrid g;
    fss::Mesh& m = g.mesh;
    double before = 180, areaBefore = 0;
    for (fss::FaceIndex f : g.band) {
        before = std::min(before, smallestAngleOf(m, f));
        areaBefore += faceArea(m, f);
    }
    ASSERT_LT(before, 5.0);
    std::set<fss::FaceIndex> inBand(g.band.begin(), g.band.end());
    std::map<fss::FaceIndex, std::array<fss::Point3, 3>> outside;
    for (fss::FaceIndex f : m.faces())
        if (!inBand.count(f)) {
            std::array<fss::Point3, 3> p;
            int k = 0;
            for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                p[std::size_t(k++)] = m.point(v);
            outside[f] = p;
        }
    fss::stitch::BandRemeshInput in;
    in.mesh = &m;
    in.band = g.band;
    in.camera = &g.camera;
    in.edgeLength = 1.0;
    std::size_t created = 0;
    in.faceData = [&](fss::FaceIndex, fss::FaceIndex) { ++created; };
    const auto r = fss::stitch::remeshBand(in);
    EXPECT_TRUE(m.is_valid(false));
    EXPECT_TRUE(CGAL::is_triangle_mesh(m));
    double after = 180, areaAfter = 0, above30 = 0;
    for (fss::FaceIndex f : r.faces) {
        const double a = smallestAngleOf(m, f);
        after = std::min(after, a);
        above30 += a >= 30;
        areaAfter += faceArea(m, f);
        EXPECT_GT(faceArea(m, f), 0.0);
    }
    for (fss::VertexIndex v : m.vertices())
        EXPECT_EQ(m.point(v).z(), 0.0);
    EXPECT_NEAR(areaAfter, areaBefore, 1e-9);
    for (const auto& [f, p] : outside) {
        ASSERT_FALSE(m.is_removed(f));
        int k = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
            EXPECT_EQ(m.point(v), p[std::size_t(k++)]);
    }
    std::printf("band: smallest angle %.2f -> %.2f deg, %.3f of %zu faces >= 30 deg; %zu splits, %zu "
                "collapses, %zu flips, %zu moves\n",
                before, after, above30 / double(r.faces.size()), r.faces.size(), r.splits, r.collapses,
                r.flips, r.moves);
    EXPECT_NEAR(r.minAngleBeforeDeg, before, 1e-9);
    EXPECT_NEAR(r.minAngleAfterDeg, after, 1e-9);
    EXPECT_GE(after, 30.0);
    EXPECT_EQ(created, r.splits * 2);
}

// False creases (issue 19): a single face whose crease normal differs from all its neighbours' (tilted by
// 45 deg, as a face cut from a finely tessellated curved surface can be) is an outlier, not a feature: it
// makes no crease, so the band comes out exactly as with all normals up, whichever band face (with three band
// neighbours) it is. Without the filter (FSS_STITCH_BAND_OFF=creasefilter) its three edges are creases that
// no flip or collapse may touch and its corners do not relax (measured: 16 of the 80 results differ, the
// smallest angle down to 21.15 deg from 45).
TEST(BandRemesh, OutlierFaceMakesNoCrease) {
    struct Result {
        double after = 180;
        std::vector<fss::Point3> points;
    };
    auto run = [](int outlier) {
        SliverGrid g;
        fss::Mesh& m = g.mesh;
        const std::set<fss::FaceIndex> inBand(g.band.begin(), g.band.end());
        std::vector<fss::FaceIndex> inner; // band faces whose three neighbours are band faces
        for (fss::FaceIndex f : g.band) {
            int n = 0;
            for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m))
                n += !m.is_border(m.opposite(h)) && inBand.count(m.face(m.opposite(h))) > 0;
            if (n == 3) inner.push_back(f);
        }
        const fss::FaceIndex tilted = outlier >= 0 && std::size_t(outlier) < inner.size()
                                          ? inner[std::size_t(outlier)]
                                          : fss::Mesh::null_face();
        fss::stitch::BandRemeshInput in;
        in.mesh = &m;
        in.band = g.band;
        in.camera = &g.camera;
        in.edgeLength = 1.0;
        const Eigen::Vector3d up(0, 0, 1), tilt = Eigen::Vector3d(1, 0, 1).normalized();
        in.creaseNormal = [&](fss::FaceIndex f) -> Eigen::Vector3d { return f == tilted ? tilt : up; };
        const auto r = fss::stitch::remeshBand(in);
        EXPECT_TRUE(m.is_valid(false));
        Result out;
        for (fss::FaceIndex f : r.faces)
            out.after = std::min(out.after, smallestAngleOf(m, f));
        for (fss::VertexIndex v : m.vertices())
            if (!m.is_removed(v)) out.points.push_back(m.point(v));
        return std::pair{out, inner.size()};
    };
    const auto [clean, candidates] = run(-1);
    ASSERT_GT(candidates, 20u);
    std::size_t changed = 0;
    double worst = 180;
    for (std::size_t i = 0; i < candidates; ++i) {
        const Result r = run(int(i)).first;
        worst = std::min(worst, r.after);
        changed += r.points != clean.points;
    }
    std::printf(
        "band with one outlier face normal (%zu faces tried): %zu results differ from all normals up; "
        "smallest angle %.2f (all up %.2f) deg\n",
        candidates, changed, worst, clean.after);
    EXPECT_GE(clean.after, 30.0);
    EXPECT_EQ(changed, 0u);
    EXPECT_EQ(worst, clean.after);
}

// A tilted cap (issue 19, the main job's 16.06 deg face): a cap below 20 deg (an angle above 120 deg)
// whose crease normal differs by 45 deg from two of its three neighbours while those agree with each other
// (the third tilted by 25 deg, within the crease angle of the others) is an outlier too: its two edges
// against the agreeing neighbours would make a crease turning back on itself at the cap's corner, pinning it.
// So the band comes out exactly as with the cap's normal like its neighbours', for every such cap of the
// sliver row.
TEST(BandRemesh, TiltedCapMakesNoCrease) {
    auto run = [](int which, bool tiltCap) {
        SliverGrid g;
        fss::Mesh& m = g.mesh;
        const std::set<fss::FaceIndex> inBand(g.band.begin(), g.band.end());
        std::vector<fss::FaceIndex> caps; // band caps below 20 deg with three band neighbours
        for (fss::FaceIndex f : g.band) {
            int n = 0;
            double largest = 0;
            for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
                n += !m.is_border(m.opposite(h)) && inBand.count(m.face(m.opposite(h))) > 0;
                const auto p = m.point(m.target(h)), a = m.point(m.source(h)),
                           b = m.point(m.target(m.next(h)));
                largest = std::max(largest, CGAL::approximate_angle(a, p, b));
            }
            if (n == 3 && largest > 120 && smallestAngleOf(m, f) < 20) caps.push_back(f);
        }
        if (std::size_t(which) >= caps.size()) return std::pair{std::vector<fss::Point3>{}, caps.size()};
        const fss::FaceIndex cap = caps[std::size_t(which)];
        const fss::FaceIndex leaning = m.face(m.opposite(m.halfedge(cap)));
        fss::stitch::BandRemeshInput in;
        in.mesh = &m;
        in.band = g.band;
        in.camera = &g.camera;
        in.edgeLength = 1.0;
        const double deg = std::numbers::pi / 180;
        const Eigen::Vector3d up(0, 0, 1), tilt45(std::sin(45 * deg), 0, std::cos(45 * deg)),
            tilt25(std::sin(25 * deg), 0, std::cos(25 * deg));
        in.creaseNormal = [&](fss::FaceIndex f) -> Eigen::Vector3d {
            return f == cap && tiltCap ? tilt45 : f == leaning ? tilt25 : up;
        };
        fss::stitch::remeshBand(in);
        EXPECT_TRUE(m.is_valid(false));
        std::vector<fss::Point3> points;
        for (fss::VertexIndex v : m.vertices())
            if (!m.is_removed(v)) points.push_back(m.point(v));
        return std::pair{points, caps.size()};
    };
    const std::size_t caps = run(0, false).second;
    ASSERT_GE(caps, 4u);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < caps; ++i)
        changed += run(int(i), true).first != run(int(i), false).first;
    std::printf("band with one tilted cap (%zu caps tried): %zu results differ from the cap untilted\n", caps,
                changed);
    EXPECT_EQ(changed, 0u);
}

// The band's growth: given only the half of the sliver row below y = 6, the slivers above it (outside the
// band, holding the vertices on y = 6) stay without growth; with the other faces of the region growable, the
// band takes them in (only those: faces outside the region are untouched) and every face it ends with is >=
// 30 deg.
TEST(BandRemesh, BandGrowsOverTheSliversAtItsBorder) {
    for (const bool grow : {false, true}) {
        SliverGrid g;
        fss::Mesh& m = g.mesh;
        auto centroidY = [&](fss::FaceIndex f) {
            double y = 0;
            for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                y += m.point(v).y() / 3;
            return y;
        };
        std::set<fss::FaceIndex> region(g.band.begin(), g.band.end());
        std::vector<fss::FaceIndex> lower;
        for (fss::FaceIndex f : g.band)
            if (centroidY(f) < 6) lower.push_back(f);
        std::map<fss::FaceIndex, std::array<fss::Point3, 3>> outside;
        for (fss::FaceIndex f : m.faces())
            if (!region.count(f)) {
                std::array<fss::Point3, 3> p;
                int k = 0;
                for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                    p[std::size_t(k++)] = m.point(v);
                outside[f] = p;
            }
        fss::stitch::BandRemeshInput in;
        in.mesh = &m;
        in.band = lower;
        in.camera = &g.camera;
        in.edgeLength = 1.0;
        if (grow) in.growable = [&](fss::FaceIndex f) { return region.count(f) > 0; };
        const auto r = fss::stitch::remeshBand(in);
        EXPECT_TRUE(m.is_valid(false));
        double inRegion = 180, inBand = 180;
        for (fss::FaceIndex f : m.faces()) {
            if (outside.count(f)) continue;
            inRegion = std::min(inRegion, smallestAngleOf(m, f));
        }
        for (fss::FaceIndex f : r.faces)
            inBand = std::min(inBand, smallestAngleOf(m, f));
        for (const auto& [f, p] : outside) {
            ASSERT_FALSE(m.is_removed(f));
            int k = 0;
            for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
                EXPECT_EQ(m.point(v), p[std::size_t(k++)]);
        }
        std::printf(
            "band %s growth: %zu faces grown, smallest angle in the band %.2f, in the region %.2f deg\n",
            grow ? "with" : "without", r.grown, inBand, inRegion);
        if (grow) {
            EXPECT_GT(r.grown, 0u);
            EXPECT_GE(inRegion, 30.0);
        } else {
            EXPECT_EQ(r.grown, 0u);
            EXPECT_LT(inRegion, 5.0); // the slivers above y = 6 are still there
        }
    }
}

// Across a crease (a roof z = -0.6 |x - 6|, the faces' normals 62 deg apart): every vertex stays on the roof,
// no edge crosses the ridge (the crease is kept as a line of edges), and the slivers are gone.
TEST(BandRemesh, CreaseIsKept) {
    SliverGrid g;
    fss::Mesh& m = g.mesh;
    for (fss::VertexIndex v : m.vertices()) {
        const auto p = m.point(v);
        m.point(v) = fss::Point3(p.x(), p.y(), -0.6 * std::abs(p.x() - 6));
    }
    fss::stitch::BandRemeshInput in;
    in.mesh = &m;
    in.band = g.band;
    in.camera = &g.camera;
    in.edgeLength = 1.0;
    const auto r = fss::stitch::remeshBand(in);
    EXPECT_TRUE(m.is_valid(false));
    for (fss::VertexIndex v : m.vertices()) {
        const auto p = m.point(v);
        EXPECT_NEAR(p.z(), -0.6 * std::abs(p.x() - 6), 1e-9);
    }
    for (fss::EdgeIndex e : m.edges()) {
        const double a = m.point(m.vertex(e, 0)).x() - 6, b = m.point(m.vertex(e, 1)).x() - 6;
        EXPECT_FALSE((a < -1e-9 && b > 1e-9) || (a > 1e-9 && b < -1e-9)) << "an edge crosses the ridge";
    }
    double after = 180;
    for (fss::FaceIndex f : r.faces)
        after = std::min(after, smallestAngleOf(m, f));
    std::printf(
        "roof band: smallest angle %.2f -> %.2f deg; %zu splits, %zu collapses, %zu flips, %zu moves\n",
        r.minAngleBeforeDeg, after, r.splits, r.collapses, r.flips, r.moves);
    EXPECT_LT(r.minAngleBeforeDeg, 5.0);
    EXPECT_GE(after, 30.0);
}

// Faces whose three corners lie on creases (issue 19: what the band could not fix before): a strip 0.15 wide
// between two creases (a step: z = 0, a slope of 40 deg, flat again, the creases at x = 6 and x = 6.15, the
// grid's column x = 7 moved to 6.15), every face of it a sliver (0.196 wide in 3D for edges of 1) with all
// corners on the creases, which never leave their lines. What holds: every vertex stays on the step, every
// crease vertex on its line, no edge crosses a crease, and the smallest angle does not drop. NOT fixed yet
// (measured: 11.08 deg before and after): no single guarded operation raises the strip's smallest angle —
// splitting one crease edge leaves the far corner's angle atan(0.196 / 1) as it was — so the band's greedy
// repair does not start; the strip needs both creases split at once (a pair of splits and a flip judged
// together), the next step of issue 19. The bound on `before` keeps the case a sliver strip.
TEST(BandRemesh, FacesBetweenTwoCreasesKeepTheCreasesAndDoNotGetWorse) {
    fss::Mesh m = fss::shapes::grid(12, 12, 1.0);
    const double slope = std::tan(40.0 * std::numbers::pi / 180.0);
    auto height = [&](double x) { return x <= 6 ? 0.0 : x <= 6.15 ? -slope * (x - 6) : -slope * 0.15; };
    for (fss::VertexIndex v : m.vertices()) {
        const auto p = m.point(v);
        const double x = p.x() == 7 ? 6.15 : p.x();
        m.point(v) = fss::Point3(x, p.y(), height(x));
    }
    std::vector<fss::FaceIndex> band;
    double before = 180;
    for (fss::FaceIndex f : m.faces()) {
        double x = 0, y = 0;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
            x += m.point(v).x() / 3;
            y += m.point(v).y() / 3;
        }
        if (x > 3.5 && x < 9.5 && y > 2.5 && y < 9.5) {
            band.push_back(f);
            before = std::min(before, smallestAngleOf(m, f));
        }
    }
    fss::Camera camera;
    camera.eye = {6, 6, 25};
    camera.focal = {6, 6, 0};
    camera.width = camera.height = 256;
    fss::stitch::BandRemeshInput in;
    in.mesh = &m;
    in.band = band;
    in.camera = &camera;
    in.edgeLength = 1.0;
    const auto r = fss::stitch::remeshBand(in);
    EXPECT_TRUE(m.is_valid(false));
    double after = 180;
    for (fss::FaceIndex f : r.faces)
        after = std::min(after, smallestAngleOf(m, f));
    std::size_t onCrease = 0;
    for (fss::VertexIndex v : m.vertices()) {
        const auto p = m.point(v);
        EXPECT_NEAR(p.z(), height(p.x()), 1e-9);
        onCrease += std::abs(p.x() - 6) < 1e-9 || std::abs(p.x() - 6.15) < 1e-9;
    }
    for (fss::EdgeIndex e : m.edges()) {
        const double a = m.point(m.vertex(e, 0)).x(), b = m.point(m.vertex(e, 1)).x();
        for (double c : {6.0, 6.15})
            EXPECT_FALSE((a < c - 1e-9 && b > c + 1e-9) || (a > c + 1e-9 && b < c - 1e-9))
                << "an edge crosses the crease at x = " << c;
    }
    std::printf("crease strip: smallest angle %.2f -> %.2f deg; %zu vertices on the creases (26 before); %zu "
                "splits, %zu collapses, %zu flips, %zu repairs\n",
                before, after, onCrease, r.splits, r.collapses, r.flips, r.repairs);
    EXPECT_LT(before, 12.0);
    EXPECT_GE(after, before - 1e-9);
    EXPECT_GE(onCrease, 26u);
}
