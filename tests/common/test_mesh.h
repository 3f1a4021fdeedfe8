#pragma once
// The meshes of CGAL's data set (fss::test::meshPath) read for a test; a file that cannot be read fails the
// test that asked for it and gives an empty mesh.
#include "fss/mesh.h"
#include "test_data.h"

#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include <gtest/gtest.h>

#include <string>

namespace fss::test {

inline fss::Mesh loadMesh(const std::string& name) {
    fss::Mesh m;
    if (!CGAL::IO::read_polygon_mesh(meshPath(name).string(), m)) ADD_FAILURE() << "cannot read " << name;
    return m;
}

} // namespace fss::test
