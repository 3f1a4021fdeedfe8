// What the mesh readers and writers share (io_detail.h): message helpers, number parsing, the table of
// equal points, loading a file, and the atomic file the writers write into.
#include "mesh/io_detail.h"

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <system_error>

namespace fs = std::filesystem;

namespace fss::detail::io {
namespace {

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

constexpr std::size_t kEmpty = std::numeric_limits<std::size_t>::max();

} // namespace

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

std::size_t PointTable::firstEqual(std::size_t i) {
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

void PointTable::rehash(std::size_t expected) {
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

[[noreturn]] void failWrite(const fs::path& path, const std::string& problem) {
    throw IoError("Cannot write mesh file '" + path.string() + "': " + problem + ".");
}

AtomicFile::AtomicFile(const fs::path& target) : target_(target) {
    static std::atomic<unsigned> counter{0};
    std::random_device rd;
    const auto salt = std::to_string(rd()) + "-" + std::to_string(counter++);
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    temp_ = folder / ("." + target.filename().string() + ".tmp-" + salt);
    errno = 0;
    file_ = std::fopen(temp_.c_str(), "wb");
    if (!file_)
        failWrite(target_, "a temporary file cannot be created in the folder '" + folder.string() + "' (" +
                               std::generic_category().message(errno) + ")");
    buffer_.reserve(kChunk + 256);
}

AtomicFile::~AtomicFile() {
    if (file_) std::fclose(file_);
    if (!committed_) {
        std::error_code ec;
        fs::remove(temp_, ec);
    }
}

void AtomicFile::commit() {
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

void AtomicFile::flush() {
    errno = 0;
    if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
        failWrite(target_, "writing failed (" + std::generic_category().message(errno) + ")");
    buffer_.clear();
}

} // namespace fss::detail::io

namespace fss::detail::io {

std::int32_t groupIndex(Soup& soup, std::string_view name) {
    for (std::size_t i = 0; i < soup.groupNames.size(); ++i)
        if (soup.groupNames[i] == name) return static_cast<std::int32_t>(i);
    soup.groupNames.emplace_back(name);
    return static_cast<std::int32_t>(soup.groupNames.size() - 1);
}

} // namespace fss::detail::io
