#pragma once
// Internal (not installed): a fishbone backbone along a sharp crease of the reference (issue 20,
// FishboneOptions::creaseBackbone), for the fishbone scan (fishbone_scan.cpp).
#include "fss/camera.h"
#include "fss/fishbone.h"
#include "fss/mesh.h"
#include "fss/raycast.h"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace fss::detail {

/// What creaseBackbone needs besides the seed.
struct CreaseBackboneInput {
    const Mesh* mesh = nullptr;
    const std::vector<EdgeIndex>* creaseEdges = nullptr; ///< the reference's sharp edges
    const RayCaster* caster = nullptr;                   ///< holds *mesh
    Camera camera;           ///< the sampling camera (screen positions in its pixels)
    double spacing = 0;      ///< h, pixels of that camera
    double snapDistance = 0; ///< seed-to-crease distance bound, in h on the surface
    double maxLength = 0;    ///< bound of the backbone's screen length each way (open chains)
};

/// The backbone along the crease chain nearest to the seed's surface point (the ray through \p seed), when
/// it lies within snapDistance·h footprints of it: the chain (sharp edges between vertices where creases end
/// or branch; mesh/features.h creaseChains) resampled in 3D from the seed's nearest point on it both ways,
/// every h pixel footprints (at each sample's own depth), projected to the screen. Each way stops before the
/// chain's end, before a sample that is hidden (its ray hits the reference farther than a footprint from it)
/// or outside the image, before a turn of more than 45° between consecutive 3D edges (a corner), and after
/// maxLength on the screen. A closed chain seen whole gives a closed backbone (equal 3D arcs, the seed's
/// point first). std::nullopt when no chain is near enough, or fewer than two samples remain.
std::optional<Backbone> creaseBackbone(const CreaseBackboneInput& in, const Eigen::Vector2d& seed);

} // namespace fss::detail
