// STL: the strict readers (ascii and binary, told by the content; identical corners merged) and the
// writer (faces with more than three corners as fans). An ascii file with several solids gives one face group
// per solid name; a mesh with groups is written as one solid per group (ascii).
#include "mesh/io_detail.h"

#include <cmath>
#include <limits>

namespace fss::detail::io {
namespace {

/// Collects STL corners, merging identical coordinates (STL stores each triangle's corners separately).
class CornerMerger {
public:
    CornerMerger(Soup& soup, std::size_t expected) : soup_(soup), table_(soup.points, expected) {}
    std::size_t add(const Point3& p) {
        soup_.points.push_back(p);
        const std::size_t last = soup_.points.size() - 1, first = table_.firstEqual(last);
        if (first != last) soup_.points.pop_back();
        return first;
    }

private:
    Soup& soup_;
    PointTable table_;
};

Soup parseStlAscii(const Source& src) {
    TokenStream ts(skipBomAndSpace(src.data));
    Soup soup;
    CornerMerger merger(soup, src.data.size() / 200); // ~ 250 bytes per facet, ~ half a point each
    std::string_view t;
    auto expect = [&](std::string_view keyword, const std::string& context) {
        if (!ts.next(t))
            src.fail("the file ends where '" + std::string(keyword) + "' of " + context +
                     " was expected (the file is truncated)");
        if (!equalsNoCase(t, keyword))
            src.fail(ts.where() + "expected '" + std::string(keyword) + "' of " + context + " but found " +
                     quoteToken(t));
    };
    auto number = [&](const std::string& what) {
        if (!ts.next(t)) src.fail("the file ends inside " + what + " (the file is truncated)");
        double v = 0;
        const NumberParse r = parseDouble(t, v);
        if (r == NumberParse::NotANumber)
            src.fail(ts.where() + "expected a number in " + what + " but found " + quoteToken(t));
        if (r == NumberParse::OutOfRange) v = std::numeric_limits<double>::infinity();
        return v;
    };

    ts.next(t);
    if (!equalsNoCase(t, "solid")) src.fail(ts.where() + "expected 'solid' but found " + quoteToken(t));
    // Each solid's faces form a group named after it (kept only when the file has more than one solid).
    std::size_t solids = 1;
    auto startSolid = [&](std::string_view name) {
        const std::string fallback = "solid_" + std::to_string(solids);
        return groupIndex(soup, name.empty() ? std::string_view(fallback) : name);
    };
    std::int32_t group = startSolid(ts.skipLine());
    while (true) {
        if (!ts.next(t)) src.fail("the file ends without 'endsolid' (the file is truncated)");
        if (equalsNoCase(t, "endsolid")) {
            ts.skipLine();
            if (!ts.next(t)) break;
            if (!equalsNoCase(t, "solid"))
                src.fail(ts.where() + "unexpected " + quoteToken(t) + " after 'endsolid'");
            ++solids;
            group = startSolid(ts.skipLine());
            continue;
        }
        const std::string facet = "facet " + std::to_string(soup.polygons.size());
        if (!equalsNoCase(t, "facet"))
            src.fail(ts.where() + "expected 'facet' or 'endsolid' but found " + quoteToken(t));
        expect("normal", facet);
        for (int i = 0; i < 3; ++i)
            number("the normal of " + facet); // recomputed, not stored
        expect("outer", facet);
        expect("loop", facet);
        Polygon poly;
        while (true) {
            if (!ts.next(t)) src.fail("the file ends inside " + facet + " (the file is truncated)");
            if (equalsNoCase(t, "endloop")) break;
            if (!equalsNoCase(t, "vertex"))
                src.fail(ts.where() + "expected 'vertex' or 'endloop' in " + facet + " but found " +
                         quoteToken(t));
            const std::string where = ts.where();
            std::array<double, 3> c{};
            for (double& v : c)
                v = number("a vertex of " + facet);
            if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
                src.fail(where + facet + " has a NaN or infinite coordinate");
            poly.push_back(merger.add({c[0], c[1], c[2]}));
        }
        if (poly.size() < 3)
            src.fail(ts.where() + facet + " has " + std::to_string(poly.size()) +
                     " corners, but a face needs at least 3");
        expect("endfacet", facet);
        soup.polygons.push_back(std::move(poly));
        soup.group.push_back(group);
    }
    if (solids < 2) {
        soup.group.clear();
        soup.groupNames.clear();
    }
    return soup;
}

Soup parseStlBinary(const Source& src) {
    const std::string_view d = src.data;
    if (d.size() < 84)
        src.fail(
            "it is neither an ascii STL file (starting with 'solid') nor a binary STL file (it has only " +
            quantity(d.size(), "byte", "bytes") + ", fewer than the 84 of a binary STL header)");
    const auto n = loadBinary<std::uint32_t>(d.data() + 80, std::endian::native == std::endian::big);
    const std::uint64_t expected = 84 + 50 * std::uint64_t(n);
    if (d.size() < expected)
        src.fail("its binary STL header announces " + quantity(n, "triangle", "triangles") + " (" +
                 std::to_string(expected) + " bytes) but the file has only " + std::to_string(d.size()) +
                 " bytes (the file is truncated)");
    const std::string_view rest = d.substr(static_cast<std::size_t>(expected));
    if (std::any_of(rest.begin(), rest.end(), [](char c) { return c != 0 && !isSpace(c); }))
        src.fail("it has " + quantity(rest.size(), "byte", "bytes") + " of unexpected data after the " +
                 quantity(n, "triangle", "triangles") + " its binary STL header announces");
    Soup soup;
    soup.polygons.reserve(n);
    CornerMerger merger(soup, n / 2 + 3);
    const bool swap = std::endian::native == std::endian::big;
    for (std::uint32_t i = 0; i < n; ++i) {
        const char* rec = d.data() + 84 + 50 * std::size_t(i);
        Polygon tri(3);
        for (std::size_t c = 0; c < 3; ++c) {
            std::array<double, 3> xyz{};
            for (std::size_t k = 0; k < 3; ++k)
                xyz[k] = loadBinary<float>(rec + 12 + 12 * c + 4 * k, swap);
            if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
                src.fail("triangle " + std::to_string(i) + " has a NaN or infinite coordinate");
            tri[c] = merger.add({xyz[0], xyz[1], xyz[2]});
        }
        soup.polygons.push_back(std::move(tri));
    }
    return soup;
}

} // namespace

bool isBinaryStlOfExactSize(std::string_view d) {
    if (d.size() < 84) return false;
    const auto n = loadBinary<std::uint32_t>(d.data() + 80, std::endian::native == std::endian::big);
    return 84 + 50 * std::uint64_t(n) == d.size();
}

Soup readStl(const Source& src, ReadReport& report) {
    report.format = "stl";
    // A binary file of the announced size, else ascii when it starts with 'solid' and is text.
    const std::string_view d = src.data;
    if (!isBinaryStlOfExactSize(d) && startsWithWordNoCase(skipBomAndSpace(d), "solid") && looksLikeText(d))
        return parseStlAscii(src);
    report.binary = true;
    return parseStlBinary(src);
}

void writeStl(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options) {
    // STL holds triangles only: faces with more corners are written as fans.
    std::size_t triangles = 0;
    for (std::size_t f = 0; f < m.faces(); ++f)
        triangles += m.degree(f) >= 3 ? m.degree(f) - 2 : 0;
    if (options.binary && triangles > std::numeric_limits<std::uint32_t>::max())
        failWrite(path, "binary STL cannot hold more than 4294967295 triangles");
    const bool binary = options.binary;
    const int precision = options.precision;
    AtomicFile file(path);
    std::string& s = file.out();
    if (binary) {
        std::string header = "FSS binary STL"; // must not start with "solid"
        header.resize(80, ' ');
        s += header;
        putBinary(s, static_cast<std::uint32_t>(triangles), false);
    }
    auto writeFace = [&](std::size_t f) {
        for (std::size_t j = 1; j + 1 < m.degree(f); ++j) {
            const std::array<const Point3*, 3> p{&m.points[m.corner(f, 0)], &m.points[m.corner(f, j)],
                                                 &m.points[m.corner(f, j + 1)]};
            Vector3 n = CGAL::cross_product(*p[1] - *p[0], *p[2] - *p[0]);
            const double len = std::sqrt(n.squared_length());
            n = len > 0 && std::isfinite(len) ? n / len : Vector3(0, 0, 0);
            if (binary) {
                for (int k = 0; k < 3; ++k)
                    putBinary(s, static_cast<float>(n[k]), false);
                for (const Point3* q : p)
                    for (int k = 0; k < 3; ++k)
                        putBinary(s, static_cast<float>((*q)[k]), false);
                putBinary(s, std::uint16_t(0), false);
            } else {
                s += "  facet normal ";
                putPoint(s, CGAL::ORIGIN + n, 9);
                s += "\n    outer loop\n";
                for (const Point3* q : p) {
                    s += "      vertex ";
                    putPoint(s, *q, precision);
                    s += '\n';
                }
                s += "    endloop\n  endfacet\n";
            }
            file.flushIfLarge();
        }
    };
    // Ascii with groups: one solid per group (the faces in no group form a solid named "fss").
    const bool solids = !binary && m.hasGroups;
    const auto groups = std::int32_t(m.groupNames.size());
    auto groupOf = [&](std::size_t f) {
        return m.group[f] >= 0 && m.group[f] < groups ? m.group[f] : kNoGroup;
    };
    bool anyUngrouped = !solids;
    for (std::size_t f = 0; solids && f < m.faces(); ++f)
        anyUngrouped = anyUngrouped || groupOf(f) == kNoGroup;
    for (std::int32_t g = anyUngrouped ? kNoGroup : 0; g < (solids ? groups : 0); ++g) {
        const std::string name = g >= 0 ? m.groupNames[std::size_t(g)] : std::string("fss");
        if (!binary) s += "solid " + name + "\n";
        for (std::size_t f = 0; f < m.faces(); ++f)
            if (!solids || groupOf(f) == g) writeFace(f);
        if (!binary) s += "endsolid " + name + "\n";
    }
    file.commit();
}

} // namespace fss::detail::io
