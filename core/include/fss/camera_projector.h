#pragma once
/// \file camera_projector.h
/// Camera maths for many points of one camera (per-pixel loops): the matrices computed once.

#include "fss/camera.h"

#include <Eigen/Core>

#include <cmath>

namespace fss {

/// Camera::project, unproject, ray, pixelFootprint and viewDepth for many points of one camera: the
/// matrices (and the inverse of viewport·projection·modelview) are computed once here instead of on every
/// call. Gives the same values as the Camera's methods (the same arithmetic on the same matrices).
/// Holds a copy of what it needs, so it stays valid when the camera changes (it then describes the old one).
class CameraProjector {
public:
    explicit CameraProjector(const Camera& camera);

    /// As Camera::project.
    Eigen::Vector3d project(const Eigen::Vector3d& world) const {
        const Eigen::Vector4d clip = viewProjection_ * world.homogeneous();
        const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
        return {(ndc.x() + 1.0) * 0.5 * width_, (1.0 - ndc.y()) * 0.5 * height_, (ndc.z() + 1.0) * 0.5};
    }
    /// As Camera::unproject.
    Eigen::Vector3d unproject(double sx, double sy, double depth) const {
        const Eigen::Vector4d ndc(2.0 * sx / width_ - 1.0, 1.0 - 2.0 * sy / height_, 2.0 * depth - 1.0, 1.0);
        const Eigen::Vector4d w = inverseViewProjection_ * ndc;
        return w.head<3>() / w.w();
    }
    /// As Camera::unprojectPixelCentre.
    Eigen::Vector3d unprojectPixelCentre(int px, int py, double depth) const {
        return unproject(px + 0.5, py + 0.5, depth);
    }
    /// As Camera::ray.
    Ray ray(double sx, double sy) const;

    /// A pixel centre unprojected at a depth, and the viewing ray through that centre.
    struct PixelCentre {
        Eigen::Vector3d point; ///< unprojectPixelCentre(px, py, depth)
        Ray ray;               ///< ray(px + ½, py + ½)
    };
    /// unprojectPixelCentre(px, py, depth) and ray(px + ½, py + ½) at once, bit for bit the same values:
    /// the three unprojections (at depth, and at 0 and 1 for the ray) share the matrix product's x and y
    /// terms, which are computed once (the product sums its terms in column order, so they come first).
    PixelCentre unprojectPixelCentreWithRay(int px, int py, double depth) const;
    /// As Camera::pixelFootprint.
    double pixelFootprint(const Eigen::Vector3d& p) const {
        if (parallel_) return parallelFootprint_;
        return 2.0 * std::abs(viewDepth(p)) * tanHalfAngle_ / height_;
    }
    /// As Camera::viewDepth.
    double viewDepth(const Eigen::Vector3d& p) const { return (p - eye_).dot(direction_); }
    /// As Camera::viewDirection.
    const Eigen::Vector3d& viewDirection() const { return direction_; }
    const Eigen::Vector3d& eye() const { return eye_; }
    bool parallel() const { return parallel_; }

private:
    Eigen::Matrix4d viewProjection_;
    Eigen::Matrix4d inverseViewProjection_;
    Eigen::Vector3d eye_;
    Eigen::Vector3d direction_;
    double width_, height_, tanHalfAngle_, parallelFootprint_;
    bool parallel_;
};

} // namespace fss
