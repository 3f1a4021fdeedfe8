#pragma once
/// \file sample_grid.h
/// The one carrier of scan samples (DESIGN.md §2): a rows × columns matrix of samples on the reference
/// surface, produced either by a regular pixel-grid scan (one sample per covered pixel centre) or by a
/// fishbone grid (rib vertices at arbitrary sub-pixel screen positions). Masks, triangulation and
/// stitching only see this type, never which grid produced it.

#include "fss/camera.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace fss {

/// One sample of a SampleGrid.
struct Sample {
    static constexpr std::uint32_t kNoFace = 0xFFFFFFFFu;

    Eigen::Vector2d screen{0, 0};    ///< sub-pixel screen position (pixels, top-left origin, see camera.h)
    Eigen::Vector3d point{0, 0, 0};  ///< position on the reference surface (world coordinates)
    Eigen::Vector3d normal{0, 0, 0}; ///< unit normal of the reference face under the sample
    std::uint32_t face = kNoFace;    ///< reference face index, kNoFace when the sample missed the surface
    float samplingAngle = 0;         ///< angle between the reversed view ray and the normal, radians
    float footprint = 0;             ///< world size of one pixel at the sample (Camera::pixelFootprint)
    float quality = std::numeric_limits<float>::infinity(); ///< lower is better (scan.h documents it)
    bool hit = false;                                       ///< the sample lies on the reference surface
    bool admissible = false; ///< hit, and passed the lasso and sampling-quality tests
    bool valid = false;      ///< currently part of the patch (admissible, and kept by erosion/dilation)
};

/// Rows × columns of samples, row-major. For a regular scan rows = image height, cols = image width and
/// sample (r, c) sits on pixel centre (c+½, r+½).
struct SampleGrid {
    int rows = 0;
    int cols = 0;
    Camera camera;               ///< the camera of the scan
    std::int32_t scanId = -1;    ///< id given to the faces this grid becomes (props::faceScanId)
    std::vector<Sample> samples; ///< rows·cols entries

    SampleGrid() = default;
    /// rows_ × cols_ default samples. Large grids get transparent huge pages where the system offers them
    /// (a 1024² grid is 88 MB: with 4 KiB pages, first touching it costs more than filling it).
    SampleGrid(int rows_, int cols_);

    bool inside(int r, int c) const { return r >= 0 && c >= 0 && r < rows && c < cols; }
    std::size_t index(int r, int c) const { return std::size_t(r) * std::size_t(cols) + std::size_t(c); }
    Sample& at(int r, int c) { return samples[index(r, c)]; }
    const Sample& at(int r, int c) const { return samples[index(r, c)]; }

    std::size_t hitCount() const { return count(&Sample::hit); }
    std::size_t admissibleCount() const { return count(&Sample::admissible); }
    std::size_t validCount() const { return count(&Sample::valid); }

private:
    std::size_t count(bool Sample::*flag) const {
        std::size_t n = 0;
        for (const Sample& s : samples)
            n += (s.*flag) ? 1 : 0;
        return n;
    }
};

} // namespace fss
