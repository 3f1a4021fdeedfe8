// Where the slivers of auto v2's result lie (sliver_repair.h, sliverCensus).
#include "remesh/sliver_repair.h"

#include "mesh/features.h"
#include "mesh/triangle_geometry.h"
#include "remesh/crease_index.h"
#include "remesh/crease_snap.h"
#include "remesh/join_regions.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace fss::detail {
std::string SliverCensus::format() const {
    static const char* names[Count] = {"border", "input", "forced_corner", "corner",
                                       "crease", "fold",  "seam",          "inside"};
    std::string out = "total " + std::to_string(total);
    char buf[64];
    std::snprintf(buf, sizeof buf, " (min %.2f deg):", minAngleDeg);
    out += buf;
    for (int c = 0; c < Count; ++c)
        out += std::string(" ") + names[c] + " " + std::to_string(faces[std::size_t(c)]);
    return out;
}

SliverCensus sliverCensus(const Mesh& mesh, const Mesh& reference, double edgeLength, double featureAngleDeg,
                          double belowDeg) {
    SliverCensus census;
    const double floor = belowDeg * std::numbers::pi / 180.0;
    // The reference's crease corners, and its vertices where two creases meet below the bound (forced).
    const char* env = std::getenv("FSS_AUTO_V2_SLIVERS");
    const bool verbose = env && std::string(env) == "2";
    const std::vector<char> refSharp = sharpEdges(reference, featureAngleDeg);
    const creases::CreaseIndex creases(reference, featureAngleDeg, edgeLength);
    std::vector<Eigen::Vector3d> corners, forced;
    for (VertexIndex v : creaseCorners(reference, refSharp))
        corners.push_back(pos(reference, v));
    for (VertexIndex v : reference.vertices()) {
        std::vector<Eigen::Vector3d> out;
        for (HalfedgeIndex h : CGAL::halfedges_around_source(reference.halfedge(v), reference))
            if (refSharp[reference.edge(h).idx()])
                out.push_back((pos(reference, reference.target(h)) - pos(reference, v)).normalized());
        bool tight = false;
        for (std::size_t i = 0; i < out.size(); ++i)
            for (std::size_t j = i + 1; j < out.size(); ++j)
                tight = tight || angleBetween(out[i], out[j]) < floor;
        if (tight) forced.push_back(pos(reference, v));
    }
    PointGrid cornerGrid(0.5 * edgeLength), forcedGrid(0.5 * edgeLength);
    for (const Eigen::Vector3d& p : corners)
        cornerGrid.add(p);
    for (const Eigen::Vector3d& p : forced)
        forcedGrid.add(p);
    const std::vector<char> sharp = sharpEdges(mesh, featureAngleDeg);
    const auto [ids, haveIds] = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    const auto [onCrease, haveMarks] = mesh.property_map<VertexIndex, bool>(kOnCreaseProperty);
    auto isInput = [&](FaceIndex f) { return !haveIds || ids[f] < 0; };
    for (FaceIndex f : mesh.faces()) {
        const HalfedgeIndex h0 = mesh.halfedge(f);
        const VertexIndex vs[3] = {mesh.source(h0), mesh.target(h0), mesh.target(mesh.next(h0))};
        const double angle = minAngle(pos(mesh, vs[0]), pos(mesh, vs[1]), pos(mesh, vs[2]));
        census.minAngleDeg = std::min(census.minAngleDeg, angle * 180.0 / std::numbers::pi);
        if (angle >= floor) continue;
        ++census.total;
        bool border = false, input = isInput(f), forcedNear = false, cornerNear = false, crease = false,
             fold = false, seam = false;
        for (VertexIndex v : vs) {
            const Eigen::Vector3d p = pos(mesh, v);
            border = border || mesh.is_border(v);
            cornerNear = cornerNear || cornerGrid.near(p);
            crease = crease || (haveMarks && onCrease[v]);
            std::int32_t first = -2;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
                if (sharp[mesh.edge(h).idx()]) {
                    Eigen::Vector3d q;
                    double d1 = 0, d2 = 0;
                    const bool along =
                        creases.closest(pos(mesh, mesh.source(h)), q, d1) && d1 <= 0.1 * edgeLength &&
                        creases.closest(pos(mesh, mesh.target(h)), q, d2) && d2 <= 0.1 * edgeLength;
                    (along ? crease : fold) = true;
                }
                const FaceIndex g = mesh.face(h);
                if (g == Mesh::null_face()) continue;
                input = input || isInput(g);
                const std::int32_t id = haveIds ? ids[g] : -1;
                seam = seam || (first != -2 && id != first);
                first = id;
            }
        }
        // Forced: the sliver's smallest corner lies at the meeting point of two creases that make an angle
        // below the bound (any triangulation that keeps both has one there).
        {
            const Eigen::Vector3d p0 = pos(mesh, vs[0]), p1 = pos(mesh, vs[1]), p2 = pos(mesh, vs[2]);
            const double a0 = angleBetween(p1 - p0, p2 - p0), a1 = angleBetween(p2 - p1, p0 - p1);
            const double a2 = std::numbers::pi - a0 - a1;
            const int k = a0 <= a1 && a0 <= a2 ? 0 : a1 <= a2 ? 1 : 2;
            forcedNear = forcedGrid.near(pos(mesh, vs[k]));
        }
        const SliverCensus::Class c = border       ? SliverCensus::Border
                                      : input      ? SliverCensus::InputFaces
                                      : forcedNear ? SliverCensus::ForcedCorner
                                      : cornerNear ? SliverCensus::CreaseCorner
                                      : crease     ? SliverCensus::Crease
                                      : fold       ? SliverCensus::Fold
                                      : seam       ? SliverCensus::Seam
                                                   : SliverCensus::Inside;
        ++census.faces[std::size_t(c)];
        if (verbose) {
            std::fprintf(stderr, "  sliver class %d:", int(c));
            for (VertexIndex v : vs) {
                const Eigen::Vector3d p = pos(mesh, v);
                int sharpCount = 0;
                for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh))
                    sharpCount += sharp[mesh.edge(h).idx()];
                Eigen::Vector3d q;
                double d = -1;
                creases.closest(p, q, d);
                std::fprintf(stderr, " [deg %zu sharp %d mark %d crease %.3f L]", std::size_t(mesh.degree(v)),
                             sharpCount, int(haveMarks && onCrease[v]), d / edgeLength);
            }
            const Eigen::Vector3d p0 = pos(mesh, vs[0]), p1 = pos(mesh, vs[1]), p2 = pos(mesh, vs[2]);
            std::fprintf(stderr, " angles %.1f %.1f at (%.4f %.4f %.4f)\n",
                         angleBetween(p1 - p0, p2 - p0) * 180 / std::numbers::pi,
                         angleBetween(p2 - p1, p0 - p1) * 180 / std::numbers::pi, p0.x(), p0.y(), p0.z());
        }
    }
    return census;
}

} // namespace fss::detail
