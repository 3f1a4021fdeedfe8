// Stitch v2, design B: short band edges merged as clusters (band_remesher.h). A draft's sliver often leaves
// two or three vertices within a few percent of the local size of each other, one of them a crease vertex or
// a crease end (a sliver's normal is unknown, so the crease stops at it). Each single collapse of such a
// cluster leaves another of its short edges in a face (a needle whose normal turns, or an angle lower than
// before), so no single guarded collapse goes; the crease edge stays, and a later band, whose rim it is,
// cannot remove it (the main job's 10.83 deg, DESIGN.md §6.2). Merged at once into one of its vertices,
// the cluster's faces are judged as they will be.
#include "stitch/band_remesher.h"

namespace fss::stitch::band {

namespace {
// A band edge shorter than this fraction of the local size is short.
constexpr double kShortEdge = 0.25;
// At most this many vertices merge at once.
constexpr std::size_t kMaxCluster = 4;
} // namespace

bool BandRemesher::shortEdgePass() {
    std::vector<std::pair<double, std::pair<VertexIndex, VertexIndex>>> cands;
    for (HalfedgeIndex h : bandEdges()) {
        const VertexIndex a = S_.source(h), b = S_.target(h);
        const double len = (detail::pos(S_, a) - detail::pos(S_, b)).norm();
        const double target = 0.5 * (sizeOf(a) + sizeOf(b));
        if (len < kShortEdge * target) cands.push_back({len / target, {a, b}});
    }
    std::sort(cands.begin(), cands.end());
    bool changed = false;
    for (const auto& c : cands) {
        const auto [a, b] = c.second;
        if (S_.is_removed(a) || S_.is_removed(b)) continue;
        const HalfedgeIndex h = S_.halfedge(a, b);
        if (h == Mesh::null_halfedge() || !interiorEdge(h)) continue;
        if (collapseCluster(a)) changed = true;
    }
    return changed;
}

bool BandRemesher::collapseCluster(VertexIndex a) {
    // The cluster: a and the vertices reached from it over short band edges (breadth first, a bounded few).
    std::vector<VertexIndex> cluster{a};
    std::unordered_set<std::uint32_t> inCluster{std::uint32_t(a)};
    for (std::size_t i = 0; i < cluster.size() && cluster.size() < kMaxCluster; ++i)
        for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(cluster[i]), S_)) {
            const VertexIndex w = S_.source(h);
            if (!interiorEdge(h) || inCluster.count(std::uint32_t(w))) continue;
            const double len = (detail::pos(S_, w) - detail::pos(S_, cluster[i])).norm();
            if (len < kShortEdge * 0.5 * (sizeOf(w) + sizeOf(cluster[i])) && cluster.size() < kMaxCluster) {
                cluster.push_back(w);
                inCluster.insert(std::uint32_t(w));
            }
        }
    if (cluster.size() < 2) return false;
    std::sort(cluster.begin(), cluster.end());
    const double aim = in_.minAngleDeg * kBandDeg;

    // The faces that change (the stars of the vertices that go), the smallest angle among them before.
    auto evaluate = [&](VertexIndex t, double& score) {
        std::vector<FaceIndex> faces;
        std::unordered_set<std::uint32_t> seenFace, around;
        for (VertexIndex v : cluster) {
            if (v == t) continue;
            // A vertex that goes moves onto t: free, its whole star in the band; a crease vertex only along
            // its crease, onto its neighbour on it, where the crease keeps its line.
            if (isFixed(v) || !wholeStarInBand(v)) return false;
            if (creaseDegree(v) > 0) {
                if (creaseDegree(v) != 2 || !isCrease(v, t)) return false;
                VertexIndex other = Mesh::null_vertex();
                for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(v), S_))
                    if (w != t && isCrease(v, w)) other = w;
                if (other == Mesh::null_vertex() || inCluster.count(std::uint32_t(other)) ||
                    !creaseCollapseKeepsLine(v, t, other))
                    return false;
            }
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_)) {
                if (seenFace.insert(std::uint32_t(S_.face(h))).second) faces.push_back(S_.face(h));
                if (!inCluster.count(std::uint32_t(S_.source(h)))) around.insert(std::uint32_t(S_.source(h)));
            }
        }
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(t), S_))
            if (!inCluster.count(std::uint32_t(w))) around.insert(std::uint32_t(w));
        // Valences after the merge: t's neighbours are the cluster's; each neighbour keeps one edge to it.
        if (!valenceOk(t, int(around.size()) - int(S_.degree(t)))) return false;
        for (std::uint32_t wi : around) {
            const VertexIndex w(wi);
            int kept = 0, toCluster = 0;
            for (VertexIndex x : CGAL::vertices_around_target(S_.halfedge(w), S_))
                ++(inCluster.count(std::uint32_t(x)) ? toCluster : kept);
            if (!valenceOk(w, kept + (toCluster > 0) - int(S_.degree(w)))) return false;
        }
        V3 star(0, 0, 0);
        for (FaceIndex f : faces)
            star += areaVector(f);
        star.normalize();
        const V3 pt = detail::pos(S_, t);
        const double limit = 2.0 * sizeOf(t);
        double oldMin = std::numbers::pi, newMin = std::numbers::pi;
        for (FaceIndex f : faces) {
            oldMin = std::min(oldMin, faceMinAngle(f));
            std::array<V3, 3> p;
            int k = 0, inside = 0;
            for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(f), S_)) {
                const bool c = inCluster.count(std::uint32_t(v)) > 0;
                inside += c;
                p[std::size_t(k++)] = c ? pt : detail::pos(S_, v);
            }
            if (inside >= 2) continue; // the face goes
            if (!acceptableFace(p[0], p[1], p[2], referenceNormal(f, star), !unseen(f))) return false;
            for (const V3& q : p)
                if ((q - pt).norm() > limit) return false;
            newMin = std::min(newMin, detail::minAngle(p[0], p[1], p[2]));
        }
        if (newMin < std::min(oldMin, aim)) return false;
        score = newMin;
        return true;
    };
    VertexIndex best = Mesh::null_vertex();
    double bestScore = -1;
    for (VertexIndex t : cluster) {
        double score = -1;
        if (evaluate(t, score) && score > bestScore) {
            bestScore = score;
            best = t;
        }
    }
    if (best == Mesh::null_vertex()) return false;

    // The order of the merges: breadth first from the survivor over the cluster's edges, so each vertex is
    // next to the survivor when its turn comes. Rehearsed on a copy: every collapse must keep the mesh
    // manifold (the link condition), else nothing changes.
    std::vector<VertexIndex> order{best};
    std::unordered_set<std::uint32_t> queued{std::uint32_t(best)};
    for (std::size_t i = 0; i < order.size(); ++i)
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(order[i]), S_))
            if (inCluster.count(std::uint32_t(w)) && queued.insert(std::uint32_t(w)).second)
                order.push_back(w);
    if (order.size() != cluster.size()) return false;
    {
        Mesh trial = S_;
        VertexIndex t = best;
        for (std::size_t i = 1; i < order.size(); ++i) {
            const HalfedgeIndex h = trial.halfedge(order[i], t);
            if (h == Mesh::null_halfedge() || !detail::canCollapse(trial, trial.edge(h), true)) return false;
            const VertexIndex kept = CGAL::Euler::collapse_edge(trial.edge(h), trial);
            t = kept;
        }
    }
    VertexIndex t = best;
    for (std::size_t i = 1; i < order.size(); ++i)
        t = collapse(order[i], t);
    ++report_.repairs;
    return true;
}

} // namespace fss::stitch::band
