#pragma once
// Paths of test data and scratch files, configured by CMake (never hard-coded absolute paths).
#include <cstdlib>
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

/// Whether the opt-in long measurements run (FSS_LONG_TESTS=1): tables over many meshes and views that take
/// minutes; CI runs without them.
inline bool longTests() {
    const char* env = std::getenv("FSS_LONG_TESTS");
    return env && std::string(env) == "1";
}

#ifdef FSS_REMESH_EXE
/// The fss-remesh executable built with the tests (only when the apps are built).
inline std::filesystem::path remeshExe() {
    return std::filesystem::path(FSS_REMESH_EXE);
}
#endif

} // namespace fss::test
