// fss-remesh info MESH [--ref REF] [--json] [--no-self-intersections]
#include "command_line.h"
#include "commands.h"
#include "mesh_files.h"

#include "fss/face_groups.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>

namespace fss::cli {
namespace {

struct InfoOptions {
    std::string meshPath, refPath;
    const CLI::Option* ref = nullptr; // --ref, given when its count() > 0
    bool json = false, noSelf = false;
};

int runInfo(const InfoOptions& o) {
    const bool haveRef = o.ref->count() > 0;
    ReadReport report;
    const Mesh mesh = readInputMesh(o.meshPath, &report);
    Mesh reference;
    MetricsOptions options;
    options.selfIntersections = !o.noSelf;
    if (haveRef) {
        reference = readInputMesh(o.refPath);
        options.reference = &reference;
    }
    Metrics m = computeMetrics(mesh, options);
    const std::vector<GroupStats> groups = groupStats(mesh);

    if (o.json) {
        nlohmann::json j = nlohmann::json::parse(metricsToJson(m));
        j["file"] = o.meshPath;
        j["format"] = report.format;
        j["binary"] = report.binary;
        j["non_manifold_edges"] = report.soup.nonManifoldEdges;
        j["non_manifold_vertices"] = std::max(report.soup.nonManifoldVertices, m.nonManifoldVertices);
        j["soup_polygons"] = report.soup.polygons;
        j["soup_points"] = report.soup.points;
        j["repairs"] = report.repairs;
        if (haveRef) j["reference"] = o.refPath;
        nlohmann::json g = nlohmann::json::array();
        for (const GroupStats& s : groups)
            g.push_back({{"name", s.name}, {"faces", s.faces}, {"area", s.area}});
        j["groups"] = g;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << o.meshPath << " (" << report.format << (report.binary ? ", binary" : "") << ")\n";
        for (const std::string& r : report.repairs)
            std::cout << "  repaired: " << r << "\n";
        std::cout << "  non-manifold edges (file): " << report.soup.nonManifoldEdges << "\n"
                  << "  non-manifold vertices (file): " << report.soup.nonManifoldVertices << "\n";
        std::cout << metricsToText(m);
        for (const GroupStats& s : groups)
            std::cout << "  group " << (s.name.empty() ? std::string("(none)") : "'" + s.name + "'") << ": "
                      << s.faces << " faces, area " << s.area << "\n";
    }
    return 0;
}

} // namespace

Subcommand addInfo(CLI::App& app) {
    auto o = std::make_shared<InfoOptions>();
    CLI::App* p =
        addCommand(app, "info",
                   "Print quality metrics of MESH: counts, topology, valence regularity, triangle "
                   "shape (angles, radius ratio / gamma, aspect ratio, scaled Jacobian), its face groups "
                   "and, with --ref, distances to a reference surface.",
                   "example:\n  fss-remesh info fandisk.off --json");
    p->add_option("MESH", o->meshPath, "Mesh file (.off .obj .ply .stl .msh .vtu .vtp .vtk).")
        ->required()
        ->type_name("");
    o->ref = p->add_option("--ref", o->refPath,
                           "Reference mesh: adds Hausdorff distances both ways and the RMS distance.")
                 ->type_name("REF");
    p->add_flag("--json", o->json, "Print one JSON object (snake_case keys) instead of text.");
    p->add_flag("--no-self-intersections", o->noSelf,
                "Skip the self-intersection test (slow on huge meshes).");
    return {p, [o] { return runInfo(*o); }};
}

} // namespace fss::cli
