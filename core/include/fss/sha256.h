#pragma once
/// \file sha256.h
/// SHA-256 (FIPS 180-4, "Secure Hash Standard"): the fingerprint session files keep of their input mesh, so
/// that a session is never replayed on a different file by accident. Computed by OpenSSL's libcrypto (EVP
/// digest API); this header keeps OpenSSL out of FSS's public interface.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

struct evp_md_ctx_st; // OpenSSL's EVP_MD_CTX, opaque here

namespace fss {

/// Incremental SHA-256. Feed bytes with update() in any number of pieces, then call digest() once; the
/// result does not depend on how the input was split.
class Sha256 {
public:
    /// \throw std::runtime_error when libcrypto cannot provide SHA-256 (e.g. a FIPS-only configuration
    ///        without it), which no supported system does.
    Sha256();
    ~Sha256();
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;
    Sha256(Sha256&&) noexcept;
    Sha256& operator=(Sha256&&) noexcept;
    /// Appends \p size bytes at \p data to the message. \pre digest() was not called yet.
    void update(const void* data, std::size_t size);
    void update(std::string_view bytes) { update(bytes.data(), bytes.size()); }
    /// Pads the message and returns the 32-byte digest. Further calls return the same digest; update()
    /// after it is a programming error (throws std::logic_error).
    std::array<std::uint8_t, 32> digest();
    /// digest() as 64 lowercase hexadecimal digits.
    std::string hexDigest();

private:
    evp_md_ctx_st* context_ = nullptr; // released by the destructor
    bool finished_ = false;
    std::array<std::uint8_t, 32> digest_{};
};

/// SHA-256 of \p bytes as 64 lowercase hexadecimal digits.
std::string sha256Hex(std::string_view bytes);

/// SHA-256 of the contents of the file \p path as 64 lowercase hexadecimal digits (read in blocks).
/// \throw IoError naming the file when it is missing, not a regular file or cannot be read.
std::string sha256OfFile(const std::filesystem::path& path);

} // namespace fss
