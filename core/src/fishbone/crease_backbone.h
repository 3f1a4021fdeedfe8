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
    double ribMaxLength = 0; ///< bound of a rib half's screen length (creaseRibs)
    double maxLength = 0;    ///< bound of the backbone's screen length each way (open chains)
};

/// The backbone along the crease chain nearest to the seed's surface point (the ray through \p seed), when
/// it lies within snapDistance·h footprints of it: the chain (sharp edges between vertices where creases end
/// or branch; mesh/features.h creaseChains) resampled in 3D from the seed's nearest point on it both ways,
/// every h pixel footprints (at each sample's own depth), projected to the screen. Each way stops before the
/// chain's end, before a sample that is hidden or outside the image (seen: the
/// viewing ray through its projection, or 0.01 px beside it across a crease on the silhouette, first hits
/// the reference within 0.05 footprints of it; the backbone sample is that screen position), before a turn of
/// more than 45° between consecutive 3D edges (a corner), and after maxLength on the screen. A closed chain
/// seen whole gives a closed backbone (equal 3D arcs, the seed's point first). std::nullopt when no chain is
/// near enough, or fewer than two samples remain. A backbone on a crease with the 3D points of its samples.
struct CreaseBackbone {
    Backbone backbone;
    std::vector<Eigen::Vector3d> points; ///< on the crease, one per sample
};

std::optional<CreaseBackbone> creaseBackbone(const CreaseBackboneInput& in, const Eigen::Vector2d& seed);

/// The ribs of a crease backbone, perpendicular to the crease on both sides: from each sample, on each side,
/// the straightest line on the surface leaving it perpendicular to the crease in the face hit by the ray h/2
/// beside the sample on that side of the screen: steps of h footprints of the sample, each projected onto the
/// surface under its end (on a planar CAD face: straight lines, square quads along a straight crease). A half
/// stops where it leaves the image, the view or the front surface, at a depth jump (the surface more than
/// half a step from the step's end), where its screen edges shrink below 0.3h and after ribMaxLength, and is
/// empty where the side shows the background or a back face. The caller stops them at creases.
std::vector<Rib> creaseRibs(const CreaseBackboneInput& in, const CreaseBackbone& crease);

} // namespace fss::detail
