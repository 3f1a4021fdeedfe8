#pragma once
// The mesh files of fss-remesh: every format FSS reads and writes. With FSS::render these include the FEM
// and VTK formats of fss/render/fem_io.h (.msh .inp .bdf .unv .vtu .vtp, reading .msh .vtu .vtp .vtk);
// without it, fss::readMesh / fss::writeMesh's (.off .obj .ply .stl). Named face groups are carried from the
// input to the output (fss/face_groups.h: every output face takes the group of the nearest input face).
#include "fss/mesh.h"
#include "fss/mesh_io.h"

#include <CLI/CLI.hpp>

#include <cstddef>
#include <string>

namespace fss::cli {

/// Options of the output file (--feature-edges, --feature-angle, --msh-version, --max-nodes,
/// --max-elements).
struct OutputFileOptions {
    bool featureEdges = false;
    double featureAngleDeg = 45;
    std::string mshVersion = "4.1";
    std::size_t maxNodes = 0;    ///< 0: the format's own limit only
    std::size_t maxElements = 0; ///< 0: the format's own limit only
};

/// Adds --feature-edges, --feature-angle, --msh-version, --max-nodes and --max-elements to \p command.
void addOutputFileOptions(CLI::App& command, OutputFileOptions& options);

/// The extensions the output may have, for messages: ".off .obj .ply .stl ...".
std::string outputExtensions();
/// Whether \p path has an extension fss-remesh can write.
bool isOutputMeshFile(const std::string& path);

/// Reads \p path in any format FSS reads.
Mesh readInputMesh(const std::string& path, ReadReport* report = nullptr);

/// \throw UsageError when --feature-edges is given for a format that cannot hold line elements (.off .obj
/// .ply .stl). Called before the work starts, so that a wrong command line costs nothing.
void checkOutputFileOptions(const std::string& path, const OutputFileOptions& options);

/// Writes \p mesh to \p path by its extension. When \p reference has face groups they are first carried to
/// the mesh (fss::transferFaceGroups). \throw UsageError when --feature-edges is given for a format that
/// cannot hold line elements (.off .obj .ply .stl); IoError as the writers throw.
void writeOutputMesh(Mesh mesh, const Mesh* reference, const std::string& path,
                     const OutputFileOptions& options, const WriteOptions& coreOptions = {});

} // namespace fss::cli
