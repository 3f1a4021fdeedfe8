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
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string_view>
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

/// The value of a Nastran real ("1.5", ".15+1", "-1.5-300", "1.5E+3"): an exponent sign that does not
/// follow an 'E' gets one. Locale-free (std::from_chars). NaN when \p s is not a real.
double parseNastranReal(std::string_view s) {
    std::string t(s);
    for (std::size_t i = 1; i < t.size(); ++i)
        if ((t[i] == '+' || t[i] == '-') && t[i - 1] != 'E' && t[i - 1] != 'e') {
            t.insert(i, 1, 'e');
            break;
        }
    double v = std::numeric_limits<double>::quiet_NaN();
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::numeric_limits<double>::quiet_NaN();
    return v;
}

/// Drops the trailing zeros of the digits after a decimal point ("1.500" -> "1.5", "2.000" -> "2.").
void trimZeros(std::string& mantissa) {
    if (mantissa.find('.') == std::string::npos) return;
    while (mantissa.back() == '0')
        mantissa.pop_back();
}

constexpr std::size_t kLargeField = 16;

/// Fixed form ("123.456789012345", ".000123456789012"), the most decimals that fit; "" when none fit or no
/// digit is left.
std::string nastranFixed(double v) {
    const double a = std::abs(v);
    if (!(a < 1e15)) return {};
    const int sign = v < 0 ? 1 : 0;
    const int intDigits = a < 1 ? 0 : int(std::floor(std::log10(a))) + 1;
    // One more decimal than the estimate first: log10 may be off by one at powers of ten.
    for (int decimals = std::min(15, int(kLargeField) - sign - 1 - intDigits + 1); decimals >= 0;
         --decimals) {
        char b[64];
        const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::fixed, decimals);
        std::string t(b, r.ptr);
        if (t.find('.') == std::string::npos) t += '.';
        const std::size_t zero = std::size_t(sign);
        if (t.compare(zero, 2, "0.") == 0) t.erase(zero, 1); // "0.123" -> ".123"
        trimZeros(t);
        if (t.find_first_of("123456789") == std::string::npos) return {};
        if (t.size() <= kLargeField) return t;
    }
    return {};
}

/// Exponent form without 'E' ("1.23456789012+3", "-.123456789012-9"), the most digits that fit, rounded
/// (or truncated towards zero when \p truncate: rounding up overflows at the top of the double range). The
/// decimal point goes after the first digit, or before it / after the second where that shortens the
/// exponent (1.2e-10 = ".12-9", 1.2e100 = "12.+99").
std::string nastranExponent(double v, bool truncate) {
    const int sign = v < 0 ? 1 : 0;
    for (int digits = 15; digits >= 1; --digits) {
        char b[64];
        const auto r = std::to_chars(b, b + sizeof b, std::abs(v), std::chars_format::scientific,
                                     truncate ? 16 : digits - 1);
        const std::string s(b, r.ptr);
        const std::size_t e = s.find('e');
        const int exponent = std::stoi(s.substr(e + 1));
        std::string allDigits;
        for (std::size_t i = 0; i < e; ++i)
            if (s[i] != '.') allDigits += s[i];
        allDigits.resize(std::min(allDigits.size(), std::size_t(digits)));
        // Point after `k` digits: exponent - k + 1; choose the shortest exponent (k = 1 on ties).
        int bestK = 1;
        auto expLength = [](int x) { return std::to_string(std::abs(x)).size(); };
        for (int k : {0, 2})
            if (k <= int(allDigits.size()) && expLength(exponent - k + 1) < expLength(exponent - bestK + 1))
                bestK = k;
        const int shown = exponent - bestK + 1;
        std::string t = sign ? "-" : "";
        t += allDigits.substr(0, std::size_t(bestK)) + "." + allDigits.substr(std::size_t(bestK));
        trimZeros(t);
        t += (shown < 0 ? "-" : "+") + std::to_string(std::abs(shown));
        if (t.size() <= kLargeField) return t;
    }
    return {};
}

} // namespace

std::string nastranReal(double v) {
    if (!std::isfinite(v)) throw InvalidInputError("A Nastran real must be a finite number.");
    if (v == 0) return "0.";
    // Both forms at their most digits; the one that reads back closer wins (the fixed form on a tie: easier
    // to read). A form that does not read back as a finite number (rounded past the largest double) loses.
    std::string best;
    double bestError = std::numeric_limits<double>::infinity();
    for (const std::string& t : {nastranFixed(v), nastranExponent(v, false), nastranExponent(v, true)}) {
        if (t.empty()) continue;
        double error = std::abs(parseNastranReal(t) - v);
        if (!std::isfinite(error)) error = std::numeric_limits<double>::infinity();
        if (best.empty() || error < bestError) {
            best = t;
            bestError = error;
        }
    }
    // Room left: put back the leading zero that was dropped for room (".5" -> "0.5").
    const std::size_t point = best[0] == '-' ? 1 : 0;
    if (best.size() < kLargeField && best[point] == '.') best.insert(point, 1, '0');
    return best;
}

namespace {

std::string field(std::string text, std::size_t width) {
    text.resize(std::max(text.size(), width), ' ');
    return text;
}

/// Group names go into comment lines: printable ASCII without '"' (HyperMesh quotes the name) or ';'
/// (ANSA separates fields with it).
bool isNastranCommentName(const std::string& name) {
    if (name.empty()) return false;
    return std::all_of(name.begin(), name.end(),
                       [](char c) { return c >= 0x20 && c <= 0x7e && c != '"' && c != ';'; });
}

/// The name of property \p pid in the comment conventions FEM preprocessors read (see fem_io.h).
std::string nastranNameComments(std::size_t pid, const std::string& card, const std::string& name) {
    char hm[64];
    std::snprintf(hm, sizeof hm, "%20zu", pid);
    const std::string id = std::to_string(pid);
    return "$HMNAME COMP" + std::string(hm) + "\"" + name + "\"\n" + "$HMNAME PROP" + std::string(hm) + "\"" +
           name + "\"\n" + "$ANSA_NAME_COMMENT;" + id + ";" + card + ";" + name + ";;NO;NO;NO;NO;\n" +
           "$ Femap Property " + id + " : " + name + "\n" +
           "$ Elements and Element Properties for region : " + name + "\n";
}

/// Nastran bulk data by hand: GRID* (large field, nastranReal), then per group its names (comments), a
/// PSHELL with its PID and its CTRIA3; feature edges as CROD with a PROD of their own.
void writeBdf(const FemMesh& m, const fs::path& path) {
    for (const std::string& name : m.groupNames)
        if (!isNastranCommentName(name))
            failWrite(path, "Nastran BDF cannot hold the group name '" + name +
                                "' (names go into comment lines: printable ASCII without '\"' or ';')");
    std::string s = "$ written by FSS\n$ group names: comments before each PSHELL (see FSS's fem_io.h)\n"
                    "BEGIN BULK\n";
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        for (double c : m.nodes[i])
            if (!std::isfinite(c)) failWrite(path, "node " + std::to_string(i + 1) + " is not finite");
        s += field("GRID*", 8) + field(std::to_string(i + 1), 16) + field("", 16) +
             field(nastranReal(m.nodes[i][0]), 16) + field(nastranReal(m.nodes[i][1]), 16) + "\n";
        s += field("*", 8) + field(nastranReal(m.nodes[i][2]), 16) + "\n";
    }
    std::size_t id = 0;
    for (std::size_t g = 0; g < m.groupNames.size(); ++g) {
        const std::string pid = std::to_string(g + 1);
        s += nastranNameComments(g + 1, "PSHELL", m.groupNames[g]) + field("PSHELL", 8) + pid + "\n";
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            if (m.group[t] != std::int32_t(g)) continue;
            s += field("CTRIA3", 8) + field(std::to_string(++id), 8) + field(pid, 8);
            for (std::size_t n : m.triangles[t])
                s += field(std::to_string(n + 1), 8);
            s += '\n';
        }
    }
    if (!m.edges.empty()) {
        const std::string pid = std::to_string(m.groupNames.size() + 1);
        s +=
            nastranNameComments(m.groupNames.size() + 1, "PROD", m.edgeGroup) + field("PROD", 8) + pid + "\n";
        for (const auto& e : m.edges)
            s += field("CROD", 8) + field(std::to_string(++id), 8) + field(pid, 8) +
                 field(std::to_string(e[0] + 1), 8) + std::to_string(e[1] + 1) + "\n";
    }
    s += "ENDDATA\n";
    writeText(path, s);
}

} // namespace

FormatLimits formatLimits(const fs::path& path, const FemWriteOptions& options,
                          const WriteOptions& coreOptions) {
    FormatLimits limits;
    const std::string ext = lowerExtension(path);
    switch (femFormat(path)) {
    case Fem::Bdf: // 8-character integer fields (CTRIA3 refers to its nodes in them)
        limits = {99'999'999, 99'999'999, 99'999'999};
        break;
    case Fem::Inp: // Abaqus: "the maximum node (element) number allowed is 999999999"
        limits.nodes = limits.elements = 999'999'999;
        break;
    case Fem::Msh:
        if (options.mshVersion == 2.2) limits.nodes = limits.elements = limits.groups = 2'147'483'647;
        break;
    case Fem::Unv: // I-deas labels are 32-bit integers (I10 fields)
        limits.nodes = limits.elements = limits.groups = 2'147'483'647;
        break;
    default:
        if (ext == ".ply") limits.nodes = 2'147'483'647;                          // int vertex indices
        if (ext == ".stl" && coreOptions.binary) limits.elements = 4'294'967'295; // uint32 count
        break;
    }
    if (options.maxNodes) limits.nodes = std::min(limits.nodes, options.maxNodes);
    if (options.maxElements) limits.elements = std::min(limits.elements, options.maxElements);
    return limits;
}

void checkFormatLimits(const fs::path& path, std::size_t nodes, std::size_t elements, std::size_t groups,
                       const FemWriteOptions& options, const WriteOptions& coreOptions) {
    const FormatLimits limits = formatLimits(path, options, coreOptions);
    const std::string ext = lowerExtension(path);
    auto refuse = [&](std::size_t count, std::size_t limit, std::size_t formatLimit, const char* what) {
        if (count <= limit) return;
        failWrite(path, "the mesh has " + std::to_string(count) + " " + what + ", more than the " +
                            std::to_string(limit) +
                            (limit < formatLimit ? " asked for as the limit"
                                                 : " that a " + ext + " file can number"));
    };
    const FormatLimits format = formatLimits(path, FemWriteOptions{options.mshVersion}, coreOptions);
    refuse(nodes, limits.nodes, format.nodes, "nodes");
    refuse(elements, limits.elements, format.elements, "elements");
    refuse(groups, limits.groups, format.groups, "groups");
}

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
        checkFormatLimits(path, mesh.number_of_vertices(), mesh.number_of_faces(), groupNames(mesh).size(),
                          options, coreOptions);
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
    checkFormatLimits(path, fem.nodes.size(), fem.triangles.size() + fem.edges.size(),
                      fem.groupNames.size() + (fem.edges.empty() ? 0 : 1), options, coreOptions);
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
