// Records the bundled example session examples/fandisk.session.json through the C++ API, so that the file
// is reproducible: seven regular scans of CGAL's fandisk from the six axis views and the iso view, then two
// fishbone scans from +x on its cylindrical features — the concave band under the top (its backbone runs
// along the cylinder's axis, the ribs around it) and the rounded end of the middle block. CPU renderer:
// the replay (`fss-remesh run`) is deterministic on every machine.
//
//   record_fandisk_session [MESH [OUT.session.json]]
//
// Run from the repository root with the default arguments, it rewrites examples/fandisk.session.json with
// the mesh path relative to it (../.cache/cgal-data/meshes/fandisk.off).
#include "fss/camera.h"
#include "fss/mesh_io.h"
#include "fss/session.h"
#include "fss/session_file.h"

#include <chrono>
#include <exception>
#include <iostream>
#include <string>

namespace {

fss::ScanStep viewStep(const fss::Mesh& mesh, fss::StandardView view, int resolution, int scanId) {
    fss::ScanStep step;
    step.params.camera = fss::Camera::standardView(view, fss::boundingBox(mesh), resolution, resolution);
    step.params.scan.scanId = scanId;
    return step;
}

fss::ScanStep fishboneStep(const fss::Mesh& mesh, fss::StandardView view, int resolution, int scanId,
                           Eigen::Vector2d seed, double h) {
    fss::ScanStep step = viewStep(mesh, view, resolution, scanId);
    step.fishbone = fss::FishboneParams{};
    step.fishbone->seed = seed;
    step.fishbone->direction = fss::PrincipalDirection::Min; // backbone along the cylinder's axis
    step.fishbone->spacing = h;
    // Traced on every pixel of the scan image (the finest alignment with the features; the automatic
    // sampling image would trace on 1/⌊h⌋ of the resolution, as fast as a regular scan).
    step.fishbone->samplingFactor = 1;
    return step;
}

} // namespace

int main(int argc, char** argv) {
    const std::string meshPath = argc > 1 ? argv[1] : ".cache/cgal-data/meshes/fandisk.off";
    const std::string outPath = argc > 2 ? argv[2] : "examples/fandisk.session.json";
    try {
        const auto start = std::chrono::steady_clock::now();
        fss::Session session(fss::readMesh(meshPath)); // CPU renderer (the SessionOptions default)
        const fss::Mesh& ref = session.reference();
        int id = 0;
        for (fss::StandardView view :
             {fss::StandardView::PosZ, fss::StandardView::NegZ, fss::StandardView::PosY,
              fss::StandardView::NegY, fss::StandardView::PosX, fss::StandardView::NegX,
              fss::StandardView::Iso}) {
            session.scan(viewStep(ref, view, 160, ++id));
            const fss::StitchReport& r = session.accept();
            std::cout << "regular scan " << id << " (" << fss::standardViewName(view) << "): +"
                      << r.facesAdded << " / -" << r.facesRemoved << " faces\n";
        }
        // Seeds in pixels of the 256x256 +x view: the concave band below the top, and the rounded end of the
        // middle block.
        const Eigen::Vector2d seeds[] = {{120.3, 75.2}, {110.3, 106.4}};
        for (const Eigen::Vector2d& seed : seeds) {
            const fss::ScanPreview& preview =
                session.scan(fishboneStep(ref, fss::StandardView::PosX, 256, ++id, seed, 2.0));
            const std::size_t ribs = preview.fishbone ? std::size_t(preview.fishbone->rows) : 0;
            const fss::StitchReport& r = session.accept();
            std::cout << "fishbone scan " << id << " (+x, seed " << seed.x() << "," << seed.y()
                      << "): " << ribs << " ribs, +" << r.facesAdded << " / -" << r.facesRemoved
                      << " faces\n";
        }
        fss::SessionFile file = fss::sessionFileFromSession(session, meshPath, "cpu");
        file.description =
            "FSS example: CGAL's fandisk remeshed by seven regular scans (six axis views and iso, "
            "160x160) and two fishbone scans from +x on its cylindrical features. Written by "
            "examples/record_fandisk_session.cpp; replay with 'fss-remesh run'.";
        fss::saveSessionFile(file, outPath);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::cout << "recorded " << session.events().size() << " events in " << seconds
                  << " s: " << session.current().number_of_vertices() << " vertices, "
                  << session.current().number_of_faces() << " faces; written to " << outPath << "\n";
    } catch (const std::exception& e) {
        std::cerr << "record_fandisk_session: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
