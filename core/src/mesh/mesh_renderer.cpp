#include "fss/mesh_renderer.h"

#include "fss/error.h"
#include "fss/raycast.h"

namespace fss {

struct CpuMeshRenderer::Impl {
    std::unique_ptr<RayCaster> caster;
};

CpuMeshRenderer::CpuMeshRenderer() : impl_(std::make_unique<Impl>()) {}
CpuMeshRenderer::~CpuMeshRenderer() = default;

void CpuMeshRenderer::setMesh(const Mesh& mesh) {
    if (mesh.number_of_faces() == 0) throw InvalidInputError("The mesh to render has no faces.");
    impl_->caster = std::make_unique<RayCaster>(mesh);
}

FrameBuffers CpuMeshRenderer::render(const Camera& camera) {
    if (!impl_->caster) throw InvalidInputError("No mesh was given to the CPU renderer before rendering.");
    const Mesh& mesh = impl_->caster->mesh();
    Camera fitted = camera;
    fitted.fitClippingRange(boundingBox(mesh));
    fitted.validate();
    return rasterizeOnCpu(*impl_->caster, fitted);
}

} // namespace fss
