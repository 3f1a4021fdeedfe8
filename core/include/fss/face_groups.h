#pragma once
/// \file face_groups.h
/// Named face groups (the surfaces FEM boundary conditions are attached to) on a Mesh, and how they are
/// carried through remeshing.
///
/// A mesh with groups holds (see also fss/mesh.h):
/// - the face property props::faceGroup (`std::int32_t`): the index of the face's group in the group-name
///   table, or kNoGroup (-1) for a face in no group (the default of faces a scan or stitch creates);
/// - the group-name table, kept on the mesh itself so that it follows every copy of the mesh: a `bool` face
///   property (one bit per face, never read) whose *name* is props::faceGroupNamesPrefix followed by the
///   names joined by '\n'. groupNames() / setGroupNames() hide this encoding.
/// Readers fill both (OBJ `g`/`o`, multi-solid ascii STL names, the PLY face property `group`, MSH physical
/// surfaces, VTU/VTP cell data `group`); writers store them as each format can (fss/mesh_io.h,
/// fss/render/fem_io.h).

#include "fss/mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fss {

namespace props {
/// `std::int32_t` index of the face's group in groupNames(mesh); kNoGroup (-1) for none.
inline constexpr const char* faceGroup = "f:group";
/// Prefix of the name of the face property that carries the group-name table (see the file comment).
inline constexpr const char* faceGroupNamesPrefix = "f:group_names:";
} // namespace props

/// The group index of a face in no group.
inline constexpr std::int32_t kNoGroup = -1;

/// Whether \p mesh has the face property props::faceGroup.
bool hasFaceGroups(const Mesh& mesh);

/// The group-name table of \p mesh (empty when it has none). Index i names group i.
std::vector<std::string> groupNames(const Mesh& mesh);

/// Replaces the group-name table of \p mesh and adds props::faceGroup (every face kNoGroup) when missing.
/// \throw InvalidInputError when a name is empty or contains a line break or a NUL character.
void setGroupNames(Mesh& mesh, const std::vector<std::string>& names);

/// Removes the groups (property and table) from \p mesh.
void removeFaceGroups(Mesh& mesh);

/// Gives every face of \p result the group of the face of \p reference closest to its centroid (CGAL AABB
/// tree through RayCaster::closestPoint) and copies the group-name table. After a remeshing this is "the
/// group of the reference face its samples came from": a face sampled from one reference face has its
/// centroid on (or within the sampling error of) that face; a seam face gets its nearest reference face.
/// Does nothing when \p reference has no groups.
/// \pre every face of both meshes is a triangle.
void transferFaceGroups(const Mesh& reference, Mesh& result);

/// The sharp crease edges of \p mesh (an interior edge whose two faces' normals differ by more than
/// \p angleDeg degrees, as CGAL's detect_sharp_edges decides), as vertex pairs in edge order; the FEM writers
/// export them as line elements (fss/render/fem_io.h).
/// \pre \p mesh is a triangle mesh. \throw InvalidInputError unless 0 < angleDeg < 180.
std::vector<std::array<VertexIndex, 2>> sharpFeatureEdges(const Mesh& mesh, double angleDeg);

/// Faces and area of one group.
struct GroupStats {
    std::string name;      ///< the group's name ("" for the faces in no group)
    std::size_t faces = 0; ///< faces in the group
    double area = 0;       ///< their total area
};

/// One entry per name of groupNames(mesh), in order, then (only when there are such faces) one entry with
/// an empty name for the faces in no group (or with an index outside the table). Empty when \p mesh has
/// no groups.
std::vector<GroupStats> groupStats(const Mesh& mesh);

} // namespace fss
