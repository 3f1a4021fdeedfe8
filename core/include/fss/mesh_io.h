#pragma once
/// \file mesh_io.h
/// Reading and writing triangle meshes: OFF, OBJ, PLY (ascii / binary), STL (ascii / binary).
///
/// Files are read as polygon soups. A soup that is not a valid oriented 2-manifold is repaired with CGAL's
/// polygon-soup functions (merge duplicate points, remove degenerate polygons, orient, duplicate
/// non-manifold vertices); polygons with more than three corners are triangulated. Everything that was
/// changed is listed in the ReadReport, so nothing is lost silently.

#include "fss/mesh.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace fss {

/// Topological facts about the polygon soup as it was in the file, before any repair.
struct SoupStats {
    std::size_t points = 0;               ///< points in the file
    std::size_t polygons = 0;             ///< polygons in the file
    std::size_t nonTriangles = 0;         ///< polygons with more than 3 corners
    std::size_t nonManifoldEdges = 0;     ///< undirected edges shared by more than two polygons
    std::size_t nonManifoldVertices = 0;  ///< vertices whose polygon fan is not one disc or half-disc
    std::size_t degeneratePolygons = 0;   ///< polygons with repeated corners or zero area
    std::size_t duplicatePoints = 0;      ///< points geometrically equal to an earlier point
};

/// What readMesh found and what it changed.
struct ReadReport {
    std::string format;                ///< "off", "obj", "ply", "stl"
    bool binary = false;               ///< binary PLY / STL
    SoupStats soup;                    ///< the soup as read
    std::vector<std::string> repairs;  ///< one sentence per repair made ("merged 12 duplicate points", ...)
    bool hasFaceQuality = false;       ///< a PLY face property `quality` was restored into props::faceQuality
    bool hasScanId = false;            ///< a PLY face property `scan_id` was restored into props::faceScanId
    bool repaired() const { return !repairs.empty(); }
};

/// Options of readMesh.
struct ReadOptions {
    /// Repair soups that are not a valid mesh (else such a file is an error).
    bool repair = true;
};

/// Reads a triangle mesh; the format is chosen by the extension (case-insensitive), falling back to the
/// file's content when the extension is unknown.
/// \throw IoError when the file is missing, unreadable, empty, truncated, of unknown format, contains
///        garbage, NaN/inf coordinates, faces indexing missing vertices, or nothing is left after repair.
///        The message names the file.
Mesh readMesh(const std::filesystem::path& path, ReadReport* report = nullptr, const ReadOptions& options = {});

/// Options of writeMesh.
struct WriteOptions {
    bool binary = false;        ///< binary PLY / STL (ascii otherwise)
    int precision = 17;         ///< significant digits of ascii coordinates (17 round-trips doubles)
};

/// Writes a mesh; the format is chosen by the extension (.off .obj .ply .stl). PLY files also store the
/// face properties props::faceQuality (as `quality`) and props::faceScanId (as `scan_id`) when present.
/// The file is written to a temporary name and renamed, so a failed write never destroys an existing file.
/// \throw IoError naming the file when the extension is unknown or the file cannot be written.
void writeMesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& options = {});

/// True when the extension of \p path names a format writeMesh can write.
bool isSupportedMeshFile(const std::filesystem::path& path);

} // namespace fss
