#pragma once
/// \file frame_buffers.h
/// What one off-screen render of a mesh gives back: the depth buffer and the face-id buffer, with the
/// exact camera (image size, clipping range) that produced them. Produced by fss::render::Rasterizer;
/// plain data so that core code (scan, masks, direction fields) never needs VTK.

#include "fss/camera.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fss {

/// Depth + face id per pixel. Row 0 is the **top** image row (same convention as Camera screen coords).
struct FrameBuffers {
    /// faceId value of a pixel that no face covers.
    static constexpr std::uint32_t kNoFace = 0xFFFFFFFFu;

    Camera camera;                     ///< camera of the render; camera.width × camera.height pixels
    std::vector<float> depth;          ///< window depth in [0, 1]; 1 where nothing was drawn
    std::vector<std::uint32_t> faceId; ///< index (Face_index) of the mesh face under the pixel centre

    int width() const { return camera.width; }
    int height() const { return camera.height; }
    std::size_t index(int x, int y) const {
        return std::size_t(y) * std::size_t(camera.width) + std::size_t(x);
    }
    float depthAt(int x, int y) const { return depth[index(x, y)]; }
    std::uint32_t faceAt(int x, int y) const { return faceId[index(x, y)]; }
    bool covered(int x, int y) const { return faceId[index(x, y)] != kNoFace; }
    /// Number of covered pixels.
    std::size_t coveredCount() const {
        std::size_t n = 0;
        for (auto id : faceId)
            n += (id != kNoFace);
        return n;
    }
};

} // namespace fss
