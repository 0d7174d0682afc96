#include "liversim/storage/password_hash.h"

#include <sodium.h>

#include <charconv>
#include <cstdint>
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

std::optional<std::string> stored_password_hash_problem(std::string_view stored_hash) {
  constexpr std::string_view kForm = "$argon2id$v=19$";
  if (!stored_hash.starts_with(kForm))
    return std::string("it is not an Argon2id hash of version 19 ($argon2id$v=19$...)");
  // m=<KiB>,t=<passes>,p=<lanes>$
  std::string_view rest = stored_hash.substr(kForm.size());
  const auto number = [&rest](std::string_view label, std::uint64_t& value) {
    if (!rest.starts_with(label)) return false;
    rest.remove_prefix(label.size());
    const auto [end, error] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
    if (error != std::errc() || end == rest.data()) return false;
    rest.remove_prefix(static_cast<std::size_t>(end - rest.data()));
    return true;
  };
  std::uint64_t memory_kib = 0, passes = 0, lanes = 0;
  if (!number("m=", memory_kib) || !number(",t=", passes) || !number(",p=", lanes) ||
      !rest.starts_with('$'))
    return std::string("its cost is not written as m=KiB,t=passes,p=lanes");
  if (memory_kib > crypto_pwhash_MEMLIMIT_SENSITIVE / 1024)
    return "it asks for " + std::to_string(memory_kib / 1024) + " MiB, more than the " +
           std::to_string(crypto_pwhash_MEMLIMIT_SENSITIVE / (1024 * 1024)) +
           " MiB of the highest cost";
  if (passes > crypto_pwhash_OPSLIMIT_SENSITIVE)
    return "it asks for " + std::to_string(passes) + " passes, more than the " +
           std::to_string(crypto_pwhash_OPSLIMIT_SENSITIVE) + " of the highest cost";
  return std::nullopt;
}

bool password_matches(std::string_view password, const std::string& stored_hash) {
  initialise_sodium();
  return crypto_pwhash_str_verify(stored_hash.c_str(), password.data(), password.size()) == 0;
}

}  // namespace liversim
