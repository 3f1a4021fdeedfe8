#include "mesh_files.h"

#include "command_line.h"

#include "fss/face_groups.h"
#ifdef FSS_HAVE_RENDER
#include "fss/render/fem_io.h"
#endif

namespace fss::cli {

void addOutputFileOptions(CLI::App& command, OutputFileOptions& options) {
#ifdef FSS_HAVE_RENDER
    command.add_flag("--feature-edges", options.featureEdges,
                     "FEM/VTK output: also write the sharp crease edges as line elements in a group "
                     "'feature_edges'.");
    addDouble(command, "--feature-angle", options.featureAngleDeg, true, "DEG",
              "Dihedral angle above which an edge is a crease for --feature-edges (default 45).");
    command
        .add_option("--msh-version", options.mshVersion,
                    "gmsh MSH version of a .msh output: 4.1 (default) or 2.2.")
        ->type_name("V")
        ->check(oneOf("--msh-version", {"4.1", "2.2"}));
    command
        .add_option("--max-nodes", options.maxNodes,
                    "Refuse to write a file with more nodes than N (a target solver's limit, e.g. a student "
                    "edition's); the format's own limit always applies.")
        ->type_name("N")
        ->check(CLI::PositiveNumber);
    command
        .add_option("--max-elements", options.maxElements,
                    "Refuse to write a file with more elements (faces + feature edges) than N.")
        ->type_name("N")
        ->check(CLI::PositiveNumber);
#else
    (void)command;
    (void)options;
#endif
}

std::string outputExtensions() {
#ifdef FSS_HAVE_RENDER
    return ".off .obj .ply .stl .msh .inp .bdf .unv .vtu .vtp";
#else
    return ".off .obj .ply .stl";
#endif
}

bool isOutputMeshFile(const std::string& path) {
#ifdef FSS_HAVE_RENDER
    return render::isWritableMeshFile(path);
#else
    return isSupportedMeshFile(path);
#endif
}

Mesh readInputMesh(const std::string& path, ReadReport* report) {
#ifdef FSS_HAVE_RENDER
    return render::readMeshFile(path, report);
#else
    return readMesh(path, report);
#endif
}

void checkOutputFileOptions(const std::string& path, const OutputFileOptions& options) {
#ifdef FSS_HAVE_RENDER
    if (options.featureEdges && !render::isFemMeshFile(path))
        throw UsageError("--feature-edges needs an output that holds line elements (.msh .inp .bdf .unv .vtu "
                         ".vtp), not " +
                         path + ".");
    if (!(options.featureAngleDeg > 0 && options.featureAngleDeg < 180))
        throw UsageError("The value of --feature-angle must lie between 0 and 180 degrees.");
#else
    (void)path;
    (void)options;
#endif
}

void writeOutputMesh(Mesh mesh, const Mesh* reference, const std::string& path,
                     const OutputFileOptions& options, const WriteOptions& coreOptions) {
    checkOutputFileOptions(path, options);
    if (reference && hasFaceGroups(*reference)) transferFaceGroups(*reference, mesh);
#ifdef FSS_HAVE_RENDER
    render::FemWriteOptions fem;
    fem.featureEdges = options.featureEdges;
    fem.featureAngleDeg = options.featureAngleDeg;
    fem.mshVersion = options.mshVersion == "2.2" ? 2.2 : 4.1;
    fem.maxNodes = options.maxNodes;
    fem.maxElements = options.maxElements;
    render::writeMeshFile(mesh, path, fem, coreOptions);
#else
    (void)options;
    writeMesh(mesh, path, coreOptions);
#endif
}

} // namespace fss::cli
