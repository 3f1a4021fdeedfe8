// The seam band grown past a held rim vertex (stitch_rim.cpp, DESIGN.md §6.2 sessions 19 and 21) on an
// analytic set-up: a flat grid whose one vertex, moved, makes the only replaced face at it thin there.
#include "stitch_helpers.h"

using namespace stitch_test_helpers;

// A 20 x 20 grid of unit squares on z = 0 scanned straight down (96², the square patch over [5.9, 14.1]²);
// the grid vertex (5, 5) moved to (5, 4.3), 1.6 from the patch's corner. Kept faces hold it after the first
// build, and the new faces there share the thin wedge that the replaced faces leave at it: with the growth
// past held rim vertices off (FSS_STITCH_BAND_OFF=rim) the vertex stays where it is and the smallest angle
// of the faces the stitch created is 16.70 deg, there. With it, the vertex's whole star joins the band, the
// vertex moves and every created angle is at least 20 deg (measured 30.16 deg).
TEST(StitchRim, HeldKeptFaceCornerIsFreed) {
    Mesh grid = fss::shapes::grid(20, 20, 1.0);
    const Point3 held(5, 4.3, 0);
    VertexIndex v;
    for (VertexIndex w : grid.vertices())
        if (grid.point(w) == Point3(5, 5, 0)) v = w;
    ASSERT_NE(v, VertexIndex());
    grid.point(v) = held;
    const Mesh before = grid;
    const Camera cam = downCamera(10.0, 10.0, 30, 0.0, 96);
    auto mask = [](int x, int y) { return x >= 30 && x < 66 && y >= 30 && y < 66; };
    const Mesh patch = makePatch(cam, mask, planeZ0());
    ASSERT_GT(patch.number_of_faces(), 2000u);

    const fss::StitchReport r = fss::stitchPatch(grid, patch, cam);
    SCOPED_TRACE(reportText(r));
    EXPECT_EQ(r.componentsStitched, 1);
    expectValid(grid, {false, 1});
    EXPECT_NEAR(PMP::area(grid), 400.0, 400.0 * 1e-9);
    for (VertexIndex w : grid.vertices())
        EXPECT_EQ(grid.point(w).z(), 0.0);

    // The held vertex was freed: no vertex is left where it was, and none of its faces before is kept.
    bool stays = false;
    for (VertexIndex w : grid.vertices())
        stays = stays || grid.point(w) == held;
    EXPECT_FALSE(stays);
    std::set<FaceKey> after;
    for (FaceIndex f : grid.faces())
        after.insert(faceKey(grid, f));
    for (FaceIndex f : CGAL::faces_around_target(before.halfedge(v), before))
        EXPECT_EQ(after.count(faceKey(before, f)), 0u);

    // Every face the stitch created (not a face of the input by its corners' positions) has a smallest
    // angle of at least 20 deg; the input's smallest angle is below (the moved vertex makes it 10.01 deg).
    std::set<FaceKey> input;
    double inputMin = 180;
    for (FaceIndex f : before.faces()) {
        input.insert(faceKey(before, f));
        inputMin = std::min(inputMin, faceMinAngleDeg(before, f));
    }
    double created = 180, near = 180;
    for (FaceIndex f : grid.faces()) {
        if (input.count(faceKey(grid, f))) continue;
        const double a = faceMinAngleDeg(grid, f);
        created = std::min(created, a);
        Vec3 c(0, 0, 0);
        for (VertexIndex w : CGAL::vertices_around_face(grid.halfedge(f), grid))
            c += vec(grid.point(w)) / 3.0;
        if ((c - vec(held)).norm() < 1.5) near = std::min(near, a);
    }
    std::printf("held rim vertex at (5, 4.3): smallest created angle %.2f deg, within 1.5 of it %.2f deg "
                "(input %.2f deg)\n",
                created, near, inputMin);
    EXPECT_LT(inputMin, 20.0);
    EXPECT_GE(near, 20.0);
    EXPECT_GE(created, 20.0);
}
