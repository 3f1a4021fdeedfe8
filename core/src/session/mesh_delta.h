#pragma once
// MeshDelta: the index-wise difference between two garbage-free meshes, for the Session's undo/redo
// history (session.h). Internal to FSS::core.
//
// A garbage-free Surface_mesh is fully described by its element arrays: per vertex the point and the
// outgoing-halfedge link, per halfedge next / prev / target / face, per face one halfedge, plus the face
// properties FSS keeps (props::faceQuality, props::faceScanId). A MeshDelta stores, for each array, the
// sizes before and after, the indices below the smaller size whose record differs (with both records), and
// the records of the larger state beyond the smaller size. Applying it forwards or backwards resizes the
// arrays and writes those records back, so the result is the other state element for element and bit for
// bit (points are compared and restored as bit patterns). Memory and apply time are proportional to the
// number of differing records, not to the mesh.
#include "fss/mesh.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace fss::detail {

class MeshDelta {
public:
    struct VertexRecord {
        Point3 point;
        std::uint32_t halfedge;
    };
    struct HalfedgeRecord {
        std::uint32_t next, prev, target, face;
    };
    struct FaceRecord {
        std::uint32_t halfedge;
        float quality;       // kInputFaceQuality when the mesh has no props::faceQuality
        std::int32_t scanId; // -1 when the mesh has no props::faceScanId
    };
    template <class Record> struct ArrayDelta {
        std::size_t sizeBefore = 0, sizeAfter = 0;
        std::vector<std::uint32_t> index;  // differing indices below min(sizeBefore, sizeAfter)
        std::vector<Record> before, after; // their records in each state
        std::vector<Record> tail;          // records of the larger state at [min, max)
        std::size_t bytes() const;
    };

    /// The difference turning \p before into \p after. Both must be garbage-free (has_garbage() false).
    /// O(size of the meshes) time: every record is compared. \throw std::logic_error on garbage.
    static MeshDelta between(const Mesh& before, const Mesh& after);

    /// Turns a mesh equal to `before` (as given to between()) into `after`, exactly. O(delta).
    void applyForward(Mesh& mesh) const;
    /// Turns a mesh equal to `after` into `before`, exactly. O(delta).
    void applyBackward(Mesh& mesh) const;

    /// Heap and object bytes of this delta.
    std::size_t bytes() const;
    /// Number of differing records (vertices + halfedges + faces, changed or beyond the smaller size).
    std::size_t records() const;

private:
    friend class MeshJournal;
    void apply(Mesh& mesh, bool forward) const;

    ArrayDelta<VertexRecord> vertices_;
    ArrayDelta<HalfedgeRecord> halfedges_;
    ArrayDelta<FaceRecord> faces_;
    bool qualityBefore_ = false, qualityAfter_ = false; // props::faceQuality present in each state
    bool scanIdBefore_ = false, scanIdAfter_ = false;   // props::faceScanId present in each state
};

/// The MeshDelta of an edit made in place, in time proportional to the edit (Session::accept): before the
/// edit touches a garbage-free mesh, record() keeps the records of every element it may change; finish()
/// then collects the garbage exactly as Mesh::collect_garbage() does (the same swaps, so the same indices,
/// bit for bit) while touching only the removed elements, the elements that move into their places and
/// those that refer to them, and returns what MeshDelta::between(before, after) would, comparing only the
/// recorded elements.
///
/// The caller guarantees the edit changes no element that record() was not told about: every element
/// changed is new (beyond the sizes at construction, or reused from garbage the edit removed) or one of the
/// given vertices, the halfedges into and out of them, the faces around them, or a given face (with its
/// halfedges and vertices). Removing and adding faces around recorded vertices (CGAL's Euler operations,
/// Mesh::add_face, remove_face, add_vertex, remove_vertex, remove_edge) satisfies that.
class MeshJournal {
public:
    /// Starts recording an edit of \p mesh, which must be garbage-free. \throw std::logic_error on garbage.
    explicit MeshJournal(const Mesh& mesh);

    /// Keeps the current records (the state before the edit where not recorded yet) of \p vertices, the
    /// vertices of \p faces, every halfedge into and out of these vertices and every face around them.
    void record(const Mesh& mesh, std::span<const VertexIndex> vertices, std::span<const FaceIndex> faces);
    /// Nothing recorded yet (the edit has not started).
    bool empty() const { return vertices_.empty() && halfedges_.empty() && faces_.empty(); }

    /// Collects the garbage of \p mesh as collect_garbage() would (without shrinking the arrays' capacity)
    /// and returns the delta from the state at construction to the result. Call once.
    /// \throw std::logic_error when the mesh's garbage does not agree with its removed counts.
    MeshDelta finish(Mesh& mesh);

private:
    void keepVertex(const Mesh& mesh, VertexIndex v);
    void keepHalfedge(const Mesh& mesh, HalfedgeIndex h);
    void keepFace(const Mesh& mesh, FaceIndex f);

    std::size_t vertexCount_, halfedgeCount_, faceCount_; // sizes at construction
    bool hadQuality_, hadScanId_;
    // Records before the edit, by index (only indices below the sizes at construction).
    std::unordered_map<std::uint32_t, MeshDelta::VertexRecord> vertices_;
    std::unordered_map<std::uint32_t, MeshDelta::HalfedgeRecord> halfedges_;
    std::unordered_map<std::uint32_t, MeshDelta::FaceRecord> faces_;
};

} // namespace fss::detail
