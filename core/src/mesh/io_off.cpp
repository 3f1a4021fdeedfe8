// OFF: the strict reader (header keyword [ST][C][N][4][n]OFF, counts, vertices, faces) and the writer.
#include "mesh/io_detail.h"

namespace fss::detail::io {
namespace {

/// OFF header keywords: [ST][C][N][4][n]OFF.
struct OffKeyword {
    bool valid = false;
    bool homogeneous = false; // 4OFF
    bool dimension = false;   // nOFF
};
OffKeyword parseOffKeyword(std::string_view t) {
    OffKeyword k;
    if (t.substr(0, 2) == "ST") t.remove_prefix(2);
    if (t.substr(0, 1) == "C") t.remove_prefix(1);
    if (t.substr(0, 1) == "N") t.remove_prefix(1);
    if (t.substr(0, 1) == "4") {
        t.remove_prefix(1);
        k.homogeneous = true;
    }
    if (t.substr(0, 1) == "n") {
        t.remove_prefix(1);
        k.dimension = true;
    }
    k.valid = t == "OFF";
    return k;
}

} // namespace

bool isOffKeyword(std::string_view t) {
    return parseOffKeyword(t).valid;
}

Soup readOff(const Source& src, ReadReport& report) {
    report.format = "off";
    Lines lines(skipBomAndSpace(src.data), '#');
    std::string_view line, t;
    if (!lines.next(line)) src.fail("it contains only comments");
    Tokens header(line);
    header.next(t);
    const OffKeyword kw = parseOffKeyword(t);
    if (!kw.valid)
        src.fail(lines.where() + "expected the OFF header keyword ('OFF', 'COFF', 'NOFF', ...) but found " +
                 quoteToken(t));

    // The header numbers ([dimension] vertices faces [edges]) may follow on the same line or the next ones.
    const std::size_t need = kw.dimension ? 3 : 2;
    std::vector<long long> numbers;
    Tokens* tok = &header;
    Tokens next{std::string_view{}};
    while (true) {
        while (numbers.size() < need + 1 && tok->next(t)) {
            long long v = 0;
            if (t == "BINARY") src.fail("binary OFF files are not supported");
            if (!parseInteger(t, v))
                src.fail(lines.where() + "expected the vertex and face counts of the OFF header but found " +
                         quoteToken(t));
            numbers.push_back(v);
        }
        if (numbers.size() >= need) break;
        if (!lines.next(line)) src.fail("the file ends before the vertex and face counts of the OFF header");
        next = Tokens(line);
        tok = &next;
    }
    if (tok->next(t)) src.fail(lines.where() + "unexpected " + quoteToken(t) + " in the OFF header");
    if (kw.dimension && numbers[0] != 3)
        src.fail("only 3-dimensional OFF files are supported but this one has dimension " +
                 std::to_string(numbers[0]));
    const long long nv = numbers[need - 2];
    const long long nf = numbers[need - 1];
    if (nv < 0 || nf < 0) src.fail(lines.where() + "the OFF header announces a negative count");

    Soup soup;
    soup.points.reserve(boundedReserve(static_cast<unsigned long long>(nv), src.data.size(), 6));
    for (long long i = 0; i < nv; ++i) {
        if (!lines.next(line))
            src.fail("the header announces " + std::to_string(nv) + " vertices but the file ends after " +
                     std::to_string(i) + " (the file is truncated)");
        Tokens vt(line);
        const std::string where = lines.where();
        soup.points.push_back(readCoordinates(src, vt, where, std::size_t(i), kw.homogeneous));
        expectOnlyNumbers(src, vt, where, "the coordinates of vertex " + std::to_string(i));
    }

    soup.polygons.reserve(boundedReserve(static_cast<unsigned long long>(nf), src.data.size(), 8));
    for (long long f = 0; f < nf; ++f) {
        if (!lines.next(line))
            src.fail("the header announces " + std::to_string(nf) + " faces but the file ends after " +
                     std::to_string(f) + " (the file is truncated)");
        Tokens ft(line);
        const std::string where = lines.where();
        const std::string face = "face " + std::to_string(f);
        long long corners = 0;
        ft.next(t);
        if (!parseInteger(t, corners))
            src.fail(where + "expected the corner count of " + face + " but found " + quoteToken(t));
        if (corners < 3)
            src.fail(where + face + " has " + std::to_string(corners) +
                     " corners, but a face needs at least 3");
        Polygon poly;
        for (long long c = 0; c < corners; ++c) {
            if (!ft.next(t))
                src.fail(where + face + " announces " + std::to_string(corners) + " corners but lists " +
                         std::to_string(c));
            long long index = 0;
            if (!parseInteger(t, index))
                src.fail(where + "expected a vertex index of " + face + " but found " + quoteToken(t));
            if (index < 0 || index >= nv)
                src.fail(where + face + " uses vertex index " + std::to_string(index) +
                         ", but the file has " +
                         (nv == 0 ? std::string("no vertices")
                                  : "only " + quantity(std::size_t(nv), "vertex", "vertices") +
                                        " (indices 0 to " + std::to_string(nv - 1) + ")"));
            poly.push_back(std::size_t(index));
        }
        expectOnlyNumbers(src, ft, where, "the corners of " + face);
        soup.polygons.push_back(std::move(poly));
    }
    if (lines.next(line))
        src.fail(lines.where() + "unexpected data after the " + quantity(std::size_t(nf), "face", "faces") +
                 " the header announces");
    return soup;
}

void writeOff(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options) {
    const int precision = options.precision;
    AtomicFile file(path);
    std::string& s = file.out();
    s += "OFF\n";
    putInteger(s, m.points.size());
    s += ' ';
    putInteger(s, m.faces());
    s += " 0\n";
    for (const Point3& p : m.points) {
        putPoint(s, p, precision);
        s += '\n';
        file.flushIfLarge();
    }
    for (std::size_t f = 0; f < m.faces(); ++f) {
        putInteger(s, m.degree(f));
        for (std::size_t j = 0; j < m.degree(f); ++j) {
            s += ' ';
            putInteger(s, m.corner(f, j));
        }
        s += '\n';
        file.flushIfLarge();
    }
    file.commit();
}

} // namespace fss::detail::io
