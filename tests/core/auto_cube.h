#pragma once
// The cube [-1/2, 1/2]³ (8 quads per side) remeshed by `auto` to about 900 vertices without the seam
// relaxation and the crease recovery: seams and bevelled creases for the tests of those two stages.
#include "fss/auto_remesh.h"
#include "fss/mesh.h"

namespace fss::test {

inline AutoResult cubeBeforeRelaxation(const Mesh& cube) {
    AutoOptions o;
    o.targetVertices = 900;
    o.seamRelaxRounds = 0;
    o.creaseSnapRounds = 0;
    return autoRemesh(cube, o);
}

} // namespace fss::test
