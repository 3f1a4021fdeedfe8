#include "fss/scan_workspace.h"

#include "scan/scan_workspace_impl.h"

#include <utility>

namespace fss {

ScanWorkspace::ScanWorkspace() : impl_(std::make_unique<Impl>()) {}
ScanWorkspace::~ScanWorkspace() = default;
ScanWorkspace::ScanWorkspace(ScanWorkspace&&) noexcept = default;
ScanWorkspace& ScanWorkspace::operator=(ScanWorkspace&&) noexcept = default;

ScanWorkspace::Impl& ScanWorkspace::impl() {
    if (!impl_) impl_ = std::make_unique<Impl>();
    return *impl_;
}

void ScanWorkspace::recycle(SampleGrid&& grid) {
    Impl& w = impl();
    if (grid.samples.capacity() > w.samples.capacity()) w.samples.swap(grid.samples);
    grid.samples.clear();
    grid.rows = grid.cols = 0;
}

void ScanWorkspace::recycle(Patch&& patch) {
    const Mesh& m = patch.mesh;
    // Only a mesh as triangulateGrid made it (nothing removed) can be refilled like a fresh one.
    const bool reusable = !m.has_garbage() && m.number_of_removed_vertices() == 0 &&
                          m.number_of_removed_edges() == 0 && m.number_of_removed_faces() == 0;
    if (!reusable) return;
    Impl& w = impl();
    std::swap(w.patch, patch); // moves only: no allocation
    w.hasPatch = true;
}

void ScanWorkspace::release() {
    impl_.reset();
}

} // namespace fss
