// Stitch v2, design B: crease ends slid along their crease (band_remesher.h). The band holds a vertex with
// one crease edge (a crease end) like a crease corner, so a face below the aim with such a corner stays as
// it is wherever no flip, collapse or split around it helps (issue 19: the main job's variant with
// lattice angle 30 ends at 11.75 deg there). A crease end whose whole star is in the band and that the
// caller does not hold may instead move along its one crease edge, onto the draft's crease polyline where
// it has a place on it: the crease then ends a little earlier, on the same line. Only where the smallest
// angle of its star rises and every face of the star stays facing and within the normal bound.
#include "stitch/band_remesher.h"

namespace fss::stitch::band {

void BandRemesher::slideCreaseEndPass() {
    const double aim = in_.minAngleDeg * kBandDeg, maxTurn = in_.maxNormalTurnDeg * kBandDeg;
    const std::vector<VertexIndex> ends = cornersOfFacesBelow(aim, [&](VertexIndex v) {
        return creaseDegree(v) == 1 && wholeStarInBand(v) && !(in_.fixed && in_.fixed(v));
    });
    for (VertexIndex v : ends) {
        VertexIndex e = Mesh::null_vertex();
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(v), S_))
            if (isCrease(v, w)) e = w;
        if (e == Mesh::null_vertex()) continue;
        slideTowards(v, {e}, true, true, maxTurn);
    }
}

} // namespace fss::stitch::band
