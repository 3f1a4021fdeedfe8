#pragma once
/// \file mesh.h
/// The mesh type of FSS and the names of the per-element properties that FSS keeps on it.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Geometry>

#include <cstdint>

namespace fss {

/// Geometry kernel: exact predicates, double constructions (robust combinatorial decisions).
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Vector3 = Kernel::Vector_3;

/// The one mesh type of FSS: a CGAL halfedge surface mesh of triangles.
using Mesh = CGAL::Surface_mesh<Point3>;
using VertexIndex = Mesh::Vertex_index;
using FaceIndex = Mesh::Face_index;
using EdgeIndex = Mesh::Edge_index;
using HalfedgeIndex = Mesh::Halfedge_index;

/// Names of the optional face properties FSS maintains. PLY files keep them (see mesh_io.h).
namespace props {
/// `float` sampling quality of a face made by a scan (lower is better, see scan.h); input faces have none.
inline constexpr const char* faceQuality = "f:quality";
/// `std::int32_t` id of the scan that made the face; -1 (or absent) for faces of the input mesh.
inline constexpr const char* faceScanId = "f:scan_id";
} // namespace props

/// Axis-aligned bounding box of the mesh's (live) vertices; empty for an empty mesh.
inline Eigen::AlignedBox3d boundingBox(const Mesh& mesh) {
    Eigen::AlignedBox3d box;
    for (VertexIndex v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        box.extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
    }
    return box;
}

/// Quality value of a face that no scan has made (input faces rank lowest: any scan sample beats them).
inline constexpr float kInputFaceQuality = 1e30f;

} // namespace fss

// Named face groups (the surfaces FEM boundary conditions are attached to) are a third optional face
// property, `f:group` (std::int32_t index into a group-name table that the mesh itself carries, -1 for a
// face in no group): see fss/face_groups.h (props::faceGroup, groupNames, transferFaceGroups).
