// SHA-256 against the FIPS 180-4 / NIST examples and around the padding boundary, where the length
// no longer fits in the last block (55 bytes fit, 56 do not; 64 fill a block exactly).
#include "liversim/storage/sha256.h"

#include <gtest/gtest.h>

#include <string>

namespace liversim {
namespace {

TEST(Sha256, EmptyMessage) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256, OneBlockMessageAbc) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, TwoBlockMessage448Bits) {
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, OneMillionA) {
  EXPECT_EQ(sha256_hex(std::string(1'000'000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Expected digests from `printf '0123456789%.0s' $(seq 7) | head -c N | sha256sum` (GNU
// coreutils): digits rather than one repeated letter, so swapped bytes or words would show.
TEST(Sha256, LengthsAroundThePaddingBoundary) {
  const std::string digits =
      "0123456789012345678901234567890123456789012345678901234567890123456789";
  const struct {
    std::size_t length;
    const char* digest;
  } cases[] = {
      {55, "f34d5a0f80c0cbf84c8c0b90218c22637abd199965249da736a20143c8c9c9d9"},
      {56, "83aa034bda83e458a0dc9cbce0d4e354716aa0ff770ed37ac0ed2b292052e4af"},
      {63, "074f6e9ac301d5d1b6df6f1dfb8c6f89c187ea945d352ce6a29279a9c630680b"},
      {64, "9674d9e078535b7cec43284387a6ee39956188e735a85452b0050b55341cda56"},
      {65, "52774b57c10e45040a61c14d35c1c8ebefe880082313aa0a21ebb077734cd067"},
  };
  for (const auto& c : cases)
    EXPECT_EQ(sha256_hex(std::string_view(digits).substr(0, c.length)), c.digest)
        << c.length << " bytes";
}

// Every byte value once, 0x00 to 0xff: bytes above 0x7f must count as unsigned. Expected digest
// from `printf` of the 256 octal escapes \000..\377 piped to `sha256sum`.
TEST(Sha256, EveryByteValue) {
  std::string bytes;
  for (int value = 0; value < 256; ++value) bytes += static_cast<char>(value);
  EXPECT_EQ(sha256_hex(bytes), "40aff2e9d2d8922e47afd4648e6967497158785fbd1da870e7110266bf944880");
}

}  // namespace
}  // namespace liversim
