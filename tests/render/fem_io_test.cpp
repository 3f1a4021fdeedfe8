// The FEM hand-off (fss/render/fem_io.h, fss/face_groups.h, issue 22), checked against the field's own
// readers: every written file is read back by gmsh's API (MSH, UNV, BDF) or VTK's readers (VTU, VTP, legacy
// VTK) and by Debian's meshio (/usr/bin/python3) as an independent reader: node and element counts,
// coordinates, group names and sizes. The triangle quality measures of fss::computeMetrics are compared with
// vtkMeshQuality's on CGAL's meshes, and groups carried through a remeshing session keep their areas.
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

namespace {

/// fandisk with two groups split by the plane z = mid-height: "upper" and "lower".
Mesh twoGroupFandisk() {
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

std::map<std::string, std::size_t> facesPerGroup(const Mesh& mesh) {
    std::map<std::string, std::size_t> out;
    for (const fss::GroupStats& s : fss::groupStats(mesh))
        out[s.name] = s.faces;
    return out;
}

fs::path scratch(const std::string& name) {
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

nlohmann::json meshio(const fs::path& file) {
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
void expectSamePoints(const Mesh& mesh, const nlohmann::json& points, double rel) {
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

GmshView readWithGmsh(const fs::path& file) {
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

// ---- Nastran names: the comment conventions of HyperMesh, ANSA, Femap and Patran -------------------------

/// Reads the names of PIDs from BDF comment lines as each convention's readers do (OpenFOAM's
/// NASsurfaceFormat for HyperMesh's and ANSA's, pyNastran-based readers for Femap's and Patran's): the name
/// must come out equal in every convention, each line before the property card of its PID.
void expectNastranNameComments(const std::string& text, const std::map<int, std::string>& expected) {
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

TEST(NastranNames, ExactConventionSyntax) {
    Mesh mesh = twoGroupFandisk();
    fss::setGroupNames(mesh, {"Upper skin-2.a", "lower (inner)"});
    const fs::path file = scratch("names.bdf");
    fss::render::writeMeshFile(mesh, file);
    const std::string text = fss::test::slurp(file);
    // The exact lines, byte for byte.
    for (const char* line : {"$HMNAME COMP                   1\"Upper skin-2.a\"\n",
                             "$HMNAME PROP                   2\"lower (inner)\"\n",
                             "$ANSA_NAME_COMMENT;1;PSHELL;Upper skin-2.a;;NO;NO;NO;NO;\n",
                             "$ Femap Property 2 : lower (inner)\n",
                             "$ Elements and Element Properties for region : Upper skin-2.a\nPSHELL  1\n"})
        EXPECT_NE(text.find(line), std::string::npos) << line;
    expectNastranNameComments(text, {{1, "Upper skin-2.a"}, {2, "lower (inner)"}});
    // meshio still reads the file (the comments and PSHELL cards are skipped) with the PIDs.
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    const auto expected = facesPerGroup(mesh);
    EXPECT_EQ(m.at("groups").at("pid_1").get<std::size_t>(), expected.at("Upper skin-2.a"));
    EXPECT_EQ(m.at("groups").at("pid_2").get<std::size_t>(), expected.at("lower (inner)"));
    // Names the comment lines cannot hold: one sentence, no file.
    for (const char* bad : {"say \"hi\"", "a;b", "caf\xc3\xa9", "tab\there"}) {
        fss::setGroupNames(mesh, {bad, "lower"});
        const fs::path refused = scratch("bad_names.bdf");
        fs::remove(refused);
        try {
            fss::render::writeMeshFile(mesh, refused);
            ADD_FAILURE() << "written: " << bad;
        } catch (const fss::IoError& e) {
            EXPECT_NE(std::string(e.what()).find("Nastran BDF cannot hold the group name"), std::string::npos)
                << e.what();
        }
        EXPECT_FALSE(fs::exists(refused));
    }
}

// ---- Nastran reals: the shortest forms of a 16-character field ----------------------------------------

/// meshio's parser of Nastran reals (nastran._nastran._nastran_string_to_float), one value per line.
std::vector<double> meshioNastranReals(const std::vector<std::string>& texts) {
    const fs::path input = scratch("reals.txt"), script = scratch("meshio_reals.py");
    {
        std::ofstream f(input);
        for (const std::string& t : texts)
            f << t << "\n";
        std::ofstream(script)
            << "import sys\nfrom meshio.nastran._nastran import _nastran_string_to_float as p\n"
               "for line in open(sys.argv[1]):\n    print(repr(p(line.rstrip('\\n'))))\n";
    }
    const auto r =
        fss::test::runProcess(FSS_SYSTEM_PYTHON, {script.string(), input.string()}, tmpPath("fem_io"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    std::vector<double> out;
    std::istringstream lines(r.out);
    for (std::string l; std::getline(lines, l);) {
        double v = std::numeric_limits<double>::quiet_NaN(); // std::stod refuses subnormals
        std::from_chars(l.data(), l.data() + l.size(), v);
        out.push_back(v);
    }
    return out;
}

/// The significant digits a 16-character field holds at least for \p v: 14 (13 if negative) in the fixed
/// form for 0.1 <= |v| < 1e14; else 13 (12) with a one-digit exponent, one fewer per further exponent digit.
int guaranteedDigits(double v) {
    const int sign = v < 0 ? 1 : 0;
    const double a = std::abs(v);
    if (a >= 0.1 && a < 1e14) return 14 - sign;
    const int e = int(std::floor(std::log10(a)));
    return 13 - sign - (int(std::to_string(std::abs(e)).size()) - 1);
}

TEST(NastranReal, EdgeCasesReadBackByMeshio) {
    std::vector<double> values = {0.0,
                                  -0.0,
                                  1.0,
                                  -1.0,
                                  0.5,
                                  0.1,
                                  -0.1,
                                  7.0,
                                  1e-300,
                                  -1e-300,
                                  1e300,
                                  -1e300,
                                  std::numeric_limits<double>::max(),
                                  -std::numeric_limits<double>::max(),
                                  std::numeric_limits<double>::min(),
                                  5e-324, // smallest normal, denormal
                                  9.9999999999999995,
                                  99999.999999999999,
                                  0.099999999999999999,
                                  9.99999999999999e-10,
                                  9.999999999999999e9,
                                  9.999999999999999e99,
                                  -9.9999999999999995e-100,
                                  999999999999999.9,
                                  1e15,
                                  123456789012345678.0,
                                  0.000123456789012345,
                                  -1.23456789012345e-5,
                                  3.14159265358979,
                                  -2.718281828459045,
                                  1.2345678901234567e-10,
                                  1.2345678901234567e100,
                                  -1.5e-100,
                                  12345678901.234567};
    // Random values over all magnitudes and both signs.
    std::mt19937_64 rng(22);
    std::uniform_real_distribution<double> mantissa(1, 10);
    std::uniform_int_distribution<int> exponent(-307, 307);
    for (int i = 0; i < 2000; ++i)
        values.push_back((i % 2 ? -1 : 1) * mantissa(rng) * std::pow(10.0, exponent(rng)));
    std::vector<std::string> texts;
    for (double v : values) {
        const std::string t = fss::render::nastranReal(v);
        EXPECT_LE(t.size(), 16u) << v << " -> " << t;
        EXPECT_NE(t.find('.'), std::string::npos) << v << " -> " << t; // a Nastran real has a point
        EXPECT_EQ(t.find_first_of("Ee "), std::string::npos) << v << " -> " << t;
        texts.push_back(t);
    }
    EXPECT_EQ(texts[0], "0.");
    EXPECT_EQ(texts[1], "0.");
    EXPECT_EQ(texts[2], "1.");
    EXPECT_EQ(texts[4], "0.5");
    EXPECT_EQ(texts[8], "1.-300");
    EXPECT_EQ(texts[10], "1.+300");
    EXPECT_EQ(texts[16], "10.");              // 9.9999999999999995 rounds up to the next power of ten
    EXPECT_EQ(texts[17], "100000.");          // 99999.999999999999 likewise
    EXPECT_EQ(texts[12], "1.7976931348+308"); // truncated: rounding up would overflow
    EXPECT_EQ(texts[27], "-1.23456789012-5"); // exponent: 12 digits (fixed would hold 10)
    EXPECT_EQ(texts[30], ".1234567890123-9"); // the point before the digits: a one-digit exponent
    EXPECT_EQ(texts[31], "12.3456789012+99"); // after two digits: a two-digit exponent
    EXPECT_EQ(texts[33], "12345678901.2346"); // fixed: 15 digits
    const std::vector<double> back = meshioNastranReals(texts);
    ASSERT_EQ(back.size(), values.size());
    double worstFixed = 0, worstExponent = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        const double v = values[i];
        if (v == 0) {
            EXPECT_EQ(back[i], 0.0);
            continue;
        }
        if (std::abs(v) < std::numeric_limits<double>::min()) { // denormal: precision is absolute
            EXPECT_NEAR(back[i], v, 1e-323) << texts[i];
            continue;
        }
        const double rel = std::abs(back[i] - v) / std::abs(v);
        EXPECT_LE(rel, 5.0001 * std::pow(10.0, -guaranteedDigits(v))) << v << " -> " << texts[i];
        double& worst = std::abs(v) >= 0.1 && std::abs(v) < 1e14 ? worstFixed : worstExponent;
        worst = std::max(worst, rel);
    }
    std::printf(
        "[ measure  ] Nastran reals read back by meshio: worst relative error %.3g for 0.1 <= |v| < 1e14, "
        "%.3g elsewhere (%zu values)\n",
        worstFixed, worstExponent, values.size());
}

// ---- format limits ----------------------------------------------------------------------------------------

TEST(FemLimits, EachFormatsLimitIsCheckedByCount) {
    using fss::render::checkFormatLimits;
    using fss::render::formatLimits;
    struct Case {
        const char* file;
        double msh;
        bool binary;
        std::size_t nodes, elements, groups;
    };
    constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    for (const Case& c :
         {Case{"a.bdf", 4.1, false, 99'999'999, 99'999'999, 99'999'999},
          Case{"a.NAS", 4.1, false, 99'999'999, 99'999'999, 99'999'999},
          Case{"a.inp", 4.1, false, 999'999'999, 999'999'999, none},
          Case{"a.msh", 2.2, false, 2'147'483'647, 2'147'483'647, 2'147'483'647},
          Case{"a.unv", 4.1, false, 2'147'483'647, 2'147'483'647, 2'147'483'647},
          Case{"a.ply", 4.1, false, 2'147'483'647, none, none},
          Case{"a.stl", 4.1, true, none, 4'294'967'295, none}, Case{"a.msh", 4.1, false, none, none, none},
          Case{"a.stl", 4.1, false, none, none, none}, Case{"a.vtu", 4.1, false, none, none, none},
          Case{"a.vtp", 4.1, false, none, none, none}, Case{"a.obj", 4.1, false, none, none, none},
          Case{"a.off", 4.1, false, none, none, none}}) {
        SCOPED_TRACE(std::string(c.file) + " msh " + std::to_string(c.msh));
        fss::render::FemWriteOptions fem;
        fem.mshVersion = c.msh;
        fss::WriteOptions core;
        core.binary = c.binary;
        const auto l = formatLimits(c.file, fem, core);
        EXPECT_EQ(l.nodes, c.nodes);
        EXPECT_EQ(l.elements, c.elements);
        EXPECT_EQ(l.groups, c.groups);
        EXPECT_NO_THROW(checkFormatLimits(c.file, l.nodes, l.elements, l.groups, fem, core));
        const std::pair<std::size_t, const char*> over[] = {{0, "nodes"}, {1, "elements"}, {2, "groups"}};
        for (const auto& [which, what] : over) {
            std::size_t n[3] = {1, 1, 1};
            const std::size_t limit = which == 0 ? l.nodes : which == 1 ? l.elements : l.groups;
            if (limit == none) continue;
            n[which] = limit + 1;
            try {
                checkFormatLimits(c.file, n[0], n[1], n[2], fem, core);
                ADD_FAILURE() << what << " over the limit accepted";
            } catch (const fss::IoError& e) {
                const std::string m = e.what();
                EXPECT_NE(m.find(std::to_string(limit + 1) + " " + what + ", more than the " +
                                 std::to_string(limit) + " that a "),
                          std::string::npos)
                    << m;
                // One sentence naming the file: "Cannot write mesh file 'a.bdf': <problem>."
                EXPECT_EQ(m.rfind(std::string("Cannot write mesh file '") + c.file + "': ", 0), 0u) << m;
                EXPECT_EQ(m.find(". "), std::string::npos) << m;
                EXPECT_EQ(m.back(), '.') << m;
            }
        }
    }
}

// A limit lowered through FemWriteOptions (a student edition's, say) exercises the writers' refusal on a
// real mesh: one sentence, no file, no temporary file, an existing file unchanged.
TEST(FemLimits, RefusedMeshLeavesNoFile) {
    const Mesh mesh = twoGroupFandisk();
    const std::size_t nodes = mesh.number_of_vertices(), faces = mesh.number_of_faces();
    for (const char* ext : {"bdf", "inp", "msh", "unv", "vtu", "vtp", "ply", "stl", "obj", "off"}) {
        SCOPED_TRACE(ext);
        const fs::path file = scratch(std::string("limited.") + ext);
        for (int which = 0; which < 2; ++which) {
            fss::render::FemWriteOptions options;
            (which == 0 ? options.maxNodes : options.maxElements) = (which == 0 ? nodes : faces) - 1;
            fs::remove(file);
            try {
                fss::render::writeMeshFile(mesh, file, options);
                ADD_FAILURE() << "written over the limit";
            } catch (const fss::IoError& e) {
                EXPECT_NE(std::string(e.what()).find("asked for as the limit"), std::string::npos)
                    << e.what();
            }
            EXPECT_FALSE(fs::exists(file));
            std::ofstream(file) << "keep me\n";
            EXPECT_THROW(fss::render::writeMeshFile(mesh, file, options), fss::IoError);
            EXPECT_EQ(fss::test::slurp(file), "keep me\n");
        }
        // At the limit: written.
        fss::render::FemWriteOptions exact;
        exact.maxNodes = nodes;
        exact.maxElements = faces;
        fs::remove(file);
        EXPECT_NO_THROW(fss::render::writeMeshFile(mesh, file, exact));
        EXPECT_TRUE(fs::exists(file));
    }
    for (const auto& entry : fs::directory_iterator(tmpPath("fem_io")))
        EXPECT_EQ(entry.path().filename().string().find(".fss-tmp-"), std::string::npos) << entry.path();
}

// fandisk's coordinates have 4 decimals; rotated, scaled and moved they use all 17 digits of a double: the
// BDF's 16-character reals are read back by meshio and by gmsh within 1e-12 of the bounding box diagonal
// and of the largest coordinate.
TEST(NastranReal, FullPrecisionCoordinatesRoundTripAt1e12) {
    Mesh mesh = fss::readMesh(meshPath("fandisk.off"));
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix());
    const Eigen::Vector3d offset(1000.123456789, -2000.987654321, 3.14159265358979);
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        const Eigen::Vector3d q = 123.456789 * rotation * Eigen::Vector3d(p.x(), p.y(), p.z()) + offset;
        mesh.point(v) = fss::Point3(q.x(), q.y(), q.z());
    }
    const fs::path file = scratch("full_precision.bdf");
    fss::render::writeMeshFile(mesh, file);
    const double diag = fss::boundingBox(mesh).diagonal().norm();
    double largest = 0;
    for (auto v : mesh.vertices())
        for (int k = 0; k < 3; ++k)
            largest = std::max(largest, std::abs(mesh.point(v)[k]));
    auto compare = [&](const char* reader, auto pointOf) {
        double worst = 0, worstPerValue = 0;
        std::size_t i = 0;
        for (auto v : mesh.vertices()) {
            const std::array<double, 3> q = pointOf(i++);
            for (int k = 0; k < 3; ++k) {
                const double x = mesh.point(v)[k], e = std::abs(q[std::size_t(k)] - x);
                worst = std::max(worst, e);
                if (x != 0) worstPerValue = std::max(worstPerValue, e / std::abs(x));
            }
        }
        EXPECT_LE(worst / diag, 1e-12) << reader;
        EXPECT_LE(worst / largest, 1e-12) << reader;
        std::printf(
            "[ measure  ] BDF coordinates read by %s: worst error %.3g of the bounding box diagonal, %.3g "
            "of the largest coordinate, %.3g of the value itself\n",
            reader, worst / diag, worst / largest, worstPerValue);
    };
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    const auto& points = m.at("points");
    ASSERT_EQ(points.size(), mesh.number_of_vertices());
    compare("meshio", [&](std::size_t i) {
        return std::array<double, 3>{points[i][0].get<double>(), points[i][1].get<double>(),
                                     points[i][2].get<double>()};
    });
    const GmshView g = readWithGmsh(file);
    ASSERT_EQ(g.points.size(), mesh.number_of_vertices());
    compare("gmsh", [&](std::size_t i) { return g.points.at(i + 1); });
}

class FemRoundTrip : public ::testing::TestWithParam<std::string> {};

// Each format: written by FSS, read by the library's own reader and by meshio; counts, coordinates, group
// names and sizes equal.
TEST_P(FemRoundTrip, LibraryReadersAndMeshioSeeTheSameMesh) {
    const std::string ext = GetParam();
    const bool msh22 = ext == "msh22";
    const fs::path file = scratch("fandisk_groups." + (msh22 ? std::string("msh") : ext));
    const Mesh mesh = twoGroupFandisk();
    fss::render::FemWriteOptions options;
    options.featureEdges = true;
    options.featureAngleDeg = 45;
    if (msh22) options.mshVersion = 2.2;
    fss::render::writeMeshFile(mesh, file, options);
    const std::size_t edges = fss::sharpFeatureEdges(mesh, 45).size();
    ASSERT_GT(edges, 100u); // fandisk's creases
    const auto expected = facesPerGroup(mesh);
    const std::size_t faces = mesh.number_of_faces(), nodes = mesh.number_of_vertices();

    // The library's own reader.
    if (ext == "msh" || msh22 || ext == "unv" || ext == "bdf") {
        const GmshView g = readWithGmsh(file);
        EXPECT_EQ(g.nodes, nodes);
        EXPECT_EQ(g.triangles, faces);
        EXPECT_EQ(g.lines, edges);
        // gmsh's own parser of the coordinates (for BDF: of the Nastran reals without 'E').
        const double diag = fss::boundingBox(mesh).diagonal().norm();
        double worst = 0;
        std::size_t tag = 0;
        for (auto v : mesh.vertices()) {
            const auto& q = g.points.at(++tag);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(q[std::size_t(k)] - mesh.point(v)[k]));
        }
        EXPECT_LE(worst / diag, 1e-12) << ext;
        if (ext != "bdf") { // BDF holds PIDs, not names
            EXPECT_EQ(g.groups.at("upper"), expected.at("upper"));
            EXPECT_EQ(g.groups.at("lower"), expected.at("lower"));
            EXPECT_EQ(g.groups.at("feature_edges"), edges);
        } else { // gmsh makes each PID an elementary entity
            EXPECT_EQ(g.entities.at({2, 1}), expected.at("upper"));
            EXPECT_EQ(g.entities.at({2, 2}), expected.at("lower"));
            EXPECT_EQ(g.entities.at({1, 3}), edges);
        }
    }
    if (ext == "msh" || msh22 || ext == "vtu" || ext == "vtp") {
        // FSS's own reader (gmsh / VTK underneath) gives back the mesh with its groups.
        fss::ReadReport report;
        const Mesh back = fss::render::readMeshFile(file, &report);
        EXPECT_EQ(back.number_of_vertices(), nodes);
        EXPECT_EQ(back.number_of_faces(), faces);
        EXPECT_EQ(report.groups, 2u);
        EXPECT_EQ(facesPerGroup(back), expected);
        EXPECT_TRUE(report.repairs.empty());
    }
    if (ext == "vtu" || ext == "vtp") {
        vtkSmartPointer<vtkDataSet> data;
        if (ext == "vtu") {
            vtkNew<vtkXMLUnstructuredGridReader> r;
            r->SetFileName(file.c_str());
            r->Update();
            data = r->GetOutput();
        } else {
            vtkNew<vtkXMLPolyDataReader> r;
            r->SetFileName(file.c_str());
            r->Update();
            data = r->GetOutput();
        }
        ASSERT_NE(data.Get(), nullptr);
        EXPECT_EQ(std::size_t(data->GetNumberOfPoints()), nodes);
        EXPECT_EQ(std::size_t(data->GetNumberOfCells()), faces + edges);
        for (const auto& [name, value] : {std::pair<const char*, double>{"group:upper", 0},
                                          {"group:lower", 1},
                                          {"group:feature_edges", 2}}) {
            vtkDataArray* a = data->GetFieldData()->GetArray(name);
            ASSERT_NE(a, nullptr) << name;
            EXPECT_EQ(a->GetComponent(0, 0), value) << name;
        }
        std::size_t i = 0;
        double worst = 0;
        for (auto v : mesh.vertices()) {
            double p[3];
            data->GetPoint(vtkIdType(i++), p);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(p[k] - mesh.point(v)[k]));
        }
        EXPECT_EQ(worst, 0.0); // doubles, binary
    }

    // meshio (gmsh cannot read INP; meshio 5.0 reads neither UNV nor VTP).
    if (ext == "unv" || ext == "vtp") return;
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    expectSamePoints(mesh, m.at("points"), ext == "bdf" ? 1e-12 : 1e-15);
    EXPECT_EQ(m.at("cells").at("triangle").get<std::size_t>(), faces);
    EXPECT_EQ(m.at("cells").at("line").get<std::size_t>(), edges);
    const auto& groups = m.at("groups");
    if (ext == "bdf") {
        EXPECT_EQ(groups.at("pid_1").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("pid_2").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("pid_3").get<std::size_t>(), edges);
        expectNastranNameComments(fss::test::slurp(file), {{1, "upper"}, {2, "lower"}, {3, "feature_edges"}});
    } else if (ext == "vtu") {
        EXPECT_EQ(m.at("names").at("group:upper").get<int>(), 0);
        EXPECT_EQ(m.at("names").at("group:lower").get<int>(), 1);
        EXPECT_EQ(groups.at("value_0").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("value_1").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("value_2").get<std::size_t>(), edges);
    } else {
        EXPECT_EQ(groups.at("upper").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("lower").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("feature_edges").get<std::size_t>(), edges);
    }
}

INSTANTIATE_TEST_SUITE_P(Formats, FemRoundTrip,
                         ::testing::Values("msh", "msh22", "inp", "bdf", "unv", "vtu", "vtp"));

// The core formats keep the groups too: OBJ `g`, PLY `group` with named comments, multi-solid ascii STL.
TEST(FaceGroups, CoreFormatsRoundTrip) {
    const Mesh mesh = twoGroupFandisk();
    for (const char* ext : {"obj", "ply", "stl"}) {
        const fs::path file = scratch(std::string("core_groups.") + ext);
        fss::writeMesh(mesh, file);
        fss::ReadReport report;
        const Mesh back = fss::readMesh(file, &report);
        EXPECT_EQ(report.groups, 2u) << ext;
        // Names come in the order the file first uses them (fandisk's first face is in "lower").
        std::vector<std::string> names = fss::groupNames(back);
        std::sort(names.begin(), names.end());
        EXPECT_EQ(names, (std::vector<std::string>{"lower", "upper"})) << ext;
        EXPECT_EQ(facesPerGroup(back), facesPerGroup(mesh)) << ext;
    }
}

// A legacy VTK file with an integer cell array `group` (no names: "group_<value>").
TEST(FaceGroups, LegacyVtkWithGroupCellData) {
    const fs::path file = scratch("two_triangles.vtk");
    std::ofstream(file) << "# vtk DataFile Version 3.0\nfss\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n"
                           "0 0 0\n1 0 0\n0 1 0\n1 1 0\nPOLYGONS 2 8\n3 0 1 2\n3 1 3 2\nCELL_DATA 2\n"
                           "SCALARS group int 1\nLOOKUP_TABLE default\n7\n9\n";
    fss::ReadReport report;
    const Mesh m = fss::render::readMeshFile(file, &report);
    EXPECT_EQ(m.number_of_faces(), 2u);
    EXPECT_EQ(report.format, "vtk");
    EXPECT_EQ(fss::groupNames(m), (std::vector<std::string>{"group_7", "group_9"}));
}

// ---- bad input: one sentence, nothing half-written -----------------------------------------------------

TEST(FemBadInput, GroupNamesTheFormatCannotHold) {
    Mesh mesh = twoGroupFandisk();
    fss::setGroupNames(mesh, {"upper face", "lower"});
    const fs::path inp = scratch("bad_name.inp");
    fs::remove(inp);
    try {
        fss::render::writeMeshFile(mesh, inp);
        FAIL() << "an Abaqus name with a space was written";
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("'upper face'"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(inp));
    // An existing file stays as it was.
    const fs::path obj = scratch("bad_name.obj");
    std::ofstream(obj) << "keep me\n";
    EXPECT_THROW(fss::writeMesh(mesh, obj), fss::IoError);
    EXPECT_EQ(fss::test::slurp(obj), "keep me\n");
    fss::setGroupNames(mesh, {"say \"hi\"", "lower"});
    EXPECT_THROW(fss::render::writeMeshFile(mesh, scratch("bad_name.msh")), fss::IoError);
    EXPECT_FALSE(fs::exists(scratch("bad_name.msh")));
    for (const auto& entry : fs::directory_iterator(tmpPath("fem_io")))
        EXPECT_EQ(entry.path().filename().string().find(".fss-tmp-"), std::string::npos) << entry.path();
}

TEST(FemBadInput, UnknownGroupSyntax) {
    const fs::path obj = scratch("two_groups_per_face.obj");
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\ng left right\nf 1 2 3\n";
    try {
        fss::readMesh(obj);
        FAIL();
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("one group per face"), std::string::npos) << e.what();
    }
    const fs::path ply = scratch("float_group.ply");
    std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                          "property float group\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0.5\n";
    EXPECT_THROW(fss::readMesh(ply), fss::IoError);
    const fs::path vtk = scratch("float_group.vtk");
    std::ofstream(vtk) << "# vtk DataFile Version 3.0\nfss\nASCII\nDATASET POLYDATA\nPOINTS 3 double\n"
                          "0 0 0\n1 0 0\n0 1 0\nPOLYGONS 1 4\n3 0 1 2\nCELL_DATA 1\n"
                          "SCALARS group float 1\nLOOKUP_TABLE default\n0.5\n";
    try {
        fss::render::readMeshFile(vtk);
        FAIL();
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("'group'"), std::string::npos) << e.what();
    }
}

// ---- quality measures against vtkMeshQuality ------------------------------------------------------------

struct Extremes {
    double min = 1e300, max = -1e300, mean = 0;
};

Extremes vtkQuality(const Mesh& mesh, int measure) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    std::map<std::size_t, vtkIdType> id;
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        id[std::size_t(v)] = points->InsertNextPoint(p.x(), p.y(), p.z());
    }
    vtkNew<vtkCellArray> cells;
    for (FaceIndex f : mesh.faces()) {
        std::vector<vtkIdType> ids;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            ids.push_back(id[std::size_t(v)]);
        cells->InsertNextCell(3, ids.data());
    }
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetPolys(cells);
    vtkNew<vtkMeshQuality> quality;
    quality->SetInputData(poly);
    quality->SetTriangleQualityMeasure(measure);
    quality->Update();
    vtkDataArray* q = quality->GetOutput()->GetCellData()->GetArray("Quality");
    Extremes e;
    for (vtkIdType i = 0; i < q->GetNumberOfTuples(); ++i) {
        const double x = q->GetTuple1(i);
        e.min = std::min(e.min, x);
        e.max = std::max(e.max, x);
        e.mean += x / double(q->GetNumberOfTuples());
    }
    return e;
}

// Aspect ratio, scaled Jacobian, radius ratio (VTK's is the inverse of gamma) and the angles of
// computeMetrics equal vtkMeshQuality's (Verdict) on CGAL's meshes.
TEST(FemQuality, MetricsAgreeWithVtkMeshQuality) {
    for (const char* name : {"fandisk.off", "rotor_small.off", "couplingdown.off", "elephant.off"}) {
        SCOPED_TRACE(name);
        const Mesh mesh = fss::readMesh(meshPath(name));
        fss::MetricsOptions options;
        options.selfIntersections = false;
        const fss::Metrics m = fss::computeMetrics(mesh, options);
        const Extremes aspect = vtkQuality(mesh, VTK_QUALITY_ASPECT_RATIO);
        EXPECT_NEAR(m.aspectRatioMax, aspect.max, 1e-9 * aspect.max);
        EXPECT_NEAR(m.aspectRatioMean, aspect.mean, 1e-9 * aspect.mean);
        const Extremes jacobian = vtkQuality(mesh, VTK_QUALITY_SCALED_JACOBIAN);
        EXPECT_NEAR(m.scaledJacobianMin, jacobian.min, 1e-9);
        EXPECT_NEAR(m.scaledJacobianMean, jacobian.mean, 1e-9);
        const Extremes radius = vtkQuality(mesh, VTK_QUALITY_RADIUS_RATIO);
        EXPECT_NEAR(m.radiusRatioMin, 1 / radius.max, 1e-9);
        const Extremes minAngle = vtkQuality(mesh, VTK_QUALITY_MIN_ANGLE);
        EXPECT_NEAR(m.minAngleDeg, minAngle.min, 1e-7);
        EXPECT_NEAR(m.meanMinAngleDeg, minAngle.mean, 1e-7);
        const Extremes maxAngle = vtkQuality(mesh, VTK_QUALITY_MAX_ANGLE);
        EXPECT_NEAR(m.maxAngleDeg, maxAngle.max, 1e-7);
    }
}

// ---- groups through a remeshing session ------------------------------------------------------------------

// Two scans of the two-group fandisk accepted in a Session (CPU renderer), then the groups carried to the
// result: every face carries a group and each group's area is within 1 % of the input's.
TEST(FaceGroups, SessionResultKeepsGroupAreas) {
    const Mesh input = twoGroupFandisk();
    fss::Session session(input);
    for (auto view : {fss::StandardView::PosZ, fss::StandardView::Iso, fss::StandardView::NegY}) {
        fss::ScanStep step;
        step.params.camera = fss::Camera::standardView(view, fss::boundingBox(input), 200, 200);
        session.scan(step);
        session.accept();
    }
    Mesh result = session.current();
    EXPECT_GT(result.number_of_faces(), 0u);
    fss::transferFaceGroups(session.reference(), result);
    const auto before = fss::groupStats(input), after = fss::groupStats(result);
    ASSERT_EQ(after.size(), 2u); // no entry for faces without a group
    for (std::size_t g = 0; g < 2; ++g) {
        EXPECT_EQ(after[g].name, before[g].name);
        EXPECT_NEAR(after[g].area, before[g].area, 0.01 * before[g].area) << before[g].name;
        std::printf("[ measure  ] session: group %s area %.6g -> %.6g (%.3f %%)\n", before[g].name.c_str(),
                    before[g].area, after[g].area, 100 * (after[g].area / before[g].area - 1));
    }
    // The groups reach the file.
    const fs::path file = scratch("session_groups.msh");
    fss::render::writeMeshFile(result, file);
    EXPECT_EQ(facesPerGroup(fss::render::readMeshFile(file)), facesPerGroup(result));
}

} // namespace
