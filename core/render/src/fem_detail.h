#pragma once
// Internal (not installed): what the FEM/VTK writers and readers of fem_io.h share. fem_io.cpp flattens the
// mesh into a FemMesh, dispatches by extension and writes INP and BDF itself; fem_gmsh.cpp holds everything
// that talks to gmsh (MSH, UNV), fem_vtk.cpp everything that talks to VTK (VTU, VTP, legacy VTK).
#include "fss/render/fem_io.h"

#include <array>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace fss::render::detail {

/// The extension of \p path in lower case ("" when none), for choosing a format.
inline std::string lowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

/// The mesh as FEM files hold it: nodes, triangles with a group each, optional feature edges.
struct FemMesh {
    std::vector<std::array<double, 3>> nodes;
    std::vector<std::array<std::size_t, 3>> triangles; ///< 0-based node indices
    std::vector<std::int32_t> group;                   ///< per triangle, index into groupNames (never -1)
    std::vector<std::string> groupNames;               ///< non-empty groups only, in table order
    std::vector<std::array<std::size_t, 2>> edges;     ///< feature edges (0-based node indices)
    std::string edgeGroup = "feature_edges";           ///< the feature edges' group name
};

/// Writes into a temporary file next to the target (same extension, so libraries that choose the format
/// by extension see the right one) and renames it over the target on commit(); removed otherwise.
class TempFile {
public:
    explicit TempFile(const std::filesystem::path& target);
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;
    ~TempFile();
    const std::filesystem::path& path() const { return temp_; }
    void commit();

private:
    std::filesystem::path target_, temp_;
    bool committed_ = false;
};

[[noreturn]] void failWrite(const std::filesystem::path& path, const std::string& problem);
[[noreturn]] void failRead(const std::filesystem::path& path, const std::string& problem);

/// .msh (version options.mshVersion) and .unv through gmsh's API.
void writeGmsh(const FemMesh& mesh, const std::filesystem::path& path, const FemWriteOptions& options);
/// .msh through gmsh's API: surface elements and their physical groups.
PolygonSoup readGmsh(const std::filesystem::path& path);

/// .vtu and .vtp through VTK's XML writers.
void writeVtk(const FemMesh& mesh, const std::filesystem::path& path, const FemWriteOptions& options);
/// .vtu .vtp (XML) and .vtk (legacy) through VTK's readers.
PolygonSoup readVtk(const std::filesystem::path& path);

} // namespace fss::render::detail
