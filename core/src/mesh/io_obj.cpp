// OBJ: the strict reader (positions, faces and their groups `g`/`o`; the other statements are checked and
// ignored) and the writer (groups as `g` statements).
#include "mesh/io_detail.h"

namespace fss::detail::io {

Soup readObj(const Source& src, ReadReport& report) {
    report.format = "obj";
    static constexpr std::string_view ignored[] = {
        "vt",         "vn",        "vp",    "l",     "p",      "s",     "usemtl",   "mtllib",   "cstype",
        "deg",        "bmat",      "step",  "curv",  "curv2",  "surf",  "parm",     "trim",     "hole",
        "scrv",       "sp",        "end",   "con",   "mg",     "bevel", "c_interp", "d_interp", "lod",
        "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
    Lines lines(skipBomAndSpace(src.data), '#');
    Soup soup;
    std::vector<std::size_t> faceLine;
    std::string_view line, t;
    // The group of the last `g` or `o` statement; a name enters the table with its first face.
    std::string groupName;
    std::int32_t group = kNoGroup;
    bool grouped = false;
    while (lines.next(line)) {
        Tokens tok(line);
        tok.next(t);
        const std::string where = lines.where();
        if (t == "v") {
            const std::size_t index = soup.points.size();
            soup.points.push_back(readCoordinates(src, tok, where, index, false));
            expectOnlyNumbers(src, tok, where, "the coordinates of vertex " + std::to_string(index));
        } else if (t == "f") {
            const std::string face = "face " + std::to_string(soup.polygons.size());
            Polygon poly;
            while (tok.next(t)) {
                // v, v/vt, v//vn or v/vt/vn: only the position index matters, the others must be integers.
                const std::string_view v = t.substr(0, std::min(t.find('/'), t.size()));
                long long index = 0;
                bool ok = parseInteger(v, index);
                for (std::size_t s = t.find('/'); ok && s != std::string_view::npos;) {
                    const std::size_t e = std::min(t.find('/', s + 1), t.size());
                    long long other = 0;
                    const std::string_view part = t.substr(s + 1, e - s - 1);
                    ok = part.empty() || parseInteger(part, other);
                    s = e < t.size() ? e : std::string_view::npos;
                }
                if (!ok)
                    src.fail(where + "expected a vertex index of " + face + " but found " + quoteToken(t));
                if (index == 0) src.fail(where + face + " uses vertex index 0, but OBJ indices start at 1");
                if (index < 0) {
                    const long long absolute = static_cast<long long>(soup.points.size()) + index;
                    if (absolute < 0)
                        src.fail(where + face + " uses relative vertex index " + std::to_string(index) +
                                 ", but only " + quantity(soup.points.size(), "vertex", "vertices") +
                                 " precede it");
                    poly.push_back(std::size_t(absolute));
                } else {
                    poly.push_back(std::size_t(index - 1));
                }
            }
            if (poly.size() < 3)
                src.fail(where + face + " has " + std::to_string(poly.size()) +
                         " corners, but a face needs at least 3");
            soup.polygons.push_back(std::move(poly));
            if (grouped && group == kNoGroup) group = groupIndex(soup, groupName);
            soup.group.push_back(group);
            faceLine.push_back(lines.number());
        } else if (t == "g" || t == "o") {
            // One group per face: `g a b` (a face in two groups) cannot be held.
            std::string_view name, extra;
            if (!tok.next(name)) name = "default";
            if (tok.next(extra))
                src.fail(where + "the group statement names more than one group (" + quoteToken(name) +
                         " and " + quoteToken(extra) + "), but FSS holds one group per face");
            groupName = std::string(name);
            group = kNoGroup;
            grouped = true;
        } else if (std::find(std::begin(ignored), std::end(ignored), t) == std::end(ignored)) {
            src.fail(where + "unknown OBJ statement " + quoteToken(t));
        }
    }
    if (!grouped) {
        soup.group.clear();
    } else {
        for (std::int32_t& g : soup.group)
            if (g == kNoGroup) g = groupIndex(soup, "default"); // faces before the first group statement
    }
    // Positive indices may refer to vertices defined later in the file, so check them at the end.
    const std::size_t nv = soup.points.size();
    for (std::size_t f = 0; f < soup.polygons.size(); ++f)
        for (std::size_t index : soup.polygons[f])
            if (index >= nv)
                src.fail("line " + std::to_string(faceLine[f]) + ": face " + std::to_string(f) +
                         " uses vertex " + std::to_string(index + 1) + ", but the file has " +
                         (nv == 0 ? std::string("no vertices")
                                  : "only " + quantity(nv, "vertex", "vertices") + " (OBJ counts from 1)"));
    return soup;
}

void writeObj(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options) {
    const int precision = options.precision;
    for (const std::string& name : m.groupNames)
        if (name.find_first_of(" \t\f\v#") != std::string::npos)
            failWrite(path, "OBJ cannot hold the group name " + quoteToken(name) +
                                " (a `g` statement ends a name at white space or '#')");
    AtomicFile file(path);
    std::string& s = file.out();
    s += "# written by FSS\n";
    for (const Point3& p : m.points) {
        s += "v ";
        putPoint(s, p, precision);
        s += '\n';
        file.flushIfLarge();
    }
    std::int32_t group = kNoGroup;
    for (std::size_t f = 0; f < m.faces(); ++f) {
        if (m.hasGroups && m.group[f] != group) {
            group = m.group[f];
            s += "g ";
            s += group >= 0 && std::size_t(group) < m.groupNames.size() ? m.groupNames[std::size_t(group)]
                                                                        : std::string("default");
            s += '\n';
        }
        s += 'f';
        for (std::size_t j = 0; j < m.degree(f); ++j) {
            s += ' ';
            putInteger(s, m.corner(f, j) + 1);
        }
        s += '\n';
        file.flushIfLarge();
    }
    file.commit();
}

} // namespace fss::detail::io
