#pragma once
// Internal (not installed): what the mesh readers and writers share (fss/mesh_io.h). Each format has one
// reader and one writer (io_off.cpp, io_obj.cpp, io_ply.cpp, io_stl.cpp) listed in the table of formats
// (meshFormats, mesh_io.cpp); the readers parse a file strictly into a polygon soup (one-sentence errors
// naming the file and, for text formats, the line: Source::fail), soup_repair.cpp turns the soup into a
// valid oriented manifold mesh and mesh_build.cpp assembles the halfedge structure. Writers get the mesh
// flattened (contiguous indices) and write into an AtomicFile that replaces the target when complete.
//
// Adding a format: write `Soup readX(const Source&, ReadReport&)` and
// `void writeX(const FlatMesh&, const std::filesystem::path&, const WriteOptions&)` in io_x.cpp, declare
// them below and add a row to the table in mesh_io.cpp (and, if its content can be recognised, to
// sniffFormat there).
#include "fss/mesh_io.h"

#include "fss/error.h"
#include "fss/face_groups.h"

#include <boost/container/small_vector.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fss::detail::io {

// =====================================================================================================
// Small helpers (io_common.cpp)
// =====================================================================================================

/// "1 point", "3 points".
std::string quantity(std::size_t n, std::string_view singular, std::string_view plural);

/// A token as it may appear in a message: quoted, at most 24 characters, non-printable bytes escaped.
std::string quoteToken(std::string_view token);

std::string lower(std::string_view s);
bool equalsNoCase(std::string_view a, std::string_view b);

inline bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
inline bool isSpace(char c) {
    return isBlank(c) || c == '\n';
}

/// \p d starts with \p word (any case) followed by white space or the end.
inline bool startsWithWordNoCase(std::string_view d, std::string_view word) {
    return d.size() >= word.size() && equalsNoCase(d.substr(0, word.size()), word) &&
           (d.size() == word.size() || isSpace(d[word.size()]));
}

enum class NumberParse { Ok, NotANumber, OutOfRange };

/// Parses a whole token as a double (locale independent, correctly rounded). Accepts a leading '+'.
NumberParse parseDouble(std::string_view t, double& value);

/// Parses a whole token as a signed 64-bit integer. Accepts a leading '+'.
bool parseInteger(std::string_view t, long long& value);

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
    /// Skips the rest of the current line (e.g. the name after 'solid') and returns it without the
    /// surrounding blanks.
    std::string_view skipLine() {
        const std::size_t start = pos_;
        while (pos_ < text_.size() && text_[pos_] != '\n')
            ++pos_;
        std::string_view rest = text_.substr(start, pos_ - start);
        while (!rest.empty() && isBlank(rest.back()))
            rest.remove_suffix(1);
        while (!rest.empty() && isBlank(rest.front()))
            rest.remove_prefix(1);
        return rest;
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

/// Finds exactly equal points (+0 and -0 are the same point): an open-addressing hash table of indices
/// into a point vector (which may grow between calls).
class PointTable {
public:
    explicit PointTable(const std::vector<Point3>& points, std::size_t expected = 0) : points_(points) {
        rehash(expected);
    }
    /// The index of the first point seen that equals points[i]; i itself (now remembered) when none does.
    std::size_t firstEqual(std::size_t i);

private:
    void rehash(std::size_t expected);

    const std::vector<Point3>& points_;
    std::vector<std::size_t> slots_;
    std::size_t count_ = 0;
};

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
    std::vector<std::int32_t>
        group; ///< per polygon: index into groupNames (kNoGroup: none); empty: no groups
    std::vector<std::string> groupNames;
};

/// The bytes of a file plus its name for messages.
struct Source {
    std::filesystem::path path;
    std::string data;

    [[noreturn]] void fail(const std::string& problem) const {
        throw IoError("Cannot read mesh file '" + path.string() + "': " + problem + ".");
    }
};

/// Largest count the parsers reserve up front; beyond it containers grow as data actually arrives, so a
/// corrupt header count can never trigger a huge allocation.
constexpr std::size_t kMaxReserve = std::size_t(1) << 20;

inline std::size_t boundedReserve(unsigned long long announced, std::size_t bytes, std::size_t minBytesEach) {
    return static_cast<std::size_t>(
        std::min<unsigned long long>({announced, bytes / minBytesEach + 1, kMaxReserve}));
}

/// The whole file; fails when it is missing, not a regular file, unreadable, empty or only white space.
Source loadFile(const std::filesystem::path& path);

std::string_view skipBomAndSpace(std::string_view d);

/// No control bytes other than white space in the first 4 KiB.
bool looksLikeText(std::string_view d);

/// Reads the coordinates of vertex `index` from the tokens of one line (dimension 3, or 4 homogeneous).
Point3 readCoordinates(const Source& src, Tokens& tok, const std::string& where, std::size_t index,
                       bool homogeneous);

/// The remaining tokens of a line must be numbers (colours, normals, texture coordinates).
void expectOnlyNumbers(const Source& src, Tokens& tok, const std::string& where, const std::string& after);

// =====================================================================================================
// Writing (io_common.cpp)
// =====================================================================================================

[[noreturn]] void failWrite(const std::filesystem::path& path, const std::string& problem);

/// The mesh with contiguous indices over its valid elements, in iteration order.
struct FlatMesh {
    std::vector<Point3> points;
    std::vector<std::size_t> faceStart{0}; // faces() + 1 entries
    std::vector<std::size_t> corners;
    std::vector<float> quality;
    std::vector<std::int32_t> scanId;
    std::vector<std::int32_t> group; // per face when hasGroups (fss/face_groups.h)
    std::vector<std::string> groupNames;
    bool hasQuality = false, hasScanId = false, hasGroups = false;
    std::size_t faces() const { return faceStart.size() - 1; }
    std::size_t degree(std::size_t f) const { return faceStart[f + 1] - faceStart[f]; }
    std::size_t corner(std::size_t f, std::size_t j) const { return corners[faceStart[f] + j]; }
};

/// Writes into a temporary file next to the target and renames it over the target on commit().
class AtomicFile {
public:
    explicit AtomicFile(const std::filesystem::path& target);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();

    std::string& out() { return buffer_; }
    /// Hands the buffer to the file when it is large.
    void flushIfLarge() {
        if (buffer_.size() >= kChunk) flush();
    }
    void commit();

private:
    static constexpr std::size_t kChunk = std::size_t(1) << 20;
    void flush();

    std::filesystem::path target_, temp_;
    std::FILE* file_ = nullptr;
    std::string buffer_;
    bool committed_ = false;
};

inline void putDouble(std::string& s, double v, int precision) {
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, precision);
    s.append(b, r.ptr);
}
inline void putFloat(std::string& s, float v) { // shortest text that reads back to the same float
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
inline void putPoint(std::string& s, const Point3& p, int precision) {
    putDouble(s, p.x(), precision);
    s += ' ';
    putDouble(s, p.y(), precision);
    s += ' ';
    putDouble(s, p.z(), precision);
}

// =====================================================================================================
// Soup repair and mesh building (soup_repair.cpp, mesh_build.cpp)
// =====================================================================================================

/// The group index of the group called \p name in \p soup, added to its table when new.
std::int32_t groupIndex(Soup& soup, std::string_view name);

/// Turns the soup into a valid triangle mesh, repairing (and reporting) what must be repaired.
Mesh soupToMesh(const Source& src, Soup& soup, ReadReport& report, const ReadOptions& options);

/// Builds the halfedge structure of a triangle soup without repeated corners, manifold and consistently
/// oriented: vertices in the order of the used points, faces in the order of the triangles; std::nullopt
/// when the soup is not such.
std::optional<Mesh> buildTriangleMesh(const std::vector<Point3>& points, const std::vector<char>& used,
                                      const std::vector<Polygon>& triangles);

/// The mesh's valid elements re-indexed contiguously in iteration order.
FlatMesh flatten(const Mesh& mesh);

// =====================================================================================================
// The formats: one reader and one writer each
// =====================================================================================================

/// A reader parses the file into a soup and sets report.format (and report.binary).
using SoupReader = Soup (*)(const Source& src, ReadReport& report);
/// A writer checks what the format cannot hold (failWrite), then writes the flat mesh atomically.
/// options.precision is already clamped to 1…17.
using MeshWriter = void (*)(const FlatMesh& mesh, const std::filesystem::path& path,
                            const WriteOptions& options);

/// One mesh file format.
struct MeshFormat {
    std::string_view extension; ///< lower case, with the dot: ".off"
    SoupReader read;
    MeshWriter write;
};

Soup readOff(const Source& src, ReadReport& report);
void writeOff(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options);
/// Whether \p t is an OFF header keyword ([ST][C][N][4][n]OFF).
bool isOffKeyword(std::string_view t);

Soup readObj(const Source& src, ReadReport& report);
void writeObj(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options);

Soup readPly(const Source& src, ReadReport& report);
void writePly(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options);

/// Ascii or binary, told by the content.
Soup readStl(const Source& src, ReadReport& report);
void writeStl(const FlatMesh& m, const std::filesystem::path& path, const WriteOptions& options);
/// Whether the file has exactly the size its binary STL header announces.
bool isBinaryStlOfExactSize(std::string_view d);

} // namespace fss::detail::io
