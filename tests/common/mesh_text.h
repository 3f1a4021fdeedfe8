#pragma once
// The exact text of a mesh, for tests that assert two computations gave the same mesh byte for byte (thread
// counts, allocation histories): every vertex position with 17 significant digits, then every face's corners.
#include "fss/mesh.h"

#include <cstdio>
#include <string>

namespace fss::test {

inline std::string exactMeshText(const fss::Mesh& m) {
    std::string out;
    char buffer[96];
    for (fss::VertexIndex v : m.vertices()) {
        const auto& p = m.point(v);
        std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
        out += buffer;
    }
    for (fss::FaceIndex f : m.faces())
        for (fss::VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m))
            out += std::to_string(v.idx()) + " ";
    return out;
}

} // namespace fss::test
