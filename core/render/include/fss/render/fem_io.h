#pragma once
/// \file fem_io.h
/// The hand-off to FEM: mesh files that FEM preprocessors and VTK read, with named face groups
/// (fss/face_groups.h). Format by extension (case-insensitive):
///
/// | extension | writes | reads | by | groups as |
/// |---|---|---|---|---|
/// | .msh | gmsh MSH 4.1 (2.2 with FemWriteOptions::mshVersion) | yes | gmsh's C++ API | physical surfaces
/// (named) | | .unv | I-deas universal file | no | gmsh's C++ API | groups (dataset 2477) | | .inp | Abaqus
/// input (S3 shells) | no | FSS (see below) | *ELSET per group and *SURFACE on it | | .bdf .nas | Nastran
/// bulk data (GRID* large field, CTRIA3, PSHELL) | no | FSS (see below) | PID per group (names in the comment
/// conventions of HyperMesh, ANSA, Femap and Patran) | | .vtu
/// | VTK XML unstructured grid | yes | VTK's XML writer / reader | cell data `group` + field data
/// `group_names` | | .vtp | VTK XML poly data | yes | VTK's XML writer / reader | as .vtu | | .vtk | — |
/// legacy VTK (unstructured grid or poly data) | VTK's legacy readers | cell data `group` |
///
/// Everything else (.off .obj .ply .stl) goes to fss::readMesh / fss::writeMesh. Why two writers are our
/// own (measured with gmsh 4.8.4): gmsh writes Abaqus triangles as CPS3, plane-stress elements of a 2D
/// model, with 14 significant digits; and Nastran GRID coordinates with 6 (free field) or 9 (large field)
/// significant digits, without the BEGIN BULK line other readers need and with CBAR line elements whose
/// orientation vector is zero. Our INP and BDF writers are tested against meshio's readers (and gmsh reads
/// the BDF back). BDF coordinates use the shortest Nastran real forms (no 'E': "1.23456789012+3"; no
/// exponent where a fixed form holds more digits; the leading "0" of ".123" dropped when short of room):
/// 12 to 15 significant digits in a 16-character field.
///
/// Nastran bulk data has no field for a name: a property (PSHELL, PROD) has an integer PID only, and the
/// named sets of other formats do not exist. FEM preprocessors therefore carry names in comment lines of
/// their own; the BDF writer writes one PSHELL (PROD for feature edges) per group, with only its PID set,
/// preceded by the name in each convention:
/// \code
///   $HMNAME COMP                   1"upper"            HyperMesh component (also read by OpenFOAM)
///   $HMNAME PROP                   1"upper"            HyperMesh property
///   $ANSA_NAME_COMMENT;1;PSHELL;upper;;NO;NO;NO;NO;     ANSA
///   $ Femap Property 1 : upper                          Femap
///   $ Elements and Element Properties for region : upper   Patran
///   PSHELL  1
/// \endcode
/// followed by the group's elements. A name these lines cannot hold ('"', ';', or characters outside
/// printable ASCII) is refused.
///
/// Faces in no group go into a group named "ungrouped"; a mesh without groups is one group "surface".
/// With FemWriteOptions::featureEdges, the sharp crease edges go out as 2-node line elements in a group
/// of their own ("feature_edges"). gmsh's API keeps global state: the gmsh writers and readers take a
/// process-wide lock (one at a time), so they may be called from any thread.
///
/// Every writer writes to a temporary file in the target's folder and renames it, so a failed write leaves
/// no file and an existing file unchanged.

#include "fss/mesh.h"
#include "fss/mesh_io.h"

#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>

namespace fss::render {

/// Options of writeMeshFile for the FEM and VTK formats.
struct FemWriteOptions {
    /// gmsh MSH version: 4.1 (default) or 2.2.
    double mshVersion = 4.1;
    /// Also write the sharp crease edges (dihedral angle above featureAngleDeg) as line elements in a group
    /// "feature_edges".
    bool featureEdges = false;
    double featureAngleDeg = 45; ///< 0 < angle < 180
    /// VTU/VTP: data arrays binary (base64, exact doubles) instead of ascii.
    bool vtkBinary = true;
    /// A lower limit than the format's own on the nodes / elements (faces + feature edges) of the file, for
    /// a target solver's (a student edition's node limit, say); 0: the format's own limit only.
    std::size_t maxNodes = 0;
    std::size_t maxElements = 0;
};

/// The largest mesh a format numbers (ids 1 … limit); std::size_t's maximum where the format sets none.
struct FormatLimits {
    std::size_t nodes = std::numeric_limits<std::size_t>::max();
    std::size_t elements = std::numeric_limits<std::size_t>::max(); ///< faces + feature edges
    std::size_t groups = std::numeric_limits<std::size_t>::max();   ///< named groups (PIDs, ...)
};

/// The limits of the format of \p path's extension, lowered by FemWriteOptions::maxNodes / maxElements:
/// Nastran BDF 99999999 nodes, elements and PIDs (8-character integer fields; element cards refer to nodes
/// in them); Abaqus INP 999999999 nodes and elements (Abaqus's largest node and element number); MSH 2.2
/// and UNV 2147483647 (32-bit integers); PLY 2147483647 nodes (int vertex indices); binary STL 4294967295
/// faces (32-bit count); MSH 4.1, VTU, VTP, OFF, OBJ and ascii STL none.
FormatLimits formatLimits(const std::filesystem::path& path, const FemWriteOptions& options = {},
                          const WriteOptions& coreOptions = {});

/// \throw IoError (one sentence naming the file, the count and the limit) when a mesh of \p nodes nodes,
///        \p elements elements and \p groups groups exceeds formatLimits(path, options, coreOptions).
///        writeMeshFile calls it before it creates any file.
void checkFormatLimits(const std::filesystem::path& path, std::size_t nodes, std::size_t elements,
                       std::size_t groups, const FemWriteOptions& options = {},
                       const WriteOptions& coreOptions = {});

/// True when this layer writes \p path's extension (.msh .unv .inp .bdf .nas .vtu .vtp).
bool isFemMeshFile(const std::filesystem::path& path);

/// True when writeMeshFile can write \p path: a FEM/VTK format above or one of fss::writeMesh's.
bool isWritableMeshFile(const std::filesystem::path& path);

/// Writes \p mesh in the format of \p path's extension: the FEM/VTK formats above, else fss::writeMesh with
/// \p coreOptions.
/// \throw IoError (one sentence naming the file) when the extension names no format, a group name cannot be
///        held by the format (MSH: '"'; INP: anything but a letter followed by letters, digits, '_', '-'
///        or '.', at most 80 characters; BDF: '"', ';' or characters outside printable ASCII), the mesh
///        exceeds the format's limits (checkFormatLimits: checked before any file is created), or the file
///        cannot be written.
/// \throw InvalidInputError when an option is out of range.
void writeMeshFile(const Mesh& mesh, const std::filesystem::path& path, const FemWriteOptions& options = {},
                   const WriteOptions& coreOptions = {});

/// \p v as a Nastran real in a large field (at most 16 characters) with as many significant digits as fit
/// (12 to 15; see the file comment): "0." for zero, "1.5" rather than ".15+1", "1.23456789012-300".
/// \throw InvalidInputError when \p v is not finite.
std::string nastranReal(double v);

/// Reads a mesh: .vtu .vtp .vtk by VTK's readers and .msh by gmsh (triangles and quads of the file; groups
/// from the integer cell data `group` (names from field data "group:<name>" arrays, else "group_<value>") or
/// from MSH physical surfaces), then checked and repaired as fss::readMesh does (fss::meshFromPolygons);
/// every other extension by fss::readMesh. \throw IoError (one sentence naming the file) when the file is
/// missing or unreadable, has no triangles,
///        has cells other than vertices, lines, triangles, quads and polygons, or a `group` array that is not
///        one integer per cell.
Mesh readMeshFile(const std::filesystem::path& path, ReadReport* report = nullptr,
                  const ReadOptions& options = {});

} // namespace fss::render
