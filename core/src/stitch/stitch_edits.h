#pragma once
// stitchPatch with a look at each edit before it is made (internal to FSS::core): Session::accept stitches
// into its current mesh in place and journals the elements each edit may change (session/mesh_delta.h).
#include "fss/stitch.h"

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace fss::detail {

/// Called by stitchPatch before it edits the mesh for one piece of the patch, with the mesh as it is then:
/// the faces the edit removes and the existing vertices its new faces use. The edit changes nothing else of
/// the mesh than these faces, these vertices and the vertices of these faces, the halfedges into and out of
/// them, and new elements (appended, or reusing elements the stitch removed); the first edit may also add
/// the face properties props::faceQuality / props::faceScanId (with the values a mesh without them reads as).
using BeforeStitchEdit = std::function<void(const Mesh& mesh, std::span<const FaceIndex> removed,
                                            std::span<const VertexIndex> vertices)>;

/// fss::stitchPatch (stitch.h), calling \p beforeEdit (when set) before every edit of \p current.
StitchReport stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                         const StitchOptions& options, std::span<const std::uint32_t> faceIds,
                         const Progress& progress, const BeforeStitchEdit& beforeEdit,
                         std::vector<std::uint8_t>* stitchedPatchFaces = nullptr);

} // namespace fss::detail
