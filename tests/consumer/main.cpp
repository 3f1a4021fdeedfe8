// Reads a mesh with the installed FSS and prints its vertex and face counts, the SHA-256 of the file
// (libcrypto, linked through FSS's package) and its self-intersecting face pairs (CGAL with TBB).
#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/metrics.h>
#include <fss/sha256.h>

#include <iostream>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: fss_consumer MESH\n";
        return 2;
    }
    try {
        const fss::Mesh mesh = fss::readMesh(argv[1]);
        std::cout << "vertices=" << mesh.number_of_vertices() << " faces=" << mesh.number_of_faces() << "\n";
        std::cout << "sha256=" << fss::sha256OfFile(argv[1]) << "\n";
        std::cout << "self_intersections=" << fss::computeMetrics(mesh).selfIntersections.value_or(999)
                  << "\n";
    } catch (const fss::Error& e) {
        std::cerr << e.what() << "\n";
        return 1;
    }
    return 0;
}
