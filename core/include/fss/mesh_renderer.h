#pragma once
/// \file mesh_renderer.h
/// How a mesh is rendered into FrameBuffers (depth + face ids) for a scan (DESIGN.md §1 "Scan"): the
/// MeshRenderer interface, implemented here by CPU ray casting (CpuMeshRenderer) and in FSS::render by
/// the GPU (render::GpuMeshRenderer). Scans, masks and the automatic remesher only see this interface.

#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"

#include <memory>

namespace fss {

/// Renders one mesh into FrameBuffers (depth + face ids) from any camera. setMesh() prepares the mesh
/// once (GPU upload, acceleration structure); render() may then be called with many cameras.
class MeshRenderer {
public:
    virtual ~MeshRenderer() = default;
    /// Prepares \p mesh for rendering. Implementations may keep a reference: the mesh must stay alive and
    /// unchanged until the next setMesh(). \throw InvalidInputError for an empty mesh.
    virtual void setMesh(const Mesh& mesh) = 0;
    /// Renders the mesh of the last setMesh() with \p camera (its clipping range fitted tightly around the
    /// mesh; FrameBuffers::camera is the camera actually used).
    /// \throw InvalidInputError for an invalid camera or a mesh entirely behind it.
    virtual FrameBuffers render(const Camera& camera) = 0;
};

/// MeshRenderer by CPU ray casting (raycast.h rasterizeOnCpu): exact, needs no OpenGL, slower than the
/// GPU (about 60 ms for 256² on a 13k-face mesh). Keeps a reference to the mesh of setMesh().
class CpuMeshRenderer final : public MeshRenderer {
public:
    CpuMeshRenderer();
    ~CpuMeshRenderer() override;
    void setMesh(const Mesh& mesh) override;
    FrameBuffers render(const Camera& camera) override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss
