#pragma once
// Internal (not installed): the last step of auto v2 (auto_v2.cpp, step 4), after the seam relaxation and the
// crease recovery: a local repair of the faces whose smallest angle is below a bound (slivers), as CGAL's
// remove_almost_degenerate_faces and pmp-library's remeshing end: for each sliver, worst first, the best of
// a flip of one of its edges (a cap's longest edge), a collapse of its shortest edge (a needle; along a
// crease only onto a crease vertex) and a tangential move of one of its corners projected onto the
// reference, taken only where it raises the smallest angle of the faces it changes. sliverCensus counts the
// slivers by where they lie (the instrument of issue 23's smallest-angle work).
#include "fss/mesh.h"
#include "fss/raycast.h"

#include <array>
#include <cstddef>
#include <string>

namespace fss::detail {

/// Options of repairSlivers.
struct SliverRepairOptions {
    /// Faces whose smallest angle is below this (degrees) are repaired.
    double belowDeg = 20.0;
    /// Target edge length of the mesh (world units): the scale of the distances below.
    double edgeLength = 1.0;
    /// Edges whose two faces' normals differ by more than this (degrees) are creases: never flipped, and
    /// collapsed only along the crease, onto a crease vertex. No operation makes two new faces meet at a
    /// crease, nor turns a face more than this from the reference's normal at its closest point (unless it
    /// was already farther).
    double featureAngleDeg = 35.0;
    /// Every new face's centroid and edge midpoints stay within the largest distance of the faces replaced
    /// from the reference, or within this many edge lengths of it.
    double tolerance = 0.05;
    /// Sweeps over the slivers (each then checked for self-intersections).
    int rounds = 4;
    /// The caller knows that the mesh does not intersect itself; else repairSlivers tests it on entry and
    /// does nothing when it does.
    bool knownFree = false;
};

/// What repairSlivers did.
struct SliverRepairReport {
    std::size_t before = 0;    ///< faces below the bound on entry
    std::size_t after = 0;     ///< faces below the bound on return
    std::size_t flips = 0;     ///< edges flipped
    std::size_t collapses = 0; ///< edges collapsed
    std::size_t moves = 0;     ///< vertices moved
    int sweepsReverted = 0;    ///< sweeps undone because they made the mesh intersect itself (then retried)
    bool freeAfter = false;    ///< the mesh returned does not intersect itself
};

/// Repairs the slivers of \p mesh (see the file comment). A sharp edge of the mesh (above featureAngleDeg)
/// is a crease edge only when both its ends lie within edgeLength / 10 of a crease of the reference;
/// elsewhere it is a fold (a sliver's own) and free. Every operation keeps the mesh a valid
/// edge-manifold triangle mesh (canFlip, canCollapse), never touches a border vertex or the edges between
/// a face left from the input (props::faceScanId < 0) and a scanned face, keeps the vertices marked
/// kOnCreaseProperty (crease_snap.h) and those on a crease edge where they are, and is taken only when the
/// smallest angle of the faces it changes rises. A sweep after which the faces it changed intersect others
/// is undone and run again without the vertices of the intersecting faces (up to three times). \p mesh is
/// garbage collected on return. \p caster is a RayCaster of \p reference.
SliverRepairReport repairSlivers(Mesh& mesh, const RayCaster& caster, const SliverRepairOptions& options);

/// Where the slivers of a mesh lie, by the first class that fits.
struct SliverCensus {
    enum Class {
        Border,       ///< a corner on the mesh's border
        InputFaces,   ///< a face left from the input, or a corner on one
        ForcedCorner, ///< a corner within L/2 of a reference vertex where two creases meet below the bound
        CreaseCorner, ///< a corner within L/2 of another corner of the creases (crease_index.h)
        Crease,       ///< a corner on a crease (kOnCreaseProperty, or a sharp edge near a reference crease)
        Fold,         ///< a corner on a sharp edge of the mesh away from the reference's creases
        Seam,         ///< a corner whose faces come from different scans (the join's zipper)
        Inside,       ///< elsewhere: inside one region's patch
        Count
    };
    std::array<std::size_t, Count> faces{};
    std::size_t total = 0;
    double minAngleDeg = 180;
    /// One line: the counts by class.
    std::string format() const;
};

/// The census of the faces of \p mesh whose smallest angle is below \p belowDeg.
SliverCensus sliverCensus(const Mesh& mesh, const Mesh& reference, double edgeLength, double featureAngleDeg,
                          double belowDeg);

} // namespace fss::detail
