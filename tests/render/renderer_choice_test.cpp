// The one choice of a head-less renderer (renderer_choice.h): names, CPU on request, the GPU when a head-less
// context can be made (this program runs without an X server), and factories that make what was chosen.
#include "fss/camera.h"
#include "fss/render/renderer_choice.h"
#include "fss/scan_pipeline.h"
#include "fss/shapes.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace {

using fss::render::RendererChoice;

TEST(RendererChoice, NamesRoundTrip) {
    for (RendererChoice c : {RendererChoice::Auto, RendererChoice::Gpu, RendererChoice::Cpu})
        EXPECT_EQ(fss::render::parseRendererChoice(fss::render::rendererChoiceName(c)), c);
    EXPECT_EQ(fss::render::rendererChoiceName(RendererChoice::Auto), "auto");
    EXPECT_EQ(fss::render::rendererChoiceName(RendererChoice::Gpu), "gpu");
    EXPECT_EQ(fss::render::rendererChoiceName(RendererChoice::Cpu), "cpu");
    EXPECT_FALSE(fss::render::parseRendererChoice("session"));
    EXPECT_FALSE(fss::render::parseRendererChoice("GPU"));
    EXPECT_FALSE(fss::render::parseRendererChoice(""));
}

TEST(RendererChoice, CpuOnRequest) {
    std::string why = "stale";
    const auto renderer = fss::render::makeRenderer(RendererChoice::Cpu, &why);
    EXPECT_EQ(fss::render::rendererKind(*renderer), RendererChoice::Cpu);
    EXPECT_EQ(fss::render::rendererDescription(*renderer), "cpu");
    EXPECT_TRUE(why.empty());
    const fss::render::RendererSelection selection = fss::render::chooseRenderer(RendererChoice::Cpu);
    EXPECT_EQ(selection.used, RendererChoice::Cpu);
    EXPECT_TRUE(selection.fallbackReason.empty());
    EXPECT_EQ(fss::render::rendererKind(*selection.factory()), RendererChoice::Cpu);
}

// Mesa's EGL surfaceless platform needs no X server: auto is the GPU here, and the GPU renderer renders.
TEST(RendererChoice, AutoIsTheGpuHeadless) {
    ASSERT_EQ(std::getenv("DISPLAY"), nullptr) << "this test must run without an X server";
    std::string why;
    const auto renderer = fss::render::makeRenderer(RendererChoice::Auto, &why);
    EXPECT_EQ(fss::render::rendererKind(*renderer), RendererChoice::Gpu) << why;
    EXPECT_TRUE(why.empty());
    EXPECT_EQ(fss::render::rendererDescription(*renderer), "gpu"); // no GL used yet

    const fss::Mesh sphere = fss::shapes::icosphere(2);
    renderer->setMesh(sphere);
    const fss::Camera camera =
        fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(sphere), 64, 48, false);
    EXPECT_GT(renderer->render(camera).coveredCount(), 0u);
    EXPECT_EQ(fss::render::rendererDescription(*renderer).rfind("gpu (", 0), 0u);

    for (RendererChoice choice : {RendererChoice::Auto, RendererChoice::Gpu}) {
        const fss::render::RendererSelection selection = fss::render::chooseRenderer(choice);
        EXPECT_EQ(selection.used, RendererChoice::Gpu);
        EXPECT_TRUE(selection.fallbackReason.empty());
        EXPECT_EQ(fss::render::rendererKind(*selection.factory()), RendererChoice::Gpu);
    }
}

} // namespace
