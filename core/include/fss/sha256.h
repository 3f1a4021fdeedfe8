#pragma once
/// \file sha256.h
/// SHA-256 (FIPS 180-4, "Secure Hash Standard", §6.2): the fingerprint session files keep of their input
/// mesh, so that a session is never replayed on a different file by accident.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace fss {

/// Incremental SHA-256. Feed bytes with update() in any number of pieces, then call digest() once; the
/// result does not depend on how the input was split.
class Sha256 {
public:
    Sha256();
    /// Appends \p size bytes at \p data to the message. \pre digest() was not called yet.
    void update(const void* data, std::size_t size);
    void update(std::string_view bytes) { update(bytes.data(), bytes.size()); }
    /// Pads the message and returns the 32-byte digest. Further calls return the same digest; update()
    /// after it is a programming error (throws std::logic_error).
    std::array<std::uint8_t, 32> digest();
    /// digest() as 64 lowercase hexadecimal digits.
    std::string hexDigest();

private:
    void compress(const std::uint8_t* block);
    std::array<std::uint32_t, 8> state_;
    std::array<std::uint8_t, 64> buffer_{};
    std::size_t buffered_ = 0;
    std::uint64_t length_ = 0; // message bytes so far
    bool finished_ = false;
    std::array<std::uint8_t, 32> digest_{};
};

/// SHA-256 of \p bytes as 64 lowercase hexadecimal digits.
std::string sha256Hex(std::string_view bytes);

/// SHA-256 of the contents of the file \p path as 64 lowercase hexadecimal digits (read in blocks).
/// \throw IoError naming the file when it is missing, not a regular file or cannot be read.
std::string sha256OfFile(const std::filesystem::path& path);

} // namespace fss
