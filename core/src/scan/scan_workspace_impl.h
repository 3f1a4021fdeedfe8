#pragma once
// Internal (not installed): what a ScanWorkspace holds. Every stage that uses a buffer sizes and fills it
// completely before reading it, so nothing of an earlier scan leaks into a later one.
#include "fss/sample_grid.h"
#include "fss/scan_workspace.h"
#include "fss/triangulate.h"

#include <array>
#include <cstdint>
#include <vector>

namespace fss {

struct ScanWorkspace::Impl {
    // Recycled outputs (ScanWorkspace::recycle).
    std::vector<Sample> samples;
    Patch patch;
    bool hasPatch = false;

    // Morphology (mask.cpp): one byte per sample.
    std::vector<std::uint8_t> valid, admissible, original, square;

    // Triangulation (triangulate.cpp).
    using Triangle = std::array<std::uint32_t, 3>;
    struct Block {
        std::vector<Triangle> candidates; // kept by the 3D tests in one of the two orders
        std::vector<std::uint8_t> keptIf; // of each candidate: kept if the grid is not mirrored, or if it is
        std::vector<std::uint8_t> top, bottom; // sample flags of the two rows of the quad row at hand
        std::size_t quads = 0, rightTurns = 0, leftTurns = 0;
        std::array<std::array<std::size_t, 6>, 2> verdicts{}; // per verdict, if not mirrored / if mirrored
    };
    std::vector<float> sampleQuality;
    std::vector<Block> blocks;
    std::vector<Triangle> triangles;
    std::vector<std::uint8_t> quadHalves, pushed;
    std::vector<std::uint32_t> work;
    std::vector<std::uint32_t> vertexOf, sampleOf, edgeSlot;
    std::vector<std::uint8_t> edgeMade;
    std::vector<Mesh::Halfedge_index> borderFrom, borders;
};

} // namespace fss
