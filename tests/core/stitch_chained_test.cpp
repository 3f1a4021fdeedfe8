// Stitching: chained random scans on analytic shapes and on real meshes keep every invariant of DESIGN.md §5.
#include "stitch_helpers.h"

using namespace stitch_test_helpers;

namespace {

// A small z-buffer rasterizer standing in for fss::render: per pixel centre, the nearest face's index.
std::vector<std::uint32_t> rasterizeIds(const Mesh& m, const Camera& cam) {
    const int W = cam.width, H = cam.height;
    std::vector<std::uint32_t> ids(std::size_t(W) * std::size_t(H), 0xFFFFFFFFu);
    std::vector<double> depth(ids.size(), 2.0);
    for (auto f : m.faces()) {
        Vec3 s[3];
        int k = 0;
        bool ok = true;
        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
            const Vec3 p = vec(m.point(v));
            if (cam.viewDepth(p) <= cam.nearPlane) ok = false;
            s[k++] = cam.project(p);
        }
        if (!ok) continue;
        forEachCoveredPixel(s, W, H, [&](int x, int y, double z) {
            const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
            if (z < depth[i]) {
                depth[i] = z;
                ids[i] = std::uint32_t(f);
            }
        });
    }
    return ids;
}

// Random scan masks: disks, rings (a hole), two disks (two components), rectangles.
std::function<bool(int, int)> randomMask(std::mt19937& rng, int res) {
    std::uniform_real_distribution<double> U(0, 1);
    const double cx = res * (0.25 + 0.5 * U(rng)), cy = res * (0.25 + 0.5 * U(rng));
    const double r = 3 + 0.2 * res * U(rng);
    switch (int(U(rng) * 4)) {
    case 0:
        return disk(cx, cy, r);
    case 1: {
        const double inner = 0.25 * r + 1;
        return [=](int x, int y) {
            const double d2 = (x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy);
            return d2 <= (r + 3) * (r + 3) && d2 > inner * inner;
        };
    }
    case 2: {
        const double dx = r + 4 + 6 * U(rng);
        return [=](int x, int y) {
            return disk(cx - dx, cy, 0.6 * r + 2)(x, y) || disk(cx + dx, cy, 0.5 * r + 2)(x, y);
        };
    }
    default: {
        const int w = int(r) + 2, h = int(0.7 * r) + 2;
        return [=](int x, int y) { return std::abs(x - cx) < w && std::abs(y - cy) < h; };
    }
    }
}

Vec3 randomDirection(std::mt19937& rng) {
    std::normal_distribution<double> N(0, 1);
    Vec3 d;
    do
        d = Vec3(N(rng), N(rng), N(rng));
    while (d.norm() < 1e-3);
    return d.normalized();
}

} // namespace

TEST(Stitch, RandomChainedScansKeepAllInvariants) {
    struct Stats {
        int stitched = 0, refused = 0;
        double minAngle = 180, fracSum = 0, seconds = 0;
    } sphereStats, gridStats;

    // Sphere: random cameras all around, chained.
    {
        std::mt19937 rng(20240611);
        std::uniform_real_distribution<double> U(0, 1);
        Mesh m = fss::shapes::icosphere(2, 1.0);
        double sag = sphereSag(m, 1.0); // grows with the patches' own discretisation error
        for (int i = 0; i < 70; ++i) {
            SCOPED_TRACE("sphere scan " + std::to_string(i));
            Camera cam = orbitCamera(randomDirection(rng), 3.0 + 2.0 * U(rng), 64, 20.0 + 20.0 * U(rng));
            cam.up = (cam.up + 0.5 * randomDirection(rng)).normalized();
            if (cam.viewDirection().cross(cam.up).norm() < 0.1) cam.up = randomDirection(rng);
            const Mesh patch = makePatch(cam, randomMask(rng, 64), sphere(1.0), i + 1, 80.0);
            if (patch.number_of_faces() == 0) continue;
            sag = std::max(sag, sphereSag(patch, 1.0));
            const Mesh before = m;
            std::vector<std::uint32_t> ids;
            if (i % 2) ids = rasterizeIds(m, cam);
            try {
                const fss::StitchReport r = fss::stitchPatch(m, patch, cam, {}, ids);
                ++sphereStats.stitched;
                sphereStats.minAngle = std::min(sphereStats.minAngle, r.seamMinAngleDeg);
                sphereStats.fracSum += r.seamFracMinAngleAbove25;
                sphereStats.seconds += r.seconds;
            } catch (const fss::InvalidInputError& e) {
                ++sphereStats.refused;
                expectBitIdentical(m, before);
            }
            expectValid(m, {true, 0});
            expectOnSphere(m, 1.0, sag * 1.0001);
            // This scan's faces face its camera.
            auto sid = m.property_map<FaceIndex, std::int32_t>(fss::props::faceScanId);
            if (sid.second) {
                std::set<std::uint32_t> mine;
                for (auto f : m.faces())
                    if (sid.first[f] == i + 1) mine.insert(std::uint32_t(f));
                if (!mine.empty()) {
                    EXPECT_EQ(facesNotFacing(m, cam, mine), 0u);
                }
            }
            if (HasFailure()) return;
        }
    }
    // Grid: straight-down and oblique cameras, chained; the plane's area is preserved exactly.
    {
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> U(0, 1);
        Mesh g = fss::shapes::grid(16, 16, 1.0);
        for (int i = 0; i < 70; ++i) {
            SCOPED_TRACE("grid scan " + std::to_string(i));
            Camera cam = downCamera(2 + 12 * U(rng), 2 + 12 * U(rng), 10 + 15 * U(rng), 360 * U(rng), 64);
            cam.eye += Vec3(6 * (U(rng) - 0.5), 6 * (U(rng) - 0.5), 0); // oblique views
            const Mesh patch = makePatch(cam, randomMask(rng, 64), planeZ0(), i + 1, 80.0);
            if (patch.number_of_faces() == 0) continue;
            const Mesh before = g;
            std::vector<std::uint32_t> ids;
            if (i % 2) ids = rasterizeIds(g, cam);
            try {
                const fss::StitchReport r = fss::stitchPatch(g, patch, cam, {}, ids);
                ++gridStats.stitched;
                gridStats.minAngle = std::min(gridStats.minAngle, r.seamMinAngleDeg);
                gridStats.fracSum += r.seamFracMinAngleAbove25;
                gridStats.seconds += r.seconds;
            } catch (const fss::InvalidInputError& e) {
                ++gridStats.refused;
                expectBitIdentical(g, before);
            }
            expectValid(g, {false, 1});
            EXPECT_NEAR(sumArea(g), 256.0, 256.0 * 1e-9);
            for (auto v : g.vertices())
                ASSERT_EQ(g.point(v).z(), 0.0);
            if (HasFailure()) return;
        }
    }
    for (const auto& [name, s] : {std::pair{"sphere", sphereStats}, std::pair{"grid", gridStats}}) {
        std::printf("random %s: %d stitched, %d refused, seam min angle %.2f deg, mean frac >= 25 deg %.3f, "
                    "mean %.1f ms per stitch\n",
                    name, s.stitched, s.refused, s.minAngle, s.fracSum / std::max(1, s.stitched),
                    1e3 * s.seconds / std::max(1, s.stitched));
        EXPECT_GE(s.stitched, 50);
    }
}

namespace {

// A mesh as the reference surface: the nearest hit of a view ray (Moeller-Trumbore, all faces).
Surface meshSurface(const Mesh& ref) {
    std::vector<std::array<Vec3, 3>> tris;
    for (auto f : ref.faces()) {
        std::array<Vec3, 3> t;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(ref.halfedge(f), ref))
            t[std::size_t(k++)] = vec(ref.point(v));
        tris.push_back(t);
    }
    return [tris](const fss::Ray& r) -> std::optional<Vec3> {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& t : tris) {
            const Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0], p = r.direction.cross(e2);
            const double det = e1.dot(p);
            if (std::abs(det) < 1e-14) continue;
            const Vec3 s = r.origin - t[0];
            const double u = s.dot(p) / det;
            if (u < 0 || u > 1) continue;
            const Vec3 q = s.cross(e1);
            const double v = r.direction.dot(q) / det;
            if (v < 0 || u + v > 1) continue;
            const double d = e2.dot(q) / det;
            if (d > 0 && d < best) best = d;
        }
        if (!std::isfinite(best)) return std::nullopt;
        return r.origin + best * r.direction;
    };
}

} // namespace

TEST(Stitch, RealMeshChainedScans) {
    Mesh ref;
    std::ifstream in(fss::test::meshPath("elephant.off"));
    ASSERT_TRUE(CGAL::IO::read_OFF(in, ref));
    ASSERT_TRUE(CGAL::is_triangle_mesh(ref));
    const bool closed = CGAL::is_closed(ref);
    const std::size_t loops = boundaryLoops(ref);
    const double volume = closed ? PMP::volume(ref) : 0.0;
    Eigen::AlignedBox3d box;
    for (auto v : ref.vertices())
        box.extend(vec(ref.point(v)));
    const Surface surface = meshSurface(ref);
    Mesh m = ref;
    const Vec3 dirs[] = {{0, 0, 1}, {1, 0.3, 0.2}, {-0.4, 1, 0.3}, {0.3, -0.5, -1}, {-1, -0.2, 0.5}};
    int n = 0;
    double minAngle = 180;
    std::size_t patchFaces = 0, trimmed = 0;
    for (const Vec3& d : dirs) {
        Camera cam = Camera::standardView(fss::StandardView::PosZ, box, 96, 96);
        const double dist = (cam.eye - cam.focal).norm();
        cam.eye = cam.focal + d.normalized() * dist;
        cam.up = std::abs(d.normalized().z()) < 0.9 ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
        cam.fitClippingRange(box);
        const Mesh patch = makePatch(cam, disk(48, 48, 26), surface, ++n, 75.0);
        if (patch.number_of_faces() == 0) continue;
        const fss::StitchReport r = fss::stitchPatch(m, patch, cam);
        SCOPED_TRACE(reportText(r));
        EXPECT_GE(r.componentsStitched, 1);
        expectValid(m, {closed, loops});
        minAngle = std::min(minAngle, r.seamMinAngleDeg);
        patchFaces += patch.number_of_faces();
        trimmed += r.patchFacesTrimmed;
    }
    if (closed) {
        EXPECT_NEAR(PMP::volume(m), volume, 0.01 * volume);
    }
    std::printf("elephant: %d scans, %zu of %zu patch faces stitched, %zu faces, seam min angle %.2f deg\n",
                n, patchFaces - trimmed, patchFaces, std::size_t(m.number_of_faces()), minAngle);
}
