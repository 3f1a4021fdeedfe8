#pragma once
// The helpers the FEM hand-off tests share (fem_io_test.cpp, fem_nastran_test.cpp): fandisk in two groups,
// scratch files, meshio as the independent reader and gmsh's own reader.
#include "run_process.h"
#include "test_data.h"

#include "fss/camera.h"
#include "fss/face_groups.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"
#include "fss/render/fem_io.h"
#include "fss/session.h"

#include <gmsh.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkMeshQuality.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using fss::FaceIndex;
using fss::Mesh;
using fss::test::meshPath;
using fss::test::tmpPath;

namespace fem_io_test_helpers {

/// fandisk with two groups split by the plane z = mid-height: "upper" and "lower".
inline Mesh twoGroupFandisk() {
    Mesh mesh = fss::readMesh(meshPath("fandisk.off"));
    const Eigen::AlignedBox3d box = fss::boundingBox(mesh);
    const double mid = box.center().z();
    fss::setGroupNames(mesh, {"upper", "lower"});
    auto group = mesh.property_map<FaceIndex, std::int32_t>(fss::props::faceGroup).first;
    for (FaceIndex f : mesh.faces()) {
        double z = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            z += mesh.point(v).z() / 3;
        group[f] = z > mid ? 0 : 1;
    }
    return mesh;
}

inline std::map<std::string, std::size_t> facesPerGroup(const Mesh& mesh) {
    std::map<std::string, std::size_t> out;
    for (const fss::GroupStats& s : fss::groupStats(mesh))
        out[s.name] = s.faces;
    return out;
}

inline fs::path scratch(const std::string& name) {
    fs::create_directories(tmpPath("fem_io"));
    return tmpPath("fem_io/" + name);
}

// ---- meshio, the independent reader ---------------------------------------------------------------------

/// meshio's view of a file: points, cells per type, group sizes by name (MSH physical names, INP element
/// sets, VTU/VTP cell data `group`, BDF PIDs as "pid_<n>").
constexpr const char* kMeshioScript = R"(
import json, sys, collections
import meshio
m = meshio.read(sys.argv[1])
out = {"points": m.points.tolist(), "cells": {}, "groups": {}}
for block in m.cells:
    out["cells"][block.type] = out["cells"].get(block.type, 0) + len(block.data)
groups = collections.Counter()
if "gmsh:physical" in m.cell_data:
    names = {(int(v[1]), int(v[0])): k for k, v in m.field_data.items()}
    dims = {"vertex": 0, "line": 1, "triangle": 2}
    for block, tags in zip(m.cells, m.cell_data["gmsh:physical"]):
        for t in tags:
            groups[names.get((dims[block.type], int(t)), "tag_%d" % t)] += 1
elif "nastran:ref" in m.cell_data:
    for tags in m.cell_data["nastran:ref"]:
        for t in tags:
            groups["pid_%d" % int(t)] += 1
elif "group" in m.cell_data:
    for tags in m.cell_data["group"]:
        for t in tags:
            groups["value_%d" % int(t)] += 1
elif m.cell_sets:
    for name, parts in m.cell_sets.items():
        groups[name] = sum(len(p) for p in parts)
out["groups"] = dict(groups)
out["names"] = {k: int(v[0]) for k, v in m.field_data.items()}
print(json.dumps(out))
)";

inline nlohmann::json meshio(const fs::path& file) {
    const fs::path script = scratch("meshio_read.py");
    {
        std::ofstream s(script);
        s << kMeshioScript;
    }
    const auto r =
        fss::test::runProcess(FSS_SYSTEM_PYTHON, {script.string(), file.string()}, tmpPath("fem_io"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    if (r.exitCode != 0) return {};
    return nlohmann::json::parse(r.out);
}

/// Every point of \p mesh (in iteration order, as the writers number them) equals meshio's within \p rel of
/// the bounding box diagonal.
inline void expectSamePoints(const Mesh& mesh, const nlohmann::json& points, double rel) {
    ASSERT_EQ(points.size(), mesh.number_of_vertices());
    const double diag = fss::boundingBox(mesh).diagonal().norm();
    double worst = 0;
    std::size_t i = 0;
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        for (int k = 0; k < 3; ++k)
            worst = std::max(worst, std::abs(points[i][std::size_t(k)].get<double>() - p[k]));
        ++i;
    }
    EXPECT_LE(worst / diag, rel);
}

// ---- gmsh, the library's own reader ----------------------------------------------------------------------

struct GmshView {
    std::size_t nodes = 0, triangles = 0, lines = 0;
    std::map<std::size_t, std::array<double, 3>> points; // node tag -> coordinates
    std::map<std::string, std::size_t> groups;           // physical name -> elements
    std::map<std::pair<int, int>, std::size_t> entities; // (dim, elementary tag) -> elements
};

inline GmshView readWithGmsh(const fs::path& file) {
    GmshView view;
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::open(file.string());
    std::vector<std::size_t> tags;
    std::vector<double> coords, parametric;
    gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, false, false);
    view.nodes = tags.size();
    for (std::size_t i = 0; i < tags.size(); ++i)
        view.points[tags[i]] = {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> elementTags, nodeTags;
    gmsh::model::mesh::getElements(types, elementTags, nodeTags);
    for (std::size_t k = 0; k < types.size(); ++k) {
        if (types[k] == 2) view.triangles += elementTags[k].size();
        if (types[k] == 1) view.lines += elementTags[k].size();
    }
    gmsh::vectorpair entities;
    gmsh::model::getEntities(entities);
    for (const auto& [dim, tag] : entities) {
        std::vector<int> t;
        std::vector<std::vector<std::size_t>> et, nt;
        gmsh::model::mesh::getElements(t, et, nt, dim, tag);
        for (const auto& block : et)
            view.entities[{dim, tag}] += block.size();
    }
    gmsh::vectorpair physicals;
    gmsh::model::getPhysicalGroups(physicals);
    for (const auto& [dim, tag] : physicals) {
        std::string name;
        gmsh::model::getPhysicalName(dim, tag, name);
        if (name.empty()) name = "pid_" + std::to_string(tag);
        std::vector<int> entities;
        gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
        for (int e : entities) {
            std::vector<int> t;
            std::vector<std::vector<std::size_t>> et, nt;
            gmsh::model::mesh::getElements(t, et, nt, dim, e);
            for (const auto& block : et)
                view.groups[name] += block.size();
        }
    }
    gmsh::finalize();
    return view;
}

/// Reads the names of PIDs from BDF comment lines as each convention's readers do (OpenFOAM's
/// NASsurfaceFormat for HyperMesh's and ANSA's, pyNastran-based readers for Femap's and Patran's): the name
/// must come out equal in every convention, each line before the property card of its PID.
inline void expectNastranNameComments(const std::string& text, const std::map<int, std::string>& expected) {
    std::map<std::string, std::map<int, std::string>> found; // convention -> pid -> name
    std::istringstream in(text);
    std::string line, pendingFemap, pendingPatran;
    std::map<int, bool> hasCard;
    while (std::getline(in, line)) {
        if (line.rfind("$HMNAME COMP", 0) == 0 || line.rfind("$HMNAME PROP", 0) == 0) {
            // A 32-character record ("$HMNAME COMP" + the id right-aligned in 20), then the quoted name.
            ASSERT_GE(line.size(), 34u) << line;
            EXPECT_EQ(line[32], '"') << line;
            EXPECT_EQ(line.back(), '"') << line;
            const int id = std::stoi(line.substr(12, 20));
            found[line.substr(0, 12)][id] = line.substr(33, line.size() - 34);
        } else if (line.rfind("$ANSA_NAME_COMMENT;", 0) == 0) {
            std::vector<std::string> args;
            std::istringstream fields(line);
            for (std::string a; std::getline(fields, a, ';');)
                args.push_back(a);
            ASSERT_GE(args.size(), 5u) << line;
            EXPECT_TRUE(args[2] == "PSHELL" || args[2] == "PROD") << line;
            found["ANSA"][std::stoi(args[1])] = args[3];
        } else if (line.rfind("$ Femap Property ", 0) == 0) {
            pendingFemap = line;
        } else if (line.rfind("$ Elements and Element Properties for region : ", 0) == 0) {
            pendingPatran =
                line.substr(std::string("$ Elements and Element Properties for region : ").size());
        } else if (line.rfind("PSHELL", 0) == 0 || line.rfind("PROD", 0) == 0) {
            const int pid = std::stoi(line.substr(8));
            hasCard[pid] = true;
            // Femap: "$ Femap Property <pid> : <name>" right before the card.
            const std::size_t colon = pendingFemap.find(" : ");
            ASSERT_NE(colon, std::string::npos) << "no Femap comment before " << line;
            EXPECT_EQ(std::stoi(pendingFemap.substr(17, colon - 17)), pid);
            found["Femap"][pid] = pendingFemap.substr(colon + 3);
            found["Patran"][pid] = pendingPatran;
            pendingFemap.clear();
            pendingPatran.clear();
        }
    }
    for (const char* convention : {"$HMNAME COMP", "$HMNAME PROP", "ANSA", "Femap", "Patran"})
        EXPECT_EQ(found[convention], expected) << convention;
    for (const auto& [pid, name] : expected)
        EXPECT_TRUE(hasCard[pid]) << "no property card for PID " << pid << " (" << name << ")";
}

} // namespace fem_io_test_helpers
