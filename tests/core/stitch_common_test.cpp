// Stitch v1's shared pieces (stitch_common.h: the view, the bucket grid, the index map, the star, the
// replay), each on its own since the split of stitch.cpp. References are independent: the camera's own
// projection, brute-force searches, std::unordered_map, angles of known triangles.
#include "stitch/stitch_common.h"

#include "fss/shapes.h"

#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <numbers>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <vector>

// The view's projection is the camera's (Camera::project as the reference, y flipped), and
// perspectiveParam inverts the projection along an edge: the 3D point at parameter t projects to the 2D
// parameter s whose perspectiveParam is t again.
TEST(StitchCommon, ViewProjectsLikeTheCameraAndInvertsEdgeParameters) {
    namespace st = fss::detail::stitching;
    fss::Camera cam;
    cam.eye = {0.7, -0.4, 4};
    cam.focal = {0, 0.1, 0};
    cam.width = 320;
    cam.height = 240;
    const st::View view(cam);
    int checked = 0;
    for (int i = 0; i < 40; ++i) {
        const Eigen::Vector3d u(std::sin(1.3 * i), std::cos(0.7 * i), 0.8 * std::sin(0.37 * i)),
            w(std::cos(2.1 * i), 0.5 * std::sin(1.9 * i), -0.6 * std::cos(0.53 * i));
        st::Point2 pu, pw, pm;
        double wu = 0, ww = 0, wm = 0;
        ASSERT_TRUE(view.project(u, pu, wu));
        ASSERT_TRUE(view.project(w, pw, ww));
        const Eigen::Vector3d s = cam.project(u);
        EXPECT_NEAR(pu.x(), s.x(), 1e-9);
        EXPECT_NEAR(pu.y(), -s.y(), 1e-9);
        if (st::dist2(pu, pw) < 1.0) continue; // too short on screen for a parameter
        const double t = 0.1 + 0.8 * (0.5 + 0.5 * std::sin(3.1 * i));
        ASSERT_TRUE(view.project(u + t * (w - u), pm, wm));
        const double s2 = st::lineParam(pm, pu, pw);
        EXPECT_NEAR(st::View::perspectiveParam(s2, wu, ww), t, 1e-9);
        ++checked;
    }
    EXPECT_GT(checked, 30);
    // Behind the eye: refused.
    st::Point2 p;
    double w = 0;
    EXPECT_FALSE(view.project(Eigen::Vector3d(1.4, -0.8, 8), p, w));
}

// The bucket grid reports exactly the boxes that overlap a query box, each once (brute force as the
// reference), and the open-addressing IndexMap behaves like std::unordered_map under growth.
TEST(StitchCommon, BucketGridAndIndexMapMatchBruteForce) {
    namespace st = fss::detail::stitching;
    std::vector<CGAL::Bbox_2> boxes;
    for (int i = 0; i < 400; ++i) {
        const double x = 10 * std::sin(0.91 * i), y = 10 * std::cos(1.37 * i);
        const double dx = 0.05 + 1.5 * (0.5 + 0.5 * std::sin(2.3 * i)),
                     dy = 0.05 + 0.8 * (0.5 + 0.5 * std::cos(i));
        boxes.emplace_back(x, y, x + dx, y + dy);
    }
    st::BucketGrid grid(0.7, boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
        grid.insert(int(i), boxes[i]);
    std::size_t hits = 0;
    for (int q = 0; q < 60; ++q) {
        const double x = 9 * std::cos(0.77 * q), y = 9 * std::sin(1.11 * q), r = 0.2 + 0.05 * q;
        const CGAL::Bbox_2 box(x - r, y - r, x + r, y + r);
        std::vector<int> got;
        grid.query(box, [&](int id) { got.push_back(id); });
        std::vector<int> expected;
        for (std::size_t i = 0; i < boxes.size(); ++i)
            if (CGAL::do_overlap(box, boxes[i])) expected.push_back(int(i));
        std::sort(got.begin(), got.end());
        EXPECT_EQ(std::adjacent_find(got.begin(), got.end()), got.end()) << "an id reported twice";
        // Cells are coarser than boxes: the grid may report more, never fewer.
        std::vector<int> missed;
        std::set_difference(expected.begin(), expected.end(), got.begin(), got.end(),
                            std::back_inserter(missed));
        EXPECT_TRUE(missed.empty()) << missed.size() << " overlapping boxes missed by query " << q;
        hits += expected.size();
    }
    EXPECT_GT(hits, 100u);
    // With bounds (dense cells inside, hashed outside: the bounds cover part of the boxes only), the same
    // ids in the same order as without.
    st::BucketGrid dense(0.7, boxes.size(), CGAL::Bbox_2(-6, -8, 7, 5));
    for (std::size_t i = 0; i < boxes.size(); ++i)
        dense.insert(int(i), boxes[i]);
    for (int q = 0; q < 60; ++q) {
        const double x = 11 * std::cos(0.53 * q), y = 11 * std::sin(1.29 * q), r = 0.3 + 0.07 * q;
        const CGAL::Bbox_2 box(x - r, y - r, x + r, y + r);
        std::vector<int> a, b;
        grid.query(box, [&](int id) { a.push_back(id); });
        dense.query(box, [&](int id) { b.push_back(id); });
        EXPECT_EQ(a, b) << "query " << q;
    }

    st::IndexMap<int> map;
    std::unordered_map<std::uint32_t, int> ref;
    for (std::uint32_t i = 0; i < 5000; ++i) {
        const std::uint32_t key = (i * 2654435761u) % 7919u;
        auto [value, fresh] = map.try_emplace(key, -1);
        auto [it, refFresh] = ref.try_emplace(key, -1);
        ASSERT_EQ(fresh, refFresh);
        *value += int(i);
        it->second += int(i);
    }
    EXPECT_EQ(map.size(), ref.size());
    for (const auto& [key, value] : ref)
        EXPECT_EQ(map.at(key), value);
    EXPECT_EQ(map.find(7919u), nullptr);
    EXPECT_THROW(map.at(7920u), std::logic_error);
}

// The star of faces copies every face around their vertices (the vertices' degrees as in the mesh), and
// replaying a plan on the mesh splits a face into three around a new vertex: faces +2, vertices +1, edges
// +3 (Euler), the mesh still closed and valid; a plan whose face cannot be added is refused.
TEST(StitchCommon, StarAndReplayEditTheMeshAsPlanned) {
    namespace st = fss::detail::stitching;
    fss::Mesh m = fss::shapes::icosphere(2);
    const std::size_t faces = m.number_of_faces(), vertices = m.number_of_vertices(),
                      edges = m.number_of_edges();
    const fss::FaceIndex f = *m.faces().begin();
    st::Star star;
    ASSERT_TRUE(st::buildStar(m, {f}, star));
    std::set<std::uint32_t> around;
    for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
        for (fss::FaceIndex g : CGAL::faces_around_target(m.halfedge(v), m))
            around.insert(std::uint32_t(g));
    EXPECT_EQ(star.S.number_of_faces(), around.size());
    EXPECT_EQ(star.full.size(), 3u);
    for (fss::VertexIndex s : star.full)
        EXPECT_EQ(star.S.degree(s), m.degree(fss::VertexIndex(star.cur[s])));

    st::Plan plan;
    plan.removed = {f};
    std::array<fss::VertexIndex, 3> corner;
    int k = 0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m)) {
        corner[std::size_t(k++)] = v;
        centre += st::toVec(m.point(v)) / 3.0;
        plan.reused.push_back(v);
    }
    plan.freshPositions = {centre};
    for (int i = 0; i < 3; ++i)
        plan.faces.push_back({st::PlanVertex{std::uint32_t(corner[std::size_t(i)]), false},
                              st::PlanVertex{std::uint32_t(corner[std::size_t((i + 1) % 3)]), false},
                              st::PlanVertex{0, true}});
    std::vector<fss::FaceIndex> added;
    const auto same = [](auto x) { return x; };
    ASSERT_TRUE(st::replay(m, plan, same, same, [&](std::size_t, fss::FaceIndex g) { added.push_back(g); }));
    EXPECT_EQ(added.size(), 3u);
    EXPECT_EQ(m.number_of_faces(), faces + 2);
    EXPECT_EQ(m.number_of_vertices(), vertices + 1);
    EXPECT_EQ(m.number_of_edges(), edges + 3);
    EXPECT_TRUE(CGAL::is_closed(m));
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));

    // Adding a face that is already there (same orientation) is refused.
    st::Plan twice;
    twice.faces.resize(1);
    fss::Mesh copy = m;
    const auto h = copy.halfedge(added[0]);
    twice.faces[0] = {st::PlanVertex{std::uint32_t(copy.source(h)), false},
                      st::PlanVertex{std::uint32_t(copy.target(h)), false},
                      st::PlanVertex{std::uint32_t(copy.target(copy.next(h))), false}};
    EXPECT_FALSE(st::replay(copy, twice, same, same, [](std::size_t, fss::FaceIndex) {}));
}

// minAngle passes one angle through atan2 when the order of the three is clear: it must return the very
// same double as the minimum of the three atan2 values (the formula before, the reference here) on random,
// near-equilateral, near-isosceles and nearly degenerate triangles, and the known angles of known ones.
TEST(StitchCommon, MinAngleIsExactlyTheSmallestOfTheThreeAngles) {
    namespace st = fss::detail::stitching;
    auto reference = [](const st::Vec3& a, const st::Vec3& b, const st::Vec3& c) {
        const st::Vec3 e[3] = {b - a, c - b, a - c};
        double best = std::numbers::pi;
        for (int i = 0; i < 3; ++i) {
            const st::Vec3 u = -e[(i + 2) % 3], v = e[i];
            if (!(u.norm() > 0) || !(v.norm() > 0)) return 0.0;
            best = std::min(best, std::atan2(u.cross(v).norm(), u.dot(v)));
        }
        return best;
    };
    std::uint64_t state = 12345;
    auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) * 0x1.0p-53 - 0.5;
    };
    std::size_t checked = 0;
    for (int i = 0; i < 100000; ++i) {
        const st::Vec3 a(uniform(), uniform(), uniform());
        st::Vec3 b(uniform(), uniform(), uniform()), c(uniform(), uniform(), uniform());
        switch (i % 4) {
        case 1: { // near-equilateral: ties between all three angles
            const st::Vec3 u = st::Vec3(1, 0, 0), v = st::Vec3(0.5, std::sqrt(3.0) / 2, 0);
            b = a + u + 1e-12 * b;
            c = a + v + 1e-12 * c;
            break;
        }
        case 2: // isosceles: two equal angles at the base, apex at the mid-perpendicular
            c = 0.5 * (a + b) + st::Vec3(0, 0, 1e-3 * (1 + uniform()));
            break;
        case 3: // nearly degenerate: c almost on the line ab
            c = a + (0.5 + uniform()) * (b - a) + 1e-14 * c;
            break;
        default:
            break;
        }
        ASSERT_EQ(st::minAngle(a, b, c), reference(a, b, c)) << "triangle " << i;
        ++checked;
    }
    EXPECT_EQ(checked, 100000u);
    EXPECT_NEAR(st::minAngle({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}), std::numbers::pi / 3,
                1e-15);
    EXPECT_NEAR(st::minAngle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}), std::numbers::pi / 4, 1e-15);
    EXPECT_EQ(st::minAngle({0, 0, 0}, {0, 0, 0}, {0, 1, 0}), 0.0);
}
