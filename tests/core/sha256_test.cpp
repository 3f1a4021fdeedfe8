// SHA-256 against the FIPS 180-4 example vectors (NIST "SHA256.pdf", FIPS 180-2 appendix B) and, for the
// padding boundaries, against digests computed by GNU coreutils' sha256sum.
#include "fss/error.h"
#include "fss/sha256.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>

namespace {

TEST(Sha256, FipsExampleVectors) {
    EXPECT_EQ(fss::sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(fss::sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(fss::sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    EXPECT_EQ(fss::sha256Hex(
                  "abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnop"
                  "qrlmnopqrsmnopqrstnopqrstu"),
              "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
    EXPECT_EQ(fss::sha256Hex(std::string(1000000, 'a')),
              "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Messages whose padding needs one or two extra blocks (lengths around 56 and 64 bytes mod 64).
TEST(Sha256, PaddingBoundaries) {
    const std::pair<int, const char*> cases[] = {
        {55, "d5e285683cd4efc02d021a5c62014694958901005d6f71e89e0989fac77e4072"},
        {56, "04c26261370ee7541549d16dee320c723e3fd14671e66a099afe0a377c16888e"},
        {63, "75220b47218278e656f2013bb8f0c455a25eaf01e86c64924e9d48d89776d6f2"},
        {64, "7ce100971f64e7001e8fe5a51973ecdfe1ced42befe7ee8d5fd6219506b5393c"},
        {65, "9537c5fdf120482f7d58d25e9ed583f52c02b4e304ea814db1633ad565aed7e9"},
        {119, "000b48d4edf0fa7bee3c6236ecd2785baa5db4eeb8bb54341b029e0d9fa5fb0c"},
        {120, "13f05a0b594787f5ecd315edc96141bd3243203d1b7d4f0836f37308b276ba98"}};
    for (const auto& [n, hex] : cases)
        EXPECT_EQ(fss::sha256Hex(std::string(std::size_t(n), 'x')), hex) << n;
}

// The digest does not depend on how the message is cut into update() calls.
TEST(Sha256, IncrementalEqualsOneShot) {
    std::mt19937 rng(7);
    std::string message(5000, '\0');
    for (char& c : message)
        c = char(rng() & 0xff);
    const std::string expected = fss::sha256Hex(message);
    for (std::size_t piece : {1u, 3u, 63u, 64u, 65u, 1000u}) {
        fss::Sha256 hash;
        for (std::size_t i = 0; i < message.size(); i += piece)
            hash.update(std::string_view(message).substr(i, piece));
        EXPECT_EQ(hash.hexDigest(), expected) << piece;
        EXPECT_EQ(hash.hexDigest(), expected) << "digest() twice";
        EXPECT_THROW(hash.update("x"), std::logic_error);
    }
}

TEST(Sha256, OfFile) {
    const auto path = fss::test::tmpPath("sha256_of_file.bin");
    {
        std::ofstream out(path, std::ios::binary);
        out << "abc";
    }
    EXPECT_EQ(fss::sha256OfFile(path), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_THROW(fss::sha256OfFile(fss::test::tmpPath("no_such_file.bin")), fss::IoError);
    EXPECT_THROW(fss::sha256OfFile(fss::test::tmpPath("")), fss::IoError); // a folder
}

} // namespace
