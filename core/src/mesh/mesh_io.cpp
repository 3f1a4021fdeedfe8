// Mesh I/O: strict parsers for OFF, OBJ, PLY and STL into a polygon soup, soup statistics, repair with
// CGAL's polygon-soup functions, and writers that replace the target atomically. See fss/mesh_io.h.
#include "base/disjoint_sets.h"
#include "fss/mesh_io.h"

#include "fss/error.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/boost/graph/iterator.h>

#include <boost/container/small_vector.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <string_view>
#include <system_error>

namespace fs = std::filesystem;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace fss {
namespace {

// =====================================================================================================
// Small helpers
// =====================================================================================================

/// "1 point", "3 points".
std::string quantity(std::size_t n, std::string_view singular, std::string_view plural) {
    return std::to_string(n) + " " + std::string(n == 1 ? singular : plural);
}

/// A token as it may appear in a message: quoted, at most 24 characters, non-printable bytes escaped.
std::string quoteToken(std::string_view token) {
    std::string s = "'";
    const std::size_t shown = std::min<std::size_t>(token.size(), 24);
    for (std::size_t i = 0; i < shown; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        if (c >= 0x20 && c < 0x7f) {
            s += static_cast<char>(c);
        } else {
            static constexpr char hex[] = "0123456789abcdef";
            s += "\\x";
            s += hex[c >> 4];
            s += hex[c & 15];
        }
    }
    if (shown < token.size()) s += "...";
    return s + "'";
}

std::string lower(std::string_view s) {
    std::string r(s);
    for (char& c : r)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

bool equalsNoCase(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    return true;
}

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
bool isSpace(char c) {
    return isBlank(c) || c == '\n';
}

enum class NumberParse { Ok, NotANumber, OutOfRange };

/// Parses a whole token as a double (locale independent, correctly rounded). Accepts a leading '+'.
NumberParse parseDouble(std::string_view t, double& value) {
    if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
    if (t.empty()) return NumberParse::NotANumber;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
    if (r.ptr != t.data() + t.size()) return NumberParse::NotANumber;
    if (r.ec == std::errc::result_out_of_range) {
        // Underflow to (sub)normal zero is harmless; overflow is an infinite coordinate.
        return NumberParse::OutOfRange;
    }
    if (r.ec != std::errc()) return NumberParse::NotANumber;
    return NumberParse::Ok;
}

/// Parses a whole token as a signed 64-bit integer. Accepts a leading '+'.
bool parseInteger(std::string_view t, long long& value) {
    if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
    if (t.empty()) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

/// The non-empty lines of a text, with comments (from `comment` to the end of the line) removed.
class Lines {
public:
    explicit Lines(std::string_view text, char comment = '\0', std::size_t firstLineNumber = 1)
        : text_(text), next_(firstLineNumber), comment_(comment) {}

    /// The next line with content; false at the end of the text.
    bool next(std::string_view& line) {
        while (pos_ < text_.size()) {
            const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
            std::string_view l = text_.substr(pos_, end - pos_);
            pos_ = end + 1;
            number_ = next_++;
            if (comment_ != '\0') l = l.substr(0, std::min(l.find(comment_), l.size()));
            while (!l.empty() && isBlank(l.back()))
                l.remove_suffix(1);
            while (!l.empty() && isBlank(l.front()))
                l.remove_prefix(1);
            if (!l.empty()) {
                line = l;
                return true;
            }
        }
        return false;
    }

    /// Number (from 1) of the line last returned by next().
    std::size_t number() const { return number_; }
    std::string where() const { return "line " + std::to_string(number_) + ": "; }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t next_ = 1;
    std::size_t number_ = 0;
    char comment_ = '\0';
};

/// The white-space separated tokens of one line.
class Tokens {
public:
    explicit Tokens(std::string_view line) : line_(line) {}
    bool next(std::string_view& token) {
        while (pos_ < line_.size() && isBlank(line_[pos_]))
            ++pos_;
        if (pos_ >= line_.size()) return false;
        const std::size_t start = pos_;
        while (pos_ < line_.size() && !isBlank(line_[pos_]))
            ++pos_;
        token = line_.substr(start, pos_ - start);
        return true;
    }

private:
    std::string_view line_;
    std::size_t pos_ = 0;
};

/// The white-space separated tokens of a whole text, with the line number of each token.
class TokenStream {
public:
    explicit TokenStream(std::string_view text) : text_(text) {}
    bool next(std::string_view& token) {
        while (pos_ < text_.size() && isSpace(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ >= text_.size()) return false;
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !isSpace(text_[pos_]))
            ++pos_;
        token = text_.substr(start, pos_ - start);
        tokenLine_ = line_;
        return true;
    }
    /// Skips the rest of the current line (e.g. the name after 'solid').
    void skipLine() {
        while (pos_ < text_.size() && text_[pos_] != '\n')
            ++pos_;
    }
    std::string where() const { return "line " + std::to_string(tokenLine_) + ": "; }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t line_ = 1;
    std::size_t tokenLine_ = 1;
};

template <class T> T loadBinary(const char* p, bool swap) {
    std::array<char, sizeof(T)> bytes;
    std::memcpy(bytes.data(), p, sizeof(T));
    if (swap) std::reverse(bytes.begin(), bytes.end());
    return std::bit_cast<T>(bytes);
}

/// Exact coordinates as a hash key (+0 and -0 are the same point).
struct PointKey {
    double x, y, z;
    bool operator==(const PointKey&) const = default;
};
PointKey keyOf(const Point3& p) {
    auto norm = [](double v) { return v == 0.0 ? 0.0 : v; };
    return {norm(p.x()), norm(p.y()), norm(p.z())};
}
std::uint64_t mixBits(std::uint64_t x) { // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}
std::uint64_t hashOf(const PointKey& k) {
    return mixBits(std::bit_cast<std::uint64_t>(k.x) ^
                   mixBits(std::bit_cast<std::uint64_t>(k.y) ^ mixBits(std::bit_cast<std::uint64_t>(k.z))));
}

/// Finds exactly equal points: an open-addressing hash table of indices into a point vector (which may
/// grow between calls).
class PointTable {
public:
    explicit PointTable(const std::vector<Point3>& points, std::size_t expected = 0) : points_(points) {
        rehash(expected);
    }
    /// The index of the first point seen that equals points[i]; i itself (now remembered) when none does.
    std::size_t firstEqual(std::size_t i) {
        if (2 * (count_ + 1) > slots_.size()) rehash(slots_.size());
        const PointKey key = keyOf(points_[i]);
        const std::size_t mask = slots_.size() - 1;
        for (std::size_t h = hashOf(key) & mask;; h = (h + 1) & mask) {
            const std::size_t s = slots_[h];
            if (s == kEmpty) {
                slots_[h] = i;
                ++count_;
                return i;
            }
            if (keyOf(points_[s]) == key) return s;
        }
    }

private:
    static constexpr std::size_t kEmpty = std::numeric_limits<std::size_t>::max();
    void rehash(std::size_t expected) {
        std::size_t capacity = 16;
        while (capacity < 2 * expected)
            capacity <<= 1;
        std::vector<std::size_t> old = std::move(slots_);
        slots_.assign(capacity, kEmpty);
        for (std::size_t s : old) {
            if (s == kEmpty) continue;
            std::size_t h = hashOf(keyOf(points_[s])) & (capacity - 1);
            while (slots_[h] != kEmpty)
                h = (h + 1) & (capacity - 1);
            slots_[h] = s;
        }
    }

    const std::vector<Point3>& points_;
    std::vector<std::size_t> slots_;
    std::size_t count_ = 0;
};

using detail::DisjointSets;

// =====================================================================================================
// The soup and the file it comes from
// =====================================================================================================

/// Corner indices of one polygon; triangles and quads need no heap allocation.
using Polygon = boost::container::small_vector<std::size_t, 4>;

/// Points and polygons as read, with optional per-polygon PLY properties.
struct Soup {
    std::vector<Point3> points;
    std::vector<Polygon> polygons;
    std::vector<float> quality;       ///< per polygon, empty when the file has none
    std::vector<std::int32_t> scanId; ///< per polygon, empty when the file has none
};

/// The bytes of a file plus its name for messages.
struct Source {
    fs::path path;
    std::string data;

    [[noreturn]] void fail(const std::string& problem) const {
        throw IoError("Cannot read mesh file '" + path.string() + "': " + problem + ".");
    }
};

/// Largest count the parsers reserve up front; beyond it containers grow as data actually arrives, so a
/// corrupt header count can never trigger a huge allocation.
constexpr std::size_t kMaxReserve = std::size_t(1) << 20;

std::size_t boundedReserve(unsigned long long announced, std::size_t bytes, std::size_t minBytesEach) {
    return static_cast<std::size_t>(
        std::min<unsigned long long>({announced, bytes / minBytesEach + 1, kMaxReserve}));
}

Source loadFile(const fs::path& path) {
    Source src{path, {}};
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) src.fail("the file does not exist");
    if (ec) src.fail("its status cannot be read (" + ec.message() + ")");
    if (fs::is_directory(status)) src.fail("it is a folder, not a file");
    // Reading a FIFO or a device could block forever.
    if (!fs::is_regular_file(status)) src.fail("it is not a regular file");
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int err = errno;
        src.fail("it cannot be opened (" +
                 (err ? std::generic_category().message(err) : std::string("permission denied?")) + ")");
    }
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) src.fail("its size cannot be read (" + ec.message() + ")");
    if (size > std::uintmax_t(src.data.max_size()) || size > std::uintmax_t(SIZE_MAX / 2))
        src.fail("it is too large to be read into memory");
    src.data.resize(static_cast<std::size_t>(size));
    in.read(src.data.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::uintmax_t>(in.gcount()) != size)
        src.fail("it cannot be read (" + (errno ? std::generic_category().message(errno) : "read error") +
                 ")");
    if (src.data.empty()) src.fail("the file is empty");
    if (std::all_of(src.data.begin(), src.data.end(), isSpace))
        src.fail("the file contains only white space");
    return src;
}

// =====================================================================================================
// Format detection
// =====================================================================================================

enum class Format { Off, Obj, Ply, StlAscii, StlBinary };

std::string_view skipBomAndSpace(std::string_view d) {
    if (d.substr(0, 3) == "\xEF\xBB\xBF") d.remove_prefix(3);
    while (!d.empty() && isSpace(d.front()))
        d.remove_prefix(1);
    return d;
}

/// No control bytes other than white space in the first 4 KiB.
bool looksLikeText(std::string_view d) {
    d = d.substr(0, 4096);
    return std::none_of(d.begin(), d.end(), [](char ch) {
        const auto c = static_cast<unsigned char>(ch);
        return c < 0x20 && !isSpace(ch);
    });
}

bool isBinaryStlOfExactSize(std::string_view d) {
    if (d.size() < 84) return false;
    const auto n = loadBinary<std::uint32_t>(d.data() + 80, std::endian::native == std::endian::big);
    return 84 + 50 * std::uint64_t(n) == d.size();
}

bool startsWithWordNoCase(std::string_view d, std::string_view word) {
    return d.size() >= word.size() && equalsNoCase(d.substr(0, word.size()), word) &&
           (d.size() == word.size() || isSpace(d[word.size()]));
}

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

Format stlKind(std::string_view d) {
    if (isBinaryStlOfExactSize(d)) return Format::StlBinary;
    if (startsWithWordNoCase(skipBomAndSpace(d), "solid") && looksLikeText(d)) return Format::StlAscii;
    return Format::StlBinary;
}

std::optional<Format> sniffFormat(std::string_view d) {
    const std::string_view s = skipBomAndSpace(d);
    if (s.size() > 3 && s.substr(0, 3) == "ply" && (s[3] == '\n' || s[3] == '\r')) return Format::Ply;
    std::string_view first = s.substr(0, std::min(s.size(), s.find_first_of(" \t\r\n\f\v#")));
    if (parseOffKeyword(first).valid) return Format::Off;
    if (isBinaryStlOfExactSize(d)) return Format::StlBinary;
    if (!looksLikeText(d)) return std::nullopt;
    if (startsWithWordNoCase(s, "solid")) return Format::StlAscii;
    Lines lines(s, '#');
    std::string_view line, keyword;
    if (lines.next(line) && Tokens(line).next(keyword)) {
        static constexpr std::string_view objStarts[] = {"v", "vt", "vn", "vp",     "f",
                                                         "o", "g",  "s",  "mtllib", "usemtl"};
        if (std::find(std::begin(objStarts), std::end(objStarts), keyword) != std::end(objStarts))
            return Format::Obj;
    }
    return std::nullopt;
}

Format detectFormat(const Source& src) {
    const std::string ext = lower(src.path.extension().string());
    if (ext == ".off") return Format::Off;
    if (ext == ".obj") return Format::Obj;
    if (ext == ".ply") return Format::Ply;
    if (ext == ".stl") return stlKind(src.data);
    if (auto f = sniffFormat(src.data)) return *f;
    src.fail("its format is not recognised: " +
             (ext.empty() ? std::string("it has no extension")
                          : "the extension " + quoteToken(ext) + " is not .off, .obj, .ply or .stl") +
             " and the content is not OFF, OBJ, PLY or STL either");
}

// =====================================================================================================
// OFF
// =====================================================================================================

/// Reads the coordinates of vertex `index` from the tokens of one line (dimension 3, or 4 homogeneous).
Point3 readCoordinates(const Source& src, Tokens& tok, const std::string& where, std::size_t index,
                       bool homogeneous) {
    const int need = homogeneous ? 4 : 3;
    std::array<double, 4> c{0, 0, 0, 1};
    std::string_view t;
    for (int i = 0; i < need; ++i) {
        if (!tok.next(t))
            src.fail(where + "expected " + std::to_string(need) + " coordinates for vertex " +
                     std::to_string(index) + " but found " + std::to_string(i));
        const NumberParse r = parseDouble(t, c[std::size_t(i)]);
        if (r == NumberParse::NotANumber)
            src.fail(where + "expected a coordinate of vertex " + std::to_string(index) + " but found " +
                     quoteToken(t));
        if (r == NumberParse::OutOfRange || !std::isfinite(c[std::size_t(i)]))
            src.fail(where + "vertex " + std::to_string(index) + " has a NaN or infinite coordinate " +
                     quoteToken(t));
    }
    if (homogeneous) {
        if (c[3] == 0.0) src.fail(where + "vertex " + std::to_string(index) + " has homogeneous weight 0");
        for (int i = 0; i < 3; ++i)
            c[std::size_t(i)] /= c[3];
        if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
            src.fail(where + "vertex " + std::to_string(index) + " has an infinite coordinate");
    }
    return {c[0], c[1], c[2]};
}

/// The remaining tokens of a line must be numbers (colours, normals, texture coordinates).
void expectOnlyNumbers(const Source& src, Tokens& tok, const std::string& where, const std::string& after) {
    std::string_view t;
    double ignored = 0;
    while (tok.next(t))
        if (parseDouble(t, ignored) == NumberParse::NotANumber)
            src.fail(where + "unexpected " + quoteToken(t) + " after " + after);
}

Soup parseOff(const Source& src) {
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

// =====================================================================================================
// OBJ
// =====================================================================================================

Soup parseObj(const Source& src) {
    static constexpr std::string_view ignored[] = {
        "vt",       "vn",     "vp",         "l",         "p",     "o",     "g",      "s",     "usemtl",
        "mtllib",   "cstype", "deg",        "bmat",      "step",  "curv",  "curv2",  "surf",  "parm",
        "trim",     "hole",   "scrv",       "sp",        "end",   "con",   "mg",     "bevel", "c_interp",
        "d_interp", "lod",    "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
    Lines lines(skipBomAndSpace(src.data), '#');
    Soup soup;
    std::vector<std::size_t> faceLine;
    std::string_view line, t;
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
            faceLine.push_back(lines.number());
        } else if (std::find(std::begin(ignored), std::end(ignored), t) == std::end(ignored)) {
            src.fail(where + "unknown OBJ statement " + quoteToken(t));
        }
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

// =====================================================================================================
// PLY
// =====================================================================================================

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
    std::optional<std::size_t> quality, scanId;
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
    bool ended = false;
    while (!ended && nextHeaderLine(line)) {
        const std::string where = "header line " + std::to_string(lineNo) + ": ";
        Tokens tok(line);
        if (!tok.next(t)) continue;
        if (t == "comment" || t == "obj_info") continue;
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
    return soup;
}

// =====================================================================================================
// STL
// =====================================================================================================

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
    ts.skipLine();
    while (true) {
        if (!ts.next(t)) src.fail("the file ends without 'endsolid' (the file is truncated)");
        if (equalsNoCase(t, "endsolid")) {
            ts.skipLine();
            if (!ts.next(t)) break;
            if (!equalsNoCase(t, "solid"))
                src.fail(ts.where() + "unexpected " + quoteToken(t) + " after 'endsolid'");
            ts.skipLine();
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

// =====================================================================================================
// Soup statistics
// =====================================================================================================

/// All corners collinear (exact predicate): the polygon has zero area.
bool hasZeroArea(const std::vector<Point3>& pts, const Polygon& poly) {
    const Point3& p = pts[poly[0]];
    std::size_t j = 1;
    while (j < poly.size() && pts[poly[j]] == p)
        ++j;
    if (j == poly.size()) return true;
    const Point3& q = pts[poly[j]];
    for (std::size_t k = j + 1; k < poly.size(); ++k)
        if (!CGAL::collinear(p, q, pts[poly[k]])) return false;
    return true;
}

bool hasRepeatedCorner(const Polygon& p) {
    if (p.size() == 3) return p[0] == p[1] || p[1] == p[2] || p[0] == p[2];
    Polygon sorted = p;
    std::sort(sorted.begin(), sorted.end());
    return std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
}

/// Edge and vertex manifoldness and orientation consistency of a soup whose polygons have no repeated
/// corners. The soup is a valid oriented polygon mesh exactly when all three counts are zero (the
/// condition of CGAL's is_polygon_soup_a_polygon_mesh, computed here in linear time).
struct Topology {
    std::size_t nonManifoldEdges = 0;    ///< undirected edges in more than two polygons
    std::size_t nonManifoldVertices = 0; ///< vertices whose polygons form more than one fan
    std::size_t misorientedEdges = 0;    ///< directed edges used twice (neighbours of opposite orientation)
    bool isMesh() const { return nonManifoldEdges == 0 && nonManifoldVertices == 0 && misorientedEdges == 0; }
};

/// Polygons with skip[f] != 0 (when skip is given) are left out.
Topology analyseTopology(const std::vector<Polygon>& polys, std::size_t pointCount,
                         const std::vector<char>* skip = nullptr) {
    // The corners around each vertex, bucketed by vertex (counting sort): (previous, next) vertex.
    std::vector<std::size_t> start(pointCount + 1, 0);
    for (std::size_t f = 0; f < polys.size(); ++f)
        if (!skip || !(*skip)[f])
            for (std::size_t c : polys[f])
                ++start[c + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::pair<std::size_t, std::size_t>> wedges(start.back());
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (skip && (*skip)[f]) continue;
        const Polygon& p = polys[f];
        const std::size_t m = p.size();
        for (std::size_t j = 0; j < m; ++j)
            wedges[fill[p[j]]++] = {p[(j + m - 1) % m], p[(j + 1) % m]};
    }

    Topology t;
    std::vector<std::pair<std::size_t, bool>> around; // (neighbour, edge points towards it)
    std::vector<std::size_t> neighbours;
    for (std::size_t v = 0; v < pointCount; ++v) {
        const std::size_t b = start[v], e = start[v + 1];
        if (b == e) continue;
        around.clear();
        for (std::size_t k = b; k < e; ++k) {
            around.emplace_back(wedges[k].second, true);
            around.emplace_back(wedges[k].first, false);
        }
        std::sort(around.begin(), around.end());
        neighbours.clear();
        for (std::size_t i = 0; i < around.size();) {
            std::size_t j = i, outgoing = 0;
            for (; j < around.size() && around[j].first == around[i].first; ++j)
                outgoing += around[j].second;
            // Each polygon with the edge v–x has exactly one corner at v next to x.
            if (around[i].first > v && j - i > 2) ++t.nonManifoldEdges;
            if (outgoing > 1) t.misorientedEdges += outgoing - 1;
            neighbours.push_back(around[i].first);
            i = j;
        }
        if (e - b < 2) continue;
        // One fan exactly when the link (segments previous–next around v) is connected.
        auto local = [&](std::size_t x) {
            return std::size_t(std::lower_bound(neighbours.begin(), neighbours.end(), x) -
                               neighbours.begin());
        };
        DisjointSets sets(neighbours.size());
        for (std::size_t k = b; k < e; ++k)
            sets.unite(local(wedges[k].first), local(wedges[k].second));
        std::size_t fans = 0;
        for (std::size_t k = 0; k < neighbours.size(); ++k)
            fans += sets.find(k) == k;
        if (fans > 1) ++t.nonManifoldVertices;
    }
    return t;
}

/// Statistics of the soup as read. `canonical[i]` is the first point equal to point i; `topology` is that
/// of the polygons without repeated corners, equal points identified.
SoupStats computeStats(const Soup& soup, std::vector<std::size_t>& canonical, Topology& topology) {
    SoupStats s;
    s.points = soup.points.size();
    s.polygons = soup.polygons.size();
    canonical.resize(soup.points.size());
    PointTable table(soup.points, soup.points.size());
    for (std::size_t i = 0; i < soup.points.size(); ++i) {
        canonical[i] = table.firstEqual(i);
        if (canonical[i] != i) ++s.duplicatePoints;
    }
    // Topology of the surface the file means: equal points identified, repeated-corner polygons left out.
    std::vector<Polygon> merged;
    if (s.duplicatePoints > 0) {
        merged = soup.polygons;
        for (Polygon& p : merged)
            for (std::size_t& c : p)
                c = canonical[c];
    }
    const std::vector<Polygon>& polys = s.duplicatePoints > 0 ? merged : soup.polygons;
    std::vector<char> repeated(polys.size(), 0);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (polys[f].size() > 3) ++s.nonTriangles;
        repeated[f] = hasRepeatedCorner(polys[f]);
        if (repeated[f] || hasZeroArea(soup.points, soup.polygons[f])) ++s.degeneratePolygons;
    }
    topology = analyseTopology(polys, soup.points.size(), &repeated);
    s.nonManifoldEdges = topology.nonManifoldEdges;
    s.nonManifoldVertices = topology.nonManifoldVertices;
    return s;
}

// =====================================================================================================
// Repair and mesh construction
// =====================================================================================================

/// Polygons with more corners are triangulated as a fan (ear clipping is quadratic).
constexpr std::size_t kMaxEarClippingCorners = 10000;

/// Triangulates one polygon by ear clipping in the plane of its dominant normal axis (exact orientation
/// tests on the projected coordinates), keeping its orientation; falls back to a fan when no ear is left
/// (self-intersecting or zero-area polygons) or when `budget` (point tests left for the whole file, which
/// bounds the time an adversarial file can take) runs out. Returns false when it fell back to a fan for a
/// polygon with area (whose triangles may then overlap).
bool triangulatePolygon(const std::vector<Point3>& pts, const Polygon& poly, std::vector<Polygon>& out,
                        std::size_t& budget) {
    const std::size_t n = poly.size();
    auto fan = [&](const std::vector<std::size_t>& ids) {
        for (std::size_t i = 1; i + 1 < ids.size(); ++i)
            out.push_back({poly[ids[0]], poly[ids[i]], poly[ids[i + 1]]});
    };
    std::vector<std::size_t> remaining(n);
    std::iota(remaining.begin(), remaining.end(), 0);

    std::array<double, 3> normal{0, 0, 0}; // Newell's normal
    for (std::size_t i = 0; i < n; ++i) {
        const Point3& a = pts[poly[i]];
        const Point3& b = pts[poly[(i + 1) % n]];
        normal[0] += (a.y() - b.y()) * (a.z() + b.z());
        normal[1] += (a.z() - b.z()) * (a.x() + b.x());
        normal[2] += (a.x() - b.x()) * (a.y() + b.y());
    }
    std::size_t axis = 0;
    for (std::size_t k = 1; k < 3; ++k)
        if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
    if (normal[axis] == 0.0 || !std::isfinite(normal[axis])) { // zero area: any triangulation will do
        fan(remaining);
        return true;
    }
    if (n > kMaxEarClippingCorners) {
        fan(remaining);
        return false;
    }
    // Dropping the dominant axis and keeping the cyclic order of the other two preserves the sign of the
    // projected area: the polygon turns left in 2D exactly when normal[axis] > 0.
    const CGAL::Orientation convex = normal[axis] > 0 ? CGAL::LEFT_TURN : CGAL::RIGHT_TURN;
    std::vector<Kernel::Point_2> p2(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Point3& p = pts[poly[i]];
        p2[i] = Kernel::Point_2(p[int((axis + 1) % 3)], p[int((axis + 2) % 3)]);
    }

    std::size_t i = 0, failures = 0;
    while (remaining.size() > 3) {
        const std::size_t m = remaining.size();
        if (budget < m) {
            fan(remaining);
            return false;
        }
        i %= m;
        const std::size_t ia = remaining[(i + m - 1) % m], ib = remaining[i], ic = remaining[(i + 1) % m];
        const Kernel::Point_2 &a = p2[ia], &b = p2[ib], &c = p2[ic];
        bool ear = CGAL::orientation(a, b, c) == convex;
        budget -= ear ? m : 1; // an emptiness test costs m point tests
        for (std::size_t k = 0; ear && k < m; ++k) {
            const std::size_t id = remaining[k];
            if (id == ia || id == ib || id == ic) continue;
            const Kernel::Point_2& q = p2[id];
            if (q == a || q == b || q == c) continue;
            const CGAL::Orientation outside = convex == CGAL::LEFT_TURN ? CGAL::RIGHT_TURN : CGAL::LEFT_TURN;
            if (CGAL::orientation(a, b, q) != outside && CGAL::orientation(b, c, q) != outside &&
                CGAL::orientation(c, a, q) != outside)
                ear = false;
        }
        if (ear) {
            out.push_back({poly[ia], poly[ib], poly[ic]});
            remaining.erase(remaining.begin() + std::ptrdiff_t(i));
            failures = 0;
        } else if (++failures > m) {
            fan(remaining);
            return false;
        } else {
            ++i;
        }
    }
    out.push_back({poly[remaining[0]], poly[remaining[1]], poly[remaining[2]]});
    return true;
}

/// Records which polygons orient_polygon_soup reversed.
struct ReversalRecorder : PMP::Default_orientation_visitor {
    std::vector<char>* reversed = nullptr;
    void polygon_orientation_reversed(std::size_t i) { (*reversed)[i] ^= 1; }
};

/// orient_polygon_soup keeps the orientation of the first polygon of each component; flip back the
/// components where that reversed the majority of the file's polygons, so the fewest are changed.
void keepMajorityOrientation(std::vector<Polygon>& polys, std::vector<char>& reversed) {
    std::vector<std::array<std::size_t, 3>> edges; // (min, max, polygon)
    for (std::size_t f = 0; f < polys.size(); ++f)
        for (std::size_t j = 0; j < polys[f].size(); ++j) {
            const std::size_t a = polys[f][j], b = polys[f][(j + 1) % polys[f].size()];
            edges.push_back({std::min(a, b), std::max(a, b), f});
        }
    std::sort(edges.begin(), edges.end());
    DisjointSets sets(polys.size());
    for (std::size_t i = 1; i < edges.size(); ++i)
        if (edges[i][0] == edges[i - 1][0] && edges[i][1] == edges[i - 1][1])
            sets.unite(edges[i][2], edges[i - 1][2]);
    std::vector<std::size_t> size(polys.size(), 0), flipped(polys.size(), 0);
    for (std::size_t f = 0; f < polys.size(); ++f) {
        ++size[sets.find(f)];
        if (reversed[f]) ++flipped[sets.find(f)];
    }
    for (std::size_t f = 0; f < polys.size(); ++f) {
        const std::size_t root = sets.find(f);
        if (2 * flipped[root] > size[root]) {
            std::reverse(polys[f].begin(), polys[f].end());
            reversed[f] ^= 1;
        }
    }
}

/// Removes triangles with the same corners as an earlier one (either orientation); true when any.
bool removeDuplicateTriangles(std::vector<Polygon>& polys, std::vector<std::size_t>& origin,
                              ReadReport& report) {
    std::vector<std::array<std::size_t, 4>> keys(polys.size());
    for (std::size_t f = 0; f < polys.size(); ++f) {
        keys[f] = {polys[f][0], polys[f][1], polys[f][2], f};
        std::sort(keys[f].begin(), keys[f].begin() + 3);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<char> drop(polys.size(), 0);
    std::size_t duplicates = 0;
    for (std::size_t i = 1; i < keys.size(); ++i)
        if (std::equal(keys[i].begin(), keys[i].begin() + 3, keys[i - 1].begin())) {
            drop[keys[i][3]] = 1;
            ++duplicates;
        }
    if (!duplicates) return false;
    std::size_t kept = 0;
    for (std::size_t f = 0; f < polys.size(); ++f) {
        if (drop[f]) continue;
        if (kept != f) polys[kept] = std::move(polys[f]); // self-move would empty it
        origin[kept++] = origin[f];
    }
    polys.resize(kept);
    origin.resize(kept);
    report.repairs.push_back("removed " + quantity(duplicates, "duplicate triangle", "duplicate triangles"));
    return true;
}

/// Builds the halfedge structure of a triangle soup that analyseTopology accepts (no repeated corners,
/// manifold, consistently oriented) directly: CGAL::Euler::add_face looks every new edge up around its
/// vertex, which is quadratic in the valence (a fan apex of a finely segmented cylinder cap). Vertices keep
/// the order of the used points and faces the order of the triangles. std::nullopt if the soup is not such.
std::optional<Mesh> buildTriangleMesh(const std::vector<Point3>& points, const std::vector<char>& used,
                                      const std::vector<Polygon>& triangles) {
    const std::size_t nf = triangles.size();
    Mesh mesh;
    mesh.reserve(Mesh::size_type(points.size()), Mesh::size_type(nf * 3 / 2 + 3), Mesh::size_type(nf));
    std::vector<VertexIndex> vertex(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        if (used[i]) vertex[i] = mesh.add_vertex(points[i]);

    // Corner c = 3f + j owns the halfedge from corner j to corner j + 1 of triangle f. Bucket the corners
    // by the smaller end of their edge (counting sort); an edge's two halfedges meet in one bucket.
    auto from = [&](std::size_t c) { return triangles[c / 3][c % 3]; };
    auto to = [&](std::size_t c) { return triangles[c / 3][(c % 3 + 1) % 3]; };
    std::vector<std::size_t> start(points.size() + 1, 0);
    for (std::size_t c = 0; c < 3 * nf; ++c)
        ++start[std::min(from(c), to(c)) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::size_t> bucket(3 * nf), fill(start.begin(), start.end() - 1);
    for (std::size_t c = 0; c < 3 * nf; ++c)
        bucket[fill[std::min(from(c), to(c))]++] = c;

    std::vector<HalfedgeIndex> halfedge(3 * nf);
    std::vector<HalfedgeIndex> borderFrom(points.size());       // the border halfedge leaving a point
    std::vector<std::pair<HalfedgeIndex, std::size_t>> borders; // border halfedge, the point it ends at
    for (std::size_t v = 0; v < points.size(); ++v) {
        const auto begin = bucket.begin() + std::ptrdiff_t(start[v]),
                   end = bucket.begin() + std::ptrdiff_t(start[v + 1]);
        auto other = [&](std::size_t c) { return std::max(from(c), to(c)); };
        std::sort(begin, end, [&](std::size_t a, std::size_t b) { return other(a) < other(b); });
        for (auto it = begin; it != end;) {
            const std::size_t c = *it;
            const HalfedgeIndex h = mesh.add_edge(), o = mesh.opposite(h);
            mesh.set_target(h, vertex[to(c)]);
            mesh.set_target(o, vertex[from(c)]);
            halfedge[c] = h;
            if (it + 1 != end && other(*(it + 1)) == other(c)) {
                const std::size_t d = *(it + 1);
                if (from(d) != to(c) || (it + 2 != end && other(*(it + 2)) == other(c))) return std::nullopt;
                halfedge[d] = o;
                it += 2;
            } else {
                if (borderFrom[to(c)] != HalfedgeIndex()) return std::nullopt;
                borderFrom[to(c)] = o;
                borders.emplace_back(o, from(c));
                ++it;
            }
        }
    }
    for (std::size_t f = 0; f < nf; ++f) {
        const FaceIndex face = mesh.add_face();
        mesh.set_halfedge(face, halfedge[3 * f]);
        for (std::size_t j = 0; j < 3; ++j) {
            mesh.set_face(halfedge[3 * f + j], face);
            mesh.set_next(halfedge[3 * f + j], halfedge[3 * f + (j + 1) % 3]);
            mesh.set_halfedge(vertex[triangles[f][(j + 1) % 3]], halfedge[3 * f + j]);
        }
    }
    // Border halfedges follow each other around holes; a border vertex points to its incoming one.
    for (const auto& [h, end] : borders) {
        if (borderFrom[end] == HalfedgeIndex()) return std::nullopt;
        mesh.set_next(h, borderFrom[end]);
        mesh.set_halfedge(vertex[end], h);
    }
    return mesh;
}

/// Turns the soup into a valid triangle mesh, repairing (and reporting) what must be repaired.
Mesh soupToMesh(const Source& src, Soup& soup, ReadReport& report, const ReadOptions& options) {
    if (soup.polygons.empty())
        src.fail(soup.points.empty()
                     ? std::string("it contains no faces")
                     : "it contains no faces, only " + quantity(soup.points.size(), "point", "points"));
    std::vector<std::size_t> canonical;
    Topology topology;
    report.soup = computeStats(soup, canonical, topology);
    bool changed =
        report.soup.duplicatePoints > 0; // topology above is that of the current soup until changed
    const SoupStats& stats = report.soup;
    std::vector<Polygon>& polys = soup.polygons;
    std::vector<std::size_t> origin(polys.size()); // polygon of the file each current polygon comes from
    std::iota(origin.begin(), origin.end(), 0);
    auto refuse = [&](const std::string& problem) {
        src.fail("it is not a valid oriented manifold mesh (" + problem + ") and repair is disabled");
    };

    // 1. Merge geometrically equal points.
    const bool merge = options.repair && stats.duplicatePoints > 0;
    if (merge) {
        for (Polygon& p : polys)
            for (std::size_t& c : p)
                c = canonical[c];
        report.repairs.push_back("merged " +
                                 quantity(stats.duplicatePoints, "duplicate point", "duplicate points"));
    }

    // 2. Polygons with repeated corners: drop consecutive repeats, remove what is still degenerate.
    {
        std::size_t simplified = 0, removed = 0, kept = 0;
        for (std::size_t f = 0; f < polys.size(); ++f) {
            Polygon& p = polys[f];
            Polygon q;
            for (std::size_t j = 0; j < p.size(); ++j)
                if (p[j] != p[(j + 1) % p.size()]) q.push_back(p[j]);
            if (q.size() < 3 || hasRepeatedCorner(q)) {
                ++removed;
                continue;
            }
            if (q.size() != p.size()) ++simplified;
            polys[kept] = std::move(q);
            origin[kept++] = origin[f];
        }
        polys.resize(kept);
        origin.resize(kept);
        changed = changed || removed || simplified;
        if (!options.repair && (removed || simplified))
            refuse(quantity(removed + simplified, "polygon has", "polygons have") + " repeated corners");
        if (removed)
            report.repairs.push_back("removed " +
                                     quantity(removed, "degenerate polygon", "degenerate polygons") +
                                     " with repeated corners");
        if (simplified)
            report.repairs.push_back("removed repeated corners from " +
                                     quantity(simplified, "polygon", "polygons"));
        if (polys.empty())
            src.fail("nothing is left after repair: all " +
                     quantity(stats.polygons, "polygon is", "polygons are") + " degenerate");
    }

    // 3. Triangulate polygons with more than three corners (a Mesh holds triangles).
    if (std::any_of(polys.begin(), polys.end(), [](const Polygon& p) { return p.size() > 3; })) {
        std::vector<Polygon> triangles;
        std::vector<std::size_t> triangleOrigin;
        triangles.reserve(polys.size());
        std::size_t split = 0, fanned = 0, corners = 0;
        for (const Polygon& p : polys)
            corners += p.size();
        std::size_t budget = 10'000'000 + 64 * corners; // generous for real polygons, bounded for any file
        for (std::size_t f = 0; f < polys.size(); ++f) {
            const std::size_t before = triangles.size();
            if (polys[f].size() == 3) {
                triangles.push_back(std::move(polys[f]));
            } else {
                if (!triangulatePolygon(soup.points, polys[f], triangles, budget)) ++fanned;
                ++split;
            }
            triangleOrigin.insert(triangleOrigin.end(), triangles.size() - before, origin[f]);
        }
        report.repairs.push_back(
            "triangulated " +
            quantity(split, "polygon with more than three corners", "polygons with more than three corners") +
            " into " + quantity(triangles.size() - (polys.size() - split), "triangle", "triangles"));
        if (fanned)
            report.repairs.push_back(
                "triangulated " +
                quantity(fanned, "polygon as a simple fan because it is",
                         "polygons as simple fans because they are") +
                " self-intersecting or too large to triangulate carefully, so the triangles may overlap");
        polys = std::move(triangles);
        origin = std::move(triangleOrigin);
        changed = true;
    }

    // 4. Orientation and manifoldness.
    if (changed) topology = analyseTopology(polys, soup.points.size());
    if (!topology.isMesh()) {
        if (!options.repair) {
            std::vector<std::string> parts;
            if (topology.nonManifoldEdges)
                parts.push_back(
                    quantity(topology.nonManifoldEdges, "non-manifold edge", "non-manifold edges"));
            if (topology.nonManifoldVertices)
                parts.push_back(
                    quantity(topology.nonManifoldVertices, "non-manifold vertex", "non-manifold vertices"));
            if (topology.misorientedEdges)
                parts.push_back(quantity(topology.misorientedEdges, "edge", "edges") +
                                " between polygons of opposite orientation");
            std::string joined = parts[0];
            for (std::size_t i = 1; i < parts.size(); ++i)
                joined += ", " + parts[i];
            refuse(joined);
        }
        // Duplicate triangles (same corners, either orientation) always show up here: their edges are
        // non-manifold or misoriented. Keep the first of each.
        if (removeDuplicateTriangles(polys, origin, report))
            topology = analyseTopology(polys, soup.points.size());
    }
    if (!topology.isMesh()) {
        const std::size_t pointsBefore = soup.points.size();
        const std::size_t nonManifoldEdges = topology.nonManifoldEdges;
        std::vector<char> reversed(polys.size(), 0);
        ReversalRecorder recorder;
        recorder.reversed = &reversed;
        PMP::orient_polygon_soup(soup.points, polys, CGAL::parameters::visitor(recorder));
        keepMajorityOrientation(polys, reversed);
        const auto flipped = static_cast<std::size_t>(std::count(reversed.begin(), reversed.end(), 1));
        if (flipped)
            report.repairs.push_back("reoriented " + quantity(flipped, "polygon", "polygons") +
                                     " to match the orientation of their neighbours");
        if (nonManifoldEdges)
            report.repairs.push_back("separated the polygons around " +
                                     quantity(nonManifoldEdges, "edge", "edges") +
                                     " shared by more than two polygons");
        if (const std::size_t added = soup.points.size() - pointsBefore)
            report.repairs.push_back("duplicated " +
                                     quantity(added, "non-manifold vertex", "non-manifold vertices") +
                                     " to make the mesh manifold");
        if (!analyseTopology(polys, soup.points.size()).isMesh())
            src.fail("it could not be repaired into a manifold mesh");
    }

    // 5. Points no polygon uses (merged-away duplicates are not counted again) are dropped.
    std::vector<char> used(soup.points.size(), 0);
    for (const Polygon& p : polys)
        for (std::size_t c : p)
            used[c] = 1;
    std::size_t isolated = 0;
    for (std::size_t i = 0; i < used.size(); ++i)
        if (!used[i] && !(merge && i < canonical.size() && canonical[i] != i)) ++isolated;
    // Isolated vertices would make the mesh invalid (CGAL::is_valid_polygon_mesh).
    if (isolated && !options.repair)
        refuse(quantity(isolated, "point is", "points are") + " used by no polygon");
    if (isolated)
        report.repairs.push_back("removed " + quantity(isolated, "isolated point", "isolated points") +
                                 " that no polygon uses");

    // 6. Build: vertices in file order, faces in polygon order (so face properties keep their order).
    std::optional<Mesh> built = buildTriangleMesh(soup.points, used, polys);
    if (!built) src.fail("its polygons could not be assembled into a mesh (an internal error of FSS)");
    Mesh& mesh = *built;
    if (!soup.quality.empty()) {
        auto map = mesh.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality).first;
        for (std::size_t f = 0; f < polys.size(); ++f)
            map[FaceIndex(Mesh::size_type(f))] = soup.quality[origin[f]];
        report.hasFaceQuality = true;
    }
    if (!soup.scanId.empty()) {
        auto map = mesh.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1).first;
        for (std::size_t f = 0; f < polys.size(); ++f)
            map[FaceIndex(Mesh::size_type(f))] = soup.scanId[origin[f]];
        report.hasScanId = true;
    }
    return std::move(mesh);
}

// =====================================================================================================
// Writing
// =====================================================================================================

[[noreturn]] void failWrite(const fs::path& path, const std::string& problem) {
    throw IoError("Cannot write mesh file '" + path.string() + "': " + problem + ".");
}

/// The mesh with contiguous indices over its valid elements, in iteration order.
struct FlatMesh {
    std::vector<Point3> points;
    std::vector<std::size_t> faceStart{0}; // faces() + 1 entries
    std::vector<std::size_t> corners;
    std::vector<float> quality;
    std::vector<std::int32_t> scanId;
    bool hasQuality = false, hasScanId = false;
    std::size_t faces() const { return faceStart.size() - 1; }
    std::size_t degree(std::size_t f) const { return faceStart[f + 1] - faceStart[f]; }
    std::size_t corner(std::size_t f, std::size_t j) const { return corners[faceStart[f] + j]; }
};

FlatMesh flatten(const Mesh& mesh) {
    FlatMesh flat;
    std::vector<std::size_t> index(mesh.num_vertices(), 0);
    flat.points.reserve(mesh.number_of_vertices());
    for (VertexIndex v : mesh.vertices()) {
        index[std::size_t(v)] = flat.points.size();
        flat.points.push_back(mesh.point(v));
    }
    const auto quality = mesh.property_map<FaceIndex, float>(props::faceQuality);
    const auto scanId = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    flat.hasQuality = quality.second;
    flat.hasScanId = scanId.second;
    flat.faceStart.reserve(mesh.number_of_faces() + 1);
    flat.corners.reserve(3 * mesh.number_of_faces());
    for (FaceIndex f : mesh.faces()) {
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            flat.corners.push_back(index[std::size_t(v)]);
        flat.faceStart.push_back(flat.corners.size());
        if (flat.hasQuality) flat.quality.push_back(quality.first[f]);
        if (flat.hasScanId) flat.scanId.push_back(scanId.first[f]);
    }
    return flat;
}

/// Writes into a temporary file next to the target and renames it over the target on commit().
class AtomicFile {
public:
    explicit AtomicFile(const fs::path& target) : target_(target) {
        static std::atomic<unsigned> counter{0};
        std::random_device rd;
        const auto salt = std::to_string(rd()) + "-" + std::to_string(counter++);
        const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
        temp_ = folder / ("." + target.filename().string() + ".tmp-" + salt);
        errno = 0;
        file_ = std::fopen(temp_.c_str(), "wb");
        if (!file_)
            failWrite(target_, "a temporary file cannot be created in the folder '" + folder.string() +
                                   "' (" + std::generic_category().message(errno) + ")");
        buffer_.reserve(kChunk + 256);
    }
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile() {
        if (file_) std::fclose(file_);
        if (!committed_) {
            std::error_code ec;
            fs::remove(temp_, ec);
        }
    }

    std::string& out() { return buffer_; }
    /// Hands the buffer to the file when it is large.
    void flushIfLarge() {
        if (buffer_.size() >= kChunk) flush();
    }
    void commit() {
        flush();
        const bool closed = std::fclose(file_) == 0;
        const int err = errno;
        file_ = nullptr;
        if (!closed) failWrite(target_, "writing failed (" + std::generic_category().message(err) + ")");
        std::error_code ec;
        fs::rename(temp_, target_, ec);
        if (ec) failWrite(target_, "the written file cannot replace it (" + ec.message() + ")");
        committed_ = true;
    }

private:
    static constexpr std::size_t kChunk = std::size_t(1) << 20;
    void flush() {
        errno = 0;
        if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
            failWrite(target_, "writing failed (" + std::generic_category().message(errno) + ")");
        buffer_.clear();
    }

    fs::path target_, temp_;
    std::FILE* file_ = nullptr;
    std::string buffer_;
    bool committed_ = false;
};

void putDouble(std::string& s, double v, int precision) {
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, precision);
    s.append(b, r.ptr);
}
void putFloat(std::string& s, float v) { // shortest text that reads back to the same float
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v);
    s.append(b, r.ptr);
}
template <class T> void putInteger(std::string& s, T v) {
    char b[32];
    const auto r = std::to_chars(b, b + sizeof b, v);
    s.append(b, r.ptr);
}
template <class T> void putBinary(std::string& s, T v, bool bigEndian) {
    auto bytes = std::bit_cast<std::array<char, sizeof(T)>>(v);
    if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(bytes.begin(), bytes.end());
    s.append(bytes.data(), bytes.size());
}
void putPoint(std::string& s, const Point3& p, int precision) {
    putDouble(s, p.x(), precision);
    s += ' ';
    putDouble(s, p.y(), precision);
    s += ' ';
    putDouble(s, p.z(), precision);
}

void writeOff(const FlatMesh& m, AtomicFile& file, int precision) {
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
}

void writeObj(const FlatMesh& m, AtomicFile& file, int precision) {
    std::string& s = file.out();
    s += "# written by FSS\n";
    for (const Point3& p : m.points) {
        s += "v ";
        putPoint(s, p, precision);
        s += '\n';
        file.flushIfLarge();
    }
    for (std::size_t f = 0; f < m.faces(); ++f) {
        s += 'f';
        for (std::size_t j = 0; j < m.degree(f); ++j) {
            s += ' ';
            putInteger(s, m.corner(f, j) + 1);
        }
        s += '\n';
        file.flushIfLarge();
    }
}

void writePly(const FlatMesh& m, AtomicFile& file, bool binary, int precision) {
    std::string& s = file.out();
    const bool bigEndian = std::endian::native == std::endian::big;
    std::size_t maxDegree = 0;
    for (std::size_t f = 0; f < m.faces(); ++f)
        maxDegree = std::max(maxDegree, m.degree(f));
    const bool wideCount = maxDegree > 255;
    s += "ply\nformat ";
    s += !binary ? "ascii" : bigEndian ? "binary_big_endian" : "binary_little_endian";
    s += " 1.0\ncomment written by FSS\nelement vertex ";
    putInteger(s, m.points.size());
    s += "\nproperty double x\nproperty double y\nproperty double z\nelement face ";
    putInteger(s, m.faces());
    s += wideCount ? "\nproperty list uint int vertex_indices\n"
                   : "\nproperty list uchar int vertex_indices\n";
    if (m.hasQuality) s += "property float quality\n";
    if (m.hasScanId) s += "property int scan_id\n";
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
            s += '\n';
        }
        file.flushIfLarge();
    }
}

void writeStl(const FlatMesh& m, AtomicFile& file, bool binary, int precision) {
    std::string& s = file.out();
    // STL holds triangles only: faces with more corners are written as fans.
    std::size_t triangles = 0;
    for (std::size_t f = 0; f < m.faces(); ++f)
        triangles += m.degree(f) >= 3 ? m.degree(f) - 2 : 0;
    if (binary) {
        std::string header = "FSS binary STL"; // must not start with "solid"
        header.resize(80, ' ');
        s += header;
        putBinary(s, static_cast<std::uint32_t>(triangles), false);
    } else {
        s += "solid fss\n";
    }
    for (std::size_t f = 0; f < m.faces(); ++f) {
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
    }
    if (!binary) s += "endsolid fss\n";
}

} // namespace

// =====================================================================================================
// Public interface
// =====================================================================================================

Mesh readMesh(const fs::path& path, ReadReport* report, const ReadOptions& options) {
    ReadReport local;
    ReadReport& rep = report ? *report : local;
    rep = ReadReport{};
    const Source src = loadFile(path);
    const Format format = detectFormat(src);
    Soup soup;
    switch (format) {
    case Format::Off:
        rep.format = "off";
        soup = parseOff(src);
        break;
    case Format::Obj:
        rep.format = "obj";
        soup = parseObj(src);
        break;
    case Format::Ply:
        rep.format = "ply";
        soup = parsePly(src, rep.binary);
        break;
    case Format::StlAscii:
        rep.format = "stl";
        soup = parseStlAscii(src);
        break;
    case Format::StlBinary:
        rep.format = "stl";
        rep.binary = true;
        soup = parseStlBinary(src);
        break;
    }
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
    const Source src{"(mesh in memory)", {}};
    ReadReport report;
    return soupToMesh(src, soup, report, ReadOptions{});
}

bool isSupportedMeshFile(const fs::path& path) {
    const std::string ext = lower(path.extension().string());
    return ext == ".off" || ext == ".obj" || ext == ".ply" || ext == ".stl";
}

void writeMesh(const Mesh& mesh, const fs::path& path, const WriteOptions& options) {
    const std::string ext = lower(path.extension().string());
    if (!isSupportedMeshFile(path))
        failWrite(path,
                  (ext.empty() ? std::string("it has no extension") : "the extension " + quoteToken(ext)) +
                      " does not name a format (use .off, .obj, .ply or .stl)");
    std::error_code ec;
    if (fs::is_directory(path, ec)) failWrite(path, "it is a folder");
    const int precision = std::clamp(options.precision, 1, 17);
    const FlatMesh flat = flatten(mesh);
    if (ext == ".stl") {
        std::size_t triangles = 0;
        for (std::size_t f = 0; f < flat.faces(); ++f)
            triangles += flat.degree(f) >= 3 ? flat.degree(f) - 2 : 0;
        if (options.binary && triangles > std::numeric_limits<std::uint32_t>::max())
            failWrite(path, "binary STL cannot hold more than 4294967295 triangles");
    }
    if (ext == ".ply" && flat.points.size() > std::size_t(std::numeric_limits<std::int32_t>::max()))
        failWrite(path, "PLY files written by FSS cannot index more than 2147483647 vertices");
    AtomicFile file(path);
    if (ext == ".off")
        writeOff(flat, file, precision);
    else if (ext == ".obj")
        writeObj(flat, file, precision);
    else if (ext == ".ply")
        writePly(flat, file, options.binary, precision);
    else
        writeStl(flat, file, options.binary, precision);
    file.commit();
}

} // namespace fss
