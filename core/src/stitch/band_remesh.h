#pragma once
// Stitch v2, design B (DESIGN.md §6.2): the seam band remeshed in 3D. After version 1 has glued the patch in
// (a draft on the stitch's local mesh: the patch, pieces of the old faces around it, its repair passes), the
// faces along the seam on both sides, a few rings wide, are remeshed on the draft surface by guarded local
// operations in the manner of isotropic remeshing (Botsch & Kobbelt 2004): splits of long edges, collapses
// of short ones, flips towards valence 6 and larger angles, tangential relaxation with projection onto the
// draft (mesh/relax.h). Sizes are graded from the band's border (patch edges on one side, the old mesh's
// edges on the other) across the band, so the band meets both without slivers.
//
// Own operations rather than CGAL's PMP::isotropic_remeshing (CGAL 5.5): that one takes a single target
// length (no grading between a fine patch and a coarse mesh), projects onto the input without refusing a move
// that would turn a face away from the scan camera or cross a crease, and gives no hook to carry the stitch's
// per-face data through its operations.
//
// The band's border vertices, the caller's fixed vertices and corners of creases never move; border edges
// and crease edges are never flipped or collapsed (crease edges may be split, the new vertex on the edge).
// No operation turns a face away from the camera, makes it degenerate or turns its normal by more than
// maxNormalTurnDeg; collapses and moves never lower the smallest angle around them below the smaller of the
// angle before and minAngleDeg. Only band faces change. The caller validates the result (stitch.cpp,
// DESIGN.md §6.1 step 7).

#include "fss/camera.h"
#include "fss/mesh.h"

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <vector>

namespace fss::stitch {

/// What to remesh and how.
struct BandRemeshInput {
    Mesh* mesh = nullptr;           ///< the local mesh holding the draft (edited in place)
    std::vector<FaceIndex> band;    ///< its faces to remesh: front-facing, on the draft surface
    const Camera* camera = nullptr; ///< the scan camera: every band face keeps facing it
    /// Vertices that must stay (besides the band's border and crease corners).
    std::function<bool(VertexIndex)> fixed;
    /// Called for every vertex the stage creates (a split) and for the surviving descriptor of a collapse
    /// when it is not the kept vertex (\p from is then the kept vertex whose data \p to takes over).
    std::function<void(VertexIndex to, VertexIndex from)> vertexData;
    /// Called for every face the stage creates (\p from: the face it was split from).
    std::function<void(FaceIndex to, FaceIndex from)> faceData;
    /// The normal of a band face for finding creases (unit, or zero when unknown: an edge of such a face is
    /// no crease). When empty: the face's own normal where its smallest angle is at least 10 deg (a sliver's
    /// normal says nothing about the surface), else unknown.
    std::function<Eigen::Vector3d(FaceIndex)> creaseNormal;
    /// Faces outside `band` that the band may grow into (new faces). When set, the band grows
    /// until the faces at and beyond its border are fine: a growable face below growBelowDeg that touches
    /// the band, or one below 20 deg anywhere, joins it with the growable faces around its corners; so do
    /// the growable faces around a band vertex that a bad band face would need to move but that is held by
    /// a face outside. At most maxGrowRounds rounds.
    std::function<bool(FaceIndex)> growable;
    /// New faces the view does not see (pieces of old faces): they keep their own orientation (the normal
    /// bound against their creaseNormal) instead of facing the camera.
    std::function<bool(FaceIndex)> unseen;
    /// Called once, after the growth and before any edit, with the band's faces as they are then (the draft);
    /// BandRemeshReport::origin refers to this list.
    std::function<void(const std::vector<FaceIndex>&)> draft;
    double growBelowDeg = 30.0;
    int maxGrowRounds = 6;
    double edgeLength = 0;          ///< initial target edge length inside the band (world units), > 0
    double creaseAngleDeg = 30.0;   ///< band edges whose faces' normals differ more are creases
    double maxNormalTurnDeg = 20.0; ///< no operation turns a face's normal by more
    double minAngleDeg = 30.0;      ///< collapses and flips aim at faces of at least this smallest angle
    int iterations = 4;             ///< rounds of (split, collapse, flip, relax)
};

/// What the stage did.
struct BandRemeshReport {
    std::vector<FaceIndex> faces; ///< the band's faces afterwards
    /// Per face of `faces`: the index (in the list given to BandRemeshInput::draft) of the draft face under
    /// its centroid (the closest point on the draft), or SIZE_MAX when none was found. Labels that say where
    /// a face lies (a patch's scan id) follow the surface this way, not the split history (faceData).
    std::vector<std::size_t> origin;
    std::vector<VertexIndex> touched; ///< vertices created or moved (live at the end)
    std::size_t splits = 0, collapses = 0, flips = 0, moves = 0;
    std::size_t repairs = 0; ///< flips, collapses and splits of the last repair of faces below the aim
    double minAngleBeforeDeg = 180, minAngleAfterDeg = 180; ///< smallest angle over the band
    double fracAbove30Before = 1, fracAbove30After = 1;     ///< share of band faces ≥ 30 deg
    std::size_t grown = 0; ///< faces the band grew by (BandRemeshInput::growable)
    /// New faces below 20 deg afterwards, by where they are: in the band with a vertex free to move, in the
    /// band with every vertex held (by a face outside or the caller), growable but outside the band, unseen.
    std::size_t below20Free = 0, below20Held = 0, below20Beyond = 0, below20Unseen = 0;
};

/// Whether FSS_STITCH_BAND_DIAG=1: the stitch then prints, per band remesh, where the faces below 20 deg are.
bool bandDiagnostics();

/// Remeshes the band (see BandRemeshInput). \pre the band faces are triangles of *mesh.
BandRemeshReport remeshBand(const BandRemeshInput& input);

} // namespace fss::stitch
