// Precompiled header of the GoogleTest programs (tests/core, tests/render, tests/cli): the third-party
// headers nearly every test includes and which cost most of a test's compile time (CGAL's Surface_mesh and
// kernel pull in much of Boost; parsing them takes ~10 s per translation unit). Built once, reused by every
// test (tests/CMakeLists.txt, FSS_TEST_PCH). Only third-party headers belong here: FSS's own headers stay
// out, so editing them does not rebuild the header, and every test still includes what it uses.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>
