#include "fss/direction_field.h"

#include "fss/error.h"

#include "detail/parallel_rows.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace fss {
namespace {

Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

// Camera::project / ray with the matrices computed once (Camera rebuilds them on every call), same
// conventions as camera.h.
class Projector {
public:
    explicit Projector(const Camera& c)
        : c_(c), vp_(c.viewProjectionMatrix()), inverse_(vp_.inverse()),
          footprintPerDepth_(2.0 * std::tan(0.5 * c.viewAngleDeg * std::numbers::pi / 180.0) / c.height),
          viewDirection_(c.viewDirection()) {}

    Eigen::Vector2d project(const Eigen::Vector3d& world) const {
        const Eigen::Vector4d clip = vp_ * world.homogeneous();
        return {(clip.x() / clip.w() + 1.0) * 0.5 * c_.width, (1.0 - clip.y() / clip.w()) * 0.5 * c_.height};
    }
    Eigen::Vector3d unproject(double sx, double sy, double depth) const {
        const Eigen::Vector4d ndc(2.0 * sx / c_.width - 1.0, 1.0 - 2.0 * sy / c_.height, 2.0 * depth - 1.0,
                                  1.0);
        const Eigen::Vector4d w = inverse_ * ndc;
        return w.head<3>() / w.w();
    }
    Ray ray(double sx, double sy) const {
        const Eigen::Vector3d a = unproject(sx, sy, 0.0), b = unproject(sx, sy, 1.0);
        return {c_.parallel ? a : c_.eye, (b - a).normalized()};
    }
    double pixelFootprint(const Eigen::Vector3d& p) const {
        if (c_.parallel) return 2.0 * c_.parallelScale / c_.height;
        return std::abs((p - c_.eye).dot(viewDirection_)) * footprintPerDepth_;
    }

private:
    const Camera& c_;
    Eigen::Matrix4d vp_, inverse_;
    double footprintPerDepth_;
    Eigen::Vector3d viewDirection_;
};

constexpr double kMinDirectionWeight = 1e-3;

std::string pixelName(int x, int y) {
    return "(" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

} // namespace

DirectionField::DirectionField(int w, int h) : width(w), height(h) {
    if (w < 0 || h < 0) throw InvalidInputError("A direction field cannot have a negative size.");
    const std::size_t n = std::size_t(w) * std::size_t(h);
    direction.assign(n, Eigen::Vector2d::Zero());
    anisotropy.assign(n, 0.0f);
    valid.assign(n, 0);
}

void DirectionField::setPixel(int x, int y, const Eigen::Vector2d& dir, double aniso) {
    const std::size_t i = index(x, y);
    const double len = dir.norm();
    if (!(len > 0) || !std::isfinite(len) || !std::isfinite(aniso)) {
        direction[i].setZero();
        anisotropy[i] = 0;
        valid[i] = 0;
        return;
    }
    direction[i] = dir / len;
    anisotropy[i] = float(std::clamp(aniso, 0.0, 1.0));
    valid[i] = 1;
}

std::size_t DirectionField::validCount() const {
    std::size_t n = 0;
    for (auto v : valid)
        n += v != 0;
    return n;
}

std::optional<DirectionSample> DirectionField::sample(const Eigen::Vector2d& pos,
                                                      const Eigen::Vector2d& reference,
                                                      double straightBelow) const {
    if (!(pos.x() >= 0 && pos.y() >= 0 && pos.x() <= width && pos.y() <= height)) return std::nullopt;
    // The pixel containing pos decides coverage (so background stops are pixel-exact).
    const int cx = std::min(int(pos.x()), width - 1), cy = std::min(int(pos.y()), height - 1);
    if (!isValid(cx, cy)) return std::nullopt;
    // Bilinear weights between the four nearest pixel centres.
    const double gx = pos.x() - 0.5, gy = pos.y() - 0.5;
    const int x0 = int(std::floor(gx)), y0 = int(std::floor(gy));
    const double fx = gx - x0, fy = gy - y0;
    // The unit reference is needed only where a low-anisotropy neighbour is bent towards it.
    std::optional<Eigen::Vector2d> unitReference;
    auto unitRef = [&]() -> const Eigen::Vector2d& {
        if (!unitReference) unitReference = reference.normalized();
        return *unitReference;
    };
    const bool interior = x0 >= 0 && y0 >= 0 && x0 + 1 < width && y0 + 1 < height;
    Eigen::Vector2d dir = Eigen::Vector2d::Zero();
    double aniso = 0, weight = 0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const int x = x0 + i, y = y0 + j;
            const std::size_t k = std::size_t(y) * std::size_t(width) + std::size_t(x);
            if (!(interior ? valid[k] != 0 : isValid(x, y))) continue;
            const double w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
            if (w <= 0) continue;
            const double a = double(anisotropy[k]);
            Eigen::Vector2d d =
                direction[k].dot(reference) < 0 ? Eigen::Vector2d(-direction[k]) : direction[k];
            if (straightBelow > 0 && a < 2 * straightBelow) {
                const double f = std::clamp((a - straightBelow) / straightBelow, 0.0, 1.0);
                d = f * d + (1 - f) * unitRef();
            }
            // Well-defined directions dominate ill-defined ones; the floor keeps an all-isotropic
            // neighbourhood (a plane, anisotropy 0) a plain bilinear average.
            dir += (w * std::max(a, kMinDirectionWeight)) * d;
            aniso += w * double(anisotropy[k]);
            weight += w;
        }
    if (weight <= 0) {
        // pos sits exactly on the containing pixel's far edge with zero weight everywhere else.
        const std::size_t k = index(cx, cy);
        if (straightBelow > 0 && double(anisotropy[k]) < straightBelow)
            return DirectionSample{unitRef(), double(anisotropy[k])};
        const Eigen::Vector2d& d = direction[k];
        return DirectionSample{d.dot(reference) < 0 ? Eigen::Vector2d(-d) : d, double(anisotropy[k])};
    }
    const double len = dir.norm();
    if (!(len > 1e-12)) return std::nullopt;
    return DirectionSample{dir / len, aniso / weight};
}

namespace {

// Fills the requested fields (either pointer may be null) in one pass over the pixels: the face lookup,
// the ray/plane point and the barycentric coordinates are shared by both principal directions.
void fillDirectionFields(const Mesh& mesh, const CurvatureField& curvature, const FrameBuffers& buffers,
                         DirectionField* minField, DirectionField* maxField) {
    const Camera& camera = buffers.camera;
    camera.validate();
    const std::size_t pixels = std::size_t(camera.width) * std::size_t(camera.height);
    if (buffers.faceId.size() != pixels || buffers.depth.size() != pixels)
        throw InvalidInputError("The frame buffers do not have width × height entries.");
    const std::size_t slots = mesh.number_of_vertices() + mesh.number_of_removed_vertices();
    if (curvature.size() != slots || curvature.d1.size() != slots || curvature.d2.size() != slots ||
        curvature.anisotropy.size() != slots || curvature.defined.size() != slots ||
        curvature.normal.size() != slots)
        throw InvalidInputError("The curvature field does not belong to this mesh (it has " +
                                std::to_string(curvature.size()) + " vertices, the mesh " +
                                std::to_string(slots) + ").");
    const std::size_t faceSlots = mesh.number_of_faces() + mesh.number_of_removed_faces();
    if (minField) *minField = DirectionField(camera.width, camera.height);
    if (maxField) *maxField = DirectionField(camera.width, camera.height);
    const Projector projector(camera);
    // Rows in blocks, one per thread (parallel.h): every pixel is computed on its own.
    detail::parallelRows(
        camera.height, detail::rowBlocks(camera.height, 16), [&](int, int rowBegin, int rowEnd) {
            for (int y = rowBegin; y < rowEnd; ++y)
                for (int x = 0; x < camera.width; ++x) {
                    const std::uint32_t id = buffers.faceAt(x, y);
                    if (id == FrameBuffers::kNoFace) continue;
                    const FaceIndex f(id);
                    if (std::size_t(id) >= faceSlots || mesh.is_removed(f))
                        throw InvalidInputError("The face id " + std::to_string(id) + " at pixel " +
                                                pixelName(x, y) + " is not a face of the mesh.");
                    std::array<VertexIndex, 3> v;
                    int nv = 0;
                    for (VertexIndex w : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
                        if (nv == 3)
                            throw InvalidInputError("Face " + std::to_string(id) + " is not a triangle.");
                        v[std::size_t(nv++)] = w;
                    }
                    if (nv != 3)
                        throw InvalidInputError("Face " + std::to_string(id) + " is not a triangle.");
                    const Eigen::Vector3d a = toEigen(mesh.point(v[0])), b = toEigen(mesh.point(v[1])),
                                          c = toEigen(mesh.point(v[2]));
                    const Eigen::Vector3d n = (b - a).cross(c - a);
                    const double n2 = n.squaredNorm();
                    if (!(n2 > 0)) continue; // degenerate face: no plane, no direction

                    // 3D point under the pixel centre: ray ∩ face plane (double), depth buffer as fallback.
                    const Ray ray = projector.ray(x + 0.5, y + 0.5);
                    const double denom = n.dot(ray.direction);
                    Eigen::Vector3d p;
                    if (std::abs(denom) > 1e-12 * std::sqrt(n2))
                        p = ray.origin + (n.dot(a - ray.origin) / denom) * ray.direction;
                    else
                        p = projector.unproject(x + 0.5, y + 0.5, double(buffers.depthAt(x, y)));

                    // Barycentric coordinates, clamped to the triangle (the pixel centre may lie a hair
                    // outside).
                    std::array<double, 3> w = {n.dot((b - p).cross(c - p)) / n2,
                                               n.dot((c - p).cross(a - p)) / n2,
                                               n.dot((a - p).cross(b - p)) / n2};
                    double sum = 0;
                    for (double& wi : w)
                        sum += (wi = std::max(0.0, wi));
                    if (!(sum > 0)) continue;
                    for (double& wi : w)
                        wi /= sum;
                    p = w[0] * a + w[1] * b + w[2] * c;

                    // Into the tangent plane of the interpolated vertex normal (the smooth surface's plane at
                    // p). The face plane would tilt D by up to half the dihedral angle of the faceting, which
                    // the foreshortening near silhouettes turns into screen errors of degrees.
                    Eigen::Vector3d N = Eigen::Vector3d::Zero();
                    double aniso = 0;
                    for (int k = 0; k < 3; ++k) {
                        N += w[std::size_t(k)] * curvature.normal[v[std::size_t(k)].idx()];
                        if (curvature.isDefined(v[std::size_t(k)]))
                            aniso += w[std::size_t(k)] * curvature.anisotropy[v[std::size_t(k)].idx()];
                    }
                    if (!(N.norm() > 1e-9)) N = n;
                    N.normalize();
                    const double eps = 1e-3 * projector.pixelFootprint(p);

                    for (DirectionField* field : {minField, maxField}) {
                        if (!field) continue;
                        const bool useMax = field == maxField;
                        // Line field: align every vertex direction with the first defined one, then blend.
                        Eigen::Vector3d D = Eigen::Vector3d::Zero();
                        const Eigen::Vector3d* first = nullptr;
                        for (int k = 0; k < 3; ++k) {
                            if (!curvature.isDefined(v[std::size_t(k)])) continue;
                            // By magnitude: Max is the direction of the principal curvature of larger
                            // |k| (across a crease, convex or concave), Min the other.
                            const std::size_t vi = v[std::size_t(k)].idx();
                            const bool swapped = std::abs(curvature.k2[vi]) > std::abs(curvature.k1[vi]);
                            const Eigen::Vector3d& d = curvature.direction(v[std::size_t(k)], useMax != swapped);
                            if (!first) first = &d;
                            D += (d.dot(*first) < 0 ? -w[std::size_t(k)] : w[std::size_t(k)]) * d;
                        }
                        D -= D.dot(N) * N;
                        const double coherence = D.norm();
                        if (!(coherence > 1e-9)) continue;
                        const Eigen::Vector3d unit = D / coherence;
                        const Eigen::Vector2d screen =
                            projector.project(p + eps * unit) - projector.project(p - eps * unit);
                        // A direction along the viewing ray projects to (almost) nothing: no screen
                        // direction.
                        if (!(screen.norm() > 1e-6 * 2e-3)) continue;
                        field->setPixel(x, y, screen, aniso * std::min(1.0, coherence));
                    }
                }
        });
}

} // namespace

DirectionField computeDirectionField(const Mesh& mesh, const CurvatureField& curvature,
                                     const FrameBuffers& buffers, const DirectionFieldOptions& options) {
    DirectionField field;
    if (options.direction == PrincipalDirection::Max)
        fillDirectionFields(mesh, curvature, buffers, nullptr, &field);
    else
        fillDirectionFields(mesh, curvature, buffers, &field, nullptr);
    return field;
}

DirectionFieldPair computeDirectionFields(const Mesh& mesh, const CurvatureField& curvature,
                                          const FrameBuffers& buffers) {
    DirectionFieldPair pair;
    fillDirectionFields(mesh, curvature, buffers, &pair.min, &pair.max);
    return pair;
}

} // namespace fss
