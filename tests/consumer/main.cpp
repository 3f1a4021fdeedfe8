// Reads a mesh with the installed FSS and prints its vertex and face counts.
#include <fss/error.h>
#include <fss/mesh_io.h>

#include <iostream>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: fss_consumer MESH\n";
        return 2;
    }
    try {
        const fss::Mesh mesh = fss::readMesh(argv[1]);
        std::cout << "vertices=" << mesh.number_of_vertices() << " faces=" << mesh.number_of_faces() << "\n";
    } catch (const fss::Error& e) {
        std::cerr << e.what() << "\n";
        return 1;
    }
    return 0;
}
