#pragma once
/// \file gpu_mesh_renderer.h
/// fss::MeshRenderer on the GPU: the scan pipeline (scan_pipeline.h) rendering through a Rasterizer.

#include "fss/mesh_renderer.h"
#include "fss/render/rasterizer.h"

namespace fss::render {

/// A MeshRenderer backed by a Rasterizer: the mesh is uploaded once by setMesh(), render() draws it from
/// any camera (clipping range fitted tightly to the mesh).
class GpuMeshRenderer final : public MeshRenderer {
public:
    /// Renders head-less (Mesa EGL surfaceless context). \throw fss::Error when no context can be made.
    GpuMeshRenderer() = default;
    /// Renders in the caller's context (e.g. a Qt widget's); \p context must outlive this object.
    explicit GpuMeshRenderer(GlContext& context) : rasterizer_(context) {}

    void setMesh(const Mesh& mesh) override { rasterizer_.setMesh(mesh); }
    FrameBuffers render(const Camera& camera) override { return rasterizer_.render(camera); }

    /// The underlying Rasterizer (statistics, upload count).
    Rasterizer& rasterizer() { return rasterizer_; }

private:
    Rasterizer rasterizer_;
};

} // namespace fss::render
