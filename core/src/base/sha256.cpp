// SHA-256 by OpenSSL's libcrypto (EVP digest API): a well-kept, FIPS-validated implementation replaces
// the own one; tests/core/sha256_test.cpp checks the wrapper against the FIPS 180-4 example vectors.
#include "fss/sha256.h"

#include "fss/error.h"

#include <openssl/evp.h>

#include <fstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace fss {
namespace {

std::string toHex(const std::array<std::uint8_t, 32>& bytes) {
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string hex;
    hex.reserve(64);
    for (std::uint8_t b : bytes) {
        hex.push_back(kDigits[b >> 4]);
        hex.push_back(kDigits[b & 0xf]);
    }
    return hex;
}

} // namespace

Sha256::Sha256() {
    EVP_MD_CTX* ctx = EVP_MD_CTX_new();
    if (!ctx || EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) != 1) {
        EVP_MD_CTX_free(ctx);
        throw std::runtime_error("OpenSSL could not start a SHA-256 digest.");
    }
    context_ = ctx;
}

Sha256::~Sha256() {
    EVP_MD_CTX_free(context_);
}

Sha256::Sha256(Sha256&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)), finished_(other.finished_), digest_(other.digest_) {}

Sha256& Sha256::operator=(Sha256&& other) noexcept {
    if (this != &other) {
        EVP_MD_CTX_free(context_);
        context_ = std::exchange(other.context_, nullptr);
        finished_ = other.finished_;
        digest_ = other.digest_;
    }
    return *this;
}

void Sha256::update(const void* data, std::size_t size) {
    if (finished_) throw std::logic_error("Sha256::update after digest()");
    if (!context_) throw std::logic_error("Sha256::update on a moved-from object");
    if (size > 0 && EVP_DigestUpdate(context_, data, size) != 1)
        throw std::runtime_error("OpenSSL failed to hash data with SHA-256.");
}

std::array<std::uint8_t, 32> Sha256::digest() {
    if (finished_) return digest_;
    if (!context_) throw std::logic_error("Sha256::digest on a moved-from object");
    unsigned int length = 0;
    if (EVP_DigestFinal_ex(context_, digest_.data(), &length) != 1 || length != digest_.size())
        throw std::runtime_error("OpenSSL failed to finish a SHA-256 digest.");
    finished_ = true;
    return digest_;
}

std::string Sha256::hexDigest() {
    return toHex(digest());
}

std::string sha256Hex(std::string_view bytes) {
    Sha256 hash;
    hash.update(bytes);
    return hash.hexDigest();
}

std::string sha256OfFile(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw IoError("The file " + path.string() + " does not exist.");
    if (!std::filesystem::is_regular_file(path, ec))
        throw IoError("The path " + path.string() + " is not a regular file.");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError("The file " + path.string() + " cannot be opened for reading.");
    Sha256 hash;
    std::vector<char> block(1 << 16);
    while (in) {
        in.read(block.data(), std::streamsize(block.size()));
        const std::streamsize got = in.gcount();
        if (got > 0) hash.update(block.data(), std::size_t(got));
    }
    if (in.bad()) throw IoError("The file " + path.string() + " could not be read to the end.");
    return hash.hexDigest();
}

} // namespace fss
