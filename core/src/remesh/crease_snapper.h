#pragma once
// Internal to the crease recovery (crease_snap.h): the class whose sweeps snapToCreases runs, its members
// defined by topic in crease_snap.cpp (rounds, intersection checks), crease_snap_measure.cpp (distances to
// the reference and the acceptance tests), crease_snap_moves.cpp (corner and crease snaps, valence-3
// removals), crease_snap_repair.cpp (repairs of faces turned over or far) and crease_snap_split.cpp (splits,
// flips).
#include "remesh/closest_points.h"
#include "remesh/crease_index.h"
#include "remesh/crease_snap.h"

#include "fss/mesh.h"
#include "fss/raycast.h"

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <numbers>
#include <unordered_map>
#include <vector>

namespace fss::detail::creases {

struct Tri {
    Vec a, b, c;
};

class CreaseSnapper {
public:
    CreaseSnapper(Mesh& mesh, const Mesh& reference, const CreaseSnapOptions& o)
        : m_(mesh), ref_(reference), o_(o), L_(o.edgeLength),
          floor_(o.minAngleDeg * std::numbers::pi / 180.0), caster_(reference), closest_(caster_),
          creases_(reference, o.creaseAngleDeg, o.edgeLength) {}

    std::size_t creaseEdges() const { return creases_.size(); }

    /// Sets the vertex property kOnCreaseProperty of the vertices this step put on a crease.
    void markCreaseVertices() {
        auto on = m_.add_property_map<VertexIndex, bool>(kOnCreaseProperty, false).first;
        for (VertexIndex v : m_.vertices())
            if (v.idx() < onCrease_.size() && onCrease_[v.idx()]) on[v] = true;
    }
    /// The vertices this step put on a crease (one flag per vertex index), to be restored with the mesh.
    std::vector<char> creaseMarks() const { return onCrease_; }
    void setCreaseMarks(std::vector<char> marks) { onCrease_ = std::move(marks); }
    /// One round: snaps, splits, flips; adds their counts to \p r.
    void round(CreaseSnapReport& r);

private:
    Mesh& m_;
    const Mesh& ref_;
    const CreaseSnapOptions& o_;
    const double L_, floor_;
    RayCaster caster_;
    ClosestPoints closest_; // every closest-point query, memoized
    CreaseIndex creases_;
    std::vector<char> frozen_;   // vertices that never move: border vertices
    std::vector<char> onCrease_; // vertices this step put on a crease
    /// The corners of a triangle, in order (exact: a cache key).
    struct TriKey {
        std::array<double, 9> x;
        bool operator==(const TriKey& o) const { return x == o.x; }
    };
    struct TriKeyHash {
        std::size_t operator()(const TriKey& k) const {
            std::uint64_t h = 1469598103934665603ull;
            for (double d : k.x)
                h = (h ^ std::bit_cast<std::uint64_t>(d)) * 1099511628211ull;
            return std::size_t(h);
        }
    };
    bool isInput(FaceIndex f) const;
    void markFrozen();
    /// Whether the faces within two vertex rings of \p vertices intersect each other (CGAL PMP, exact
    /// predicates): checked after each operation, which is undone when they do.
    bool intersectsAround(std::initializer_list<VertexIndex> vertices) const;
    /// The faces around \p vertices (each once).
    std::vector<FaceIndex> faceIndicesAround(const std::vector<VertexIndex>& vertices) const;
    /// Distance of a triangle to the reference, sampled at its centroid, edge midpoints and three inner
    /// points: the largest, and the area times the mean square.
    struct Error {
        double max = 0, integral = 0;
    };
    mutable std::unordered_map<TriKey, Error, TriKeyHash> errors_; // error() of the triangles measured
    Error error(const Tri& t) const;
    Error measureError(const Tri& t) const;
    /// The points error() samples: the centroid, the edge midpoints and three inner points.
    static std::array<Vec, 7> errorSamples(const Tri& t);
    /// Answers, in parallel, the closest-point queries the sweeps over every face ask first: the faces'
    /// centroids, and the samples of the faces whose distance `far` measures.
    void prefetchFaces() const;
    /// Whether the triangles \p after may replace \p before: no degenerate face, no normal turned by 90° or
    /// more (each face against its own old normal when \p sameCount, else against the old faces' mean
    /// normal), no angle below the floor (or the smallest old angle), a largest distance to the reference
    /// that does not grow and an integrated squared distance that falls below \p gain times the old one;
    /// never when the old faces are within \p minOldError of the reference already.
    bool better(const std::vector<Tri>& before, const std::vector<Tri>& after, bool sameCount, double gain,
                double minOldError = 0) const;
    /// Whether the triangle \p t (unit normal \p n) lies on the reference: its centroid within a tenth of an
    /// edge length of the reference, on a reference face whose normal is within 60° of \p n. Such a face
    /// replaces faces that fold over (a bevel whose two faces overlap), whose normals say nothing of the
    /// surface's side.
    bool liesOnReference(const Tri& t, const Vec& n) const;
    /// Moves, for each corner of the creases (crease_snap.h), the nearest vertex within twice the snap
    /// radius onto it (else the next nearest, up to three), where that brings its faces closer to the
    /// reference: the snap sweep alone puts a vertex on one of the creases there, not at their meeting point.
    std::size_t cornerSweep();
    /// Moves \p v to \p target where its faces come closer to the reference (better, with the same number of
    /// faces) and the faces around it intersect no other; false (and \p v where it was) otherwise.
    bool moveVertex(VertexIndex v, const Vec& target);
    /// Puts \p v at \p target unless the faces around it then intersect others (then \p v stays where it
    /// was).
    bool place(VertexIndex v, const Vec& target);
    /// Removes vertices of valence 3 whose three faces lie farther from the reference than the one face
    /// that replaces them (better): the stitches leave a few inside the bevel of a crease, off the reference,
    /// where no snap can move them. The three faces must all be scanned or all be left from the input.
    std::size_t removeSweep();
    /// The reference's unit normal at the point closest to \p p (zero when there is none).
    Vec referenceNormal(const Vec& p) const;
    /// Whether \p t faces away from the reference: its normal against the reference's normal at the point
    /// closest to its centroid (a degenerate triangle counts as turned over).
    /// Whether \p t lies farther from the reference than errorSplitDistance edge lengths (sampled), looked at
    /// only for the faces within 1.5 edge lengths of a crease or whose centroid is off the reference by more
    /// than a tenth of an edge length (\p centroidDistance): a face whose centroid lies on the reference is
    /// that far from it only across a crease.
    bool far(const Tri& t, double centroidDistance) const;
    /// Whether `far` measures \p t (near a crease, or its centroid off the reference).
    bool mayBeFar(const Tri& t, double centroidDistance) const;
    Vec referenceNormalOf(FaceIndex f) const;
    bool turnedOver(const Tri& t) const;
    /// The smallest angle and the largest distance to the reference of the faces an operation replaces.
    struct Before {
        double minAngle = std::numbers::pi, maxError = 0;
    };
    Before measure(const std::vector<Tri>& before) const;
    /// Whether \p after may replace faces measured as \p before, among which a face turned over or far from
    /// the reference: none of \p after is turned over, no angle below the floor (or the smallest angle
    /// before), and a largest distance to the reference at most \p gain times the one before.
    bool repairs(const Before& before, const std::vector<Tri>& after, double gain) const;
    /// Whether \p v is on a crease: put there by this step, or lying on one (within 10⁻⁶ edge lengths).
    bool onACrease(VertexIndex v) const;
    /// Collapses edges shorter than a third of an edge length between two vertices on a crease (two snaps,
    /// splits or grid samples next to each other), onto one of them, where that turns no face over, makes no
    /// angle below the floor (or the smallest one there) and takes no face farther from the reference.
    std::size_t shortCreaseEdgeSweep();
    /// Repairs the faces turned over against the reference (folds the stitches and the seam relaxation leave
    /// at a crease, where two faces overlap) and the faces still farther from it than errorSplitDistance edge
    /// lengths (far): for each, the first of these that leaves no face there turned over and (for a far face)
    /// lowers the largest distance to the reference by a fifth (repairs) is taken: a flip of one of its
    /// edges, else a move of one of its corners onto the crease within an edge length of it, else a
    /// collapse of one of its edges to one end, to the crease point within an edge length of its midpoint,
    /// or to the reference point closest to its midpoint. Vertices put on a crease stay there; no edge
    /// between a face left from the input and a scanned one changes; an operation after which the faces
    /// around it intersect others is undone.
    std::size_t repairSweep();
    Tri triangle(FaceIndex f) const;
    /// Whether the faces on the two sides of \p h are both scanned or both left from the input.
    bool sameKind(HalfedgeIndex h) const { return isInput(m_.face(h)) == isInput(m_.face(m_.opposite(h))); }
    bool tryFlip(HalfedgeIndex h, double gain);
    /// Moves \p v onto its closest crease point when that is within one edge length, then flips the edge
    /// opposite \p v in each of its faces that the move flattened into a cap (an angle above 160° at \p v,
    /// between two vertices on the crease): the move with those flips must repair (repairs) the faces
    /// around \p v and the caps' neighbours, else the mesh is restored.
    bool tryMoveToCrease(VertexIndex v, double gain);
    /// Flips edges around \p v (opposite it or from it) where that raises the smaller angle of their two
    /// faces (at most eight, the best first), then whether the faces around \p region may replace \p
    /// regionBefore (the faces around the same vertices before the operation at \p v): none turned over, no
    /// angle below the floor (or the smallest angle before), none farther than \p maxError from the
    /// reference, and no intersection around \p v. The caller restores the mesh when not.
    bool mendAround(VertexIndex v, const std::vector<VertexIndex>& region,
                    const std::vector<Tri>& regionBefore, double maxError);
    /// The triangles around \p vertices (each once).
    std::vector<Tri> facesAround(const std::vector<VertexIndex>& vertices) const;
    /// How much a flip of the edge of \p c raises the smaller angle of its two faces (radians; ≤ 0 when it
    /// does not, or when the flipped faces would bend by more than 60° against each other).
    double flipAngleGain(HalfedgeIndex c) const;
    /// Flips the edge of \p c when that keeps the mesh valid (not a border, faces of one kind, valences above
    /// 3, the other diagonal not an edge yet).
    bool flipIfValid(HalfedgeIndex c);
    /// Whether \p after, with no face turned over, lies within \p gain times the largest distance of the
    /// faces measured as \p before (repairs without the angles).
    bool closeEnough(const Before& before, const std::vector<Tri>& after, double gain) const;
    bool tryCollapse(HalfedgeIndex h, double gain);
    /// Runs \p op; undoes it (the whole mesh and the vertex marks restored) when the faces within two rings
    /// of \p around then intersect others. True when it stays.
    template <typename Op> bool applyOrUndo(Op op, std::initializer_list<VertexIndex> around);
    /// Moves vertices near a crease onto their closest crease point, nearest first; a vertex next to one
    /// already on a crease within the snap radius of that point stays (two vertices there make a short edge).
    /// Vertices farther from the crease but off the reference go onto their closest reference point.
    std::size_t snapSweep();
    /// The split of the edge of \p h at \p q that `better` refused, taken with the flips around the new
    /// vertex that mend its angles (mendAround) when its four faces, turned over none, lie within \p gain
    /// times the largest distance of the two faces it replaces; the new vertex, or the null vertex and the
    /// mesh as it was.
    VertexIndex mendedSplit(HalfedgeIndex h, const Vec& q, double gain);
    /// Splits, at the crease, edges that pass a crease point farther from both ends than the snap radius and
    /// farther from the edge than a tenth of the edge length (the bevel no snap could remove).
    std::size_t splitSweep();
    /// Splits the edge of \p h at \p q (the faces (a, b, c), (b, a, d) become (a, q, c), (q, b, c),
    /// (b, q, d), (q, a, d); new faces keep the scan id and quality of the face they split), unless the faces
    /// around the new vertex then intersect others: the null vertex and the mesh as it was. Returns the new
    /// vertex (not marked on a crease).
    VertexIndex splitAt(HalfedgeIndex h, const Vec& q);
    /// Splits the longest edge of each face still farther from the reference than errorSplitDistance edge
    /// lengths (far: a face the crease runs through, away from its edges' ends, or one spanning a sharp bend)
    /// at the reference point closest to the edge's midpoint, or at the closest crease point when a
    /// crease passes within the snap radius of it, where that brings the faces closer (better).
    std::size_t errorSplitSweep();
    /// Flips edges near a crease where the other diagonal of their two faces lies closer to the reference.
    std::size_t flipSweep();
};

} // namespace fss::detail::creases
