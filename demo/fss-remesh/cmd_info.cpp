// fss-remesh info MESH [--ref REF] [--json] [--no-self-intersections]
#include "args.h"
#include "commands.h"

#include "fss/mesh_io.h"
#include "fss/metrics.h"

#include <nlohmann/json.hpp>

#include <iostream>

namespace fss::cli {

int runInfo(const std::vector<std::string>& args) {
    std::string meshPath, refPath;
    bool haveRef = false, json = false, noSelf = false;
    ArgParser p("fss-remesh info", "Print quality metrics of MESH: counts, topology, valence regularity, triangle "
                                   "shape and, with --ref, distances to a reference surface.");
    p.positional("MESH", "Mesh file (.off .obj .ply .stl).", &meshPath);
    p.option("--ref", "REF", "Reference mesh: adds Hausdorff distances both ways and the RMS distance.", &refPath,
             &haveRef);
    p.flag("--json", "Print one JSON object (snake_case keys) instead of text.", &json);
    p.flag("--no-self-intersections", "Skip the self-intersection test (slow on huge meshes).", &noSelf);
    p.epilog("example:\n  fss-remesh info fandisk.off --json");
    if (!p.parse(args)) return 0;

    ReadReport report;
    const Mesh mesh = readMesh(meshPath, &report);
    Mesh reference;
    MetricsOptions options;
    options.selfIntersections = !noSelf;
    if (haveRef) {
        reference = readMesh(refPath);
        options.reference = &reference;
    }
    Metrics m = computeMetrics(mesh, options);

    if (json) {
        nlohmann::json j = nlohmann::json::parse(metricsToJson(m));
        j["file"] = meshPath;
        j["format"] = report.format;
        j["binary"] = report.binary;
        j["non_manifold_edges"] = report.soup.nonManifoldEdges;
        j["non_manifold_vertices"] = std::max(report.soup.nonManifoldVertices, m.nonManifoldVertices);
        j["soup_polygons"] = report.soup.polygons;
        j["soup_points"] = report.soup.points;
        j["repairs"] = report.repairs;
        if (haveRef) j["reference"] = refPath;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << meshPath << " (" << report.format << (report.binary ? ", binary" : "") << ")\n";
        for (const std::string& r : report.repairs) std::cout << "  repaired: " << r << "\n";
        std::cout << "  non-manifold edges (file): " << report.soup.nonManifoldEdges << "\n"
                  << "  non-manifold vertices (file): " << report.soup.nonManifoldVertices << "\n";
        std::cout << metricsToText(m);
    }
    return 0;
}

} // namespace fss::cli
