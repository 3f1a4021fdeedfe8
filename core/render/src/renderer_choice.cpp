// GPU else CPU: the one choice of a head-less renderer (renderer_choice.h).
#include "fss/render/renderer_choice.h"

#include "fss/error.h"
#include "fss/render/gpu_mesh_renderer.h"

namespace fss::render {

std::string_view rendererChoiceName(RendererChoice choice) {
    return kRendererChoiceNames[std::size_t(choice)];
}

std::optional<RendererChoice> parseRendererChoice(std::string_view name) {
    for (std::size_t i = 0; i < kRendererChoiceNames.size(); ++i)
        if (name == kRendererChoiceNames[i]) return RendererChoice(i);
    return std::nullopt;
}

std::unique_ptr<MeshRenderer> makeRenderer(RendererChoice choice, std::string* fallbackReason) {
    if (fallbackReason) fallbackReason->clear();
    if (choice == RendererChoice::Cpu) return std::make_unique<CpuMeshRenderer>();
    try {
        return std::make_unique<GpuMeshRenderer>(); // creates the head-less context: throws without GL
    } catch (const InvalidInputError&) {
        throw; // a wrong input, not a missing OpenGL context
    } catch (const Error& e) {
        if (choice == RendererChoice::Gpu) throw;
        if (fallbackReason) *fallbackReason = e.what();
        return std::make_unique<CpuMeshRenderer>();
    }
}

RendererChoice rendererKind(const MeshRenderer& renderer) {
    return dynamic_cast<const GpuMeshRenderer*>(&renderer) ? RendererChoice::Gpu : RendererChoice::Cpu;
}

std::string rendererDescription(MeshRenderer& renderer) {
    auto* gpu = dynamic_cast<GpuMeshRenderer*>(&renderer);
    if (!gpu) return "cpu";
    const std::string gl = gpu->rasterizer().glRenderer();
    return gl.empty() ? "gpu" : "gpu (" + gl + ")";
}

RendererSelection chooseRenderer(RendererChoice choice) {
    RendererSelection selection;
    if (choice != RendererChoice::Cpu) // the probe: a GPU renderer, or the CPU one Auto falls back to
        selection.used = rendererKind(*makeRenderer(choice, &selection.fallbackReason));
    if (selection.used == RendererChoice::Gpu)
        selection.factory = [] { return std::make_unique<GpuMeshRenderer>(); };
    else
        selection.factory = [] { return std::make_unique<CpuMeshRenderer>(); };
    return selection;
}

} // namespace fss::render
