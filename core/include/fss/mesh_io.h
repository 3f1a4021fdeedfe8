#pragma once
/// \file mesh_io.h
/// Reading and writing triangle meshes: OFF, OBJ, PLY (ascii / binary), STL (ascii / binary).
///
/// Files are read as polygon soups by strict parsers of our own (a truncated or corrupt file is an error
/// with a precise message, never a silently shortened mesh). A soup that is not a valid oriented
/// 2-manifold is repaired (merge duplicate points, remove polygons with repeated corners and duplicate
/// triangles, orient with CGAL's orient_polygon_soup, duplicate non-manifold vertices, drop isolated
/// points); polygons with more than three corners are triangulated (ear clipping, so non-convex planar
/// polygons come out right). Everything that was changed is listed in the ReadReport, so nothing is lost
/// silently. Faces keep the order of the file (a triangulated polygon's triangles take its place).

#include "fss/mesh.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace fss {

/// Topological facts about the polygon soup as it was in the file, before any repair.
/// The topology counts (edges, vertices) identify geometrically equal points and ignore polygons with
/// repeated corners, i.e. they describe the surface the file means. STL stores every triangle's corners
/// separately: its identical corners are merged while reading and are not counted as duplicates.
struct SoupStats {
    std::size_t points = 0;           ///< points in the file
    std::size_t polygons = 0;         ///< polygons in the file
    std::size_t nonTriangles = 0;     ///< polygons with more than 3 corners
    std::size_t nonManifoldEdges = 0; ///< undirected edges shared by more than two polygons
    /// vertices whose incident polygons form more than one fan (bow-ties); the ends of a non-manifold edge
    /// are counted in nonManifoldEdges only
    std::size_t nonManifoldVertices = 0;
    /// polygons with repeated corners or zero area (exactly collinear corners). Only those with repeated
    /// corners are removed by the repair: removing a zero-area triangle from a closed mesh would open a hole.
    std::size_t degeneratePolygons = 0;
    std::size_t duplicatePoints = 0; ///< points geometrically equal to an earlier point
};

/// What readMesh found and what it changed.
struct ReadReport {
    std::string format;               ///< "off", "obj", "ply", "stl"
    bool binary = false;              ///< binary PLY / STL
    SoupStats soup;                   ///< the soup as read
    std::vector<std::string> repairs; ///< one sentence per repair made ("merged 12 duplicate points", ...)
    bool hasFaceQuality = false;      ///< a PLY face property `quality` was restored into props::faceQuality
    bool hasScanId = false;           ///< a PLY face property `scan_id` was restored into props::faceScanId
    /// number of named face groups read (fss/face_groups.h): OBJ `g`/`o` statements, the solids of an ascii
    /// STL file with more than one solid, the PLY face property `group` (names from "comment group <value>
    /// <name>" header lines, else "group_<value>"); 0 when the file has none
    std::size_t groups = 0;
    bool repaired() const { return !repairs.empty(); }
};

/// Options of readMesh.
struct ReadOptions {
    /// Repair soups that are not a valid mesh (else such a file is an error: polygons with repeated corners,
    /// non-manifold or inconsistently oriented polygons, points no polygon uses). Triangulating polygons
    /// with more than three corners is always done (and reported), since a Mesh holds triangles.
    bool repair = true;
};

/// Reads a triangle mesh; the format is chosen by the extension (case-insensitive), falling back to the
/// file's content when the extension is unknown. Ascii or binary STL is always told by the content.
/// PLY face properties `quality` and `scan_id` are restored into props::faceQuality / props::faceScanId.
/// \param path    the file to read
/// \param report  when not null, receives the format, the SoupStats and one sentence per repair
/// \param options see ReadOptions
/// \return a valid, consistently oriented, edge-manifold triangle mesh (CGAL::is_valid_polygon_mesh)
/// \throw IoError when the file is missing, unreadable, empty, truncated, of unknown format, contains
///        garbage, NaN/inf coordinates, faces indexing missing vertices, faces with fewer than 3 corners,
///        no faces, or nothing is left after repair (or needs repair while options.repair is false).
///        The message is one sentence that names the file and, for text formats, the line.
Mesh readMesh(const std::filesystem::path& path, ReadReport* report = nullptr,
              const ReadOptions& options = {});

/// The mesh as readMesh (default options) builds it from a binary PLY that writeMesh made of \p mesh:
/// garbage dropped, vertices and faces re-indexed contiguously in iteration order, the reader's halfedge
/// layout, face quality and scan ids kept; points bit-identical. Use it when a mesh from memory must behave
/// exactly like the same mesh read back from a file (session files replay from the file). Not idempotent:
/// canonicalMesh(canonicalMesh(m)) may differ in layout (the reader's halfedge of a face need not start at
/// the corner it was given first), so write \p mesh itself, not its canonical form, to get it back.
/// \throw IoError (naming "(mesh in memory)") when readMesh would refuse such a file: no faces, NaN
///        coordinates, or nothing left after repair.
Mesh canonicalMesh(const Mesh& mesh);

/// A polygon soup read by a reader outside core (fss/render/fem_io.h: VTK and gmsh files), to be turned
/// into a Mesh exactly as readMesh turns its files' soups (same checks, repairs and report).
struct PolygonSoup {
    std::vector<Point3> points;
    std::vector<std::vector<std::size_t>> polygons; ///< corner indices into points, ≥ 3 corners each
    std::vector<std::int32_t> groups;               ///< per polygon (index into groupNames), or empty
    std::vector<std::string> groupNames;            ///< names of the groups (fss/face_groups.h)
};

/// The mesh of \p soup, checked and repaired as readMesh does (see ReadOptions); \p source names the file
/// in messages and \p format goes into the report.
/// \throw IoError naming \p source when a polygon has fewer than 3 corners or an index out of range, a
///        coordinate is not finite, a group index is outside groupNames, or readMesh would refuse the soup.
Mesh meshFromPolygons(PolygonSoup soup, const std::filesystem::path& source, const std::string& format,
                      ReadReport* report = nullptr, const ReadOptions& options = {});

/// Options of writeMesh.
struct WriteOptions {
    bool binary = false; ///< binary PLY / STL (ascii otherwise); binary PLY stores doubles, STL floats
    int precision = 17;  ///< significant digits of ascii coordinates (17 round-trips doubles); 1…17
};

/// Writes a mesh; the format is chosen by the extension (.off .obj .ply .stl, case-insensitive). PLY files
/// also store the face properties props::faceQuality (as `quality`) and props::faceScanId (as `scan_id`)
/// when present; the other formats cannot hold them. Face groups (fss/face_groups.h) are written as the
/// PLY face property `group` with "comment group <index> <name>" lines, as OBJ `g` statements and as one
/// ascii STL solid per group; OFF and binary STL cannot hold them. (FEM and VTK formats:
/// fss/render/fem_io.h.) Only valid elements are written, re-indexed
/// contiguously in iteration order (removed elements of a mesh with garbage are skipped). STL holds
/// triangles only: a face with more corners is written as a fan.
/// The file is written to a temporary name in the same folder and renamed, so a failed write never
/// destroys an existing file.
/// \param mesh    the mesh to write
/// \param path    the target file
/// \param options see WriteOptions (precision is clamped to 1…17)
/// \throw IoError naming the file when the extension is unknown, a group name cannot be held (OBJ: white
///        space or '#') or the file cannot be written.
void writeMesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& options = {});

/// True when the extension of \p path (case-insensitive) names a format writeMesh can write.
bool isSupportedMeshFile(const std::filesystem::path& path);

} // namespace fss
