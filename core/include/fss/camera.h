#pragma once
/// \file camera.h
/// The scan camera: a value type holding an OpenGL/VTK-style pinhole (or parallel) camera plus the size
/// of the image it produces, with its matrices in double precision.
///
/// Screen coordinates are in pixels with the origin at the **top-left** corner of the image, x to the
/// right and y downwards (as Qt's mouse events); pixel (i, j) covers [i, i+1) × [j, j+1) and its centre
/// is (i+½, j+½). Depth is the OpenGL window depth in [0, 1] (0 = near plane, 1 = far plane). The
/// matrices follow OpenGL and VTK exactly (a VTK camera set from this one renders the same image).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <string_view>

namespace fss {

/// A ray: origin + t·direction, direction of unit length.
struct Ray {
    Eigen::Vector3d origin;
    Eigen::Vector3d direction;
};

/// The standard views of `fss-remesh --view`. The name is the side the camera looks *from*
/// (`+x`: the eye is on the +x side, looking towards −x). `iso` looks from (+1, +1, +1).
enum class StandardView { Iso, PosX, NegX, PosY, NegY, PosZ, NegZ };

/// Parses "iso", "+x", "-x", "+y", "-y", "+z", "-z"; std::nullopt for anything else.
std::optional<StandardView> parseStandardView(std::string_view name);
/// The name accepted by parseStandardView.
std::string standardViewName(StandardView view);

/// Pinhole or parallel camera with an image size. Plain value type: copy freely.
struct Camera {
    Eigen::Vector3d eye{0, 0, 1};   ///< position of the eye
    Eigen::Vector3d focal{0, 0, 0}; ///< point looked at
    Eigen::Vector3d up{0, 1, 0};    ///< approximate up direction (orthogonalised internally)
    bool parallel = false;          ///< parallel (orthographic) projection instead of perspective
    double viewAngleDeg = 30.0;     ///< vertical full view angle of a perspective camera, degrees
    double parallelScale = 1.0;     ///< half the image height in world units, parallel camera
    double nearPlane = 0.01;        ///< distance of the near clipping plane from the eye (> 0)
    double farPlane = 1000.0;       ///< distance of the far clipping plane from the eye (> near)
    int width = 256;                ///< image width in pixels
    int height = 256;               ///< image height in pixels

    /// Largest accepted image side (larger buffers exceed what GL drivers reliably allocate).
    static constexpr int kMaxResolution = 8192;

    /// Checks every field (finite, eye ≠ focal, up not parallel to the view direction, 0 < angle < 180,
    /// scale > 0, 0 < near < far, 1 ≤ width, height ≤ kMaxResolution).
    /// \throw InvalidInputError with one sentence naming the bad field.
    void validate() const;

    double aspect() const { return double(width) / double(height); }
    /// Unit vector from the eye towards the focal point.
    Eigen::Vector3d viewDirection() const;

    /// World → eye coordinates (eye at the origin looking down −z, y up), as gluLookAt.
    Eigen::Matrix4d viewMatrix() const;
    /// Eye → clip coordinates, as glFrustum / glOrtho with the camera's near and far planes.
    Eigen::Matrix4d projectionMatrix() const;
    /// projectionMatrix() · viewMatrix().
    Eigen::Matrix4d viewProjectionMatrix() const;

    /// World point → (screen x, screen y, depth). Points behind the eye give meaningless values.
    Eigen::Vector3d project(const Eigen::Vector3d& world) const;
    /// (screen x, screen y, depth) → world point; the inverse of project().
    Eigen::Vector3d unproject(double sx, double sy, double depth) const;
    /// World point of the centre of pixel (px, py) at window depth \p depth.
    Eigen::Vector3d unprojectPixelCentre(int px, int py, double depth) const {
        return unproject(px + 0.5, py + 0.5, depth);
    }
    /// The viewing ray through the sub-pixel screen position (sx, sy): from the eye (perspective) or from
    /// the near plane (parallel), pointing away from the viewer.
    Ray ray(double sx, double sy) const;
    /// World-space side length of one pixel at the depth of world point \p p (the "pixel footprint").
    double pixelFootprint(const Eigen::Vector3d& p) const;
    /// Distance of \p p in front of the eye along the view direction (negative behind the eye).
    double viewDepth(const Eigen::Vector3d& p) const;

    /// Sets near/far tightly around \p box (a small relative margin). A box partly behind the eye gets
    /// near = far·1e-4. \throw InvalidInputError when the whole box is behind the eye.
    void fitClippingRange(const Eigen::AlignedBox3d& box);

    /// Zooms by \p factor (> 1 magnifies): divides the view angle (perspective) or the parallel scale.
    /// \throw InvalidInputError when factor is not finite and positive.
    void zoom(double factor);

    /// A camera looking at \p box from \p view so that the whole box is visible at any aspect, with a
    /// tight clipping range. Up is +z, except for the ±z views whose up is +y.
    static Camera standardView(StandardView view, const Eigen::AlignedBox3d& box, int width, int height,
                               bool parallel = false, double viewAngleDeg = 30.0);
};

} // namespace fss
