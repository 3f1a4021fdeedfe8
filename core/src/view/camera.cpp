#include "fss/camera.h"
#include "fss/camera_projector.h"

#include "fss/error.h"

#include <Eigen/LU>

#include <array>
#include <cmath>
#include <numbers>
#include <sstream>

namespace fss {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

bool allFinite(const Eigen::Vector3d& v) {
    return v.allFinite();
}

// Orthonormal camera frame (s = right, u = up, f = forward).
struct Frame {
    Eigen::Vector3d s, u, f;
};

Frame frameOf(const Camera& c) {
    Frame fr;
    fr.f = (c.focal - c.eye).normalized();
    fr.s = fr.f.cross(c.up).normalized();
    fr.u = fr.s.cross(fr.f);
    return fr;
}

std::string fmt(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

} // namespace

std::optional<StandardView> parseStandardView(std::string_view name) {
    if (name == "iso") return StandardView::Iso;
    if (name == "+x" || name == "x") return StandardView::PosX;
    if (name == "-x") return StandardView::NegX;
    if (name == "+y" || name == "y") return StandardView::PosY;
    if (name == "-y") return StandardView::NegY;
    if (name == "+z" || name == "z") return StandardView::PosZ;
    if (name == "-z") return StandardView::NegZ;
    return std::nullopt;
}

std::string standardViewName(StandardView view) {
    switch (view) {
    case StandardView::Iso:
        return "iso";
    case StandardView::PosX:
        return "+x";
    case StandardView::NegX:
        return "-x";
    case StandardView::PosY:
        return "+y";
    case StandardView::NegY:
        return "-y";
    case StandardView::PosZ:
        return "+z";
    case StandardView::NegZ:
        return "-z";
    }
    return "iso";
}

void Camera::validate() const {
    if (!allFinite(eye) || !allFinite(focal) || !allFinite(up))
        throw InvalidInputError("The camera has a non-finite eye, focal point or up vector.");
    const Eigen::Vector3d d = focal - eye;
    if (d.norm() <= 1e-12 * std::max(1.0, eye.norm()))
        throw InvalidInputError("The camera's eye and focal point coincide, so it has no viewing direction.");
    if (up.norm() == 0 || d.normalized().cross(up.normalized()).norm() < 1e-9)
        throw InvalidInputError("The camera's up vector is zero or parallel to its viewing direction.");
    if (width < 1 || height < 1 || width > kMaxResolution || height > kMaxResolution)
        throw InvalidInputError("The scan resolution " + std::to_string(width) + "x" +
                                std::to_string(height) + " is outside the supported range 1 to " +
                                std::to_string(kMaxResolution) + " pixels per side.");
    if (!parallel && !(viewAngleDeg > 0 && viewAngleDeg < 180))
        throw InvalidInputError("The camera's view angle " + fmt(viewAngleDeg) +
                                " degrees is outside the open range 0 to 180.");
    if (parallel && !(parallelScale > 0 && std::isfinite(parallelScale)))
        throw InvalidInputError("The parallel camera's scale " + fmt(parallelScale) + " is not positive.");
    if (!(nearPlane > 0 && farPlane > nearPlane && std::isfinite(farPlane)))
        throw InvalidInputError("The camera's clipping range [" + fmt(nearPlane) + ", " + fmt(farPlane) +
                                "] is not a positive increasing range.");
}

Eigen::Vector3d Camera::viewDirection() const {
    return (focal - eye).normalized();
}

Eigen::Matrix4d Camera::viewMatrix() const {
    const Frame fr = frameOf(*this);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<1, 3>(0, 0) = fr.s.transpose();
    m.block<1, 3>(1, 0) = fr.u.transpose();
    m.block<1, 3>(2, 0) = -fr.f.transpose();
    m(0, 3) = -fr.s.dot(eye);
    m(1, 3) = -fr.u.dot(eye);
    m(2, 3) = fr.f.dot(eye);
    return m;
}

Eigen::Matrix4d Camera::projectionMatrix() const {
    const double n = nearPlane, f = farPlane;
    Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
    if (parallel) {
        const double h = parallelScale, w = parallelScale * aspect();
        p(0, 0) = 1.0 / w;
        p(1, 1) = 1.0 / h;
        p(2, 2) = -2.0 / (f - n);
        p(2, 3) = -(f + n) / (f - n);
        p(3, 3) = 1.0;
    } else {
        const double h = n * std::tan(0.5 * viewAngleDeg * kDegToRad), w = h * aspect();
        p(0, 0) = n / w;
        p(1, 1) = n / h;
        p(2, 2) = -(f + n) / (f - n);
        p(2, 3) = -2.0 * f * n / (f - n);
        p(3, 2) = -1.0;
    }
    return p;
}

Eigen::Matrix4d Camera::viewProjectionMatrix() const {
    return projectionMatrix() * viewMatrix();
}

Eigen::Vector3d Camera::project(const Eigen::Vector3d& world) const {
    const Eigen::Vector4d clip = viewProjectionMatrix() * world.homogeneous();
    const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    return {(ndc.x() + 1.0) * 0.5 * width, (1.0 - ndc.y()) * 0.5 * height, (ndc.z() + 1.0) * 0.5};
}

Eigen::Vector3d Camera::unproject(double sx, double sy, double depth) const {
    const Eigen::Vector4d ndc(2.0 * sx / width - 1.0, 1.0 - 2.0 * sy / height, 2.0 * depth - 1.0, 1.0);
    const Eigen::Vector4d w = viewProjectionMatrix().inverse() * ndc;
    return w.head<3>() / w.w();
}

Ray Camera::ray(double sx, double sy) const {
    const Eigen::Vector3d a = unproject(sx, sy, 0.0);
    const Eigen::Vector3d b = unproject(sx, sy, 1.0);
    Ray r;
    r.origin = parallel ? a : eye;
    r.direction = (b - a).normalized();
    return r;
}

CameraProjector::CameraProjector(const Camera& camera)
    : viewProjection_(camera.viewProjectionMatrix()), inverseViewProjection_(viewProjection_.inverse()),
      eye_(camera.eye), direction_(camera.viewDirection()), width_(camera.width), height_(camera.height),
      tanHalfAngle_(std::tan(0.5 * camera.viewAngleDeg * kDegToRad)),
      parallelFootprint_(2.0 * camera.parallelScale / camera.height), parallel_(camera.parallel) {}

Ray CameraProjector::ray(double sx, double sy) const {
    const Eigen::Vector3d a = unproject(sx, sy, 0.0);
    const Eigen::Vector3d b = unproject(sx, sy, 1.0);
    Ray r;
    r.origin = parallel_ ? a : eye_;
    r.direction = (b - a).normalized();
    return r;
}

CameraProjector::PixelCentre CameraProjector::unprojectPixelCentreWithRay(int px, int py,
                                                                          double depth) const {
    const double sx = px + 0.5, sy = py + 0.5;
    const Eigen::Matrix4d& m = inverseViewProjection_;
    // unproject's product m · (x, y, z, 1) = ((m₀x + m₁y) + m₂z) + m₃ per coordinate.
    const Eigen::Vector4d xy = m.col(0) * (2.0 * sx / width_ - 1.0) + m.col(1) * (1.0 - 2.0 * sy / height_);
    auto at = [&](double z) {
        const Eigen::Vector4d w = (xy + m.col(2) * z) + m.col(3) * 1.0;
        return Eigen::Vector3d(w.head<3>() / w.w());
    };
    PixelCentre out;
    out.point = at(2.0 * depth - 1.0);
    const Eigen::Vector3d a = at(2.0 * 0.0 - 1.0), b = at(2.0 * 1.0 - 1.0);
    out.ray.origin = parallel_ ? a : eye_;
    out.ray.direction = (b - a).normalized();
    return out;
}

double Camera::viewDepth(const Eigen::Vector3d& p) const {
    return (p - eye).dot(viewDirection());
}

double Camera::pixelFootprint(const Eigen::Vector3d& p) const {
    if (parallel) return 2.0 * parallelScale / height;
    return 2.0 * std::abs(viewDepth(p)) * std::tan(0.5 * viewAngleDeg * kDegToRad) / height;
}

void Camera::fitClippingRange(const Eigen::AlignedBox3d& box) {
    if (box.isEmpty()) throw InvalidInputError("Cannot fit the camera's clipping range to an empty box.");
    const Eigen::Vector3d dir = viewDirection();
    double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
    for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d corner = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i));
        const double z = (corner - eye).dot(dir);
        zmin = std::min(zmin, z);
        zmax = std::max(zmax, z);
    }
    if (!(zmax > 0)) throw InvalidInputError("The mesh lies entirely behind the camera.");
    const double margin = 1e-3 * std::max(zmax - zmin, 1e-9 * std::max(1.0, zmax));
    farPlane = zmax + margin;
    nearPlane = std::max(zmin - margin, farPlane * 1e-4);
}

void Camera::zoom(double factor) {
    if (!(factor > 0) || !std::isfinite(factor))
        throw InvalidInputError("The zoom factor " + fmt(factor) + " is not a finite positive number.");
    if (factor == 1.0) return; // exactly: no rounding of the view angle
    if (parallel)
        parallelScale /= factor;
    else
        viewAngleDeg = 2.0 * std::atan(std::tan(0.5 * viewAngleDeg * kDegToRad) / factor) / kDegToRad;
}

Camera Camera::standardView(StandardView view, const Eigen::AlignedBox3d& box, int width, int height,
                            bool parallel, double viewAngleDeg) {
    if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite())
        throw InvalidInputError("Cannot place a camera around an empty or non-finite bounding box.");
    Eigen::Vector3d from; // direction from the centre towards the eye
    Eigen::Vector3d up(0, 0, 1);
    switch (view) {
    case StandardView::Iso:
        from = Eigen::Vector3d(1, 1, 1).normalized();
        break;
    case StandardView::PosX:
        from = {1, 0, 0};
        break;
    case StandardView::NegX:
        from = {-1, 0, 0};
        break;
    case StandardView::PosY:
        from = {0, 1, 0};
        break;
    case StandardView::NegY:
        from = {0, -1, 0};
        break;
    case StandardView::PosZ:
        from = {0, 0, 1};
        up = {0, 1, 0};
        break;
    case StandardView::NegZ:
        from = {0, 0, -1};
        up = {0, 1, 0};
        break;
    }
    Camera c;
    c.width = width;
    c.height = height;
    c.parallel = parallel;
    c.viewAngleDeg = viewAngleDeg;
    const Eigen::Vector3d centre = box.center();
    const double radius = std::max(0.5 * box.diagonal().norm(), 1e-12);
    // Smallest of the vertical and horizontal half angles decides how far back the eye must be.
    const double halfV = 0.5 * viewAngleDeg * kDegToRad;
    const double halfH = std::atan(std::tan(halfV) * double(width) / double(height));
    const double half = std::min(halfV, halfH);
    const double distance = radius / std::sin(half);
    c.focal = centre;
    c.eye = centre + distance * from;
    c.up = up;
    c.parallelScale = radius * std::max(1.0, double(height) / double(width));
    c.fitClippingRange(box);
    c.validate();
    return c;
}

} // namespace fss
