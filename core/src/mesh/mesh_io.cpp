// Mesh I/O: the table of formats (one reader and one writer each: io_off.cpp, io_obj.cpp, io_ply.cpp,
// io_stl.cpp), format detection by extension or content, and the public interface. The readers parse into a
// polygon soup that soup_repair.cpp turns into a mesh; the writers replace the target atomically.
// See fss/mesh_io.h and mesh/io_detail.h.
#include "fss/mesh_io.h"

#include "mesh/io_detail.h"

#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <system_error>

namespace fs = std::filesystem;

namespace fss {
namespace {

using namespace detail::io;

/// The formats, by extension (lower case). A new format is one more row (and its reader and writer).
constexpr std::array kFormats{
    MeshFormat{".off", readOff, writeOff},
    MeshFormat{".obj", readObj, writeObj},
    MeshFormat{".ply", readPly, writePly},
    MeshFormat{".stl", readStl, writeStl},
};

const MeshFormat* formatOfExtension(std::string_view ext) {
    for (const MeshFormat& f : kFormats)
        if (f.extension == ext) return &f;
    return nullptr;
}

/// The format the content shows, for files whose extension names none (nullptr when none fits).
const MeshFormat* sniffFormat(std::string_view d) {
    const std::string_view s = skipBomAndSpace(d);
    if (s.size() > 3 && s.substr(0, 3) == "ply" && (s[3] == '\n' || s[3] == '\r'))
        return formatOfExtension(".ply");
    std::string_view first = s.substr(0, std::min(s.size(), s.find_first_of(" \t\r\n\f\v#")));
    if (isOffKeyword(first)) return formatOfExtension(".off");
    if (isBinaryStlOfExactSize(d)) return formatOfExtension(".stl");
    if (!looksLikeText(d)) return nullptr;
    if (startsWithWordNoCase(s, "solid")) return formatOfExtension(".stl");
    Lines lines(s, '#');
    std::string_view line, keyword;
    if (lines.next(line) && Tokens(line).next(keyword)) {
        static constexpr std::string_view objStarts[] = {"v", "vt", "vn", "vp",     "f",
                                                         "o", "g",  "s",  "mtllib", "usemtl"};
        if (std::find(std::begin(objStarts), std::end(objStarts), keyword) != std::end(objStarts))
            return formatOfExtension(".obj");
    }
    return nullptr;
}

const MeshFormat& detectFormat(const Source& src) {
    const std::string ext = lower(src.path.extension().string());
    if (const MeshFormat* f = formatOfExtension(ext)) return *f;
    if (const MeshFormat* f = sniffFormat(src.data)) return *f;
    src.fail("its format is not recognised: " +
             (ext.empty() ? std::string("it has no extension")
                          : "the extension " + quoteToken(ext) + " is not .off, .obj, .ply or .stl") +
             " and the content is not OFF, OBJ, PLY or STL either");
}

} // namespace

Mesh readMesh(const fs::path& path, ReadReport* report, const ReadOptions& options) {
    ReadReport local;
    ReadReport& rep = report ? *report : local;
    rep = ReadReport{};
    const Source src = loadFile(path);
    Soup soup = detectFormat(src).read(src, rep);
    return soupToMesh(src, soup, rep, options);
}

Mesh canonicalMesh(const Mesh& mesh) {
    // Exactly what readMesh does with the file writeMesh makes of the mesh, without the file.
    const FlatMesh flat = flatten(mesh);
    Soup soup;
    soup.points = flat.points;
    soup.polygons.reserve(flat.faces());
    for (std::size_t f = 0; f < flat.faces(); ++f) {
        Polygon poly;
        for (std::size_t j = 0; j < flat.degree(f); ++j)
            poly.push_back(flat.corner(f, j));
        soup.polygons.push_back(std::move(poly));
    }
    if (flat.hasQuality) soup.quality = flat.quality;
    if (flat.hasScanId) soup.scanId = flat.scanId;
    if (flat.hasGroups) {
        soup.group = flat.group;
        soup.groupNames = flat.groupNames;
    }
    const Source src{"(mesh in memory)", {}};
    ReadReport report;
    return soupToMesh(src, soup, report, ReadOptions{});
}

Mesh meshFromPolygons(PolygonSoup in, const fs::path& source, const std::string& format, ReadReport* report,
                      const ReadOptions& options) {
    ReadReport local;
    ReadReport& rep = report ? *report : local;
    rep = ReadReport{};
    rep.format = format;
    const Source src{source, {}};
    Soup soup;
    soup.points = std::move(in.points);
    for (std::size_t i = 0; i < soup.points.size(); ++i) {
        const Point3& p = soup.points[i];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
            src.fail("point " + std::to_string(i) + " has a NaN or infinite coordinate");
    }
    if (in.polygons.empty()) src.fail("it has no faces");
    soup.polygons.reserve(in.polygons.size());
    for (std::size_t f = 0; f < in.polygons.size(); ++f) {
        const auto& poly = in.polygons[f];
        if (poly.size() < 3)
            src.fail("face " + std::to_string(f) + " has " + std::to_string(poly.size()) +
                     " corners, but a face needs at least 3");
        for (std::size_t c : poly)
            if (c >= soup.points.size())
                src.fail("face " + std::to_string(f) + " uses point " + std::to_string(c) +
                         ", but there are only " + quantity(soup.points.size(), "point", "points"));
        soup.polygons.emplace_back(poly.begin(), poly.end());
    }
    if (!in.groups.empty()) {
        if (in.groups.size() != in.polygons.size())
            src.fail("it has " + std::to_string(in.groups.size()) + " group values for " +
                     quantity(in.polygons.size(), "face", "faces"));
        for (std::size_t f = 0; f < in.groups.size(); ++f)
            if (in.groups[f] != kNoGroup &&
                (in.groups[f] < 0 || std::size_t(in.groups[f]) >= in.groupNames.size()))
                src.fail("face " + std::to_string(f) + " is in group " + std::to_string(in.groups[f]) +
                         ", which has no name");
        soup.group = std::move(in.groups);
        soup.groupNames = std::move(in.groupNames);
    }
    return soupToMesh(src, soup, rep, options);
}

bool isSupportedMeshFile(const fs::path& path) {
    return formatOfExtension(lower(path.extension().string())) != nullptr;
}

void writeMesh(const Mesh& mesh, const fs::path& path, const WriteOptions& options) {
    const std::string ext = lower(path.extension().string());
    const MeshFormat* format = formatOfExtension(ext);
    if (!format)
        failWrite(path, (ext.empty() ? std::string("it has no extension, so the format is unknown")
                                     : "the extension " + quoteToken(ext) + " does not name a format") +
                            " (use .off, .obj, .ply or .stl)");
    std::error_code ec;
    if (fs::is_directory(path, ec)) failWrite(path, "it is a folder");
    WriteOptions clamped = options;
    clamped.precision = std::clamp(options.precision, 1, 17);
    format->write(flatten(mesh), path, clamped);
}

} // namespace fss
