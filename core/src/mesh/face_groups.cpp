// Named face groups: the group-name table kept on the mesh and the transfer of groups after remeshing
// (fss/face_groups.h).
#include "fss/face_groups.h"

#include "fss/error.h"
#include "fss/raycast.h"
#include "mesh/features.h"

#include <CGAL/Polygon_mesh_processing/measure.h>

#include <algorithm>
#include <string_view>

namespace fss {
namespace {

std::string tableProperty(const Mesh& mesh) {
    const std::string_view prefix = props::faceGroupNamesPrefix;
    for (const std::string& name : mesh.properties<FaceIndex>())
        if (std::string_view(name).substr(0, prefix.size()) == prefix) return name;
    return {};
}

} // namespace

bool hasFaceGroups(const Mesh& mesh) {
    return mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup).second;
}

std::vector<std::string> groupNames(const Mesh& mesh) {
    const std::string property = tableProperty(mesh);
    std::vector<std::string> names;
    if (property.empty()) return names;
    std::string_view rest =
        std::string_view(property).substr(std::string_view(props::faceGroupNamesPrefix).size());
    if (rest.empty()) return names;
    while (true) {
        const std::size_t end = rest.find('\n');
        names.emplace_back(rest.substr(0, end));
        if (end == std::string_view::npos) break;
        rest.remove_prefix(end + 1);
    }
    return names;
}

void setGroupNames(Mesh& mesh, const std::vector<std::string>& names) {
    std::string property = props::faceGroupNamesPrefix;
    for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string& n = names[i];
        if (n.empty()) throw InvalidInputError("Group " + std::to_string(i) + " has an empty name.");
        if (n.find_first_of(std::string_view("\n\r\0", 3)) != std::string::npos)
            throw InvalidInputError("The name of group " + std::to_string(i) +
                                    " contains a line break or a NUL character.");
        if (i) property += '\n';
        property += n;
    }
    const std::string old = tableProperty(mesh);
    if (!old.empty()) {
        auto map = mesh.property_map<FaceIndex, bool>(old);
        if (map.second) mesh.remove_property_map(map.first);
    }
    mesh.add_property_map<FaceIndex, bool>(property, false);
    mesh.add_property_map<FaceIndex, std::int32_t>(props::faceGroup, kNoGroup);
}

void removeFaceGroups(Mesh& mesh) {
    const std::string old = tableProperty(mesh);
    if (!old.empty()) {
        auto map = mesh.property_map<FaceIndex, bool>(old);
        if (map.second) mesh.remove_property_map(map.first);
    }
    auto group = mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup);
    if (group.second) mesh.remove_property_map(group.first);
}

void transferFaceGroups(const Mesh& reference, Mesh& result) {
    const auto source = reference.property_map<FaceIndex, std::int32_t>(props::faceGroup);
    if (!source.second) return;
    setGroupNames(result, groupNames(reference));
    auto target = result.property_map<FaceIndex, std::int32_t>(props::faceGroup).first;
    const RayCaster caster(reference);
    for (FaceIndex f : result.faces()) {
        Eigen::Vector3d c(0, 0, 0);
        int n = 0;
        for (VertexIndex v : CGAL::vertices_around_face(result.halfedge(f), result)) {
            const Point3& p = result.point(v);
            c += Eigen::Vector3d(p.x(), p.y(), p.z());
            ++n;
        }
        const SurfacePoint hit = caster.closestPoint(c / double(std::max(n, 1)));
        target[f] = hit.face == Mesh::null_face() ? kNoGroup : source.first[hit.face];
    }
}

std::vector<std::array<VertexIndex, 2>> sharpFeatureEdges(const Mesh& mesh, double angleDeg) {
    if (!(angleDeg > 0 && angleDeg < 180))
        throw InvalidInputError("The feature angle must lie between 0 and 180 degrees, not " +
                                std::to_string(angleDeg) + ".");
    const std::vector<char> sharp = detail::sharpEdges(mesh, angleDeg);
    std::vector<std::array<VertexIndex, 2>> edges;
    for (EdgeIndex e : mesh.edges())
        if (sharp[std::size_t(e)])
            edges.push_back({mesh.source(mesh.halfedge(e)), mesh.target(mesh.halfedge(e))});
    return edges;
}

std::vector<GroupStats> groupStats(const Mesh& mesh) {
    const auto group = mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup);
    std::vector<GroupStats> stats;
    if (!group.second) return stats;
    for (const std::string& name : groupNames(mesh))
        stats.push_back({name, 0, 0.0});
    GroupStats none;
    for (FaceIndex f : mesh.faces()) {
        const std::int32_t g = group.first[f];
        GroupStats& s = g >= 0 && std::size_t(g) < stats.size() ? stats[std::size_t(g)] : none;
        ++s.faces;
        s.area += CGAL::Polygon_mesh_processing::face_area(f, mesh);
    }
    if (none.faces) stats.push_back(none);
    return stats;
}

} // namespace fss
