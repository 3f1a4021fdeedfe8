#pragma once
/// \file renderer_choice.h
/// Which fss::MeshRenderer a head-less program scans and pictures with: the GPU (GpuMeshRenderer in its
/// own Mesa EGL surfaceless context, no X server needed) or CPU ray casting (CpuMeshRenderer: exact, needs
/// no OpenGL, slower). This is the one place that decides "GPU, else CPU": `fss-remesh scan`, `run` and
/// `auto` (their `--renderer auto|gpu|cpu`) and renderSnapshot (snapshot.h) all choose here.
///
///     std::string why;
///     auto renderer = fss::render::makeRenderer(fss::render::RendererChoice::Auto, &why);
///     if (!why.empty()) std::cerr << "note: " << why << " Falling back to CPU ray casting.\n";
///
/// A renderer that draws in an application's own context (a Qt widget's) is not made here: see
/// GpuMeshRenderer(GlContext&).

#include "fss/scan_pipeline.h"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace fss::render {

/// Which renderer to use.
enum class RendererChoice {
    Auto, ///< the GPU when a head-less OpenGL context can be created, else CPU ray casting
    Gpu,  ///< the GPU only: fails when no OpenGL context can be created
    Cpu,  ///< CPU ray casting
};

/// The names of the choices, in the order of the enum: "auto", "gpu", "cpu" (as the command lines take
/// them).
inline constexpr std::array<std::string_view, 3> kRendererChoiceNames{"auto", "gpu", "cpu"};

/// The name of \p choice: "auto", "gpu" or "cpu".
std::string_view rendererChoiceName(RendererChoice choice);

/// The choice named \p name ("auto", "gpu" or "cpu", exactly); nullopt for any other text.
std::optional<RendererChoice> parseRendererChoice(std::string_view name);

/// Makes one renderer as \p choice says: a GpuMeshRenderer with its own head-less context (Gpu, and Auto
/// when that context can be created) or a CpuMeshRenderer (Cpu, and Auto when it cannot). When Auto falls
/// back to the CPU, \p fallbackReason (if given) receives the sentence saying why the GPU failed; it is
/// set empty otherwise.
/// \throw fss::Error with Gpu when no OpenGL context can be created; fss::InvalidInputError is never
///        taken for a missing context and always propagates.
std::unique_ptr<MeshRenderer> makeRenderer(RendererChoice choice, std::string* fallbackReason = nullptr);

/// Gpu for a GpuMeshRenderer, Cpu for any other MeshRenderer (what makeRenderer made).
RendererChoice rendererKind(const MeshRenderer& renderer);

/// How a renderer made by makeRenderer renders, for reports: "gpu (<GL_RENDERER>)" for a GpuMeshRenderer
/// (just "gpu" before its first use of GL), "cpu" for any other MeshRenderer.
std::string rendererDescription(MeshRenderer& renderer);

/// What chooseRenderer decided.
struct RendererSelection {
    /// Makes a renderer of the kind that was decided on, a new one per call: a fss::RendererFactory
    /// (session.h) for SessionOptions::renderer, AutoOptions::renderer and replaySession.
    std::function<std::unique_ptr<MeshRenderer>()> factory;
    /// Gpu or Cpu: what the factory makes (never Auto).
    RendererChoice used = RendererChoice::Cpu;
    /// Why Auto fell back to the CPU (one sentence); empty when it did not.
    std::string fallbackReason;
};

/// Decides once which renderer a fss::RendererFactory makes (for work that creates several renderers, such as
/// replaySession and autoRemesh). For Gpu and Auto a GPU renderer is created and dropped as a probe
/// (makeRenderer): when that works, the factory makes GpuMeshRenderers, else (Auto only) CpuMeshRenderers.
/// \throw fss::Error with Gpu when no OpenGL context can be created.
RendererSelection chooseRenderer(RendererChoice choice);

} // namespace fss::render
