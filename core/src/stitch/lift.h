#pragma once
// Stitch v2, stage "lift" (DESIGN.md §6.2 step 4): points of the gap triangulation, found in the scan's view,
// are lifted onto the reference surface by casting the scan camera's ray through them.

#include "fss/camera.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace fss::stitch {

/// View coordinates of the stitch: (screen x, −screen y), so front-facing triangles are counter-clockwise.
Eigen::Vector2d viewPoint(const Camera& camera, const Eigen::Vector3d& p);

/// The reference surface under the gap: triangles (the current mesh's faces that the stitch removes).
struct LiftReference {
    std::vector<Eigen::Vector3d> points;
    std::vector<std::array<int, 3>> triangles;
};

/// The point of the plane through \p a, \p b, \p c on the scan camera's ray through view point \p uv
/// (none when the ray is parallel to the plane or the point lies behind the eye).
std::optional<Eigen::Vector3d> liftOntoPlane(const Camera& camera, const Eigen::Vector2d& uv,
                                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                             const Eigen::Vector3d& c);

/// Finds, for a view point, the reference triangle under it and the point of that triangle on the scan
/// camera's ray (the triangle nearest the eye when several overlap; within \p tolerance pixels of the
/// outline, the nearest in the view). Built once in O(triangles) (a bucket grid in the view: the 2D point
/// location needs no triangulation, and the triangles may overlap); each query looks at one bucket.
class ReferenceLocator {
public:
    struct Hit {
        int triangle = -1;
        Eigen::Vector3d point;
    };
    ReferenceLocator(const Camera& camera, const LiftReference& reference);
    std::optional<Hit> lift(const Eigen::Vector2d& uv, double tolerance = 0.0) const;
    /// Is uv over a reference triangle (strictly, within \p tolerance pixels)?
    bool covers(const Eigen::Vector2d& uv, double tolerance = 0.0) const;

private:
    std::int64_t key(double x, double y) const;
    const Camera& camera_;
    const LiftReference& reference_;
    std::vector<Eigen::Vector2d> proj_;
    double cell_ = 1;
    std::unordered_map<std::int64_t, std::vector<int>> grid_;
};

} // namespace fss::stitch
