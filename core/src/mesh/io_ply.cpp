// PLY: the strict reader (ascii, binary little and big endian; face properties quality, scan_id and group,
// with group names from "comment group <value> <name>" header lines) and the writer.
#include "mesh/io_detail.h"

#include <cmath>
#include <limits>

namespace fss::detail::io {
namespace {

enum class PlyType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

std::optional<PlyType> plyType(std::string_view n) {
    if (n == "char" || n == "int8") return PlyType::Int8;
    if (n == "uchar" || n == "uint8") return PlyType::Uint8;
    if (n == "short" || n == "int16") return PlyType::Int16;
    if (n == "ushort" || n == "uint16") return PlyType::Uint16;
    if (n == "int" || n == "int32") return PlyType::Int32;
    if (n == "uint" || n == "uint32") return PlyType::Uint32;
    if (n == "float" || n == "float32") return PlyType::Float32;
    if (n == "double" || n == "float64") return PlyType::Float64;
    return std::nullopt;
}

std::size_t plySize(PlyType t) {
    switch (t) {
    case PlyType::Int8:
    case PlyType::Uint8:
        return 1;
    case PlyType::Int16:
    case PlyType::Uint16:
        return 2;
    case PlyType::Int32:
    case PlyType::Uint32:
    case PlyType::Float32:
        return 4;
    case PlyType::Float64:
        return 8;
    }
    return 8;
}

bool plyIsInteger(PlyType t) {
    return t != PlyType::Float32 && t != PlyType::Float64;
}

struct PlyProperty {
    std::string name;
    bool list = false;
    PlyType countType = PlyType::Uint8;
    PlyType type = PlyType::Float32;
};

struct PlyElement {
    std::string name;
    unsigned long long count = 0;
    std::vector<PlyProperty> properties;
};

/// Reads values of the binary body; every read is bounds-checked.
class PlyBinaryReader {
public:
    PlyBinaryReader(const Source& src, std::string_view body, bool bigEndian)
        : src_(src), body_(body), swap_(bigEndian != (std::endian::native == std::endian::big)) {}

    void begin(const PlyElement& e, unsigned long long index) {
        element_ = &e;
        index_ = index;
    }
    std::string where() const { return ""; }
    double scalar(PlyType t) {
        need(plySize(t));
        const char* p = body_.data() + pos_;
        pos_ += plySize(t);
        switch (t) {
        case PlyType::Int8:
            return loadBinary<std::int8_t>(p, false);
        case PlyType::Uint8:
            return loadBinary<std::uint8_t>(p, false);
        case PlyType::Int16:
            return loadBinary<std::int16_t>(p, swap_);
        case PlyType::Uint16:
            return loadBinary<std::uint16_t>(p, swap_);
        case PlyType::Int32:
            return loadBinary<std::int32_t>(p, swap_);
        case PlyType::Uint32:
            return loadBinary<std::uint32_t>(p, swap_);
        case PlyType::Float32:
            return loadBinary<float>(p, swap_);
        case PlyType::Float64:
            return loadBinary<double>(p, swap_);
        }
        return 0;
    }
    void skip(PlyType t, unsigned long long n) {
        if (n > (body_.size() - pos_) / plySize(t)) truncated();
        pos_ += static_cast<std::size_t>(n) * plySize(t);
    }
    /// Fails early when a list announces more items than the remaining bytes can hold.
    void expectItems(PlyType t, unsigned long long n) {
        if (n > (body_.size() - pos_) / plySize(t)) truncated();
    }
    void end() {}
    void finish() {
        const std::string_view rest = body_.substr(pos_);
        if (std::any_of(rest.begin(), rest.end(), [](char c) { return c != 0 && !isSpace(c); }))
            src_.fail("it has " + quantity(rest.size(), "byte", "bytes") +
                      " of unexpected data after the last element the header announces");
    }

private:
    void need(std::size_t n) {
        if (body_.size() - pos_ < n) truncated();
    }
    [[noreturn]] void truncated() const {
        src_.fail("the binary data ends inside " + element_->name + " " + std::to_string(index_) +
                  " although the header announces " + std::to_string(element_->count) + " " + element_->name +
                  " elements (the file is truncated)");
    }

    const Source& src_;
    std::string_view body_;
    std::size_t pos_ = 0;
    bool swap_;
    const PlyElement* element_ = nullptr;
    unsigned long long index_ = 0;
};

/// Reads values of the ascii body: one element per line.
class PlyAsciiReader {
public:
    PlyAsciiReader(const Source& src, std::string_view body, std::size_t firstLine)
        : src_(src), lines_(body, '\0', firstLine), tokens_(std::string_view{}) {}

    void begin(const PlyElement& e, unsigned long long index) {
        element_ = &e;
        index_ = index;
        std::string_view line;
        if (!lines_.next(line))
            src_.fail("the header announces " + std::to_string(e.count) + " " + e.name +
                      " elements but the file ends after " + std::to_string(index) +
                      " (the file is truncated)");
        tokens_ = Tokens(line);
    }
    std::string where() const { return lines_.where(); }
    double scalar(PlyType t) {
        std::string_view tok;
        if (!tokens_.next(tok))
            src_.fail(where() + element_->name + " " + std::to_string(index_) +
                      " has fewer values than the header declares");
        if (plyIsInteger(t)) {
            long long v = 0;
            if (!parseInteger(tok, v))
                src_.fail(where() + "expected an integer in " + element_->name + " " +
                          std::to_string(index_) + " but found " + quoteToken(tok));
            return static_cast<double>(v);
        }
        double v = 0;
        const NumberParse r = parseDouble(tok, v);
        if (r == NumberParse::NotANumber)
            src_.fail(where() + "expected a number in " + element_->name + " " + std::to_string(index_) +
                      " but found " + quoteToken(tok));
        if (r == NumberParse::OutOfRange) v = std::numeric_limits<double>::infinity();
        return v;
    }
    void skip(PlyType t, unsigned long long n) {
        for (unsigned long long i = 0; i < n; ++i)
            scalar(t);
    }
    void expectItems(PlyType, unsigned long long) {}
    void end() {
        std::string_view tok;
        if (tokens_.next(tok))
            src_.fail(where() + element_->name + " " + std::to_string(index_) +
                      " has more values than the header declares (" + quoteToken(tok) + ")");
    }
    void finish() {
        std::string_view line;
        if (lines_.next(line))
            src_.fail(where() + "unexpected data after the last element the header announces");
    }

private:
    const Source& src_;
    Lines lines_;
    Tokens tokens_;
    const PlyElement* element_ = nullptr;
    unsigned long long index_ = 0;
};

struct PlyLayout {
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    std::size_t x = 0, y = 0, z = 0;
    std::size_t indices = 0;
    std::optional<std::size_t> quality, scanId, group;
};

template <class Reader>
void readPlyBody(const Source& src, Reader& r, const std::vector<PlyElement>& elements,
                 const PlyLayout& layout, Soup& soup) {
    bool verticesKnown = false;
    for (const PlyElement& e : elements) {
        const bool isVertex = &e == layout.vertex;
        const bool isFace = &e == layout.face;
        if (e.properties.empty()) continue; // nothing stored per element
        for (unsigned long long k = 0; k < e.count; ++k) {
            r.begin(e, k);
            std::array<double, 3> xyz{0, 0, 0};
            Polygon poly;
            for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
                const PlyProperty& p = e.properties[pi];
                if (p.list) {
                    const double n = r.scalar(p.countType);
                    if (n < 0)
                        src.fail(r.where() + e.name + " " + std::to_string(k) + " has a negative list size");
                    const auto items = static_cast<unsigned long long>(n);
                    if (!(isFace && pi == layout.indices)) {
                        r.skip(p.type, items);
                        continue;
                    }
                    if (items < 3)
                        src.fail(r.where() + "face " + std::to_string(k) + " has " + std::to_string(items) +
                                 " corners, but a face needs at least 3");
                    r.expectItems(p.type, items);
                    poly.reserve(static_cast<std::size_t>(std::min<unsigned long long>(items, 64)));
                    for (unsigned long long c = 0; c < items; ++c) {
                        const double index = r.scalar(p.type);
                        const std::size_t nv = soup.points.size();
                        if (index < 0 || (verticesKnown && index >= double(nv)))
                            src.fail(r.where() + "face " + std::to_string(k) + " uses vertex index " +
                                     std::to_string(static_cast<long long>(index)) + ", but the file has " +
                                     (nv == 0 ? std::string("no vertices")
                                              : "only " + quantity(nv, "vertex", "vertices") +
                                                    " (indices 0 to " + std::to_string(nv - 1) + ")"));
                        poly.push_back(static_cast<std::size_t>(index));
                    }
                    continue;
                }
                const double v = r.scalar(p.type);
                if (isVertex) {
                    if (pi == layout.x) xyz[0] = v;
                    if (pi == layout.y) xyz[1] = v;
                    if (pi == layout.z) xyz[2] = v;
                } else if (isFace && layout.quality && pi == *layout.quality) {
                    soup.quality.push_back(static_cast<float>(v));
                } else if (isFace && layout.scanId && pi == *layout.scanId) {
                    if (!(v >= std::numeric_limits<std::int32_t>::min() &&
                          v <= std::numeric_limits<std::int32_t>::max() && v == std::floor(v)))
                        src.fail(r.where() + "face " + std::to_string(k) + " has scan_id " +
                                 std::to_string(v) + ", which is not a 32-bit integer");
                    soup.scanId.push_back(static_cast<std::int32_t>(v));
                } else if (isFace && layout.group && pi == *layout.group) {
                    if (!(v >= std::numeric_limits<std::int32_t>::min() &&
                          v <= std::numeric_limits<std::int32_t>::max()))
                        src.fail(r.where() + "face " + std::to_string(k) + " has group " + std::to_string(v) +
                                 ", which is not a 32-bit integer");
                    soup.group.push_back(static_cast<std::int32_t>(v));
                }
            }
            r.end();
            if (isVertex) {
                if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
                    src.fail(r.where() + "vertex " + std::to_string(k) + " has a NaN or infinite coordinate");
                soup.points.emplace_back(xyz[0], xyz[1], xyz[2]);
            }
            if (isFace) soup.polygons.push_back(std::move(poly));
        }
        if (isVertex) verticesKnown = true;
    }
    r.finish();
    // Faces listed before the vertices: check their indices now.
    const std::size_t nv = soup.points.size();
    for (std::size_t f = 0; f < soup.polygons.size(); ++f)
        for (std::size_t index : soup.polygons[f])
            if (index >= nv)
                src.fail(
                    "face " + std::to_string(f) + " uses vertex index " + std::to_string(index) +
                    ", but the file has " +
                    (nv == 0 ? std::string("no vertices") : "only " + quantity(nv, "vertex", "vertices")));
}

Soup parsePly(const Source& src, bool& binary) {
    const std::string_view text = src.data;
    std::size_t pos = 0, lineNo = 0;
    auto nextHeaderLine = [&](std::string_view& line) {
        if (pos >= text.size()) return false;
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        line = text.substr(pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos = std::min(end + 1, text.size());
        ++lineNo;
        return true;
    };
    std::string_view line, t;
    nextHeaderLine(line);
    if (line != "ply") src.fail("it does not start with the PLY magic line 'ply'");

    enum class Encoding { Ascii, Little, Big };
    std::optional<Encoding> encoding;
    std::vector<PlyElement> elements;
    std::vector<std::pair<long long, std::string>> groupComments; // "comment group <value> <name>"
    bool ended = false;
    while (!ended && nextHeaderLine(line)) {
        const std::string where = "header line " + std::to_string(lineNo) + ": ";
        Tokens tok(line);
        if (!tok.next(t)) continue;
        if (t == "comment") {
            std::string_view word, value;
            long long v = 0;
            if (tok.next(word) && word == "group" && tok.next(value) && parseInteger(value, v)) {
                std::string_view rest = line.substr(std::size_t(value.data() + value.size() - line.data()));
                while (!rest.empty() && isBlank(rest.front()))
                    rest.remove_prefix(1);
                while (!rest.empty() && isBlank(rest.back()))
                    rest.remove_suffix(1);
                if (!rest.empty()) groupComments.emplace_back(v, std::string(rest));
            }
            continue;
        }
        if (t == "obj_info") continue;
        if (t == "end_header") {
            ended = true;
        } else if (t == "format") {
            tok.next(t);
            if (t == "ascii")
                encoding = Encoding::Ascii;
            else if (t == "binary_little_endian")
                encoding = Encoding::Little;
            else if (t == "binary_big_endian")
                encoding = Encoding::Big;
            else
                src.fail(where + "unknown PLY format " + quoteToken(t));
        } else if (t == "element") {
            PlyElement e;
            std::string_view name, n;
            long long c = 0;
            if (!tok.next(name) || !tok.next(n) || !parseInteger(n, c) || c < 0)
                src.fail(where + "expected 'element <name> <count>'");
            e.name = std::string(name);
            e.count = static_cast<unsigned long long>(c);
            elements.push_back(std::move(e));
        } else if (t == "property") {
            if (elements.empty()) src.fail(where + "a property comes before any element");
            PlyProperty p;
            std::string_view a, b, c;
            tok.next(a);
            if (a == "list") {
                tok.next(b);
                tok.next(c);
                const auto ct = plyType(b), it = plyType(c);
                std::string_view name;
                if (!ct || !it || !tok.next(name) || !plyIsInteger(*ct))
                    src.fail(where + "expected 'property list <integer type> <type> <name>'");
                p.list = true;
                p.countType = *ct;
                p.type = *it;
                p.name = std::string(name);
            } else {
                const auto st = plyType(a);
                std::string_view name;
                if (!st || !tok.next(name))
                    src.fail(where + "expected 'property <type> <name>' but found the type " + quoteToken(a));
                p.type = *st;
                p.name = std::string(name);
            }
            elements.back().properties.push_back(std::move(p));
        } else {
            src.fail(where + "unexpected " + quoteToken(t));
        }
    }
    if (!ended) src.fail("its PLY header has no 'end_header' line (the file is truncated or not a PLY file)");
    if (!encoding) src.fail("its PLY header has no 'format' line");
    binary = *encoding != Encoding::Ascii;

    PlyLayout layout;
    for (const PlyElement& e : elements) {
        if (e.name == "vertex" && !layout.vertex) layout.vertex = &e;
        if (e.name == "face" && !layout.face) layout.face = &e;
    }
    if (!layout.vertex) src.fail("its PLY header declares no 'vertex' element");
    if (!layout.face) src.fail("its PLY header declares no 'face' element, so it holds no surface");
    auto findProperty = [](const PlyElement& e, std::string_view name) -> std::optional<std::size_t> {
        for (std::size_t i = 0; i < e.properties.size(); ++i)
            if (e.properties[i].name == name) return i;
        return std::nullopt;
    };
    const auto x = findProperty(*layout.vertex, "x"), y = findProperty(*layout.vertex, "y"),
               z = findProperty(*layout.vertex, "z");
    if (!x || !y || !z || layout.vertex->properties[*x].list || layout.vertex->properties[*y].list ||
        layout.vertex->properties[*z].list)
        src.fail("its vertex element lacks one of the scalar properties 'x', 'y' and 'z'");
    layout.x = *x;
    layout.y = *y;
    layout.z = *z;
    auto indices = findProperty(*layout.face, "vertex_indices");
    if (!indices) indices = findProperty(*layout.face, "vertex_index");
    if (!indices || !layout.face->properties[*indices].list ||
        !plyIsInteger(layout.face->properties[*indices].type))
        src.fail("its face element has no integer list property 'vertex_indices'");
    layout.indices = *indices;
    layout.quality = findProperty(*layout.face, "quality");
    layout.scanId = findProperty(*layout.face, "scan_id");
    if (layout.quality && layout.face->properties[*layout.quality].list) layout.quality.reset();
    if (layout.scanId && layout.face->properties[*layout.scanId].list) layout.scanId.reset();
    layout.group = findProperty(*layout.face, "group");
    if (layout.group && (layout.face->properties[*layout.group].list ||
                         !plyIsInteger(layout.face->properties[*layout.group].type)))
        src.fail("its face property 'group' is not a scalar integer, but FSS reads face groups as integers");

    // Guard the announced counts against the size of the data before reading anything.
    const std::string_view body = text.substr(pos);
    unsigned long long minimum = 0;
    for (const PlyElement& e : elements) {
        unsigned long long each = 0;
        for (const PlyProperty& p : e.properties)
            each += binary ? plySize(p.list ? p.countType : p.type) : 2;
        if (each == 0) continue;
        const unsigned long long room = (body.size() + 1) / each;
        if (e.count > room || minimum > (body.size() + 1) - e.count * each)
            src.fail("the header announces " + std::to_string(e.count) + " " + e.name +
                     " elements, more than the " + quantity(body.size(), "byte", "bytes") +
                     " of data can hold (the file is truncated)");
        minimum += e.count * each;
    }

    Soup soup;
    soup.points.reserve(boundedReserve(layout.vertex->count, body.size(), 3));
    soup.polygons.reserve(boundedReserve(layout.face->count, body.size(), 4));
    if (binary) {
        PlyBinaryReader reader(src, body, *encoding == Encoding::Big);
        readPlyBody(src, reader, elements, layout, soup);
    } else {
        PlyAsciiReader reader(src, body, lineNo + 1);
        readPlyBody(src, reader, elements, layout, soup);
    }
    // Group values → group indices in order of first use, named by "comment group <value> <name>" lines.
    std::vector<std::pair<long long, std::int32_t>> seen;
    for (std::int32_t& g : soup.group) {
        if (g < 0) { // a face in no group
            g = kNoGroup;
            continue;
        }
        const auto it = std::find_if(seen.begin(), seen.end(), [&](const auto& e) { return e.first == g; });
        if (it != seen.end()) {
            g = it->second;
            continue;
        }
        const auto named = std::find_if(groupComments.begin(), groupComments.end(),
                                        [&](const auto& c) { return c.first == g; });
        const std::string name = named != groupComments.end() ? named->second : "group_" + std::to_string(g);
        seen.emplace_back(g, groupIndex(soup, name));
        g = seen.back().second;
    }
    return soup;
}

} // namespace

Soup readPly(const Source& src, ReadReport& report) {
    report.format = "ply";
    return parsePly(src, report.binary);
}

void writePly(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options) {
    if (m.points.size() > std::size_t(std::numeric_limits<std::int32_t>::max()))
        failWrite(path, "PLY files written by FSS cannot index more than 2147483647 vertices");
    const bool binary = options.binary;
    const int precision = options.precision;
    AtomicFile file(path);
    std::string& s = file.out();
    const bool bigEndian = std::endian::native == std::endian::big;
    std::size_t maxDegree = 0;
    for (std::size_t f = 0; f < m.faces(); ++f)
        maxDegree = std::max(maxDegree, m.degree(f));
    const bool wideCount = maxDegree > 255;
    s += "ply\nformat ";
    s += !binary ? "ascii" : bigEndian ? "binary_big_endian" : "binary_little_endian";
    s += " 1.0\ncomment written by FSS\n";
    for (std::size_t i = 0; m.hasGroups && i < m.groupNames.size(); ++i)
        s += "comment group " + std::to_string(i) + " " + m.groupNames[i] + "\n";
    s += "element vertex ";
    putInteger(s, m.points.size());
    s += "\nproperty double x\nproperty double y\nproperty double z\nelement face ";
    putInteger(s, m.faces());
    s += wideCount ? "\nproperty list uint int vertex_indices\n"
                   : "\nproperty list uchar int vertex_indices\n";
    if (m.hasQuality) s += "property float quality\n";
    if (m.hasScanId) s += "property int scan_id\n";
    if (m.hasGroups) s += "property int group\n";
    s += "end_header\n";
    for (const Point3& p : m.points) {
        if (binary) {
            putBinary(s, p.x(), bigEndian);
            putBinary(s, p.y(), bigEndian);
            putBinary(s, p.z(), bigEndian);
        } else {
            putPoint(s, p, precision);
            s += '\n';
        }
        file.flushIfLarge();
    }
    for (std::size_t f = 0; f < m.faces(); ++f) {
        const std::size_t d = m.degree(f);
        if (binary) {
            if (wideCount)
                putBinary(s, static_cast<std::uint32_t>(d), bigEndian);
            else
                putBinary(s, static_cast<std::uint8_t>(d), bigEndian);
            for (std::size_t j = 0; j < d; ++j)
                putBinary(s, static_cast<std::int32_t>(m.corner(f, j)), bigEndian);
            if (m.hasQuality) putBinary(s, m.quality[f], bigEndian);
            if (m.hasScanId) putBinary(s, m.scanId[f], bigEndian);
            if (m.hasGroups) putBinary(s, m.group[f], bigEndian);
        } else {
            putInteger(s, d);
            for (std::size_t j = 0; j < d; ++j) {
                s += ' ';
                putInteger(s, m.corner(f, j));
            }
            if (m.hasQuality) {
                s += ' ';
                putFloat(s, m.quality[f]);
            }
            if (m.hasScanId) {
                s += ' ';
                putInteger(s, m.scanId[f]);
            }
            if (m.hasGroups) {
                s += ' ';
                putInteger(s, m.group[f]);
            }
            s += '\n';
        }
        file.flushIfLarge();
    }
    file.commit();
}

} // namespace fss::detail::io
