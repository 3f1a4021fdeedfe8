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
    void apply(Mesh& mesh, bool forward) const;

    ArrayDelta<VertexRecord> vertices_;
    ArrayDelta<HalfedgeRecord> halfedges_;
    ArrayDelta<FaceRecord> faces_;
    bool qualityBefore_ = false, qualityAfter_ = false; // props::faceQuality present in each state
    bool scanIdBefore_ = false, scanIdAfter_ = false;   // props::faceScanId present in each state
};

} // namespace fss::detail
