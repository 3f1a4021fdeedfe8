// The scan rasterizer against exact CPU references: face ids against ray casting with a CGAL AABB tree,
// depth against an analytic sphere, VTK's projection against fss::Camera, the multi-pass id decode, the
// one-upload contract, a caller-supplied EGL context, no DISPLAY, several Rasterizers per process, errors.
#include "fss/camera.h"
#include "fss/error.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/render/rasterizer.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <numbers>
#include <utility>

using fss::Camera;
using fss::FrameBuffers;
using fss::Mesh;
using fss::render::Rasterizer;

namespace {

using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<fss::Kernel, Primitive>>;

Mesh loadMesh(const std::string& name) {
    Mesh mesh;
    if (!CGAL::IO::read_polygon_mesh(fss::test::meshPath(name).string(), mesh) || mesh.is_empty())
        throw std::runtime_error("cannot read test mesh " + name);
    return mesh;
}

Eigen::AlignedBox3d boundsOf(const Mesh& mesh) {
    Eigen::AlignedBox3d box;
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        box.extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
    }
    return box;
}

// fss::shapes::icosphere moved to \p centre.
Mesh icosphere(int levels, double radius, const Eigen::Vector3d& centre) {
    Mesh mesh = fss::shapes::icosphere(levels, radius);
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        mesh.point(v) = fss::Point3(p.x() + centre.x(), p.y() + centre.y(), p.z() + centre.z());
    }
    return mesh;
}

// Signed screen-space distance (pixels) of (sx, sy) outside the projection of face f: > 0 outside,
// < 0 inside (then minus the distance to the nearest edge).
double outsideDistance(const Camera& cam, const Mesh& mesh, std::uint32_t f, double sx, double sy) {
    std::array<Eigen::Vector2d, 3> s;
    int i = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(fss::FaceIndex(f)), mesh)) {
        const auto& p = mesh.point(v);
        s[i++] = cam.project(Eigen::Vector3d(p.x(), p.y(), p.z())).head<2>();
    }
    const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        return a.x() * b.y() - a.y() * b.x();
    };
    const double orientation = cross(s[1] - s[0], s[2] - s[0]) > 0 ? 1.0 : -1.0;
    const Eigen::Vector2d q(sx, sy);
    double outside = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d e = s[(k + 1) % 3] - s[k];
        outside = std::max(outside, -orientation * cross(e, q - s[k]) / e.norm());
    }
    return outside;
}

// Face ids of the rasterizer against the first face hit by a ray through every pixel centre (CGAL AABB
// tree, double precision). Where they differ, the pixel centre must lie within kTiePx of the boundary of
// one of the two faces: a GPU snaps vertices to a 1/256-pixel grid (8 sub-pixel bits, llvmpipe and common
// hardware), so centres that close to an edge may go either way. Anything farther is a real error.
constexpr double kTiePx = 1.0 / 256.0;

struct Agreement {
    std::size_t gpuCovered = 0, cpuHits = 0, unionCovered = 0, agree = 0;
    double worstTie = 0; // largest distance of a disagreeing pixel centre from the faces' boundaries
    double fraction() const { return unionCovered ? double(agree) / double(unionCovered) : 1.0; }
    std::size_t disagree() const { return unionCovered - agree; }
};

Agreement compareWithRayCasting(const FrameBuffers& fb, const Tree& tree, const Mesh& mesh) {
    Agreement a;
    const Camera& cam = fb.camera;
    for (int y = 0; y < fb.height(); ++y) {
        for (int x = 0; x < fb.width(); ++x) {
            const fss::Ray ray = cam.ray(x + 0.5, y + 0.5);
            const fss::Kernel::Ray_3 r(fss::Point3(ray.origin.x(), ray.origin.y(), ray.origin.z()),
                                       fss::Vector3(ray.direction.x(), ray.direction.y(), ray.direction.z()));
            const auto hit = tree.first_intersected_primitive(r);
            const std::uint32_t cpu = hit ? std::uint32_t(*hit) : FrameBuffers::kNoFace;
            const std::uint32_t gpu = fb.faceAt(x, y);
            a.gpuCovered += gpu != FrameBuffers::kNoFace;
            a.cpuHits += cpu != FrameBuffers::kNoFace;
            if (gpu == FrameBuffers::kNoFace && cpu == FrameBuffers::kNoFace) continue;
            ++a.unionCovered;
            if (gpu == cpu) {
                ++a.agree;
                continue;
            }
            // Explained when the centre lies on the border of the face the GPU drew (it covered a face the
            // ray just misses, e.g. a nearer occluder) or of the face the ray hit (the GPU just missed it).
            double tie = std::numeric_limits<double>::infinity();
            if (gpu != FrameBuffers::kNoFace)
                tie = std::min(tie, std::abs(outsideDistance(cam, mesh, gpu, x + 0.5, y + 0.5)));
            if (cpu != FrameBuffers::kNoFace)
                tie = std::min(tie, std::abs(outsideDistance(cam, mesh, cpu, x + 0.5, y + 0.5)));
            a.worstTie = std::max(a.worstTie, tie);
        }
    }
    return a;
}

Camera orbitView(const Eigen::AlignedBox3d& box, double azimuthDeg, double elevationDeg, int w, int h,
                 bool parallel, double zoom = 1.0) {
    Camera c = Camera::standardView(fss::StandardView::PosX, box, w, h, parallel);
    const double az = azimuthDeg * std::numbers::pi / 180, el = elevationDeg * std::numbers::pi / 180;
    const double dist = (c.eye - c.focal).norm();
    c.eye = c.focal +
            dist * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    c.up = {0, 0, 1};
    c.zoom(zoom);
    c.fitClippingRange(box);
    return c;
}

// ---- a caller-supplied context: our own EGL surfaceless context, as an application would pass -------

class TestEglContext final : public fss::render::GlContext {
public:
    TestEglContext() {
        auto getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        display_ = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        EGLint major = 0, minor = 0;
        if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor))
            throw std::runtime_error("test EGL display");
        eglBindAPI(EGL_OPENGL_API);
        const EGLint cfgAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint count = 0;
        eglChooseConfig(display_, cfgAttribs, &config, 1, &count);
        const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                  4,
                                  EGL_CONTEXT_MINOR_VERSION,
                                  1,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                  EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                  EGL_NONE};
        context_ = eglCreateContext(display_, count ? config : nullptr, EGL_NO_CONTEXT, attribs);
        if (context_ == EGL_NO_CONTEXT) throw std::runtime_error("test EGL context");
    }
    ~TestEglContext() override {
        doneCurrent();
        eglDestroyContext(display_, context_);
    }
    void makeCurrent() override {
        ++makeCurrentCalls;
        if (!isCurrent()) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
    }
    bool isCurrent() const override { return eglGetCurrentContext() == context_; }
    void doneCurrent() override {
        if (isCurrent()) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    int makeCurrentCalls = 0;

private:
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
};

// A "context" that claims to be current while no context is: GL calls go nowhere.
class AbsentContext final : public fss::render::GlContext {
public:
    void makeCurrent() override {}
    bool isCurrent() const override { return true; }
    void doneCurrent() override {}
};

// A "context" that cannot be made current, as when the platform has none.
class BrokenContext final : public fss::render::GlContext {
public:
    void makeCurrent() override { throw fss::Error("The test context cannot be made current."); }
    bool isCurrent() const override { return false; }
    void doneCurrent() override {}
};

} // namespace

// ---- face ids against CPU ray casting ----------------------------------------------------------------

struct RayCastCase {
    const char* mesh;
    double azimuth, elevation;
    bool parallel;
    double zoom;
};

class RasterizerVsRayCasting : public ::testing::TestWithParam<RayCastCase> {};

TEST_P(RasterizerVsRayCasting, FaceIdsAgreeWithFirstRayHit) {
    const RayCastCase c = GetParam();
    const Mesh mesh = loadMesh(c.mesh);
    const Tree tree(faces(mesh).first, faces(mesh).second, mesh);
    Rasterizer rasterizer;
    rasterizer.setMesh(mesh);
    // 800 × 600: triangles of bunny00 cover a few pixels, as in a real scan.
    const Camera cam = orbitView(boundsOf(mesh), c.azimuth, c.elevation, 800, 600, c.parallel, c.zoom);
    const FrameBuffers fb = rasterizer.render(cam);
    const Agreement a = compareWithRayCasting(fb, tree, mesh);
    std::cout << "  " << c.mesh << " az " << c.azimuth << " el " << c.elevation
              << (c.parallel ? " parallel" : " perspective") << ": gpu covered " << a.gpuCovered
              << ", cpu hits " << a.cpuHits << ", agree " << a.agree << "/" << a.unionCovered << " = "
              << 100.0 * a.fraction() << " %, disagreeing centres within " << a.worstTie
              << " px of an edge\n";
    EXPECT_GT(a.gpuCovered, 100000u); // the mesh fills a good part of the image
    EXPECT_GE(a.fraction(), 0.999);
    EXPECT_LE(a.worstTie, kTiePx);
    const auto diff = std::size_t(std::llabs(std::int64_t(a.gpuCovered) - std::int64_t(a.cpuHits)));
    EXPECT_LE(diff, a.disagree());
}

std::string caseName(const ::testing::TestParamInfo<RayCastCase>& info) {
    const RayCastCase& c = info.param;
    std::string mesh = c.mesh;
    mesh = mesh.substr(0, mesh.find('.'));
    const auto angle = [](double a) { return (a < 0 ? "m" : "") + std::to_string(int(std::abs(a))); };
    return mesh + "_az" + angle(c.azimuth) + "_el" + angle(c.elevation) +
           (c.parallel ? "_parallel" : "_perspective");
}

void PrintTo(const RayCastCase& c, std::ostream* os) {
    *os << c.mesh << " azimuth " << c.azimuth << " elevation " << c.elevation
        << (c.parallel ? " parallel" : " perspective") << " zoom " << c.zoom;
}

INSTANTIATE_TEST_SUITE_P(Meshes, RasterizerVsRayCasting,
                         ::testing::Values(RayCastCase{"fandisk.off", 30, 25, false, 1.6},
                                           RayCastCase{"fandisk.off", 200, -40, true, 1.6},
                                           RayCastCase{"fandisk.off", 90, 80, false, 1.6},
                                           RayCastCase{"bunny00.off", 20, 15, false, 1.5},
                                           RayCastCase{"bunny00.off", 250, 30, true, 1.5},
                                           RayCastCase{"bunny00.off", 140, -60, false, 1.5}),
                         caseName);

// ---- depth: every covered pixel unprojects onto the sphere -------------------------------------------

TEST(Rasterizer, DepthUnprojectsOntoTheSphere) {
    const Eigen::Vector3d centre(0.3, -0.2, 0.5);
    const double radius = 1.0;
    const Mesh sphere = icosphere(7, radius, centre); // 327 680 faces: polyhedral error < 2e-5 · radius
    Rasterizer rasterizer;
    rasterizer.setMesh(sphere);
    for (bool parallel : {false, true}) {
        const Camera cam = orbitView(rasterizer.bounds(), 35, 20, 256, 192, parallel, 1.2);
        const FrameBuffers fb = rasterizer.render(cam);
        double worst = 0, worstPlane = 0;
        std::size_t samples = 0;
        for (int y = 0; y < fb.height(); ++y)
            for (int x = 0; x < fb.width(); ++x) {
                if (!fb.covered(x, y)) {
                    EXPECT_EQ(fb.depthAt(x, y), 1.0f);
                    continue;
                }
                const Eigen::Vector3d p = fb.camera.unprojectPixelCentre(x, y, fb.depthAt(x, y));
                const double footprint = fb.camera.pixelFootprint(p);
                const double onSphere = std::abs((p - centre).norm() - radius) / footprint;
                // Distance to the plane of the face the id buffer names (the exact rasterized surface).
                const auto h = sphere.halfedge(fss::FaceIndex(fb.faceAt(x, y)));
                const auto& a = sphere.point(sphere.source(h));
                const auto& b = sphere.point(sphere.target(h));
                const auto& c = sphere.point(sphere.target(sphere.next(h)));
                const Eigen::Vector3d A(a.x(), a.y(), a.z()), B(b.x(), b.y(), b.z()), C(c.x(), c.y(), c.z());
                const Eigen::Vector3d n = (B - A).cross(C - A).normalized();
                const double onPlane = std::abs(n.dot(p - A)) / footprint;
                worst = std::max(worst, onSphere);
                worstPlane = std::max(worstPlane, onPlane);
                ++samples;
            }
        std::cout << "  " << (parallel ? "parallel" : "perspective") << ": " << samples
                  << " samples, max distance to the sphere " << worst << " px, to the face plane "
                  << worstPlane << " px\n";
        EXPECT_GT(samples, 10000u);
        EXPECT_LT(worst, 0.01);
        EXPECT_LT(worstPlane, 0.01);
    }
}

// ---- VTK's projection is our Camera's ------------------------------------------------------------------

TEST(Rasterizer, VtkCompositeProjectionEqualsCameraMatrix) {
    Rasterizer rasterizer; // needs no mesh and no GL for this
    for (bool parallel : {false, true}) {
        Camera c;
        c.eye = {3, 2, 5};
        c.focal = {0.5, -0.2, 0.1};
        c.up = {0.1, 0, 1}; // not orthogonal to the view direction: both orthogonalise it the same way
        c.parallel = parallel;
        c.viewAngleDeg = 40;
        c.parallelScale = 1.7;
        c.nearPlane = 2.5;
        c.farPlane = 9;
        c.width = 320;
        c.height = 200;
        const Eigen::Matrix4d vtk = rasterizer.vtkViewProjectionMatrix(c);
        const Eigen::Matrix4d ours = c.viewProjectionMatrix();
        const double rel = (vtk - ours).cwiseAbs().maxCoeff() / ours.cwiseAbs().maxCoeff();
        std::cout << "  " << (parallel ? "parallel" : "perspective") << ": max relative difference " << rel
                  << "\n";
        EXPECT_LT(rel, 1e-9) << "VTK:\n" << vtk << "\nCamera:\n" << ours;
    }
}

TEST(Rasterizer, FrameBuffersCarryTheFittedOrTheGivenCamera) {
    const Mesh mesh = loadMesh("fandisk.off");
    Rasterizer rasterizer;
    rasterizer.setMesh(mesh);
    Camera cam = orbitView(rasterizer.bounds(), 10, 10, 64, 48, false);
    cam.nearPlane = 0.01;
    cam.farPlane = 1000;
    const FrameBuffers fitted = rasterizer.render(cam);
    Camera expected = cam;
    expected.fitClippingRange(rasterizer.bounds());
    EXPECT_DOUBLE_EQ(fitted.camera.nearPlane, expected.nearPlane);
    EXPECT_DOUBLE_EQ(fitted.camera.farPlane, expected.farPlane);
    EXPECT_EQ(fitted.camera.eye, cam.eye);

    const FrameBuffers kept = rasterizer.render(cam, {.keepClippingRange = true});
    EXPECT_EQ(kept.camera.nearPlane, 0.01);
    EXPECT_EQ(kept.camera.farPlane, 1000);
    // Same pixels covered whatever the range (the mesh lies inside both).
    EXPECT_EQ(kept.coveredCount(), fitted.coveredCount());
    // ... and both depths unproject to the same points (the loose range is just less precise).
    double worst = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x)
            if (fitted.covered(x, y) && kept.covered(x, y) && fitted.faceAt(x, y) == kept.faceAt(x, y)) {
                const Eigen::Vector3d a = fitted.camera.unprojectPixelCentre(x, y, fitted.depthAt(x, y));
                const Eigen::Vector3d b = kept.camera.unprojectPixelCentre(x, y, kept.depthAt(x, y));
                worst = std::max(worst, (a - b).norm() / fitted.camera.pixelFootprint(a));
            }
    EXPECT_LT(worst, 0.5);
}

// ---- id decode over several passes -----------------------------------------------------------------

TEST(Rasterizer, MultiPassIdDecodeIsExact) {
    const Mesh mesh = loadMesh("fandisk.off"); // 12 946 faces: 14 bits → 4 passes of 4 bits
    Rasterizer single, multi;
    multi.setIdBitsPerPass(4);
    EXPECT_EQ(multi.idBitsPerPass(), 4);
    single.setMesh(mesh);
    multi.setMesh(mesh);
    for (double az : {15.0, 160.0}) {
        const Camera cam = orbitView(single.bounds(), az, 30, 200, 150, false, 1.4);
        const FrameBuffers a = single.render(cam);
        const FrameBuffers b = multi.render(cam);
        EXPECT_EQ(single.lastStats().passes, 1);
        EXPECT_EQ(multi.lastStats().passes, 4);
        ASSERT_EQ(a.faceId.size(), b.faceId.size());
        EXPECT_GT(a.coveredCount(), 5000u);
        EXPECT_TRUE(a.faceId == b.faceId);
        EXPECT_TRUE(a.depth == b.depth);
        // Ids above 4 bits really occur, so the high passes carried information.
        EXPECT_GT(*std::max_element(a.faceId.begin(), a.faceId.end(),
                                    [](auto u, auto v) {
                                        return (u == FrameBuffers::kNoFace ? 0 : u) <
                                               (v == FrameBuffers::kNoFace ? 0 : v);
                                    }),
                  1u << 12);
    }
    // Switching back rebuilds the passes for the stored mesh.
    multi.setIdBitsPerPass(24);
    multi.render(orbitView(single.bounds(), 15, 30, 32, 32, false));
    EXPECT_EQ(multi.lastStats().passes, 1);
    EXPECT_THROW(multi.setIdBitsPerPass(0), fss::InvalidInputError);
    EXPECT_THROW(multi.setIdBitsPerPass(25), fss::InvalidInputError);
}

// ---- garbage in the mesh: ids are Face_index values, not dense indices -----------------------------

TEST(Rasterizer, MeshWithRemovedFacesReportsTheirOwnIndices) {
    Mesh mesh = loadMesh("fandisk.off");
    // Remove every third face (leaving garbage: indices are no longer dense).
    std::vector<fss::FaceIndex> gone;
    for (auto f : mesh.faces())
        if (std::size_t(f) % 3 == 0) gone.push_back(f);
    for (auto f : gone)
        CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
    ASSERT_TRUE(mesh.has_garbage());
    const Tree tree(faces(mesh).first, faces(mesh).second, mesh);
    Rasterizer rasterizer;
    rasterizer.setMesh(mesh);
    EXPECT_EQ(rasterizer.faceCount(), mesh.number_of_faces());
    const FrameBuffers fb = rasterizer.render(orbitView(rasterizer.bounds(), 40, 30, 200, 160, false, 1.5));
    for (auto id : fb.faceId)
        if (id != FrameBuffers::kNoFace) {
            ASSERT_LT(id, mesh.num_faces());
            ASSERT_FALSE(mesh.is_removed(fss::FaceIndex(id)));
        }
    const Agreement a = compareWithRayCasting(fb, tree, mesh);
    EXPECT_GE(a.fraction(), 0.998); // 200 × 160: relatively more edge pixels
    EXPECT_LE(a.worstTie, kTiePx);
}

// ---- the mesh is uploaded once, whatever the camera does ---------------------------------------------

TEST(Rasterizer, MeshIsUploadedOnceForManyCameras) {
    const Mesh mesh = loadMesh("fandisk.off");
    Rasterizer rasterizer;
    EXPECT_EQ(rasterizer.uploadCount(), 0u);
    rasterizer.setMesh(mesh);
    for (int i = 0; i < 5; ++i) {
        const Camera cam =
            orbitView(rasterizer.bounds(), 70.0 * i, 10.0 * i - 20, 96 + 32 * i, 80, i % 2 == 1);
        rasterizer.render(cam);
    }
    EXPECT_EQ(rasterizer.uploadCount(), 1u);
    rasterizer.setMesh(loadMesh("elephant.off"));
    rasterizer.render(orbitView(rasterizer.bounds(), 0, 0, 64, 64, false));
    rasterizer.render(orbitView(rasterizer.bounds(), 90, 0, 64, 64, false));
    EXPECT_EQ(rasterizer.uploadCount(), 2u);
}

// ---- the caller's own context --------------------------------------------------------------------------

TEST(Rasterizer, RendersInACallerSuppliedContextAndRestoresItsState) {
    const Mesh mesh = loadMesh("fandisk.off");
    TestEglContext context;
    Camera cam;
    FrameBuffers theirs, ours;
    {
        Rasterizer rasterizer(context);
        rasterizer.setMesh(mesh);
        cam = orbitView(rasterizer.bounds(), 30, 20, 160, 120, false, 1.3);

        // The application has its own framebuffer bound and its own viewport.
        context.makeCurrent();
        auto genFramebuffers =
            reinterpret_cast<PFNGLGENFRAMEBUFFERSPROC>(eglGetProcAddress("glGenFramebuffers"));
        auto bindFramebuffer =
            reinterpret_cast<PFNGLBINDFRAMEBUFFERPROC>(eglGetProcAddress("glBindFramebuffer"));
        auto deleteFramebuffers =
            reinterpret_cast<PFNGLDELETEFRAMEBUFFERSPROC>(eglGetProcAddress("glDeleteFramebuffers"));
        GLuint fbo = 0;
        genFramebuffers(1, &fbo);
        bindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(3, 4, 50, 60);

        theirs = rasterizer.render(cam);
        EXPECT_TRUE(context.isCurrent()); // it was current before: the Rasterizer leaves it so
        GLint draw = -1, read = -1, viewport[4] = {};
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read);
        glGetIntegerv(GL_VIEWPORT, viewport);
        EXPECT_EQ(GLuint(draw), fbo);
        EXPECT_EQ(GLuint(read), fbo);
        EXPECT_EQ(viewport[0], 3);
        EXPECT_EQ(viewport[1], 4);
        EXPECT_EQ(viewport[2], 50);
        EXPECT_EQ(viewport[3], 60);
        bindFramebuffer(GL_FRAMEBUFFER, 0);
        deleteFramebuffers(1, &fbo);
        context.doneCurrent();

        // Not current before → released afterwards.
        theirs = rasterizer.render(cam);
        EXPECT_FALSE(context.isCurrent());
        EXPECT_GT(context.makeCurrentCalls, 0);
    }
    Rasterizer headless;
    headless.setMesh(mesh);
    ours = headless.render(cam);
    EXPECT_GT(ours.coveredCount(), 3000u);
    EXPECT_TRUE(theirs.faceId == ours.faceId);
    EXPECT_TRUE(theirs.depth == ours.depth);
}

// ---- head-less, several per process -------------------------------------------------------------------

TEST(Rasterizer, WorksWithoutDisplayAndQuietly) {
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    const Mesh mesh = loadMesh("elephant.off");
    // Debian's GLX-only GLEW makes VTK log "GLEW could not be initialized" in an EGL context: the
    // Rasterizer drops that known-harmless message, so a first render prints nothing at all.
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    std::size_t covered = 0;
    std::string renderer;
    {
        Rasterizer rasterizer;
        rasterizer.setMesh(mesh);
        covered = rasterizer.render(orbitView(rasterizer.bounds(), 0, 0, 128, 128, false)).coveredCount();
        renderer = rasterizer.glRenderer();
    }
    const std::string err = ::testing::internal::GetCapturedStderr();
    const std::string out = ::testing::internal::GetCapturedStdout();
    EXPECT_EQ(err, "");
    EXPECT_EQ(out, "");
    EXPECT_GT(covered, 1000u);
    EXPECT_FALSE(renderer.empty());
    std::cout << "  GL_RENDERER: " << renderer << "\n";
}

TEST(Rasterizer, TwoRasterizersInOneProcess) {
    const Mesh fandisk = loadMesh("fandisk.off");
    const Mesh elephant = loadMesh("elephant.off");
    auto a = std::make_unique<Rasterizer>();
    Rasterizer b;
    a->setMesh(fandisk);
    b.setMesh(elephant);
    const Camera ca = orbitView(a->bounds(), 30, 30, 100, 100, false);
    const Camera cb = orbitView(b.bounds(), 30, 30, 160, 120, true);
    const FrameBuffers a1 = a->render(ca), b1 = b.render(cb), a2 = a->render(ca), b2 = b.render(cb);
    EXPECT_TRUE(a1.faceId == a2.faceId);
    EXPECT_TRUE(b1.faceId == b2.faceId);
    EXPECT_GT(a1.coveredCount(), 1000u);
    EXPECT_GT(b1.coveredCount(), 1000u);
    EXPECT_LE(*std::max_element(a1.faceId.begin(), a1.faceId.end(),
                                [](auto u, auto v) {
                                    return (u == FrameBuffers::kNoFace ? 0 : u) <
                                           (v == FrameBuffers::kNoFace ? 0 : v);
                                }),
              fandisk.number_of_faces());
    a.reset(); // destroying one leaves the other working
    const FrameBuffers b3 = b.render(cb);
    EXPECT_TRUE(b1.faceId == b3.faceId);
    // Moving keeps it working.
    Rasterizer c = std::move(b);
    EXPECT_TRUE(c.render(cb).faceId == b1.faceId);
}

// ---- errors --------------------------------------------------------------------------------------------

TEST(Rasterizer, RejectsBadInputWithOneSentence) {
    Rasterizer rasterizer;
    EXPECT_THROW(rasterizer.render(Camera{}), fss::InvalidInputError); // no mesh yet
    EXPECT_THROW(rasterizer.setMesh(Mesh{}), fss::InvalidInputError);
    Mesh bad = icosphere(0, 1.0, Eigen::Vector3d::Zero());
    bad.point(*bad.vertices().begin()) = fss::Point3(std::nan(""), 0, 0);
    EXPECT_THROW(rasterizer.setMesh(bad), fss::InvalidInputError);
    EXPECT_FALSE(rasterizer.hasMesh());

    rasterizer.setMesh(icosphere(1, 1.0, Eigen::Vector3d::Zero()));
    Camera cam = orbitView(rasterizer.bounds(), 0, 0, 64, 64, false);
    Camera zeroWidth = cam;
    zeroWidth.width = 0;
    EXPECT_THROW(rasterizer.render(zeroWidth), fss::InvalidInputError);
    Camera noDirection = cam;
    noDirection.focal = noDirection.eye;
    EXPECT_THROW(rasterizer.render(noDirection), fss::InvalidInputError);
    Camera lookingAway = cam;
    lookingAway.focal = cam.eye + (cam.eye - cam.focal); // the mesh is behind the eye
    try {
        rasterizer.render(lookingAway);
        ADD_FAILURE() << "a mesh behind the camera was accepted";
    } catch (const fss::InvalidInputError& e) {
        EXPECT_NE(std::string(e.what()).find("behind"), std::string::npos) << e.what();
    }
    // A failed setMesh kept the previous mesh.
    EXPECT_NO_THROW(rasterizer.render(cam));
}

TEST(Rasterizer, UnusableContextGivesAClearError) {
    BrokenContext broken;
    Rasterizer rasterizer(broken);
    rasterizer.setMesh(icosphere(1, 1.0, Eigen::Vector3d::Zero()));
    try {
        rasterizer.render(orbitView(rasterizer.bounds(), 0, 0, 16, 16, false));
        ADD_FAILURE() << "rendering without a context succeeded";
    } catch (const fss::Error& e) {
        EXPECT_STREQ(e.what(), "The test context cannot be made current.");
    }
}

TEST(Rasterizer, NoCurrentContextGivesAClearError) {
    AbsentContext absent;
    Rasterizer rasterizer(absent);
    rasterizer.setMesh(icosphere(1, 1.0, Eigen::Vector3d::Zero()));
    try {
        rasterizer.render(orbitView(rasterizer.bounds(), 0, 0, 16, 16, false));
        ADD_FAILURE() << "rendering without a context succeeded";
    } catch (const fss::Error& e) {
        EXPECT_STREQ(e.what(),
                     "No OpenGL context is current: the Rasterizer's GlContext did not make one current.");
    }
}
