// Internal to the stitch module: the types shared by the stitch stages (DESIGN.md §6) and the component
// stitcher whose member functions are defined, one stage per file, in stitch_<stage>.cpp.
#pragma once

#include "stitch/stitch_common.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>

#include <bit>
#include <memory>

namespace fss::detail::stitching {

// ---- What the stages hand on (in the order of ComponentStitcher::run).

// A patch boundary edge (interior on the left of a → b), with the seam vertices the cut puts on it.
struct PEdge {
    int a, b;     // patch vertices, interior on the left of a → b
    int opposite; // third vertex of the patch triangle on this edge
    std::vector<std::pair<double, int>> splits;
    std::vector<int> line;
};
// An edge of the region's faces in the view, with the seam vertices the cut puts on it.
struct REdge {
    int u, w; // local ids of the mesh edge's halfedge source and target
    EdgeIndex edge;
    std::vector<std::pair<double, int>> splits;
    std::vector<int> line;
};

// The component as the stages see it (setupComponent): its boundary, sizes and a grid over its triangles.
struct ComponentShape {
    std::vector<int> verts;                                // vertices of the component, sorted
    std::unordered_map<int, std::vector<int>> vertexFaces; // faces around each boundary vertex
    std::unordered_set<int> boundary;
    std::vector<PEdge> pedges;
    std::unordered_map<std::uint64_t, int> pedgeIndex;
    std::unordered_map<int, double> snapRadius;
    double h2 = 0, h3 = 0; // median edge length in the view and in 3D
    double margin = 0;     // largest snapping distance in the view
    CGAL::Bbox_2 box;
    BucketGrid grid;
};

// A current-mesh vertex in the view (cached).
struct VProj {
    Point2 uv;
    double w = 0;
    bool ok = false;
};
// A cache by element index of the current mesh whose cost follows the elements asked for: the values'
// array is allocated uninitialised (its pages are touched only where written) and a bitmap, one bit per
// element, tells which are known. A direct look-up: the region stage asks for every face under the patch
// and its vertices several times each (a hashed map cost a probe and a cache miss per question there).
template <class T> class DenseCache {
public:
    // The slot of element i < size and whether it was unknown until now (then the caller fills it).
    std::pair<T*, bool> slot(std::size_t i, std::size_t size) {
        if (!values_) {
            values_ = std::make_unique_for_overwrite<T[]>(size);
            known_.assign(size / 64 + 1, 0);
        }
        std::uint64_t& word = known_[i / 64];
        const std::uint64_t bit = std::uint64_t(1) << (i % 64);
        const bool fresh = (word & bit) == 0;
        word |= bit;
        return {&values_[i], fresh};
    }

private:
    std::unique_ptr<T[]> values_;
    std::vector<std::uint64_t> known_;
};
// A set of element indices of the current mesh as a bitmap (one bit per element, zeroed once: an eighth of a
// byte per element of the mesh, so cheap next to a hashed set's probe per question).
class DenseSet {
public:
    explicit DenseSet(std::size_t size) : bits_(size / 64 + 1, 0) {}
    // Inserts i; whether it was not there.
    bool insert(std::size_t i) {
        std::uint64_t& word = bits_[i / 64];
        const std::uint64_t bit = std::uint64_t(1) << (i % 64);
        const bool fresh = (word & bit) == 0;
        word |= bit;
        return fresh;
    }
    bool contains(std::size_t i) const { return (bits_[i / 64] >> (i % 64)) & 1u; }

private:
    std::vector<std::uint64_t> bits_;
};
// A set of vertex indices of the local mesh: a bitmap by index (grown on demand) and the indices in the
// order inserted. What std::unordered_set gave the seam optimisation (insert, count, iteration; every user
// iterates it order-independently or sorts) without a node allocation and a hash probe per element.
class VertexSet {
public:
    explicit VertexSet(std::size_t size = 0) : bits_(size / 64 + 1, 0) {}
    // Inserts v; whether it was not there.
    bool insert(std::uint32_t v) {
        if (v / 64 >= bits_.size()) bits_.resize(std::max(std::size_t(v / 64 + 1), 2 * bits_.size()), 0);
        std::uint64_t& word = bits_[v / 64];
        const std::uint64_t bit = std::uint64_t(1) << (v % 64);
        if (word & bit) return false;
        word |= bit;
        list_.push_back(v);
        return true;
    }
    std::size_t count(std::uint32_t v) const {
        return v / 64 < bits_.size() && ((bits_[v / 64] >> (v % 64)) & 1u);
    }
    std::size_t size() const { return list_.size(); }
    // The indices in increasing order (read off the bitmap).
    std::vector<std::uint32_t> sorted() const {
        std::vector<std::uint32_t> out;
        out.reserve(list_.size());
        for (std::size_t w = 0; w < bits_.size(); ++w)
            for (std::uint64_t word = bits_[w]; word; word &= word - 1)
                out.push_back(std::uint32_t(64 * w + std::size_t(std::countr_zero(word))));
        return out;
    }
    std::vector<std::uint32_t>::const_iterator begin() const { return list_.begin(); }
    std::vector<std::uint32_t>::const_iterator end() const { return list_.end(); }

private:
    std::vector<std::uint64_t> bits_;
    std::vector<std::uint32_t> list_;
};
// VProj's fields without initialisers (DenseCache leaves what it has not been asked for uninitialised).
struct VProjSlot {
    double u, v, w;
    bool ok;
};
// The region stage's caches over the current mesh (stage-local).
struct RegionSearch {
    DenseCache<VProjSlot> vcache;
    DenseCache<char> accept; // bool (a char: vector<bool> has no addressable elements)
    bool fallbackBuilt = false;
    std::vector<FaceIndex> fallback;
    BucketGrid fallbackGrid;
};

// The faces of the current mesh under the component (findRegion, splitRegion).
struct Region {
    std::vector<FaceIndex> faces;    // faces re-triangulated in the view (near the seam)
    std::vector<FaceIndex> interior; // faces under the patch, removed whole
    IndexMap<int> index;
    BucketGrid grid;
    // faceTriangle of every face of `faces`, in its order (preTrim to the end of splitRegion, where
    // `faces` becomes the seam faces): the grid's queries test many faces per cell, each read once here
    // instead of through three vertex-cache look-ups per test.
    std::vector<Triangle2> tris;
};

// The local problem in the view (cut: local vertices, snapping, crossings; gap triangulation: the faces).
struct LocalProblem {
    std::vector<LVert> L;
    std::unordered_map<std::uint32_t, int> lidOfCurrent;
    std::unordered_map<int, int> lidOfPatch;
    std::vector<REdge> redges;
    std::unordered_map<std::uint32_t, int> redgeIndex;
    std::vector<std::pair<int, int>> subEdges;
    std::unordered_set<std::uint64_t> regionSub, patchSub;
    std::vector<FaceIndex> replaced;
    std::vector<LFace> newFaces;
    std::map<std::uint32_t, int> outerSplits; // face outside the region → the region edge of it split
    // The core (assemble, when the bypass is on): patch faces (indices into P) whose vertices all lie at
    // least coreRings() rings inside the component's boundary, in the component's order; they do not pass
    // through the local mesh but go straight into the hole the other new faces leave (Plan::coreFaces).
    std::vector<int> coreFaces;
    std::vector<std::uint8_t> coreBorder; // per core face: bit k when edge k → k+1 is on the core's border
    std::vector<std::pair<int, int>> coreChords; // inner core edges between two of its border vertices
    double coreArea = 0;                         // their area in the view (twice), for the coverage check
};

// The seam's edges (pairs of local-mesh vertices, smaller first), in order, with the number of seam edges at
// each vertex so that "is v on the seam" is O(1) (it was a scan of the whole set, ~4 % of a stitch).
class SeamEdges {
public:
    using Key = std::pair<std::uint32_t, std::uint32_t>;
    using const_iterator = std::set<Key>::const_iterator;
    bool insert(Key k) {
        if (!set_.insert(k).second) return false;
        ++ends_[k.first];
        ++ends_[k.second];
        return true;
    }
    bool erase(Key k) {
        if (!set_.erase(k)) return false;
        --ends_[k.first];
        --ends_[k.second];
        return true;
    }
    std::size_t count(Key k) const { return set_.count(k); }
    // The number of seam edges at vertex v.
    int edgesAt(std::uint32_t v) const {
        const int* n = ends_.find(v);
        return n ? *n : 0;
    }
    bool touches(std::uint32_t v) const { return edgesAt(v) > 0; }
    void clear() {
        set_.clear();
        ends_.clear();
    }
    std::size_t size() const { return set_.size(); }
    bool empty() const { return set_.empty(); }
    const_iterator begin() const { return set_.begin(); }
    const_iterator end() const { return set_.end(); }

private:
    std::set<Key> set_;
    IndexMap<int> ends_;
};

// The box of patch triangle f in the view.
inline CGAL::Bbox_2 patchTriangleBox(const PatchData& P, int f) {
    const auto& t = P.tri[std::size_t(f)];
    return bboxOf(P.uv[std::size_t(t[0])], P.uv[std::size_t(t[1])], P.uv[std::size_t(t[2])]);
}
// Stage "setup" (stitch_region.cpp): the shape of the component made of `faces` of P; an empty string, or
// why the component cannot be stitched. `progress` may be null.
std::string describeComponent(const PatchData& P, const std::vector<int>& faces, double collapseEdgeRatio,
                              ComponentShape& c, ComponentProgress* progress);

// The core bypass (DESIGN.md §6.1) is on unless the environment variable FSS_STITCH_CORE_BYPASS is 0 (for
// the tests that compare the two paths, and for measurements).
inline bool coreBypassEnabled() {
    const char* e = std::getenv("FSS_STITCH_CORE_BYPASS");
    return !(e && std::string_view(e) == "0");
}

class ComponentStitcher {
public:
    ComponentStitcher(const Mesh& m, const PatchData& p, const View& view, const StitchOptions& o,
                      std::span<const std::uint32_t> ids, const std::vector<int>& faces, bool hasQuality,
                      bool hasScanId, ComponentProgress& progress)
        : M_(m), P_(p), V_(view), O_(o), ids_(ids), faces_(faces), curHasQuality_(hasQuality),
          curHasScanId_(hasScanId), progress_(progress) {
        if (hasQuality) curQuality_ = M_.property_map<FaceIndex, float>(props::faceQuality).first;
        if (hasScanId) curScanId_ = M_.property_map<FaceIndex, std::int32_t>(props::faceScanId).first;
    }

    Attempt run() {
        Attempt a;
        // Cancellation points (progress_) lie in the steps' long loops; none of them touches the mesh.
        constexpr int kSteps = 8;
        StageClock::lap("other");
        if (!setupComponent(a)) return a;
        StageClock::lap("setup");
        progress_.step(1, kSteps);
        if (!findRegion(a)) return a;
        StageClock::lap("region");
        if (!preTrim(a)) return a;
        progress_.step(2, kSteps);
        if (!splitRegion(a)) return a;
        StageClock::lap("split");
        buildLocalVertices();
        snap();
        progress_.step(3, kSteps);
        if (!computeCrossings(a)) return a;
        StageClock::lap("snap+crossings");
        Cdt cdt;
        std::vector<CdtVertex> vh;
        if (!triangulate(cdt, vh, a)) return a;
        progress_.step(4, kSteps);
        if (!classify(cdt, vh, a)) return a;
        if (!checkCoverage(cdt, vh, a)) return a;
        StageClock::lap("cdt");
        if (!assemble(cdt, a)) return a;
        StageClock::lap("assemble");
        progress_.step(5, kSteps);
        if (!buildAndOptimise(a)) return a;
        growPastHeldRim(a);
        a.ok = true;
        return a;
    }

private:
    // ---- results of the steps
    bool fail(Attempt& a, std::string reason, std::vector<int> bad = {});

    // ---- step 0: the component's boundary, sizes and a grid over its triangles
    bool setupComponent(Attempt& a);
    CGAL::Bbox_2 triBox(int f) const;
    Triangle2 patchTriangle(int f) const;
    // Patch vertices of the component near a point of the view (for trimming there).
    std::vector<int> patchVerticesNear(const Point2& q, double radius);
    // Records a problem at q: the patch vertices nearest to it are to be trimmed. The marker -1 makes sure
    // the problem counts even when no patch vertex is near (fail() drops the markers).
    void addNear(std::vector<int>& bad, const Point2& q);
    // Patch vertices to trim for a problem at local vertex i.
    void addBad(std::vector<int>& bad, int i);

    // ---- the current mesh in the view (cached per vertex / face)
    VProj vproj(VertexIndex v);
    // Triangle face, in front of the eye, counter-clockwise in the view and not grazing.
    bool acceptable(FaceIndex f);
    std::array<VertexIndex, 3> faceVertices(FaceIndex f) const;
    Triangle2 faceTriangle(FaceIndex f);
    // Distance from patch vertex point p to the plane of face f along p's view ray.
    double gapTo(const Vec3& p, FaceIndex f) const;
    // Distance from p to the plane through A with normal n along p's view ray.
    double gapToPlane(const Vec3& p, const Vec3& A, const Vec3& n) const;
    double longestEdge(FaceIndex f) const;
    // The largest distance along view rays between the patch and a mesh face it belongs to.
    double gapTolerance(FaceIndex f) const { return O_.maxGapRatio * (longestEdge(f) + comp_.h3); }
    // Does face f meet the component in the view (or come closer to it than snapping can move things), on
    // the same sheet: the patch triangles there lie on f's plane, not in front of it (an occluder) or
    // behind it (f occludes them)?
    bool meetsComponent(FaceIndex f);
    // Distance along p's view ray from p to the patch surface at uv (infinite when uv is off the patch).
    double gapToPatch(const Vec3& p, const Point2& uv);

    // ---- step 1: the region under the component
    void candidatesAt(const Point2& uv, std::vector<FaceIndex>& out);
    // O(mesh): all faces whose view bounding box meets the component's.
    void buildFallback();
    bool findRegion(Attempt& a);

    // ---- step 1b: every patch vertex must lie over the region (else trim there)
    bool preTrim(Attempt& a);

    // ---- step 1c: seam faces (near the patch boundary: re-triangulated in the view) and faces under the
    // patch (removed whole, whatever their orientation, so folds under the patch go too)
    bool insidePatch(const Point2& p);
    // Do the interiors of two (counter-clockwise) faces overlap in the view? Separating-axis test on
    // their edges with exact orientations: disjoint interiors iff one triangle lies on the closed outer
    // side of an edge of the other.
    static bool interiorsOverlap(const Triangle2& s, const Triangle2& t);
    // A point inside the overlap of two counter-clockwise triangles (centre of s clipped by t).
    static Point2 overlapCentre(const Triangle2& s, const Triangle2& t);
    // Distance from the eye (along the view direction) of face f's plane at view position q.
    double depthAt(FaceIndex f, const Point2& q) const;
    bool splitRegion(Attempt& a);

    // ---- step 2: local vertices, snapping, crossings
    int addLocal(LVert l);
    int regionVertex(VertexIndex v);
    void buildLocalVertices();
    // Would the patch faces around patch vertex v stay counter-clockwise if v moved to uv?
    bool patchStaysValid(int v, const Point2& uv) const;
    // Current view position of a patch vertex (moved by snapping when on the boundary).
    Point2 L_uvOfPatch(int v) const;
    // Current 3D position of a patch vertex (moved by snapping when on the boundary).
    const Vec3& posOfPatch(int v) const;
    // Lift a point at 2D parameter s of region edge re onto the 3D mesh edge.
    void liftOnEdge(int re, double s, Vec3& pos, Point2& uv);
    // A region edge may be split when both its faces are region faces (never a border edge).
    bool splittable(int re) const;
    // The face beyond region edge re when exactly one of its faces is a region face and the other is a
    // triangle of the mesh that stays (not under the patch); else null.
    FaceIndex outerFace(int re, const std::unordered_set<std::uint32_t>& interior) const;
    void snap();
    void snapToMeshVertices(double cell, double ratio, const std::vector<double>& regionEdgeMin);
    void snapOntoMeshEdges(double cell, double ratio);
    void splitPatchEdgesAtMeshVertices(double cell, double ratio);
    // Polyline (local ids) of a region edge or a patch boundary edge with its splits, sorted.
    static std::vector<int> polyline(int from, int to, std::vector<std::pair<double, int>> splits);
    bool computeCrossings(Attempt& a);

    // ---- step 2b: the constrained triangulation of the view
    bool triangulate(Cdt& cdt, std::vector<CdtVertex>& vh, Attempt& a);
    // The triangle to the left of the directed edge p → q of the triangulation.
    static CdtFace leftOf(const Cdt& cdt, CdtVertex p, CdtVertex q);
    std::uint64_t keyOf(CdtFace f, int i) const;
    // ---- step 3a: which region face and which side of the patch boundary every triangle lies in
    bool classify(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a);

    // ---- step 3b: the patch must lie strictly over the region, on the same sheet
    bool checkCoverage(Cdt& cdt, const std::vector<CdtVertex>& vh, Attempt& a);

    // ---- step 3c: the faces of the result (local ids)
    // Triangulates a polygon whose corners lie on the edges of one patch triangle, maximising the
    // smallest angle (dynamic programming over the polygon's chains; exact orientation tests).
    // `edges` holds for every corner the triangle edges it lies on (bit k: edge k): a diagonal between
    // two corners on the same edge would leave a triangle of collinear points, so it is never used.
    bool triangulatePolygon(const std::vector<int>& poly, const std::vector<unsigned>& edges, float q,
                            std::int32_t sid, double floor);
    bool assemble(Cdt& cdt, Attempt& a);
    // Opens mesh face g to the seam optimisation: replaced by itself (a face the optimisation may flip, in
    // its plane); `offView` when the scan's view does not see it (checked in 3D).
    void openAsItself(FaceIndex g, bool offView);
    int localOfPatch(int p);

    // ---- steps 4 + 5: local mesh, seam optimisation, checks, rehearsal
    struct Local {
        Star star;
        Mesh::Property_map<VertexIndex, int> lid;
        Mesh::Property_map<VertexIndex, Point2> uv;
        Mesh::Property_map<VertexIndex, bool> locked;
        Mesh::Property_map<FaceIndex, float> quality;
        Mesh::Property_map<FaceIndex, std::int32_t> scanId;
        Mesh::Property_map<FaceIndex, bool> patchSide;
        Mesh::Property_map<FaceIndex, Vec3> planeNormal;  // outside pieces: normal of their mesh face
        Mesh::Property_map<FaceIndex, double> minAllowed; // smallest angle accepted (radians)
        Mesh::Property_map<FaceIndex, bool> offView;      // piece of a mesh face the view does not see
        SeamEdges seam;
        detail::FlipAngleMemo flipAngles; // flipPass's angles per halfedge, while its four corners stay
        Star pristine;                    // the star as copied from the current mesh, for the rehearsal
        // After a strip refill (v2): `seam` holds the fill's edges; the seam line's figures as glued.
        bool refilled = false;
        bool remeshed = false; // the seam band was remeshed in 3D (band_remesh.h): `seam` holds its edges
        // Core bypass: the local mesh's vertices on the core's border (patch vertex → S vertex), the core's
        // border edges in S (a → b: the core face has a → b, so S has a border halfedge a → b), and whether
        // the checks found the hole in S not to be exactly the core's (then the core goes in the local mesh).
        IndexMap<VertexIndex> coreVertex;
        std::vector<std::pair<VertexIndex, VertexIndex>> coreEdges;
        IndexSet coreVertexSet; // S vertices on the core's border
        bool coreBroken = false;
        std::size_t seamLineEdges = 0;
        double seamLineLength = 0;
    };
    static std::pair<std::uint32_t, std::uint32_t> seamKey(VertexIndex a, VertexIndex b);
    // Adds faces in an order that grows from the hole's border (each face next to what is there).
    static std::vector<std::size_t> growthOrder(const std::vector<std::array<VertexIndex, 3>>& faces,
                                                const Mesh& m);

    bool buildAndOptimise(Attempt& a);

    // ---- core bypass (DESIGN.md §6.1): the patch faces deep inside the component skip the local mesh
    // Rings of patch vertices between the component's boundary and its core: beyond every vertex the seam
    // optimisation (seamRings, + 2 for the intersection candidates) or the band remesh (2 rings, grown only
    // outside the patch) may touch.
    int coreRings() const { return std::max(6, O_.seamRings + 4); }
    // Marks the faces of faces_ in the core (by position in faces_); empty when there is no core worth it.
    std::vector<char> findCore();
    // Is v (an S vertex) on the core's border?
    static bool onCoreBorder(const Local& loc, VertexIndex v) {
        return loc.coreVertexSet.count(std::uint32_t(v)) > 0;
    }
    // The hole in S is exactly the core's border, and no kept face of S overlaps a core face in the view.
    bool coreFits(Local& loc);
    // Puts the core back among the new faces (they then pass through the local mesh like the others).
    void dissolveCore();
    bool retryWithoutCore(Attempt& a);

    // ---- v2: the seam strip filled anew by construction (strip_refill.h, DESIGN.md §6.2)
    enum class Refill { NotDone, Applied, Broken };
    // Where the refill cannot be made (or its result fails the checks), version 1's seam optimisation
    // runs on a fresh build of the component instead.
    bool retryWithoutRefill(Attempt& a);
    // ---- v2, design B: the seam band remeshed in 3D on the draft (band_remesh.h, DESIGN.md §6.2)
    // Where the band comes out worse than version 1 left it, or its result fails the checks, the component is
    // built again without it.
    bool retryWithoutRemesh(Attempt& a);
    // False when the band came out worse than version 1's (the caller then builds the component again).
    bool remeshBand(Local& loc, Plan& plan);
    // ---- the band grown past held rim vertices (stitch_rim.cpp, DESIGN.md §6.2 session 19): where a band
    // face below 20 deg has a corner held only by kept faces of the current mesh (the band's rim), those
    // faces are opened as themselves and the component is built again with the corner's whole star in the
    // band; the result is kept where the band's smallest angle rises, else \p a stays as it was.
    void growPastHeldRim(Attempt& a);
    // Called by remeshBand after a remesh that is kept: the corners of its faces below 20 deg that are held
    // only by kept faces (whole star in the local mesh, the other faces ones the band may grow into) and are
    // corners of region faces or whose whole star lies in the seam neighbourhood (into heldRim_, as
    // current-mesh vertices).
    void noteHeldRim(Local& loc, const std::vector<FaceIndex>& bandFaces);
    // Whether every face of current-mesh vertex c's star lies within seamRings vertex rings of a face that
    // touches the patch's footprint (its vertices' pixels dilated by one; the property test's definition).
    bool starInSeamNeighbourhood(std::uint32_t c);

    Refill refillSeam(Local& loc);

    // Border edges (pairs of current-mesh vertices) incident to the vertices of the replaced faces.
    std::set<std::pair<std::uint32_t, std::uint32_t>> bordersAround(Local& loc) const;

    // Seam neighbourhood: vertices within seamRings rings of the seam, over new faces.
    VertexSet seamNeighbourhood(Local& loc) const;
    Vec3 pt(const Mesh& S, VertexIndex v) const { return toVec(S.point(v)); }
    // Is the triangle (a, b, c), in place of new face f, oriented as f must be: counter-clockwise in the
    // view, or, for a piece of a mesh face the view does not see, like that face in 3D?
    static bool oriented(const Local& loc, FaceIndex f, const Point2& ua, const Point2& ub, const Point2& uc,
                         const Vec3& a, const Vec3& b, const Vec3& c);
    bool oriented(const Local& loc, FaceIndex f, VertexIndex a, VertexIndex b, VertexIndex c) const;
    // Edges incident to the given vertices (each once, in a deterministic order).
    static std::vector<EdgeIndex> edgesAround(const Mesh& S, const VertexSet& vertices);
    // Distance from the seam along edges (Dijkstra), for the vertices of the given set.
    // By vertex index of S (infinity where not reached).
    std::vector<double> seamDistance(const Local& loc, const VertexSet& within) const;

    void optimise(Local& loc, Plan& plan);

    // The smallest angle of the faces (v, p, q) of `ring` (faces `faces`) with v moved from p0 to p1, or -1
    // where one of them would turn over in the view (or, unseen, against its plane) or degenerate, a patch
    // face would turn its normal more than maxNormalChangeDeg, or (with `floors`) a face would fall below
    // its floor. uv: p1 in the view. Also -1 (uv unset) as soon as one face's smallest angle is at most
    // `mustBeat`: callers keep p1 only where the score beats their best so far, so they pass it and the
    // checks are skipped for places that cannot win. `first`, when given, is the ring face tested first
    // against mustBeat and is set to the one that failed (the same answer, sooner: in a search most places
    // fail, mostly at the same face).
    double ringScore(const Local& loc, const std::vector<std::pair<VertexIndex, VertexIndex>>& ring,
                     const std::vector<FaceIndex>& faces, const Vec3& p0, const Vec3& p1, bool floors,
                     Point2& uv, double mustBeat = -1.0, std::size_t* first = nullptr) const;

    // A seam vertex on a mesh edge (a crossing, a snapped patch vertex) slides along that edge towards the
    // centre of its neighbours where that raises the smallest angle around it: the pieces outside stay in
    // their faces' planes; the patch side turns no normal more than maxNormalChangeDeg; no face falls below
    // its floor. With `search`, where the smallest angle around stays below kSearchBelowDeg, the best of
    // kSlideSamples evenly spaced points of the edge is taken when it is better still.
    int slideAlongEdge(Local& loc, VertexIndex v, bool search);

    // Moves the free vertices near the seam where that raises the smallest angle around them, keeping the
    // surface: a seam vertex on a mesh edge along that edge (slideAlongEdge); a vertex inside one mesh face
    // (pieces of one plane) to its neighbours' centre in that plane. With `search` also, by a compass search
    // for the largest smallest angle: a vertex among nearly coplanar pieces (a smoothly curved part of the
    // mesh) within their mean plane, never farther than kNearPlanarFlipGap × the patch's edge length from
    // the surface before; a vertex on the mesh edge between two planes along that edge's line; and a patch
    // boundary vertex inside a mesh face whose faces, patch side included, all lie in that face's plane (no
    // patch normal turning more than maxNormalChangeDeg, no face below its floor). Every face stays
    // oriented in the view (exact test).
    // Returns how many vertices moved.
    std::size_t smoothOutside(Local& loc, bool search = false);

    std::size_t refineOutside(Local& loc);
    static void copyFace(Local& loc, FaceIndex from, FaceIndex to);

    // A flip of the edge of halfedge h (x → y, faces (x, y, z1) and (y, x, z2) → (x, z2, z1), (z2, y, z1))
    // that the seam optimisation may make: both faces new and near the seam, not a seam edge, no vertex left
    // with fewer than three edges, no edge doubled, every new face oriented as its kind must be (in the view,
    // or in 3D for pieces the view does not see) and not degenerate (exact); on the patch side no normal
    // turns more than maxNormalChangeDeg, outside it the surface stays (see below). Sets the smallest angles
    // before and after, and `nearPlanar` when the flip joins pieces of two nearly coplanar mesh faces.
    bool flipAllowed(const Local& loc, HalfedgeIndex h, const VertexSet& near, double& oldMin, double& newMin,
                     bool& nearPlanar) const;
    // Flips the edge of h (checked by flipAllowed).
    void flip(Local& loc, HalfedgeIndex h, bool nearPlanar);

    // -- flips: raise the smallest angle, valence towards 6
    void flipPass(Local& loc, Plan& plan);

    // The new faces near the seam (a vertex in `near`) whose smallest angle is below kNeedleDeg, with that
    // angle, smallest first.
    std::vector<std::pair<double, FaceIndex>> thinFaces(const Local& loc, const VertexSet& near);

    // -- valence: a seam vertex with more than kMaxSeamValence edges loses one by the flip of one of them
    // (every check of flipAllowed) that keeps the smallest angle there at least min(before, 15°) and
    // raises no seam vertex above kMaxSeamValence; the best such flip (largest smallest angle) first.
    void valencePass(Local& loc, Plan& plan);
    bool seamVertex(const Local& loc, VertexIndex v) const;
    // Collapses edge (from, to) so that `to` survives with its position and data.
    void collapse(Local& loc, VertexIndex from, VertexIndex to);

    // The faces that could intersect each other: new faces are a height field in the view (checked face
    // by face), so only the seam neighbourhood, the kept faces around, and new faces overlapping those in
    // the view need the 3D test.
    std::vector<FaceIndex> intersectionCandidates(Local& loc);

    bool validate(Local& loc, const std::set<std::pair<std::uint32_t, std::uint32_t>>& bordersBefore,
                  Attempt& a);

    // An order of the new faces of S in which each is added next to what is already there: breadth first
    // from the faces next to kept faces (the hole's border) across S's edges.
    static std::vector<std::size_t> growthOrderIn(const Mesh& S, const std::vector<FaceIndex>& sfaces,
                                                  const Local& loc);

    bool extractPlan(Local& loc, Attempt& a);

    // ---- inputs
    const Mesh& M_;
    const PatchData& P_;
    const View& V_;
    const StitchOptions& O_;
    std::span<const std::uint32_t> ids_;
    const std::vector<int>& faces_;
    bool curHasQuality_, curHasScanId_;
    ComponentProgress& progress_;
    bool refill_ = O_.refillSeam;       // v2 strip refill (off for the retry after a failed refill)
    bool remesh_ = O_.remeshSeam;       // v2 band remesh (off for the retry after a worse or failed one)
    bool bypass_ = coreBypassEnabled(); // core bypass (off once the core did not fit, for the retries)
    Mesh::Property_map<FaceIndex, float> curQuality_;
    Mesh::Property_map<FaceIndex, std::int32_t> curScanId_;

    // ---- the stages' results (explicit structs, stitch_stages.h)
    ComponentShape comp_;        // setupComponent (region stage)
    RegionSearch search_;        // the region stage's caches over the current mesh
    Region reg_;                 // findRegion, splitRegion
    LocalProblem cut_;           // cut, gap triangulation (buildLocalVertices … assemble)
    std::vector<char> coreMask_; // findCore: the core's faces by position in faces_ (empty: no core)
    // The band grown past held rim vertices (growPastHeldRim): the held corners the last kept band remesh
    // left below 20 deg, its smallest angle (-1: no band remesh kept), and for the build again the corners
    // whose whole star joins the band (current-mesh vertices).
    std::vector<std::uint32_t> heldRim_;
    std::unordered_set<std::uint64_t> footprint_; // starInSeamNeighbourhood, built on first use
    bool footprintBuilt_ = false;
    std::unordered_map<std::uint32_t, bool> touchesCache_;
    double bandMinAfterDeg_ = -1;
    std::unordered_set<std::uint32_t> rimStars_;
};

} // namespace fss::detail::stitching
