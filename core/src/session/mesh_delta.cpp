// MeshDelta (session/mesh_delta.h): index-wise difference of two garbage-free meshes.
#include "session/mesh_delta.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

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

} // namespace fss::detail
