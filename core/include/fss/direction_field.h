#pragma once
/// \file direction_field.h
/// The per-pixel 2D principal direction field of a scan — the second step of the fishbone grid
/// (DESIGN.md §1: "Per pixel of the scan, interpolate the direction of the triangle under the pixel
/// (barycentric, after aligning the sign of the three vertex directions) and project it to the screen").
///
/// The paper rendered the directions as RGB colours; we read the face under each pixel from the ID buffer
/// and interpolate in double precision on the CPU (PLATFORM-NOTES.md: more precise and cheaper).
/// Directions are *line fields*: d and −d are the same direction. Screen coordinates as in camera.h
/// (pixels, origin top-left, y down).

#include "fss/curvature.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace fss {

/// Which principal direction a field, backbone or rib follows. Principal curvatures are ranked by
/// magnitude here (not by signed value as k1 ≥ k2 in curvature.h), so that Min runs along a crease or a
/// fillet whether it is convex or concave: on a concave crease (fandisk's curved feature) the signed
/// minimal curvature is the large negative one across the crease.
enum class PrincipalDirection {
    Min, ///< direction of the principal curvature of smaller |k| (along a cylinder's axis, along a crease)
    Max  ///< direction of the principal curvature of larger |k| (around a cylinder, across a crease)
};

/// The other principal direction (the ribs' direction when the backbone follows \p d).
constexpr PrincipalDirection otherDirection(PrincipalDirection d) {
    return d == PrincipalDirection::Min ? PrincipalDirection::Max : PrincipalDirection::Min;
}

/// Direction and anisotropy at a sub-pixel position (DirectionField::sample).
struct DirectionSample {
    Eigen::Vector2d direction{1, 0}; ///< unit screen direction, sign aligned with the caller's reference
    double anisotropy = 0;           ///< in [0, 1], how well the direction is defined (see DirectionField)
};

/// A 2D line field on the pixels of an image: per pixel a unit screen direction (defined up to sign), an
/// anisotropy in [0, 1] and a validity flag. Values belong to the pixel centres (x+½, y+½).
/// Row 0 is the top image row. Synthetic fields can be filled with setPixel() (tests, hand-made fields).
struct DirectionField {
    int width = 0;
    int height = 0;
    std::vector<Eigen::Vector2d> direction; ///< unit screen direction per pixel (zero where invalid)
    std::vector<float> anisotropy;          ///< per pixel, in [0, 1]; 0 where invalid
    std::vector<std::uint8_t> valid;        ///< 1 where the pixel has a direction

    DirectionField() = default;
    /// An all-invalid field of the given size. \throw InvalidInputError for a negative size.
    DirectionField(int width, int height);

    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
    bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
    bool isValid(int x, int y) const { return inside(x, y) && valid[index(x, y)] != 0; }
    /// Stores a direction (normalised here; a zero or non-finite vector makes the pixel invalid).
    /// \pre inside(x, y).
    void setPixel(int x, int y, const Eigen::Vector2d& dir, double anisotropy = 1.0);
    /// Number of valid pixels.
    std::size_t validCount() const;

    /// Bilinear sampling at the sub-pixel position \p pos between the four nearest pixel centres: each
    /// neighbour's direction is first flipped to agree with \p reference (line field) and weighted by its
    /// bilinear weight times its anisotropy (floored at 10⁻³, so a well-defined direction dominates an
    /// ill-defined neighbour while an isotropic neighbourhood is still averaged plainly); invalid
    /// neighbours and those outside the image are left out, and the blend is normalised. The anisotropy is
    /// the plain bilinear average over the valid neighbours.
    /// With \p straightBelow > 0, a neighbour whose anisotropy is below straightBelow contributes the
    /// reference direction instead of its own (linear ramp back to its own up to 2·straightBelow): a
    /// streamline can cross an isotropic region straight without picking up its noise
    /// (LowAnisotropyPolicy::ContinueStraight).
    /// \return std::nullopt when \p pos lies outside the image [0, width] × [0, height], when the pixel
    ///         containing \p pos is invalid, or when the blend cancels (directions ⟂ the reference).
    /// \pre reference is non-zero (its sign decides the result's: a non-negative dot with it).
    std::optional<DirectionSample> sample(const Eigen::Vector2d& pos, const Eigen::Vector2d& reference,
                                          double straightBelow = 0) const;
};

/// Options of computeDirectionField().
struct DirectionFieldOptions {
    /// Which principal direction to interpolate and project.
    PrincipalDirection direction = PrincipalDirection::Max;
};

/// Builds the screen direction field of one principal direction for a scan of the reference mesh
/// (DESIGN.md §1, fishbone grid, first paragraph). Per covered pixel:
///  1. the face f under the pixel from the ID buffer;
///  2. the 3D point p: the pixel centre's viewing ray (Camera::ray) intersected with f's plane, in double
///     (the float depth buffer is used only when the ray grazes the plane);
///  3. barycentric coordinates (w0, w1, w2) of p in f (clamped to the triangle);
///  4. the three vertex directions (per vertex the one of smaller |k| for Min, larger |k| for Max, see
///     PrincipalDirection), each flipped to agree with the first defined one (line field), blended
///     D = Σ wᵢ·sᵢ·dᵢ (undefined vertices contribute 0) and projected into the tangent plane of the
///     interpolated vertex normal Σ wᵢ·nᵢ (not f's plane: the faceting would tilt D and foreshortening
///     near silhouettes magnifies that to degrees on the screen);
///  5. the screen direction: project p ± ε·D̂ (ε = 10⁻³ pixel footprints) and normalise the difference;
///  6. anisotropy = (Σ wᵢ·aᵢ) · |D| (vertex anisotropies interpolated, times the coherence |D| ≤ 1 of the
///     three directions, which drops near singularities where they disagree).
/// Invalid (background) pixels: no face, or no direction (all vertices undefined, directions cancelling,
/// or the direction along the viewing ray).
/// \param mesh       the reference mesh the buffers were rendered from
/// \param curvature  estimateCurvature(mesh)
/// \param buffers    ID buffer (and camera) of a render of \p mesh
/// \param options    which principal direction
/// Measured on a cylinder side view (tests/core/direction_field_test.cpp): median error of the screen
/// direction against the projected analytic one 0.007°, worst 0.14° (pixels not at grazing angles).
/// \pre curvature.size() covers every vertex slot of \p mesh; buffers' arrays have width·height entries;
///      every face id is kNoFace or a (non-removed) triangle of \p mesh; the camera is valid.
/// \throw InvalidInputError when a precondition is violated.
DirectionField computeDirectionField(const Mesh& mesh, const CurvatureField& curvature,
                                     const FrameBuffers& buffers, const DirectionFieldOptions& options = {});

/// Both principal direction fields of one scan.
struct DirectionFieldPair {
    DirectionField min; ///< PrincipalDirection::Min
    DirectionField max; ///< PrincipalDirection::Max
};

/// The min and the max direction field in one pass: identical to computeDirectionField with each
/// direction, at about 60 % of the cost of two calls (face lookup, surface point and barycentric
/// coordinates are shared). Preconditions and errors as computeDirectionField.
DirectionFieldPair computeDirectionFields(const Mesh& mesh, const CurvatureField& curvature,
                                          const FrameBuffers& buffers);

} // namespace fss
