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
#include <memory>
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

/// Options of lazyDirectionField().
struct LazyDirectionFieldOptions {
    /// Which principal direction to interpolate and project.
    PrincipalDirection direction = PrincipalDirection::Max;
    /// Side of the square pixel tiles computed at once (≥ 1; tiles at the right and bottom border may be
    /// smaller). Small tiles waste less work beside a streamline, large ones cost less bookkeeping.
    int tileSize = 8;
};

namespace detail {
struct LazyDirectionTiles; // the tile cache of a lazy field (direction_field.cpp)
} // namespace detail

/// The stored values of one pixel of a DirectionField.
struct DirectionPixel {
    Eigen::Vector2d direction = Eigen::Vector2d::Zero(); ///< unit screen direction (zero where invalid)
    float anisotropy = 0;                                ///< in [0, 1]; 0 where invalid
    bool valid = false;                                  ///< the pixel has a direction
};

/// A 2D line field on the pixels of an image: per pixel a unit screen direction (defined up to sign), an
/// anisotropy in [0, 1] and a validity flag. Values belong to the pixel centres (x+½, y+½).
/// Row 0 is the top image row. Synthetic fields can be filled with setPixel() (tests, hand-made fields).
///
/// A field is either *stored* (computeDirectionField, or the size constructor and setPixel): every pixel
/// is in the three arrays; or *lazy* (lazyDirectionField): the arrays are empty and each tile of pixels is
/// computed on the first access through isValid(), pixel(), sample() or validCount(), so a streamline pays
/// only for the area it crosses. Both give the same values for the same pixel. Copies of a lazy field share
/// its tile cache; access is thread-safe (tiles may be filled from several threads at once).
struct DirectionField {
    int width = 0;
    int height = 0;
    std::vector<Eigen::Vector2d>
        direction;                   ///< unit screen direction per pixel (zero where invalid); empty if lazy
    std::vector<float> anisotropy;   ///< per pixel, in [0, 1]; 0 where invalid; empty if lazy
    std::vector<std::uint8_t> valid; ///< 1 where the pixel has a direction; empty if lazy

    DirectionField() = default;
    /// An all-invalid stored field of the given size. \throw InvalidInputError for a negative size.
    DirectionField(int width, int height);

    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
    bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
    /// True when (x, y) lies inside the image and the pixel has a direction.
    bool isValid(int x, int y) const { return inside(x, y) && pixel(x, y).valid; }
    /// The values of pixel (x, y), stored or lazy. \pre inside(x, y).
    DirectionPixel pixel(int x, int y) const;
    /// Stores a direction (normalised here; a zero or non-finite vector makes the pixel invalid).
    /// \pre inside(x, y). \throw InvalidInputError on a lazy field (its pixels are computed, not set).
    void setPixel(int x, int y, const Eigen::Vector2d& dir, double anisotropy = 1.0);
    /// Number of valid pixels (computes every tile of a lazy field).
    std::size_t validCount() const;
    /// True for a field made by lazyDirectionField.
    bool isLazy() const { return lazy_ != nullptr; }
    /// Pixels computed so far: width·height for a stored field, the computed tiles' pixels for a lazy one.
    std::size_t computedPixels() const;

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

private:
    friend DirectionField lazyDirectionField(const Mesh&, const CurvatureField&, const FrameBuffers&,
                                             const LazyDirectionFieldOptions&);
    std::shared_ptr<const detail::LazyDirectionTiles> lazy_;
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
///  5. the screen direction: the derivative of the projection at p along D̂ (exact, from the clip
///     coordinates), normalised;
///  6. anisotropy = (Σ wᵢ·aᵢ) · |D| (vertex anisotropies interpolated, times the coherence |D| ≤ 1 of the
///     three directions, which drops near singularities where they disagree).
/// Invalid (background) pixels: no face, or no direction (all vertices undefined, directions cancelling,
/// or the direction along the viewing ray: less than 10⁻⁶ pixels per pixel footprint on the screen).
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

/// The direction field of computeDirectionField, computed lazily: per tile of tileSize² pixels on the
/// first access (DirectionField::isValid, pixel, sample, validCount), so a fishbone pays only for the
/// pixels its backbone and ribs come near, not for every covered pixel (DESIGN.md §5: work proportional
/// to the patch). Every pixel's values are exactly those of computeDirectionField.
/// The field refers to \p mesh, \p curvature and \p buffers: they must outlive it (and its copies) and
/// stay unchanged. Preconditions as computeDirectionField; sizes and the curvature are checked here,
/// the face ids when a tile is computed.
/// \throw InvalidInputError when a precondition is violated or tileSize < 1 (a bad face id throws from
///        the access that computes its tile).
DirectionField lazyDirectionField(const Mesh& mesh, const CurvatureField& curvature,
                                  const FrameBuffers& buffers, const LazyDirectionFieldOptions& options = {});

} // namespace fss
