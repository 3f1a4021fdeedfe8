// Polygon soup -> oriented manifold triangle mesh: the soup's statistics as read, then the repairs (merge
// equal points, drop repeated corners, triangulate polygons by ear clipping, remove duplicate triangles,
// orient with CGAL's orient_polygon_soup and separate non-manifold vertices, drop isolated points), each
// reported in one sentence. See fss/mesh_io.h.
#include "base/disjoint_sets.h"
#include "mesh/io_detail.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>

#include <cmath>
#include <numeric>

namespace PMP = CGAL::Polygon_mesh_processing;

namespace fss::detail::io {
namespace {

/// All corners collinear (exact predicate): the polygon has zero area.
bool hasZeroArea(const std::vector<Point3>& pts, const Polygon& poly) {
    const Point3& p = pts[poly[0]];
    std::size_t j = 1;
    while (j < poly.size() && pts[poly[j]] == p)
        ++j;
    if (j == poly.size()) return true;
    const Point3& q = pts[poly[j]];
    for (std::size_t k = j + 1; k < poly.size(); ++k)
        if (!CGAL::collinear(p, q, pts[poly[k]])) return false;
    return true;
}

bool hasRepeatedCorner(const Polygon& p) {
    if (p.size() == 3) return p[0] == p[1] || p[1] == p[2] || p[0] == p[2];
    Polygon sorted = p;
    std::sort(sorted.begin(), sorted.end());
    return std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
}

/// Edge and vertex manifoldness and orientation consistency of a soup whose polygons have no repeated
/// corners. The soup is a valid oriented polygon mesh exactly when all three counts are zero (the
/// condition of CGAL's is_polygon_soup_a_polygon_mesh, computed here in linear time).
struct Topology {
    std::size_t nonManifoldEdges = 0;    ///< undirected edges in more than two polygons
    std::size_t nonManifoldVertices = 0; ///< vertices whose polygons form more than one fan
    std::size_t misorientedEdges = 0;    ///< directed edges used twice (neighbours of opposite orientation)
    bool isMesh() const { return nonManifoldEdges == 0 && nonManifoldVertices == 0 && misorientedEdges == 0; }
};

/// Polygons with skip[f] != 0 (when skip is given) are left out.
Topology analyseTopology(const std::vector<Polygon>& polys, std::size_t pointCount,
                         const std::vector<char>* skip = nullptr) {
    // The corners around each vertex, bucketed by vertex (counting sort): (previous, next) vertex.
    std::vector<std::size_t> start(pointCount + 1, 0);
    for (std::size_t f = 0; f < polys.size(); ++f)
        if (!skip || !(*skip)[f])
            for (std::size_t c : polys[f])
                ++start[c + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::pair<std::size_t, std::size_t>> wedges(start.back());
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (skip && (*skip)[f]) continue;
        const Polygon& p = polys[f];
        const std::size_t m = p.size();
        for (std::size_t j = 0; j < m; ++j)
            wedges[fill[p[j]]++] = {p[(j + m - 1) % m], p[(j + 1) % m]};
    }

    Topology t;
    std::vector<std::pair<std::size_t, bool>> around; // (neighbour, edge points towards it)
    std::vector<std::size_t> neighbours;
    for (std::size_t v = 0; v < pointCount; ++v) {
        const std::size_t b = start[v], e = start[v + 1];
        if (b == e) continue;
        around.clear();
        for (std::size_t k = b; k < e; ++k) {
            around.emplace_back(wedges[k].second, true);
            around.emplace_back(wedges[k].first, false);
        }
        std::sort(around.begin(), around.end());
        neighbours.clear();
        for (std::size_t i = 0; i < around.size();) {
            std::size_t j = i, outgoing = 0;
            for (; j < around.size() && around[j].first == around[i].first; ++j)
                outgoing += around[j].second;
            // Each polygon with the edge v–x has exactly one corner at v next to x.
            if (around[i].first > v && j - i > 2) ++t.nonManifoldEdges;
            if (outgoing > 1) t.misorientedEdges += outgoing - 1;
            neighbours.push_back(around[i].first);
            i = j;
        }
        if (e - b < 2) continue;
        // One fan exactly when the link (segments previous–next around v) is connected.
        auto local = [&](std::size_t x) {
            return std::size_t(std::lower_bound(neighbours.begin(), neighbours.end(), x) -
                               neighbours.begin());
        };
        DisjointSets sets(neighbours.size());
        for (std::size_t k = b; k < e; ++k)
            sets.unite(local(wedges[k].first), local(wedges[k].second));
        std::size_t fans = 0;
        for (std::size_t k = 0; k < neighbours.size(); ++k)
            fans += sets.find(k) == k;
        if (fans > 1) ++t.nonManifoldVertices;
    }
    return t;
}

/// Statistics of the soup as read. `canonical[i]` is the first point equal to point i; `topology` is that
/// of the polygons without repeated corners, equal points identified.
SoupStats computeStats(const Soup& soup, std::vector<std::size_t>& canonical, Topology& topology) {
    SoupStats s;
    s.points = soup.points.size();
    s.polygons = soup.polygons.size();
    canonical.resize(soup.points.size());
    PointTable table(soup.points, soup.points.size());
    for (std::size_t i = 0; i < soup.points.size(); ++i) {
        canonical[i] = table.firstEqual(i);
        if (canonical[i] != i) ++s.duplicatePoints;
    }
    // Topology of the surface the file means: equal points identified, repeated-corner polygons left out.
    std::vector<Polygon> merged;
    if (s.duplicatePoints > 0) {
        merged = soup.polygons;
        for (Polygon& p : merged)
            for (std::size_t& c : p)
                c = canonical[c];
    }
    const std::vector<Polygon>& polys = s.duplicatePoints > 0 ? merged : soup.polygons;
    std::vector<char> repeated(polys.size(), 0);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (polys[f].size() > 3) ++s.nonTriangles;
        repeated[f] = hasRepeatedCorner(polys[f]);
        if (repeated[f] || hasZeroArea(soup.points, soup.polygons[f])) ++s.degeneratePolygons;
    }
    topology = analyseTopology(polys, soup.points.size(), &repeated);
    s.nonManifoldEdges = topology.nonManifoldEdges;
    s.nonManifoldVertices = topology.nonManifoldVertices;
    return s;
}

// =====================================================================================================
// Repair and mesh construction
// =====================================================================================================

/// Appends triangle (a, b, c) to \p out, built in place (moving a brace-initialised small_vector in makes
/// GCC 12 warn about a memcpy it cannot bound, -Wstringop-overread).
void addTriangle(std::vector<Polygon>& out, std::size_t a, std::size_t b, std::size_t c) {
    Polygon& t = out.emplace_back();
    t.push_back(a);
    t.push_back(b);
    t.push_back(c);
}

/// Polygons with more corners are triangulated as a fan (ear clipping is quadratic).
constexpr std::size_t kMaxEarClippingCorners = 10000;

/// Triangulates one polygon by ear clipping in the plane of its dominant normal axis (exact orientation
/// tests on the projected coordinates), keeping its orientation; falls back to a fan when no ear is left
/// (self-intersecting or zero-area polygons) or when `budget` (point tests left for the whole file, which
/// bounds the time an adversarial file can take) runs out. Returns false when it fell back to a fan for a
/// polygon with area (whose triangles may then overlap).
bool triangulatePolygon(const std::vector<Point3>& pts, const Polygon& poly, std::vector<Polygon>& out,
                        std::size_t& budget) {
    const std::size_t n = poly.size();
    auto fan = [&](const std::vector<std::size_t>& ids) {
        for (std::size_t i = 1; i + 1 < ids.size(); ++i)
            addTriangle(out, poly[ids[0]], poly[ids[i]], poly[ids[i + 1]]);
    };
    std::vector<std::size_t> remaining(n);
    std::iota(remaining.begin(), remaining.end(), 0);

    std::array<double, 3> normal{0, 0, 0}; // Newell's normal
    for (std::size_t i = 0; i < n; ++i) {
        const Point3& a = pts[poly[i]];
        const Point3& b = pts[poly[(i + 1) % n]];
        normal[0] += (a.y() - b.y()) * (a.z() + b.z());
        normal[1] += (a.z() - b.z()) * (a.x() + b.x());
        normal[2] += (a.x() - b.x()) * (a.y() + b.y());
    }
    std::size_t axis = 0;
    for (std::size_t k = 1; k < 3; ++k)
        if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
    if (normal[axis] == 0.0 || !std::isfinite(normal[axis])) { // zero area: any triangulation will do
        fan(remaining);
        return true;
    }
    if (n > kMaxEarClippingCorners) {
        fan(remaining);
        return false;
    }
    // Dropping the dominant axis and keeping the cyclic order of the other two preserves the sign of the
    // projected area: the polygon turns left in 2D exactly when normal[axis] > 0.
    const CGAL::Orientation convex = normal[axis] > 0 ? CGAL::LEFT_TURN : CGAL::RIGHT_TURN;
    std::vector<Kernel::Point_2> p2(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Point3& p = pts[poly[i]];
        p2[i] = Kernel::Point_2(p[int((axis + 1) % 3)], p[int((axis + 2) % 3)]);
    }

    std::size_t i = 0, failures = 0;
    while (remaining.size() > 3) {
        const std::size_t m = remaining.size();
        if (budget < m) {
            fan(remaining);
            return false;
        }
        i %= m;
        const std::size_t ia = remaining[(i + m - 1) % m], ib = remaining[i], ic = remaining[(i + 1) % m];
        const Kernel::Point_2 &a = p2[ia], &b = p2[ib], &c = p2[ic];
        bool ear = CGAL::orientation(a, b, c) == convex;
        budget -= ear ? m : 1; // an emptiness test costs m point tests
        for (std::size_t k = 0; ear && k < m; ++k) {
            const std::size_t id = remaining[k];
            if (id == ia || id == ib || id == ic) continue;
            const Kernel::Point_2& q = p2[id];
            if (q == a || q == b || q == c) continue;
            const CGAL::Orientation outside = convex == CGAL::LEFT_TURN ? CGAL::RIGHT_TURN : CGAL::LEFT_TURN;
            if (CGAL::orientation(a, b, q) != outside && CGAL::orientation(b, c, q) != outside &&
                CGAL::orientation(c, a, q) != outside)
                ear = false;
        }
        if (ear) {
            addTriangle(out, poly[ia], poly[ib], poly[ic]);
            remaining.erase(remaining.begin() + std::ptrdiff_t(i));
            failures = 0;
        } else if (++failures > m) {
            fan(remaining);
            return false;
        } else {
            ++i;
        }
    }
    addTriangle(out, poly[remaining[0]], poly[remaining[1]], poly[remaining[2]]);
    return true;
}

/// Records which polygons orient_polygon_soup reversed.
struct ReversalRecorder : PMP::Default_orientation_visitor {
    std::vector<char>* reversed = nullptr;
    void polygon_orientation_reversed(std::size_t i) { (*reversed)[i] ^= 1; }
};

/// orient_polygon_soup keeps the orientation of the first polygon of each component; flip back the
/// components where that reversed the majority of the file's polygons, so the fewest are changed.
void keepMajorityOrientation(std::vector<Polygon>& polys, std::vector<char>& reversed) {
    std::vector<std::array<std::size_t, 3>> edges; // (min, max, polygon)
    for (std::size_t f = 0; f < polys.size(); ++f)
        for (std::size_t j = 0; j < polys[f].size(); ++j) {
            const std::size_t a = polys[f][j], b = polys[f][(j + 1) % polys[f].size()];
            edges.push_back({std::min(a, b), std::max(a, b), f});
        }
    std::sort(edges.begin(), edges.end());
    DisjointSets sets(polys.size());
    for (std::size_t i = 1; i < edges.size(); ++i)
        if (edges[i][0] == edges[i - 1][0] && edges[i][1] == edges[i - 1][1])
            sets.unite(edges[i][2], edges[i - 1][2]);
    std::vector<std::size_t> size(polys.size(), 0), flipped(polys.size(), 0);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        ++size[sets.find(f)];
        if (reversed[f]) ++flipped[sets.find(f)];
    }
    for (std::size_t f = 0; f < polys.size(); ++f) {
        const std::size_t root = sets.find(f);
        if (2 * flipped[root] > size[root]) {
            std::reverse(polys[f].begin(), polys[f].end());
            reversed[f] ^= 1;
        }
    }
}

/// Removes triangles with the same corners as an earlier one (either orientation); true when any.
bool removeDuplicateTriangles(std::vector<Polygon>& polys, std::vector<std::size_t>& origin,
                              ReadReport& report) {
    std::vector<std::array<std::size_t, 4>> keys(polys.size());
    for (std::size_t f = 0; f < polys.size(); ++f) {
        keys[f] = {polys[f][0], polys[f][1], polys[f][2], f};
        std::sort(keys[f].begin(), keys[f].begin() + 3);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<char> drop(polys.size(), 0);
    std::size_t duplicates = 0;
    for (std::size_t i = 1; i < keys.size(); ++i)
        if (std::equal(keys[i].begin(), keys[i].begin() + 3, keys[i - 1].begin())) {
            drop[keys[i][3]] = 1;
            ++duplicates;
        }
    if (!duplicates) return false;
    std::size_t kept = 0;
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (drop[f]) continue;
        if (kept != f) polys[kept] = std::move(polys[f]); // self-move would empty it
        origin[kept++] = origin[f];
    }
    polys.resize(kept);
    origin.resize(kept);
    report.repairs.push_back("removed " + quantity(duplicates, "duplicate triangle", "duplicate triangles"));
    return true;
}

} // namespace

/// Turns the soup into a valid triangle mesh, repairing (and reporting) what must be repaired.
Mesh soupToMesh(const Source& src, Soup& soup, ReadReport& report, const ReadOptions& options) {
    if (soup.polygons.empty())
        src.fail(soup.points.empty()
                     ? std::string("it contains no faces")
                     : "it contains no faces, only " + quantity(soup.points.size(), "point", "points"));
    std::vector<std::size_t> canonical;
    Topology topology;
    report.soup = computeStats(soup, canonical, topology);
    bool changed =
        report.soup.duplicatePoints > 0; // topology above is that of the current soup until changed
    const SoupStats& stats = report.soup;
    std::vector<Polygon>& polys = soup.polygons;
    std::vector<std::size_t> origin(polys.size()); // polygon of the file each current polygon comes from
    std::iota(origin.begin(), origin.end(), 0);
    auto refuse = [&](const std::string& problem) {
        src.fail("it is not a valid oriented manifold mesh (" + problem + ") and repair is disabled");
    };

    // 1. Merge geometrically equal points.
    const bool merge = options.repair && stats.duplicatePoints > 0;
    if (merge) {
        for (Polygon& p : polys)
            for (std::size_t& c : p)
                c = canonical[c];
        report.repairs.push_back("merged " +
                                 quantity(stats.duplicatePoints, "duplicate point", "duplicate points"));
    }

    // 2. Polygons with repeated corners: drop consecutive repeats, remove what is still degenerate.
    {
        std::size_t simplified = 0, removed = 0, kept = 0;
        for (std::size_t f = 0; f < polys.size(); ++f) {
            Polygon& p = polys[f];
            Polygon q;
            for (std::size_t j = 0; j < p.size(); ++j)
                if (p[j] != p[(j + 1) % p.size()]) q.push_back(p[j]);
            if (q.size() < 3 || hasRepeatedCorner(q)) {
                ++removed;
                continue;
            }
            if (q.size() != p.size()) ++simplified;
            polys[kept] = std::move(q);
            origin[kept++] = origin[f];
        }
        polys.resize(kept);
        origin.resize(kept);
        changed = changed || removed || simplified;
        if (!options.repair && (removed || simplified))
            refuse(quantity(removed + simplified, "polygon has", "polygons have") + " repeated corners");
        if (removed)
            report.repairs.push_back("removed " +
                                     quantity(removed, "degenerate polygon", "degenerate polygons") +
                                     " with repeated corners");
        if (simplified)
            report.repairs.push_back("removed repeated corners from " +
                                     quantity(simplified, "polygon", "polygons"));
        if (polys.empty())
            src.fail("nothing is left after repair: all " +
                     quantity(stats.polygons, "polygon is", "polygons are") + " degenerate");
    }

    // 3. Triangulate polygons with more than three corners (a Mesh holds triangles).
    if (std::any_of(polys.begin(), polys.end(), [](const Polygon& p) { return p.size() > 3; })) {
        std::vector<Polygon> triangles;
        std::vector<std::size_t> triangleOrigin;
        triangles.reserve(polys.size());
        std::size_t split = 0, fanned = 0, corners = 0;
        for (const Polygon& p : polys)
            corners += p.size();
        std::size_t budget = 10'000'000 + 64 * corners; // generous for real polygons, bounded for any file
        for (std::size_t f = 0; f < polys.size(); ++f) {
            const std::size_t before = triangles.size();
            if (polys[f].size() == 3) {
                triangles.push_back(std::move(polys[f]));
            } else {
                if (!triangulatePolygon(soup.points, polys[f], triangles, budget)) ++fanned;
                ++split;
            }
            triangleOrigin.insert(triangleOrigin.end(), triangles.size() - before, origin[f]);
        }
        report.repairs.push_back(
            "triangulated " +
            quantity(split, "polygon with more than three corners", "polygons with more than three corners") +
            " into " + quantity(triangles.size() - (polys.size() - split), "triangle", "triangles"));
        if (fanned)
            report.repairs.push_back(
                "triangulated " +
                quantity(fanned, "polygon as a simple fan because it is",
                         "polygons as simple fans because they are") +
                " self-intersecting or too large to triangulate carefully, so the triangles may overlap");
        polys = std::move(triangles);
        origin = std::move(triangleOrigin);
        changed = true;
    }

    // 4. Orientation and manifoldness.
    if (changed) topology = analyseTopology(polys, soup.points.size());
    if (!topology.isMesh()) {
        if (!options.repair) {
            std::vector<std::string> parts;
            if (topology.nonManifoldEdges)
                parts.push_back(
                    quantity(topology.nonManifoldEdges, "non-manifold edge", "non-manifold edges"));
            if (topology.nonManifoldVertices)
                parts.push_back(
                    quantity(topology.nonManifoldVertices, "non-manifold vertex", "non-manifold vertices"));
            if (topology.misorientedEdges)
                parts.push_back(quantity(topology.misorientedEdges, "edge", "edges") +
                                " between polygons of opposite orientation");
            std::string joined = parts[0];
            for (std::size_t i = 1; i < parts.size(); ++i)
                joined += ", " + parts[i];
            refuse(joined);
        }
        // Duplicate triangles (same corners, either orientation) always show up here: their edges are
        // non-manifold or misoriented. Keep the first of each.
        if (removeDuplicateTriangles(polys, origin, report))
            topology = analyseTopology(polys, soup.points.size());
    }
    if (!topology.isMesh()) {
        const std::size_t pointsBefore = soup.points.size();
        const std::size_t nonManifoldEdges = topology.nonManifoldEdges;
        std::vector<char> reversed(polys.size(), 0);
        ReversalRecorder recorder;
        recorder.reversed = &reversed;
        PMP::orient_polygon_soup(soup.points, polys, CGAL::parameters::visitor(recorder));
        keepMajorityOrientation(polys, reversed);
        const auto flipped = static_cast<std::size_t>(std::count(reversed.begin(), reversed.end(), 1));
        if (flipped)
            report.repairs.push_back("reoriented " + quantity(flipped, "polygon", "polygons") +
                                     " to match the orientation of their neighbours");
        if (nonManifoldEdges)
            report.repairs.push_back("separated the polygons around " +
                                     quantity(nonManifoldEdges, "edge", "edges") +
                                     " shared by more than two polygons");
        if (const std::size_t added = soup.points.size() - pointsBefore)
            report.repairs.push_back("duplicated " +
                                     quantity(added, "non-manifold vertex", "non-manifold vertices") +
                                     " to make the mesh manifold");
        if (!analyseTopology(polys, soup.points.size()).isMesh())
            src.fail("it could not be repaired into a manifold mesh");
    }

    // 5. Points no polygon uses (merged-away duplicates are not counted again) are dropped.
    std::vector<char> used(soup.points.size(), 0);
    for (const Polygon& p : polys)
        for (std::size_t c : p)
            used[c] = 1;
    std::size_t isolated = 0;
    for (std::size_t i = 0; i < used.size(); ++i)
        if (!used[i] && !(merge && i < canonical.size() && canonical[i] != i)) ++isolated;
    // Isolated vertices would make the mesh invalid (CGAL::is_valid_polygon_mesh).
    if (isolated && !options.repair)
        refuse(quantity(isolated, "point is", "points are") + " used by no polygon");
    if (isolated)
        report.repairs.push_back("removed " + quantity(isolated, "isolated point", "isolated points") +
                                 " that no polygon uses");

    // 6. Build: vertices in file order, faces in polygon order (so face properties keep their order).
    std::optional<Mesh> built = buildTriangleMesh(soup.points, used, polys);
    if (!built) src.fail("its polygons could not be assembled into a mesh (an internal error of FSS)");
    Mesh& mesh = *built;
    if (!soup.quality.empty()) {
        auto map = mesh.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality).first;
        for (std::size_t f = 0; f < polys.size(); ++f)
            map[FaceIndex(Mesh::size_type(f))] = soup.quality[origin[f]];
        report.hasFaceQuality = true;
    }
    if (!soup.scanId.empty()) {
        auto map = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
        for (std::size_t f = 0; f < polys.size(); ++f)
            map[FaceIndex(Mesh::size_type(f))] = soup.scanId[origin[f]];
        report.hasScanId = true;
    }
    if (!soup.group.empty()) {
        setGroupNames(mesh, soup.groupNames);
        auto map = mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup).first;
        for (std::size_t f = 0; f < polys.size(); ++f)
            map[FaceIndex(Mesh::size_type(f))] = soup.group[origin[f]];
        report.groups = soup.groupNames.size();
    }
    return std::move(mesh);
}

} // namespace fss::detail::io
