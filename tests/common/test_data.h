#pragma once
// Paths of test data and scratch files, configured by CMake (never hard-coded absolute paths).
#include <filesystem>
#include <string>

namespace fss::test {

/// Path of one of CGAL's sample meshes (extracted by scripts/setup.sh), e.g. meshPath("fandisk.off").
inline std::filesystem::path meshPath(const std::string& name) {
    return std::filesystem::path(FSS_TEST_MESH_DIR) / name;
}

/// A scratch file path inside the build tree, unique per test name.
inline std::filesystem::path tmpPath(const std::string& name) {
    return std::filesystem::path(FSS_TEST_TMP_DIR) / name;
}

#ifdef FSS_REMESH_EXE
/// The fss-remesh executable built with the tests (only when the apps are built).
inline std::filesystem::path remeshExe() {
    return std::filesystem::path(FSS_REMESH_EXE);
}
#endif

} // namespace fss::test
