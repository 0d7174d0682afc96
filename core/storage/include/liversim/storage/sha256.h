#pragma once
// SHA-256 (FIPS 180-4), written from the standard: no external library. Sessions record the hash
// of the scenario text they ran, so a grade can be traced to the exact file.

#include <string>
#include <string_view>

namespace liversim {

// The digest of `bytes` as 64 lowercase hexadecimal digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace liversim
