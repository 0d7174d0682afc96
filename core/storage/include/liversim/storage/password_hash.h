#pragma once
// Instructor passwords are kept only as Argon2id hashes (libsodium's crypto_pwhash_str): a
// random salt and the cost are part of the stored string, so a stolen database gives no password
// and no two equal passwords look alike.

#include <optional>
#include <string>
#include <string_view>

namespace liversim {

// Interactive cost (libsodium's OPSLIMIT/MEMLIMIT_INTERACTIVE: 2 passes over 64 MiB), as for
// a login; tests may pass kCheapPasswordCostForTesting.
struct PasswordHashCost {
  unsigned long long passes;
  std::size_t memory_bytes;
};
extern const PasswordHashCost kInteractivePasswordCost;
extern const PasswordHashCost kCheapPasswordCostForTesting;

// The rule a new password must meet (at least this many characters); std::invalid_argument
// names it otherwise.
inline constexpr std::size_t kMinimumPasswordLength = 8;
void check_new_password(std::string_view password);

std::string hash_password(std::string_view password,
                          const PasswordHashCost& cost = kInteractivePasswordCost);
// True when the password is the one hashed (in time independent of where they differ).
bool password_matches(std::string_view password, const std::string& stored_hash);

// Why a stored hash will not be verified, or nothing: it must be Argon2id (version 19) in
// libsodium's form, at a cost no higher than libsodium's sensitive level (4 passes over 1 GiB).
// The cost is read from the string itself, so a damaged or doctored file could otherwise make a
// log-in run for hours or take all the memory.
std::optional<std::string> stored_password_hash_problem(std::string_view stored_hash);

}  // namespace liversim
