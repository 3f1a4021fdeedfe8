// MeshDelta (session/mesh_delta.h): index-wise difference of two garbage-free meshes.
#include "session/mesh_delta.h"

#include <CGAL/version.h>

#include <algorithm>
#include <bit>
#include <functional>
#include <limits>
#include <stdexcept>
#include <unordered_set>

namespace fss::detail {
namespace {

using QualityMap = Mesh::Property_map<FaceIndex, float>;
using ScanIdMap = Mesh::Property_map<FaceIndex, std::int32_t>;

bool sameBits(const Point3& a, const Point3& b) {
    return std::bit_cast<std::uint64_t>(a.x()) == std::bit_cast<std::uint64_t>(b.x()) &&
           std::bit_cast<std::uint64_t>(a.y()) == std::bit_cast<std::uint64_t>(b.y()) &&
           std::bit_cast<std::uint64_t>(a.z()) == std::bit_cast<std::uint64_t>(b.z());
}

bool same(const MeshDelta::VertexRecord& a, const MeshDelta::VertexRecord& b) {
    return a.halfedge == b.halfedge && sameBits(a.point, b.point);
}
bool same(const MeshDelta::HalfedgeRecord& a, const MeshDelta::HalfedgeRecord& b) {
    return a.next == b.next && a.prev == b.prev && a.target == b.target && a.face == b.face;
}
bool same(const MeshDelta::FaceRecord& a, const MeshDelta::FaceRecord& b) {
    return a.halfedge == b.halfedge &&
           std::bit_cast<std::uint32_t>(a.quality) == std::bit_cast<std::uint32_t>(b.quality) &&
           a.scanId == b.scanId;
}

// Reads the records of one mesh.
struct Reader {
    explicit Reader(const Mesh& mesh) : m(mesh) {
        std::tie(quality, hasQuality) = m.property_map<FaceIndex, float>(props::faceQuality);
        std::tie(scanId, hasScanId) = m.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    }
    MeshDelta::VertexRecord vertex(std::size_t i) const {
        const VertexIndex v(static_cast<Mesh::size_type>(i));
        return {m.point(v), std::uint32_t(m.halfedge(v))};
    }
    MeshDelta::HalfedgeRecord halfedge(std::size_t i) const {
        const HalfedgeIndex h(static_cast<Mesh::size_type>(i));
        return {std::uint32_t(m.next(h)), std::uint32_t(m.prev(h)), std::uint32_t(m.target(h)),
                std::uint32_t(m.face(h))};
    }
    MeshDelta::FaceRecord face(std::size_t i) const {
        const FaceIndex f(static_cast<Mesh::size_type>(i));
        return {std::uint32_t(m.halfedge(f)), hasQuality ? quality[f] : kInputFaceQuality,
                hasScanId ? scanId[f] : std::int32_t(-1)};
    }
    const Mesh& m;
    QualityMap quality;
    ScanIdMap scanId;
    bool hasQuality = false, hasScanId = false;
};

template <class Record, class ReadBefore, class ReadAfter>
MeshDelta::ArrayDelta<Record> diff(std::size_t sizeBefore, std::size_t sizeAfter,
                                   const ReadBefore& readBefore, const ReadAfter& readAfter) {
    MeshDelta::ArrayDelta<Record> d;
    d.sizeBefore = sizeBefore;
    d.sizeAfter = sizeAfter;
    const std::size_t common = std::min(sizeBefore, sizeAfter);
    for (std::size_t i = 0; i < common; ++i) {
        const Record b = readBefore(i), a = readAfter(i);
        if (same(a, b)) continue;
        d.index.push_back(std::uint32_t(i));
        d.before.push_back(b);
        d.after.push_back(a);
    }
    const bool grows = sizeAfter > sizeBefore;
    for (std::size_t i = common; i < std::max(sizeBefore, sizeAfter); ++i)
        d.tail.push_back(grows ? readAfter(i) : readBefore(i));
    d.index.shrink_to_fit();
    d.before.shrink_to_fit();
    d.after.shrink_to_fit();
    d.tail.shrink_to_fit();
    return d;
}

// Writes the records of one state of an array delta through \p write(index, record).
template <class Record, class Write>
void writeBack(const MeshDelta::ArrayDelta<Record>& d, bool forward, const Write& write) {
    const std::vector<Record>& values = forward ? d.after : d.before;
    for (std::size_t k = 0; k < d.index.size(); ++k)
        write(d.index[k], values[k]);
    const std::size_t target = forward ? d.sizeAfter : d.sizeBefore;
    const std::size_t other = forward ? d.sizeBefore : d.sizeAfter;
    if (target > other)
        for (std::size_t j = 0; j < d.tail.size(); ++j)
            write(other + j, d.tail[j]);
}

} // namespace

template <class Record> std::size_t MeshDelta::ArrayDelta<Record>::bytes() const {
    return index.capacity() * sizeof(std::uint32_t) +
           (before.capacity() + after.capacity() + tail.capacity()) * sizeof(Record);
}

MeshDelta MeshDelta::between(const Mesh& before, const Mesh& after) {
    if (before.has_garbage() || after.has_garbage())
        throw std::logic_error("MeshDelta::between needs meshes without garbage.");
    const Reader b(before), a(after);
    MeshDelta d;
    d.vertices_ = diff<VertexRecord>(
        before.number_of_vertices(), after.number_of_vertices(), [&](std::size_t i) { return b.vertex(i); },
        [&](std::size_t i) { return a.vertex(i); });
    d.halfedges_ = diff<HalfedgeRecord>(
        before.number_of_halfedges(), after.number_of_halfedges(),
        [&](std::size_t i) { return b.halfedge(i); }, [&](std::size_t i) { return a.halfedge(i); });
    d.faces_ = diff<FaceRecord>(
        before.number_of_faces(), after.number_of_faces(), [&](std::size_t i) { return b.face(i); },
        [&](std::size_t i) { return a.face(i); });
    d.qualityBefore_ = b.hasQuality;
    d.qualityAfter_ = a.hasQuality;
    d.scanIdBefore_ = b.hasScanId;
    d.scanIdAfter_ = a.hasScanId;
    return d;
}

void MeshDelta::apply(Mesh& mesh, bool forward) const {
    const bool wantQuality = forward ? qualityAfter_ : qualityBefore_;
    const bool wantScanId = forward ? scanIdAfter_ : scanIdBefore_;
    const std::size_t nv = forward ? vertices_.sizeAfter : vertices_.sizeBefore;
    const std::size_t nh = forward ? halfedges_.sizeAfter : halfedges_.sizeBefore;
    const std::size_t nf = forward ? faces_.sizeAfter : faces_.sizeBefore;

    // Everything that allocates happens first, undone on failure; the writes below do not allocate.
    auto [quality, hasQuality] = mesh.property_map<FaceIndex, float>(props::faceQuality);
    auto [scanId, hasScanId] = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    bool addedQuality = false, addedScanId = false;
    try {
        if (wantQuality && !hasQuality) {
            quality = mesh.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality).first;
            hasQuality = addedQuality = true;
        }
        if (wantScanId && !hasScanId) {
            scanId = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
            hasScanId = addedScanId = true;
        }
        mesh.reserve(Mesh::size_type(nv), Mesh::size_type(nh / 2), Mesh::size_type(nf));
    } catch (...) {
        if (addedQuality) mesh.remove_property_map(quality);
        if (addedScanId) mesh.remove_property_map(scanId);
        throw;
    }
    if (!wantQuality && hasQuality) {
        mesh.remove_property_map(quality);
        hasQuality = false;
    }
    if (!wantScanId && hasScanId) {
        mesh.remove_property_map(scanId);
        hasScanId = false;
    }
    mesh.resize(Mesh::size_type(nv), Mesh::size_type(nh / 2), Mesh::size_type(nf));

    writeBack(vertices_, forward, [&](std::size_t i, const VertexRecord& r) {
        const VertexIndex v(static_cast<Mesh::size_type>(i));
        mesh.point(v) = r.point;
        mesh.set_halfedge(v, HalfedgeIndex(r.halfedge));
    });
    writeBack(halfedges_, forward, [&](std::size_t i, const HalfedgeRecord& r) {
        const HalfedgeIndex h(static_cast<Mesh::size_type>(i));
        mesh.set_next_only(h, HalfedgeIndex(r.next));
        mesh.set_prev_only(h, HalfedgeIndex(r.prev));
        mesh.set_target(h, VertexIndex(r.target));
        mesh.set_face(h, FaceIndex(r.face));
    });
    writeBack(faces_, forward, [&](std::size_t i, const FaceRecord& r) {
        const FaceIndex f(static_cast<Mesh::size_type>(i));
        mesh.set_halfedge(f, HalfedgeIndex(r.halfedge));
        if (hasQuality) quality[f] = r.quality;
        if (hasScanId) scanId[f] = r.scanId;
    });
}

void MeshDelta::applyForward(Mesh& mesh) const {
    apply(mesh, true);
}
void MeshDelta::applyBackward(Mesh& mesh) const {
    apply(mesh, false);
}

std::size_t MeshDelta::bytes() const {
    return sizeof(MeshDelta) + vertices_.bytes() + halfedges_.bytes() + faces_.bytes();
}

std::size_t MeshDelta::records() const {
    return vertices_.index.size() + vertices_.tail.size() + halfedges_.index.size() + halfedges_.tail.size() +
           faces_.index.size() + faces_.tail.size();
}

// ---------------------------------------------------------------------------------------------------
// MeshJournal.
//
// Surface_mesh::collect_garbage() visits every element (index maps over the whole mesh, a pass over all
// connectivity, then shrink_to_fit copies every array): O(mesh) per accept. Its result is determined by the
// removed elements alone — the k-th lowest removed index below the new size receives the k-th highest kept
// element above it, and references to moved elements are renamed — so MeshJournal::finish() performs the
// same swaps and renames only where something moved. Surface_mesh offers no public access to its property
// containers (to swap every property, as collect_garbage() does) or to its garbage counters and free
// lists, so they are reached through the one standard-conforming way to name private members: an explicit
// template instantiation ([temp.spec.general]/6, access is not checked there). Tied to CGAL 5.5's
// Surface_mesh layout: checked below at compile time.
static_assert(
    CGAL_VERSION_NR >= 1050500000 && CGAL_VERSION_NR < 1050600000,
    "MeshJournal reaches Surface_mesh's private members as laid out in CGAL 5.5: check them again.");

namespace surface_mesh_access {
template <class Tag, typename Tag::type Member> struct Grant {
    friend typename Tag::type member(Tag) { return Member; }
};
template <class Index> using Container = CGAL::Properties::Property_container<Mesh, Index>;
#define FSS_SURFACE_MESH_MEMBER(Name, Type, member_)                                                         \
    struct Name {                                                                                            \
        using type = Type Mesh::*;                                                                           \
        friend type member(Name);                                                                            \
    };                                                                                                       \
    template struct Grant<Name, &Mesh::member_>;
FSS_SURFACE_MESH_MEMBER(VertexProps, Container<VertexIndex>, vprops_)
FSS_SURFACE_MESH_MEMBER(HalfedgeProps, Container<HalfedgeIndex>, hprops_)
FSS_SURFACE_MESH_MEMBER(EdgeProps, Container<EdgeIndex>, eprops_)
FSS_SURFACE_MESH_MEMBER(FaceProps, Container<FaceIndex>, fprops_)
FSS_SURFACE_MESH_MEMBER(RemovedVertices, Mesh::size_type, removed_vertices_)
FSS_SURFACE_MESH_MEMBER(RemovedEdges, Mesh::size_type, removed_edges_)
FSS_SURFACE_MESH_MEMBER(RemovedFaces, Mesh::size_type, removed_faces_)
FSS_SURFACE_MESH_MEMBER(VertexFreeList, Mesh::size_type, vertices_freelist_)
FSS_SURFACE_MESH_MEMBER(EdgeFreeList, Mesh::size_type, edges_freelist_)
FSS_SURFACE_MESH_MEMBER(FaceFreeList, Mesh::size_type, faces_freelist_)
FSS_SURFACE_MESH_MEMBER(Garbage, bool, garbage_)
#undef FSS_SURFACE_MESH_MEMBER
} // namespace surface_mesh_access

namespace {

constexpr Mesh::size_type kNoFree = (std::numeric_limits<Mesh::size_type>::max)();

// The removed elements of one kind, read from the mesh's free list (every removed element is on it),
// ascending; their number must be the mesh's removed count.
std::vector<std::uint32_t> freeList(Mesh::size_type head, std::size_t removed,
                                    const std::function<Mesh::size_type(Mesh::size_type)>& next) {
    std::vector<std::uint32_t> out;
    out.reserve(removed);
    for (Mesh::size_type i = head; i != kNoFree; i = next(i)) {
        if (out.size() == removed)
            throw std::logic_error("MeshJournal: a free list is longer than its count.");
        out.push_back(std::uint32_t(i));
    }
    if (out.size() != removed) throw std::logic_error("MeshJournal: a free list is shorter than its count.");
    std::sort(out.begin(), out.end());
    return out;
}

// collect_garbage()'s pairing: the k-th lowest removed index below the new size receives the element at
// the k-th highest kept index at or above it. Returns (hole, mover) pairs; `size` becomes the new size.
std::vector<std::pair<std::uint32_t, std::uint32_t>> compaction(const std::vector<std::uint32_t>& removed,
                                                                std::size_t& size) {
    const std::size_t kept = size - removed.size();
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    std::size_t k = 0;
    for (std::size_t i = size; i-- > kept;)
        if (!std::binary_search(removed.begin(), removed.end(), std::uint32_t(i)))
            pairs.push_back({removed[k++], std::uint32_t(i)});
    if (k < removed.size() && removed[k] < kept)
        throw std::logic_error("MeshJournal: the garbage does not pair up as collect_garbage's.");
    size = kept;
    return pairs;
}

template <class Index> Index renamed(const std::unordered_map<std::uint32_t, std::uint32_t>& map, Index i) {
    if (i == Index()) return i;
    auto it = map.find(std::uint32_t(i));
    return it == map.end() ? i : Index(it->second);
}

} // namespace

MeshJournal::MeshJournal(const Mesh& mesh)
    : vertexCount_(mesh.number_of_vertices()), halfedgeCount_(mesh.number_of_halfedges()),
      faceCount_(mesh.number_of_faces()) {
    if (mesh.has_garbage()) throw std::logic_error("MeshJournal needs a mesh without garbage.");
    hadQuality_ = mesh.property_map<FaceIndex, float>(props::faceQuality).second;
    hadScanId_ = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId).second;
}

void MeshJournal::keepVertex(const Mesh& mesh, VertexIndex v) {
    if (std::size_t(v) < vertexCount_ && !vertices_.count(std::uint32_t(v)))
        vertices_.emplace(std::uint32_t(v), Reader(mesh).vertex(std::size_t(v)));
}
void MeshJournal::keepHalfedge(const Mesh& mesh, HalfedgeIndex h) {
    if (std::size_t(h) < halfedgeCount_ && !halfedges_.count(std::uint32_t(h)))
        halfedges_.emplace(std::uint32_t(h), Reader(mesh).halfedge(std::size_t(h)));
}
void MeshJournal::keepFace(const Mesh& mesh, FaceIndex f) {
    if (f != FaceIndex() && std::size_t(f) < faceCount_ && !faces_.count(std::uint32_t(f)))
        faces_.emplace(std::uint32_t(f), Reader(mesh).face(std::size_t(f)));
}

void MeshJournal::record(const Mesh& mesh, std::span<const VertexIndex> vertices,
                         std::span<const FaceIndex> faces) {
    std::vector<VertexIndex> around(vertices.begin(), vertices.end());
    for (FaceIndex f : faces) {
        keepFace(mesh, f);
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
            around.push_back(mesh.target(h));
    }
    // Room for them at once (a stitch records up to the whole region under the patch in one call): no
    // rehashing while they are inserted. `around` repeats shared vertices, so this is an upper bound.
    vertices_.reserve(vertices_.size() + around.size());
    halfedges_.reserve(halfedges_.size() + 2 * around.size());
    faces_.reserve(faces_.size() + around.size());
    const Reader reader(mesh);
    for (VertexIndex v : around) {
        if (std::size_t(v) < vertexCount_ && !vertices_.count(std::uint32_t(v)))
            vertices_.emplace(std::uint32_t(v), reader.vertex(std::size_t(v)));
        if (mesh.is_isolated(v)) continue;
        for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh))
            for (HalfedgeIndex g : {h, mesh.opposite(h)}) {
                if (std::size_t(g) < halfedgeCount_ && !halfedges_.count(std::uint32_t(g)))
                    halfedges_.emplace(std::uint32_t(g), reader.halfedge(std::size_t(g)));
                const FaceIndex f = mesh.face(g);
                if (f != FaceIndex() && std::size_t(f) < faceCount_ && !faces_.count(std::uint32_t(f)))
                    faces_.emplace(std::uint32_t(f), reader.face(std::size_t(f)));
            }
    }
}

MeshDelta MeshJournal::finish(Mesh& mesh) {
    using namespace surface_mesh_access;
    // The removed elements, from the free lists.
    const auto removedVertices =
        freeList(mesh.*member(VertexFreeList{}), mesh.number_of_removed_vertices(),
                 [&](Mesh::size_type i) { return Mesh::size_type(mesh.halfedge(VertexIndex(i))); });
    const auto removedEdges =
        freeList(mesh.*member(EdgeFreeList{}), mesh.number_of_removed_edges(),
                 [&](Mesh::size_type h) { return Mesh::size_type(mesh.next(HalfedgeIndex(h))); });
    std::vector<std::uint32_t> removedEdgeIndices;
    for (std::uint32_t h : removedEdges)
        removedEdgeIndices.push_back(h / 2);
    const auto removedFaces =
        freeList(mesh.*member(FaceFreeList{}), mesh.number_of_removed_faces(),
                 [&](Mesh::size_type i) { return Mesh::size_type(mesh.halfedge(FaceIndex(i))); });
    // Array sizes, garbage included (number_of_*() leave the removed elements out).
    std::size_t nv = mesh.num_vertices(), ne = mesh.num_edges(), nf = mesh.num_faces();
    const auto vertexMoves = compaction(removedVertices, nv);
    const auto edgeMoves = compaction(removedEdgeIndices, ne);
    const auto faceMoves = compaction(removedFaces, nf);

    // Elements that refer to a moving one (in the indices before the moves), and the renaming.
    std::unordered_map<std::uint32_t, std::uint32_t> vmap, hmap, fmap;
    std::unordered_set<std::uint32_t> dirtyV, dirtyH, dirtyF;
    for (const auto& [to, from] : vertexMoves) {
        vmap[from] = to;
        dirtyV.insert(from);
        const VertexIndex v(from);
        if (!mesh.is_isolated(v))
            for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh))
                dirtyH.insert(std::uint32_t(h));
    }
    for (const auto& [to, from] : edgeMoves)
        for (std::uint32_t k = 0; k < 2; ++k) {
            const HalfedgeIndex h(2 * from + k);
            hmap[2 * from + k] = 2 * to + k;
            dirtyH.insert(std::uint32_t(h));
            dirtyH.insert(std::uint32_t(mesh.next(h)));
            dirtyH.insert(std::uint32_t(mesh.prev(h)));
            dirtyV.insert(std::uint32_t(mesh.target(h)));
            if (!mesh.is_border(h)) dirtyF.insert(std::uint32_t(mesh.face(h)));
        }
    for (const auto& [to, from] : faceMoves) {
        fmap[from] = to;
        dirtyF.insert(from);
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(FaceIndex(from)), mesh))
            dirtyH.insert(std::uint32_t(h));
    }
    // Their records before the edit: unchanged by it where not recorded (record()'s contract).
    for (std::uint32_t v : dirtyV)
        keepVertex(mesh, VertexIndex(v));
    for (std::uint32_t h : dirtyH)
        keepHalfedge(mesh, HalfedgeIndex(h));
    for (std::uint32_t f : dirtyF)
        keepFace(mesh, FaceIndex(f));
    // Where the mesh shrinks, the records beyond its new size.
    for (std::size_t i = nv; i < vertexCount_; ++i)
        keepVertex(mesh, VertexIndex(Mesh::size_type(i)));
    for (std::size_t i = 2 * ne; i < halfedgeCount_; ++i)
        keepHalfedge(mesh, HalfedgeIndex(Mesh::size_type(i)));
    for (std::size_t i = nf; i < faceCount_; ++i)
        keepFace(mesh, FaceIndex(Mesh::size_type(i)));

    // collect_garbage(): the swaps (every property), then the renaming where something moved, then the
    // removed elements cut off (capacity kept) and the garbage bookkeeping reset.
    for (const auto& [to, from] : vertexMoves)
        (mesh.*member(VertexProps{})).swap(to, from);
    for (const auto& [to, from] : edgeMoves) {
        (mesh.*member(EdgeProps{})).swap(to, from);
        (mesh.*member(HalfedgeProps{})).swap(2 * std::size_t(to), 2 * std::size_t(from));
        (mesh.*member(HalfedgeProps{})).swap(2 * std::size_t(to) + 1, 2 * std::size_t(from) + 1);
    }
    for (const auto& [to, from] : faceMoves)
        (mesh.*member(FaceProps{})).swap(to, from);
    auto moved = [](const std::unordered_map<std::uint32_t, std::uint32_t>& map, std::uint32_t i) {
        auto it = map.find(i);
        return it == map.end() ? i : it->second;
    };
    std::vector<std::uint32_t> touchedV, touchedH, touchedF; // after the moves
    for (std::uint32_t v : dirtyV)
        touchedV.push_back(moved(vmap, v));
    for (std::uint32_t h : dirtyH)
        touchedH.push_back(moved(hmap, h));
    for (std::uint32_t f : dirtyF)
        touchedF.push_back(moved(fmap, f));
    for (std::uint32_t i : touchedV) {
        const VertexIndex v(i);
        if (!mesh.is_isolated(v)) mesh.set_halfedge(v, renamed(hmap, mesh.halfedge(v)));
    }
    for (std::uint32_t i : touchedH) {
        const HalfedgeIndex h(i);
        mesh.set_target(h, renamed(vmap, mesh.target(h)));
        mesh.set_next(h, renamed(hmap, mesh.next(h)));
        if (!mesh.is_border(h)) mesh.set_face(h, renamed(fmap, mesh.face(h)));
    }
    for (std::uint32_t i : touchedF) {
        const FaceIndex f(i);
        mesh.set_halfedge(f, renamed(hmap, mesh.halfedge(f)));
    }
    (mesh.*member(VertexProps{})).resize(nv);
    (mesh.*member(HalfedgeProps{})).resize(2 * ne);
    (mesh.*member(EdgeProps{})).resize(ne);
    (mesh.*member(FaceProps{})).resize(nf);
    mesh.*member(RemovedVertices{}) = mesh.*member(RemovedEdges{}) = mesh.*member(RemovedFaces{}) = 0;
    mesh.*member(VertexFreeList{}) = mesh.*member(EdgeFreeList{}) = mesh.*member(FaceFreeList{}) = kNoFree;
    mesh.*member(Garbage{}) = false;

    // The delta: only recorded elements can differ below the smaller size.
    const Reader after(mesh);
    MeshDelta d;
    auto build = [](auto& out, std::size_t sizeBefore, std::size_t sizeAfter, const auto& recorded,
                    const auto& readAfter) {
        out.sizeBefore = sizeBefore;
        out.sizeAfter = sizeAfter;
        const std::size_t common = std::min(sizeBefore, sizeAfter);
        std::vector<std::uint32_t> indices;
        for (const auto& [i, record] : recorded)
            if (i < common) indices.push_back(i);
        std::sort(indices.begin(), indices.end());
        for (std::uint32_t i : indices) {
            const auto& b = recorded.at(i);
            const auto a = readAfter(i);
            if (same(a, b)) continue;
            out.index.push_back(i);
            out.before.push_back(b);
            out.after.push_back(a);
        }
        for (std::size_t i = common; i < std::max(sizeBefore, sizeAfter); ++i)
            out.tail.push_back(sizeAfter > sizeBefore ? readAfter(i) : recorded.at(std::uint32_t(i)));
        out.index.shrink_to_fit();
        out.before.shrink_to_fit();
        out.after.shrink_to_fit();
        out.tail.shrink_to_fit();
    };
    build(d.vertices_, vertexCount_, nv, vertices_, [&](std::size_t i) { return after.vertex(i); });
    build(d.halfedges_, halfedgeCount_, 2 * ne, halfedges_, [&](std::size_t i) { return after.halfedge(i); });
    build(d.faces_, faceCount_, nf, faces_, [&](std::size_t i) { return after.face(i); });
    d.qualityBefore_ = hadQuality_;
    d.qualityAfter_ = after.hasQuality;
    d.scanIdBefore_ = hadScanId_;
    d.scanIdAfter_ = after.hasScanId;
    return d;
}

} // namespace fss::detail
