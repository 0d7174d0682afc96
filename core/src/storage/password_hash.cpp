#include "liversim/storage/password_hash.h"

#include <sodium.h>

#include <stdexcept>

namespace liversim {

const PasswordHashCost kInteractivePasswordCost{crypto_pwhash_OPSLIMIT_INTERACTIVE,
                                                crypto_pwhash_MEMLIMIT_INTERACTIVE};
const PasswordHashCost kCheapPasswordCostForTesting{crypto_pwhash_OPSLIMIT_MIN,
                                                    crypto_pwhash_MEMLIMIT_MIN};

namespace {

void initialise_sodium() {
  // Safe to call again and from several threads.
  if (sodium_init() < 0) throw std::runtime_error("the password library (libsodium) cannot start");
}

}  // namespace

void check_new_password(std::string_view password) {
  if (password.size() < kMinimumPasswordLength)
    throw std::invalid_argument("a password needs at least " +
                                std::to_string(kMinimumPasswordLength) + " characters");
  if (password.size() > crypto_pwhash_PASSWD_MAX)
    throw std::invalid_argument("the password is too long");
}

std::string hash_password(std::string_view password, const PasswordHashCost& cost) {
  initialise_sodium();
  char stored[crypto_pwhash_STRBYTES];
  if (crypto_pwhash_str_alg(stored, password.data(), password.size(), cost.passes,
                            cost.memory_bytes, crypto_pwhash_ALG_ARGON2ID13) != 0)
    throw std::runtime_error("hashing the password failed: not enough memory");
  return stored;
}

bool password_matches(std::string_view password, const std::string& stored_hash) {
  initialise_sodium();
  return crypto_pwhash_str_verify(stored_hash.c_str(), password.data(), password.size()) == 0;
}

}  // namespace liversim
