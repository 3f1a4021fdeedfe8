// The one-pass join of auto v2 (internal, remesh/join_regions.h): the hole filling's split of a pinched
// boundary cycle (one that passes a vertex twice) into simple loops, which CGAL's hole triangulation can
// fill.
#include "remesh/join_regions.h"

#include "fss/mesh.h"

#include <gtest/gtest.h>

#include <vector>

// Session 18 measured on couplingdown (FSS_AUTO_V2_DEBUG=1): 20 of the 105 boundary cycles the gap closing
// left passed a vertex twice, and CGAL's triangulate_and_refine_hole returned no face for every one of them
// (it filled all 85 others), so the repair grew those holes round after round. The fill now cuts such a
// cycle at its repeated vertices. Vertices by index: a cycle 1 2 9 3 4 9 5 (9 twice) is the loops 9 3 4
// and 1 2 9 5; 1 2 7 8 7 3 (the edge 7-8 bordered on both sides) leaves that edge out; a simple cycle stays.
TEST(AutoJoin, PinchedCycleIsCutIntoSimpleLoops) {
    const auto v = [](std::initializer_list<std::uint32_t> ids) {
        std::vector<fss::VertexIndex> out;
        for (std::uint32_t i : ids)
            out.push_back(fss::VertexIndex(i));
        return out;
    };
    using Loops = std::vector<std::vector<fss::VertexIndex>>;
    EXPECT_EQ(fss::detail::pinchedCycleLoops(v({1, 2, 9, 3, 4, 9, 5})),
              (Loops{v({9, 3, 4}), v({1, 2, 9, 5})}));
    EXPECT_EQ(fss::detail::pinchedCycleLoops(v({1, 2, 7, 8, 7, 3})), (Loops{v({1, 2, 7, 3})}));
    EXPECT_EQ(fss::detail::pinchedCycleLoops(v({4, 5, 6})), (Loops{v({4, 5, 6})}));
    // Two vertices repeated: 1 2 3 1 4 5 6 4 is the loops 1 2 3, 4 5 6 and what joins them is left out
    // (1 4: two vertices).
    EXPECT_EQ(fss::detail::pinchedCycleLoops(v({1, 2, 3, 1, 4, 5, 6, 4})),
              (Loops{v({1, 2, 3}), v({4, 5, 6})}));
}
