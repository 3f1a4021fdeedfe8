// Snapshots: the coloured pixels of the PNG are exactly the pixels the mesh covers, their number matches
// the sphere's projected disc and the CPU ray caster's coverage, the colours follow the minimum-angle map,
// and PNG files round-trip.
#include "fss/camera.h"
#include "fss/error.h"
#include "fss/frame_buffers.h"
#include "fss/mesh_io.h"
#include "fss/render/snapshot.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

namespace {

using fss::render::Rgb;

TEST(Snapshot, ColorMap) {
    EXPECT_EQ(fss::render::minAngleColor(0), (Rgb{215, 25, 28}));
    EXPECT_EQ(fss::render::minAngleColor(30), (Rgb{250, 220, 40}));
    EXPECT_EQ(fss::render::minAngleColor(60), (Rgb{26, 150, 65}));
    EXPECT_EQ(fss::render::minAngleColor(89), (Rgb{26, 150, 65}));
    EXPECT_EQ(fss::render::minAngleColor(-5), (Rgb{215, 25, 28}));
    // Halfway between yellow and green.
    EXPECT_EQ(fss::render::minAngleColor(45), (Rgb{138, 185, 53}));
}

// A unit sphere seen by a parallel camera: the coloured pixels are the covered ones, and their number is
// the area of the projected disc (the icosphere's silhouette is inscribed: slightly less).
TEST(Snapshot, CoverageMatchesTheProjectedDisc) {
    const fss::Mesh sphere = fss::shapes::icosphere(5); // 20480 faces, all near-equilateral
    fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(sphere), 320, 240, true);
    camera.parallelScale = 1.6; // half the image height in world units
    const fss::render::Snapshot shot = fss::render::renderSnapshot(sphere, camera);
    ASSERT_EQ(shot.image.width, 320);
    ASSERT_EQ(shot.image.height, 240);
    const std::size_t coloured = shot.image.countDifferentFrom({255, 255, 255});
    EXPECT_EQ(coloured, shot.covered);
    const double pixel = 2 * camera.parallelScale / camera.height;
    const double disc = std::numbers::pi / (pixel * pixel);
    EXPECT_NEAR(double(coloured) / disc, 1.0, 0.005) << shot.renderer << ": " << coloured << " vs " << disc;

    // The colours are the map's green (every minimum angle of a level-5 icosphere is above 50°), shaded:
    // green dominates in every coloured pixel, and the centre (frontal) pixel is the brightest.
    std::size_t greenish = 0;
    for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 320; ++x) {
            const Rgb p = shot.image.pixel(x, y);
            if (p == Rgb{255, 255, 255}) continue;
            greenish += p[1] > p[0] && p[1] > p[2];
        }
    EXPECT_EQ(greenish, coloured);

    // The PNG holds the same pixels.
    const auto png = fss::test::tmpPath("snapshot_sphere.png");
    fss::render::writePng(shot.image, png);
    const fss::render::Image back = fss::render::readPng(png);
    EXPECT_EQ(back.width, 320);
    EXPECT_EQ(back.height, 240);
    EXPECT_EQ(back.rgb, shot.image.rgb);
}

// The GPU snapshot of fandisk covers the same pixels as CPU ray casting (up to pixels on the silhouette).
TEST(Snapshot, GpuCoverageMatchesCpuRayCasting) {
    const fss::Mesh fandisk = fss::readMesh(fss::test::meshPath("fandisk.off"));
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(fandisk), 400, 300);
    fss::render::SnapshotOptions options;
    const fss::render::Snapshot gpu = fss::render::renderSnapshot(fandisk, camera, options);
    options.renderer = fss::render::SnapshotOptions::Renderer::Cpu;
    const fss::render::Snapshot cpu = fss::render::renderSnapshot(fandisk, camera, options);
    EXPECT_EQ(cpu.renderer, "cpu");
    const double fraction = double(gpu.image.countDifferentFrom({255, 255, 255})) / (400.0 * 300.0);
    const double reference = double(cpu.covered) / (400.0 * 300.0);
    EXPECT_GT(fraction, 0.1); // not blank: fandisk fills a good part of the fitted view
    EXPECT_NEAR(fraction, reference, 0.01 * reference) << gpu.renderer;
    // Fandisk's minimum angles range from 17° to 60° (mean 43°): orange-yellow and green pixels both occur.
    int orange = 0, green = 0;
    for (int y = 0; y < 300; ++y)
        for (int x = 0; x < 400; ++x) {
            const Rgb p = gpu.image.pixel(x, y);
            if (p == Rgb{255, 255, 255}) continue;
            orange += p[0] > p[1];
            green += p[1] > p[0] + 20;
        }
    EXPECT_GT(orange, 100);
    EXPECT_GT(green, 1000);
    fss::render::writePng(gpu.image, fss::test::tmpPath("snapshot_fandisk.png"));
}

// Issue #21: the legend (a VTK scalar bar) is appended at the right; the mesh's picture is unchanged; the
// bar shows the map's red (0°) below its green (60°), and text in the ink colour.
TEST(Snapshot, LegendIsAppendedAtTheRight) {
    const fss::Mesh sphere = fss::shapes::icosphere(3);
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(sphere), 320, 240);
    fss::render::SnapshotOptions options;
    options.renderer = fss::render::SnapshotOptions::Renderer::Cpu; // the same pixels with and without
    const fss::render::Snapshot plain = fss::render::renderSnapshot(sphere, camera, options);
    options.legend = true;
    const fss::render::Snapshot shot = fss::render::renderSnapshot(sphere, camera, options);
    const int lw = fss::render::legendWidth(240);
    ASSERT_EQ(shot.image.width, 320 + lw);
    ASSERT_EQ(shot.image.height, 240);
    for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 320; ++x)
            ASSERT_EQ(shot.image.pixel(x, y), plain.image.pixel(x, y));
    // Rows of the legend's red (minAngleColor(0)) and green (minAngleColor(60)) pixels, and dark text.
    const Rgb red = fss::render::minAngleColor(0), green = fss::render::minAngleColor(60);
    auto near = [](const Rgb& p, const Rgb& q) {
        return std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) < 30;
    };
    long redRows = 0, greenRows = 0, reds = 0, greens = 0, dark = 0;
    for (int y = 0; y < 240; ++y)
        for (int x = 320; x < 320 + lw; ++x) {
            const Rgb p = shot.image.pixel(x, y);
            if (near(p, red)) {
                ++reds;
                redRows += y;
            }
            if (near(p, green)) {
                ++greens;
                greenRows += y;
            }
            dark += p[0] < 80 && p[1] < 80 && p[2] < 80;
        }
    EXPECT_GT(reds, 50);
    EXPECT_GT(greens, 50);
    EXPECT_GT(double(redRows) / double(reds), double(greenRows) / double(greens)); // red lower (y down)
    EXPECT_GT(dark, 30);                                                           // title and labels
    fss::render::writePng(shot.image, fss::test::tmpPath("snapshot_legend.png"));
    EXPECT_THROW(fss::render::renderMinAngleLegend(8, 8, {255, 255, 255}), fss::InvalidInputError);
}

// Flat shading of a hand-made buffer: a frontal face gets exactly its colour inside, darker on its border.
TEST(Snapshot, ShadeFacesIsFlatAndOutlined) {
    fss::Mesh mesh;
    const auto a = mesh.add_vertex({0, 0, 0}), b = mesh.add_vertex({1, 0, 0}), c = mesh.add_vertex({0, 1, 0}),
               d = mesh.add_vertex({1, 1, 0});
    mesh.add_face(a, b, d);
    mesh.add_face(a, d, c);
    fss::FrameBuffers buffers;
    buffers.camera.eye = {0.5, 0.5, 10};
    buffers.camera.focal = {0.5, 0.5, 0};
    buffers.camera.parallel = true; // every ray is frontal: cos θ = 1
    buffers.camera.width = 4;
    buffers.camera.height = 2;
    buffers.depth.assign(8, 0.5f);
    buffers.faceId = {0, 0, 1, 1, fss::FrameBuffers::kNoFace, 0, 1, 1};
    const std::vector<Rgb> colors{{200, 100, 50}, {10, 20, 255}};
    fss::render::SnapshotOptions options;
    options.outline = 0.5;
    const fss::render::Image img = fss::render::shadeFaces(mesh, buffers, colors, options);
    EXPECT_EQ(img.pixel(0, 0), (Rgb{200, 100, 50})); // below it is background: no border
    EXPECT_EQ(img.pixel(1, 0), (Rgb{100, 50, 25}));  // face 1 to its right: border
    EXPECT_EQ(img.pixel(3, 0), (Rgb{10, 20, 255}));
    EXPECT_EQ(img.pixel(0, 1), (Rgb{255, 255, 255})); // background
    EXPECT_EQ(img.pixel(1, 1), (Rgb{100, 50, 25}));
    EXPECT_EQ(img.pixel(2, 1), (Rgb{10, 20, 255}));
    buffers.faceId[0] = 7;
    EXPECT_THROW(fss::render::shadeFaces(mesh, buffers, colors, options), fss::InvalidInputError);
}

TEST(Snapshot, PngErrors) {
    fss::render::Image img{2, 1, {1, 2, 3, 4, 5, 6}};
    EXPECT_THROW(fss::render::writePng(img, fss::test::tmpPath("no_such_dir/x.png")), fss::IoError);
    img.rgb.pop_back();
    EXPECT_THROW(fss::render::writePng(img, fss::test::tmpPath("bad.png")), fss::InvalidInputError);
    EXPECT_THROW(fss::render::readPng(fss::test::tmpPath("no_such.png")), fss::IoError);
    const auto notPng = fss::test::tmpPath("not_a_png.png");
    std::ofstream(notPng) << "hello";
    EXPECT_THROW(fss::render::readPng(notPng), fss::IoError);
}

} // namespace
