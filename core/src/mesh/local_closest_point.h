#pragma once
// closestPointNear (fss/raycast.h) for many queries on one mesh that does not change meanwhile.
#include "fss/raycast.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace fss::detail {

/// closestPointNear for many queries on one mesh that does not change while this object is used (the seam
/// band's draft, DESIGN.md §6.2; relaxOnReference's reference): the same walk and the same result, face for
/// face, but the rings around a face are collected once (on its first use as a centre) and a face already
/// measured in a query is not measured again after a re-centring (it cannot be strictly closer than the
/// best so far, and the walk keeps the first of equally close faces), nor is a face whose bounding sphere
/// lies clearly farther than the best so far (by a margin far above the rounding of the distances).
/// \pre the mesh outlives this object and is not modified while it is used.
class LocalClosestPoint {
public:
    LocalClosestPoint(const Mesh& mesh, const LocalSearchOptions& options)
        : mesh_(&mesh), options_(options) {}
    /// closestPointNear(mesh, p, hint, options).
    /// \throw InvalidInputError when \p hint is not a face of the mesh.
    SurfacePoint operator()(const Eigen::Vector3d& p, FaceIndex hint);

private:
    const std::vector<FaceIndex>& ringsOf(FaceIndex centre);
    const Mesh* mesh_;
    LocalSearchOptions options_;
    std::vector<std::vector<FaceIndex>> rings_; // per face: its rings in closestPointNear's order, or empty
    std::vector<std::uint32_t> measured_;       // per face: the query that measured it last
    std::vector<Eigen::Vector4d> spheres_;      // per face: centroid and the radius around it
    std::uint32_t query_ = 0;
};

} // namespace fss::detail
