#pragma once
/// \file snapshot.h
/// Head-less pictures of a mesh with a quality colour map (`fss-remesh run --snapshot`): the mesh is
/// rendered into an ID + depth buffer (the scan Rasterizer in a Mesa EGL surfaceless context, no X server;
/// CPU ray casting when no OpenGL context can be made), and every covered pixel is shaded flat with the
/// colour of the face under it: colour · (ambient + (1 − ambient) · |cos θ|), θ between the face normal and
/// the viewing ray (a head light), with face borders darkened so the triangulation shows. PNG files are
/// written and read with VTK (vtkPNGWriter / vtkPNGReader).

#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/render/colour_maps.h"
#include "fss/render/renderer_choice.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace fss::render {

/// An 8-bit RGB image, row 0 at the top, 3 bytes per pixel, row-major.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb; ///< width · height · 3 bytes
    Rgb pixel(int x, int y) const {
        const std::size_t i = 3 * (std::size_t(y) * std::size_t(width) + std::size_t(x));
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
    /// Number of pixels whose colour differs from \p colour.
    std::size_t countDifferentFrom(const Rgb& colour) const;
};

/// Per-face colours of \p mesh by its smallest corner angle (minAngleColor, colour_maps.h), indexed by
/// Face_index (one entry per face slot, removed faces included and grey).
std::vector<Rgb> minAngleFaceColors(const Mesh& mesh);

/// How a snapshot is drawn.
struct SnapshotOptions {
    Rgb background{255, 255, 255}; ///< colour of pixels no face covers
    double ambient = 0.45;         ///< ambient share of the flat shading, in [0, 1]
    /// Pixels where the face id changes to another face (to the right or below) are multiplied by this
    /// factor: the triangulation shows as thin dark lines. 1 = no outlines.
    double outline = 0.8;
    /// Which renderer makes the ID buffer (renderer_choice.h): the GPU with a fallback to the CPU (Auto),
    /// only the GPU (Gpu: no fallback), or CPU ray casting (Cpu).
    using Renderer = RendererChoice;
    Renderer renderer = Renderer::Auto; ///< see Renderer
    /// Append a colour legend of the minimum-angle map at the right of the picture (renderMinAngleLegend,
    /// legendWidth(height) pixels wide): the picture of the mesh itself is unchanged. Needs an OpenGL
    /// context (Mesa EGL) even with the CPU renderer.
    bool legend = false;
};

/// Width in pixels of the legend renderSnapshot appends for a picture \p height pixels high.
inline int legendWidth(int height) {
    return height / 4 < 110 ? 110 : height / 4;
}

/// The minimum-angle legend: VTK's vtkScalarBarActor (the colours of minAngleColor, 0 to 60 degrees, a
/// title and five labels) rendered head-less in a Mesa EGL surfaceless context on \p background.
/// \throw InvalidInputError for a size below 16 × 16; fss::Error (one sentence) when no OpenGL context can
///        be made or it gives no image.
Image renderMinAngleLegend(int width, int height, const Rgb& background);

/// \p image with \p right placed at its right (same height). \throw InvalidInputError when the heights
/// differ.
Image appendRight(const Image& image, const Image& right);

/// Shades \p buffers (rendered from \p mesh) with one colour per face: see the file comment. Covered pixels
/// never take the background colour (a covered pixel that would equal it is changed by one unit of
/// red), so the pixels that differ from the background are exactly the covered ones.
/// \pre faceColors has an entry for every face id in the buffers.
/// \throw InvalidInputError when a face id of the buffers has no colour or the buffers' size does not match
///        their camera.
Image shadeFaces(const Mesh& mesh, const FrameBuffers& buffers, const std::vector<Rgb>& faceColors,
                 const SnapshotOptions& options = {});

/// What renderSnapshot made.
struct Snapshot {
    Image image;
    std::string renderer;    ///< "gpu (<GL renderer>)" or "cpu"
    std::size_t covered = 0; ///< pixels covered by the mesh
};

/// Renders \p mesh from \p camera (camera.width × camera.height pixels, clipping range fitted to the mesh)
/// coloured by minimum angle; with SnapshotOptions::legend the legend is appended at the right (the image
/// is then legendWidth(camera.height) pixels wider). With Renderer::Auto a failure to create an OpenGL
/// context falls back to CPU ray casting (Snapshot::renderer says which was used). \throw InvalidInputError
/// when the mesh is empty or the camera is invalid or sees nothing of the mesh;
///        fss::Error when Renderer::Gpu is asked for and no OpenGL context can be made.
Snapshot renderSnapshot(const Mesh& mesh, const Camera& camera, const SnapshotOptions& options = {});

/// Writes \p image as an 8-bit RGB PNG file (VTK's vtkPNGWriter), to a temporary name then renamed.
/// \throw InvalidInputError for an empty image or one whose byte count does not match its size; IoError
///        naming the file when it cannot be written.
void writePng(const Image& image, const std::filesystem::path& path);

/// Reads an 8-bit PNG file (grey, grey + alpha, RGB or RGBA; alpha is dropped) as RGB.
/// \throw IoError naming the file when it is missing or not a readable 8-bit PNG.
Image readPng(const std::filesystem::path& path);

} // namespace fss::render
