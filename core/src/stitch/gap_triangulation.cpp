// Stitch v2, stage "gap triangulation" (gap_triangulation.h, DESIGN.md §6.2 step 3).
#include "stitch/gap_triangulation.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_voronoi_diagram_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_2/Lloyd_move_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <list>
#include <numbers>
#include <unordered_map>
#include <utility>

namespace fss::stitch {
namespace {

using GapKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
struct GapVertexInfo {
    int id = -1; // index into GapBoundary::points; -1 for Steiner points
};
using GapVb = CGAL::Triangulation_vertex_base_with_info_2<GapVertexInfo, GapKernel,
                                                          CGAL::Delaunay_mesh_vertex_base_2<GapKernel>>;
using GapFb = CGAL::Delaunay_mesh_face_base_2<GapKernel>;
using GapTds = CGAL::Triangulation_data_structure_2<GapVb, GapFb>;
// Constraints never cross (a crossing is reported, not resolved by a constructed point: the gap's boundary
// vertices are kept as they are).
using GapCdt =
    CGAL::Constrained_Delaunay_triangulation_2<GapKernel, GapTds,
                                               CGAL::No_constraint_intersection_requiring_constructions_tag>;
using GapPoint = GapKernel::Point_2;

// CGAL's size-and-angle criteria with a size that varies over the view (graded from the patch's edge length
// to the mesh's): CGAL's Delaunay_mesh_size_criteria_2 has one size bound only, Delaunay_mesh_local_size_
// criteria_2 a size near one point only.
class GradedGapCriteria : public CGAL::Delaunay_mesh_size_criteria_2<GapCdt> {
public:
    using Base = CGAL::Delaunay_mesh_size_criteria_2<GapCdt>;
    using Size = std::function<double(const Eigen::Vector2d&)>;
    GradedGapCriteria(double bound, Size size)
        : CGAL::Delaunay_mesh_criteria_2<GapCdt>(bound), Base(bound, 0), size_(std::move(size)) {}

    class Is_bad : public Base::Is_bad {
    public:
        Is_bad(double bound, Size size, const GapKernel& traits)
            : Base::Is_bad(bound, 0, traits), size_(std::move(size)) {}
        CGAL::Mesh_2::Face_badness operator()(const Quality q) const { return Base::Is_bad::operator()(q); }
        CGAL::Mesh_2::Face_badness operator()(const GapCdt::Face_handle& fh, Quality& q) const {
            const GapPoint &pa = fh->vertex(0)->point(), &pb = fh->vertex(1)->point(),
                           &pc = fh->vertex(2)->point();
            std::array<double, 3> l{CGAL::squared_distance(pb, pc), CGAL::squared_distance(pc, pa),
                                    CGAL::squared_distance(pa, pb)};
            std::sort(l.begin(), l.end());
            q.second = 0;
            if (size_) {
                const Eigen::Vector2d centre((pa.x() + pb.x() + pc.x()) / 3, (pa.y() + pb.y() + pc.y()) / 3);
                const double s = size_(centre);
                if (s > 0) q.second = l[2] / (s * s);
                if (q.size() > 1) {
                    q.first = 1;
                    return CGAL::Mesh_2::IMPERATIVELY_BAD;
                }
            }
            const double area = 2 * CGAL::area(pa, pb, pc);
            q.first = area * area / (l[2] * l[1]);
            return q.sine() < this->B ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }

    private:
        Size size_;
    };
    Is_bad is_bad_object() const { return Is_bad(this->bound(), size_, this->traits); }

private:
    Size size_;
};

using GapMesher = CGAL::Delaunay_mesher_no_edge_refinement_2<GapCdt, GradedGapCriteria>;

// Refines the marked domain of cdt until no face is bad or the budget of Steiner points is spent.
void refineGap(GapCdt& cdt, const GradedGapCriteria& criteria, const std::list<GapPoint>& seeds,
               std::size_t& budget) {
    GapMesher mesher(cdt, criteria);
    mesher.set_seeds(seeds.begin(), seeds.end(), false);
    mesher.init();
    while (budget > 0 && !mesher.is_refinement_done()) {
        const std::size_t before = cdt.number_of_vertices();
        mesher.try_one_step_refine_mesh();
        if (cdt.number_of_vertices() > before) --budget;
    }
}

// One seed (a triangle's centroid) per region of cdt bounded by constraints where `inside` says no.
void addExcludeSeeds(GapCdt& cdt, const std::function<bool(const Eigen::Vector2d&)>& inside,
                     std::list<GapPoint>& seeds) {
    std::unordered_map<GapCdt::Face_handle, char> seen;
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        const GapCdt::Face_handle start = f;
        if (seen.count(start)) continue;
        const GapPoint c =
            CGAL::centroid(start->vertex(0)->point(), start->vertex(1)->point(), start->vertex(2)->point());
        if (!inside(Eigen::Vector2d(c.x(), c.y()))) seeds.push_back(c);
        std::vector<GapCdt::Face_handle> stack{start};
        seen[start] = 1;
        while (!stack.empty()) {
            const GapCdt::Face_handle g = stack.back();
            stack.pop_back();
            for (int i = 0; i < 3; ++i) {
                const GapCdt::Face_handle n = g->neighbor(i);
                if (g->is_constrained(i) || cdt.is_infinite(n) || !seen.emplace(n, 1).second) continue;
                stack.push_back(n);
            }
        }
    }
}

// Lloyd smoothing as CGAL's lloyd_optimize_mesh_2 does it (its move function, sizing field, freeze bound and
// convergence test, both 0.001), but with the free vertices moved in the triangulation's own vertex order:
// CGAL's optimiser keeps them in a std::set ordered by address, so where the allocator put the
// triangulation's blocks decided the order of the moves, hence the order of the faces and the refinement
// after it (DESIGN.md §6.2). The vertex order depends only on the sequence of insertions and removals. The
// density of Lloyd's moves as CGAL's Mesh_sizing_field gives it: every vertex's mean incident edge length
// (edges of the domain) before the first move, carried along by the moves, averaged over the face holding a
// point. Unlike CGAL's, its point location hint is forgotten once vertices move (it would name a removed
// face).
class GapSizing {
public:
    explicit GapSizing(GapCdt& cdt) : cdt_(cdt) {
        for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
            double sum = 0;
            int count = 0;
            auto e = cdt.incident_edges(v);
            const auto end = e;
            do {
                if (cdt.is_infinite(*e) ||
                    !(e->first->is_in_domain() || e->first->neighbor(e->second)->is_in_domain()))
                    continue;
                sum += std::sqrt(CGAL::squared_distance(e->first->vertex(GapCdt::cw(e->second))->point(),
                                                        e->first->vertex(GapCdt::ccw(e->second))->point()));
                ++count;
            } while (++e != end);
            v->set_sizing_info(count ? sum / count : 1.0);
        }
    }
    double operator()(const GapPoint& p) const {
        hint_ = cdt_.locate(p, hint_);
        if (!cdt_.is_infinite(hint_))
            return (hint_->vertex(0)->sizing_info() + hint_->vertex(1)->sizing_info() +
                    hint_->vertex(2)->sizing_info()) /
                   3;
        double sum = 0;
        for (int i = 0; i < 3; ++i)
            if (!cdt_.is_infinite(hint_->vertex(i))) sum += hint_->vertex(i)->sizing_info();
        return sum / 2;
    }
    void forgetHint() { hint_ = GapCdt::Face_handle(); }

private:
    GapCdt& cdt_;
    mutable GapCdt::Face_handle hint_;
};

void lloydSmooth(GapCdt& cdt, int iterations, const std::list<GapPoint>& seeds) {
    GapSizing sizing(cdt);
    const CGAL::Mesh_2::Lloyd_move_2<GapCdt, GapSizing> moveOf;
    constexpr double kFreeze = 0.001, kConvergence = 0.001;
    std::vector<GapCdt::Vertex_handle> moving;
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
        if (!cdt.are_there_incident_constraints(v)) moving.push_back(v);
    const std::size_t initial = moving.size();
    std::vector<double> bigMoves; // the largest squared move ratios of an iteration, at most 1 % of them
    const std::size_t bigCount = std::max<std::size_t>(1, initial / 100);
    std::size_t movedBefore = std::numeric_limits<std::size_t>::max();
    std::vector<std::pair<std::size_t, GapPoint>> moves;
    for (int iteration = 0; iteration < iterations; ++iteration) {
        CGAL::Constrained_voronoi_diagram_2<GapCdt>(cdt).tag_faces_blind();
        moves.clear();
        bigMoves.assign(bigCount, 0.0);
        std::vector<GapCdt::Vertex_handle> stillMoving;
        for (std::size_t i = 0; i < moving.size(); ++i) {
            const GapCdt::Vertex_handle v = moving[i];
            const GapKernel::Vector_2 move = moveOf(v, cdt, sizing);
            double localSq = std::numeric_limits<double>::max();
            auto f = cdt.incident_faces(v);
            const auto end = f;
            do {
                if (!cdt.is_infinite(f))
                    localSq =
                        std::min(localSq, CGAL::squared_distance(cdt.circumcenter(f), f->vertex(0)->point()));
            } while (++f != end);
            const double ratio = localSq > 0 ? move.squared_length() / localSq : 0.0;
            if (move == CGAL::NULL_VECTOR || localSq == 0 || ratio < kFreeze * kFreeze) continue; // frozen
            if (ratio > bigMoves.back()) {
                bigMoves.pop_back();
                bigMoves.insert(
                    std::find_if(bigMoves.begin(), bigMoves.end(), [&](double m) { return m < ratio; }),
                    ratio);
            }
            moves.emplace_back(stillMoving.size(), v->point() + move);
            stillMoving.push_back(v);
        }
        // CGAL stops where fewer than 1 % of the vertices still move and none froze in the last iteration.
        if (movedBefore < 0.01 * double(initial) && movedBefore == stillMoving.size()) break;
        double sum = 0;
        for (double m : bigMoves)
            sum += std::sqrt(m);
        if (sum / double(bigMoves.size()) < kConvergence) break;
        for (const auto& [index, to] : moves) {
            const double size = stillMoving[index]->sizing_info();
            cdt.remove(stillMoving[index]);
            stillMoving[index] = cdt.insert(to);
            stillMoving[index]->set_sizing_info(size);
        }
        sizing.forgetHint();
        moving = std::move(stillMoving);
        movedBefore = moving.size();
        GapMesher::mark_facets(cdt, seeds.begin(), seeds.end(), false);
    }
}

} // namespace

GapTriangulation triangulateGap(const GapBoundary& boundary, const GapOptions& options) {
    GapTriangulation out;
    out.boundaryPoints = boundary.points.size();
    GapCdt cdt;
    std::vector<GapCdt::Vertex_handle> vh;
    vh.reserve(boundary.points.size());
    for (std::size_t i = 0; i < boundary.points.size(); ++i) {
        const auto& p = boundary.points[i];
        const auto v = cdt.insert(GapPoint(p.x(), p.y()));
        if (v->info().id >= 0) {
            out.reason = "two points of the gap's boundary coincide in the view";
            return out;
        }
        v->info().id = int(i);
        vh.push_back(v);
    }
    try {
        for (const auto& [a, b] : boundary.constraints)
            cdt.insert_constraint(vh[std::size_t(a)], vh[std::size_t(b)]);
    } catch (const GapCdt::Intersection_of_constraints_exception&) {
        out.reason = "two edges of the gap's boundary cross in the view";
        return out;
    }
    // A constraint through another boundary point is split there by CGAL: the boundary would change.
    for (const auto& [a, b] : boundary.constraints)
        if (!cdt.is_edge(vh[std::size_t(a)], vh[std::size_t(b)])) {
            out.reason = "an edge of the gap's boundary passes through another boundary point in the view";
            return out;
        }
    std::list<GapPoint> seeds;
    for (const auto& s : boundary.excludeSeeds)
        seeds.emplace_back(s.x(), s.y());
    if (boundary.inside) addExcludeSeeds(cdt, boundary.inside, seeds);
    const double sine = std::sin(options.minAngleDeg * std::numbers::pi / 180.0);
    const GradedGapCriteria criteria(sine * sine, options.size);
    std::size_t budget =
        std::size_t(options.maxSteinerPerBoundaryPoint * double(boundary.points.size())) + 16;
    refineGap(cdt, criteria, seeds, budget);
    if (options.lloydIterations > 0) {
        lloydSmooth(cdt, options.lloydIterations, seeds);
        refineGap(cdt, criteria, seeds, budget);
    }
    // Lloyd re-marks the domain with the same seeds; mark once more so the output never depends on it.
    GapMesher::mark_facets(cdt, seeds.begin(), seeds.end(), false);

    out.points = boundary.points;
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
        if (v->info().id < 0) {
            v->info().id = int(out.points.size());
            out.points.emplace_back(v->point().x(), v->point().y());
        }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
        if (f->is_in_domain())
            out.triangles.push_back(
                {f->vertex(0)->info().id, f->vertex(1)->info().id, f->vertex(2)->info().id});
    // Lloyd moves free vertices only; a kept point no constraint holds could still have moved away.
    std::vector<char> used(out.boundaryPoints, 0);
    for (const auto& t : out.triangles)
        for (int i : t)
            if (std::size_t(i) < used.size()) used[std::size_t(i)] = 1;
    if (std::find(used.begin(), used.end(), 0) != used.end()) {
        out.reason = "a point of the gap's boundary is not a vertex of its triangulation";
        return out;
    }
    out.ok = true;
    return out;
}

} // namespace fss::stitch
