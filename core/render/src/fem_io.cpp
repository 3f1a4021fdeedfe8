// FEM hand-off (fss/render/fem_io.h): the table of FEM/VTK formats, the flattening of a mesh with groups
// and feature edges, and the two writers that are our own (Abaqus INP, Nastran BDF: why, see fem_io.h).
#include "fem_detail.h"

#include "fss/error.h"
#include "fss/face_groups.h"

#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <system_error>

#include <unistd.h>

namespace fs = std::filesystem;

namespace fss::render {
namespace detail {

void failWrite(const fs::path& path, const std::string& problem) {
    throw IoError("Cannot write mesh file '" + path.string() + "': " + problem + ".");
}

void failRead(const fs::path& path, const std::string& problem) {
    throw IoError("Cannot read mesh file '" + path.string() + "': " + problem + ".");
}

TempFile::TempFile(const fs::path& target) : target_(target) {
    static std::atomic<unsigned> counter{0};
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) failWrite(target, "its folder does not exist");
    temp_ = folder / ("." + target.stem().string() + ".fss-tmp-" + std::to_string(::getpid()) + "-" +
                      std::to_string(counter++) + target.extension().string());
}

TempFile::~TempFile() {
    if (!committed_) {
        std::error_code ec;
        fs::remove(temp_, ec);
    }
}

void TempFile::commit() {
    std::error_code ec;
    if (!fs::is_regular_file(temp_, ec)) failWrite(target_, "the writer produced no file");
    fs::rename(temp_, target_, ec);
    if (ec) failWrite(target_, "the written file cannot replace it (" + ec.message() + ")");
    committed_ = true;
}

} // namespace detail

using namespace detail;

namespace {

enum class Fem { None, Msh, Unv, Inp, Bdf, Vtu, Vtp, VtkLegacy };

Fem femFormat(const fs::path& path) {
    const std::string ext = lowerExtension(path);
    if (ext == ".msh") return Fem::Msh;
    if (ext == ".unv") return Fem::Unv;
    if (ext == ".inp") return Fem::Inp;
    if (ext == ".bdf" || ext == ".nas") return Fem::Bdf;
    if (ext == ".vtu") return Fem::Vtu;
    if (ext == ".vtp") return Fem::Vtp;
    if (ext == ".vtk") return Fem::VtkLegacy;
    return Fem::None;
}

FemMesh flattenForFem(const Mesh& mesh, const FemWriteOptions& options) {
    FemMesh fem;
    std::vector<std::size_t> index(mesh.num_vertices(), 0);
    for (VertexIndex v : mesh.vertices()) {
        index[std::size_t(v)] = fem.nodes.size();
        const Point3& p = mesh.point(v);
        fem.nodes.push_back({p.x(), p.y(), p.z()});
    }
    const auto group = mesh.property_map<FaceIndex, std::int32_t>(props::faceGroup);
    const std::vector<std::string> names = groupNames(mesh);
    // Table groups, then "ungrouped" (faces in no group), or "surface" when the mesh has no groups.
    std::vector<std::size_t> count(names.size() + 1, 0);
    std::vector<std::int32_t> raw;
    raw.reserve(mesh.number_of_faces());
    for (FaceIndex f : mesh.faces()) {
        std::array<std::size_t, 3> t{};
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k == 3) throw InvalidInputError("The mesh has a face with more than three corners.");
            t[std::size_t(k++)] = index[std::size_t(v)];
        }
        if (k != 3) throw InvalidInputError("The mesh has a face with fewer than three corners.");
        fem.triangles.push_back(t);
        std::int32_t g = group.second ? group.first[f] : kNoGroup;
        if (g < 0 || std::size_t(g) >= names.size()) g = std::int32_t(names.size());
        raw.push_back(g);
        ++count[std::size_t(g)];
    }
    std::vector<std::int32_t> dense(count.size(), -1);
    for (std::size_t g = 0; g < count.size(); ++g) {
        if (!count[g]) continue;
        dense[g] = std::int32_t(fem.groupNames.size());
        fem.groupNames.push_back(g < names.size() ? names[g] : names.empty() ? "surface" : "ungrouped");
    }
    fem.group.reserve(raw.size());
    for (std::int32_t g : raw)
        fem.group.push_back(dense[std::size_t(g)]);
    if (options.featureEdges) {
        for (const auto& e : sharpFeatureEdges(mesh, options.featureAngleDeg))
            fem.edges.push_back({index[std::size_t(e[0])], index[std::size_t(e[1])]});
        while (std::find(fem.groupNames.begin(), fem.groupNames.end(), fem.edgeGroup) != fem.groupNames.end())
            fem.edgeGroup += "_";
    }
    return fem;
}

void putDouble(std::string& s, double v) {
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, 17);
    s.append(b, r.ptr);
}

/// Abaqus names: a letter, then letters, digits, '_', '-' or '.', at most 80 characters (no quoting).
bool isAbaqusName(const std::string& name) {
    if (name.empty() || name.size() > 80 || !std::isalpha(static_cast<unsigned char>(name[0]))) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
    });
}

void writeText(const fs::path& path, const std::string& text) {
    TempFile temp(path);
    {
        std::ofstream out(temp.path(), std::ios::binary);
        out.write(text.data(), std::streamsize(text.size()));
        out.flush();
        if (!out) failWrite(path, "writing failed");
    }
    temp.commit();
}

/// Abaqus INP by hand: S3 shell elements (3D triangles), one *ELEMENT block with ELSET=<group> per group and
/// a *SURFACE on each element set (SPOS: the side the normals point to); feature edges as T3D2.
void writeInp(const FemMesh& m, const fs::path& path) {
    for (const std::string& name : m.groupNames)
        if (!isAbaqusName(name))
            failWrite(path, "Abaqus INP cannot hold the group name '" + name +
                                "' (a name starts with a letter and holds letters, digits, '_', '-' and '.' "
                                "only, at most 80 characters)");
    std::string s = "*HEADING\nwritten by FSS\n*NODE\n";
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        s += std::to_string(i + 1);
        for (double c : m.nodes[i]) {
            s += ", ";
            putDouble(s, c);
        }
        s += '\n';
    }
    std::size_t id = 0;
    for (std::size_t g = 0; g < m.groupNames.size(); ++g) {
        s += "*ELEMENT, TYPE=S3, ELSET=" + m.groupNames[g] + "\n";
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            if (m.group[t] != std::int32_t(g)) continue;
            s += std::to_string(++id);
            for (std::size_t n : m.triangles[t])
                s += ", " + std::to_string(n + 1);
            s += '\n';
        }
    }
    if (!m.edges.empty()) {
        s += "*ELEMENT, TYPE=T3D2, ELSET=" + m.edgeGroup + "\n";
        for (const auto& e : m.edges)
            s += std::to_string(++id) + ", " + std::to_string(e[0] + 1) + ", " + std::to_string(e[1] + 1) +
                 "\n";
    }
    for (const std::string& name : m.groupNames)
        s += "*SURFACE, TYPE=ELEMENT, NAME=" + name + "\n" + name + ", SPOS\n";
    writeText(path, s);
}

/// A real number in at most 16 characters (a Nastran large field) with as many digits as fit.
std::string nastranReal(double v) {
    for (int digits = 15; digits > 0; --digits) {
        char b[64];
        std::snprintf(b, sizeof b, "%.*E", digits, v);
        std::string t = b;
        // Compact exponent: E+05 -> E+5.
        const std::size_t e = t.find('E');
        std::size_t first = e + 2;
        while (first + 1 < t.size() && t[first] == '0')
            t.erase(first, 1);
        if (t.size() <= 16) return t;
    }
    return "0.";
}

std::string field(std::string text, std::size_t width) {
    text.resize(std::max(text.size(), width), ' ');
    return text;
}

constexpr std::size_t kNastranMaxId = 99'999'999; // 8-character integer fields

/// Nastran bulk data by hand: GRID* (large field: about 12 significant digits), CTRIA3 with the group's
/// PID, feature edges as CROD with their own PID; group names in comments.
void writeBdf(const FemMesh& m, const fs::path& path) {
    const std::size_t elements = m.triangles.size() + m.edges.size();
    if (m.nodes.size() > kNastranMaxId || elements > kNastranMaxId)
        failWrite(path, "Nastran ids have at most 8 digits, but the mesh has " +
                            std::to_string(m.nodes.size()) + " nodes and " + std::to_string(elements) +
                            " elements");
    std::string s = "$ written by FSS\n";
    for (std::size_t g = 0; g < m.groupNames.size(); ++g)
        s += "$ PID " + std::to_string(g + 1) + " = " + m.groupNames[g] + "\n";
    if (!m.edges.empty())
        s += "$ PID " + std::to_string(m.groupNames.size() + 1) + " = " + m.edgeGroup + "\n";
    s += "BEGIN BULK\n";
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        s += field("GRID*", 8) + field(std::to_string(i + 1), 16) + field("", 16) +
             field(nastranReal(m.nodes[i][0]), 16) + field(nastranReal(m.nodes[i][1]), 16) + "\n";
        s += field("*", 8) + field(nastranReal(m.nodes[i][2]), 16) + "\n";
    }
    std::size_t id = 0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
        s += field("CTRIA3", 8) + field(std::to_string(++id), 8) + field(std::to_string(m.group[t] + 1), 8);
        for (std::size_t n : m.triangles[t])
            s += field(std::to_string(n + 1), 8);
        s += '\n';
    }
    const std::string edgePid = std::to_string(m.groupNames.size() + 1);
    for (const auto& e : m.edges)
        s += field("CROD", 8) + field(std::to_string(++id), 8) + field(edgePid, 8) +
             field(std::to_string(e[0] + 1), 8) + std::to_string(e[1] + 1) + "\n";
    s += "ENDDATA\n";
    writeText(path, s);
}

} // namespace

bool isFemMeshFile(const fs::path& path) {
    const Fem f = femFormat(path);
    return f != Fem::None && f != Fem::VtkLegacy;
}

bool isWritableMeshFile(const fs::path& path) {
    return isFemMeshFile(path) || isSupportedMeshFile(path);
}

void writeMeshFile(const Mesh& mesh, const fs::path& path, const FemWriteOptions& options,
                   const WriteOptions& coreOptions) {
    const Fem format = femFormat(path);
    if (format == Fem::None) {
        if (!isSupportedMeshFile(path)) {
            const std::string ext = path.extension().string();
            failWrite(path, (ext.empty() ? std::string("it has no extension, so the format is unknown")
                                         : "the extension '" + ext + "' does not name a format") +
                                " (use .off, .obj, .ply, .stl, .msh, .inp, .bdf, .unv, "
                                ".vtu or .vtp)");
        }
        writeMesh(mesh, path, coreOptions);
        return;
    }
    if (format == Fem::VtkLegacy)
        failWrite(path, "FSS reads legacy .vtk files but writes VTK's XML formats only (use .vtu or .vtp)");
    if (options.mshVersion != 4.1 && options.mshVersion != 2.2)
        throw InvalidInputError("The MSH version must be 4.1 or 2.2.");
    std::error_code ec;
    if (fs::is_directory(path, ec)) failWrite(path, "it is a folder");
    const FemMesh fem = flattenForFem(mesh, options);
    switch (format) {
    case Fem::Msh:
    case Fem::Unv:
        writeGmsh(fem, path, options);
        break;
    case Fem::Inp:
        writeInp(fem, path);
        break;
    case Fem::Bdf:
        writeBdf(fem, path);
        break;
    default:
        writeVtk(fem, path, options);
        break;
    }
}

Mesh readMeshFile(const fs::path& path, ReadReport* report, const ReadOptions& options) {
    const Fem format = femFormat(path);
    if (format == Fem::None) return readMesh(path, report, options);
    if (format == Fem::Inp || format == Fem::Bdf || format == Fem::Unv)
        failRead(path, "FSS writes this format but does not read it (it reads .off, .obj, .ply, .stl, .msh, "
                       ".vtu, .vtp and .vtk)");
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) failRead(path, "it does not exist or is not a regular file");
    PolygonSoup soup = format == Fem::Msh ? readGmsh(path) : readVtk(path);
    const std::string name = format == Fem::Msh   ? "msh"
                             : format == Fem::Vtu ? "vtu"
                             : format == Fem::Vtp ? "vtp"
                                                  : "vtk";
    return meshFromPolygons(std::move(soup), path, name, report, options);
}

} // namespace fss::render
