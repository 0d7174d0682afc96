#pragma once
// A real PostgreSQL server for the tests: a new cluster (initdb) in a temporary folder, started
// on a free loopback port with password (SCRAM) logins, stopped and removed at the end. The
// server's programs come from Debian's `postgresql` package, which the set-up script installs.
// As root, the server runs as the `postgres` user (PostgreSQL refuses to run as root).

#include "liversim/storage/server_settings.h"

#include <filesystem>
#include <string>

namespace liversim::testing {

class ThrowawayPostgres {
 public:
  struct Options {
    bool tls = false;  // a test certificate authority signs the server's certificate
    // Writes durably (fsync on), as a real server: for the load bench. The tests need not.
    bool durable = false;
  };
  // Throws std::runtime_error saying what failed (the server's log is in the message).
  ThrowawayPostgres() : ThrowawayPostgres(Options{}) {}
  explicit ThrowawayPostgres(Options options);
  ~ThrowawayPostgres();
  ThrowawayPostgres(const ThrowawayPostgres&) = delete;
  ThrowawayPostgres& operator=(const ThrowawayPostgres&) = delete;

  // The superuser, who owns the database "liversim" (made empty at start).
  ServerSettings administrator() const { return as("liversim_admin"); }
  static constexpr const char* kAdministratorPassword = "administrator password";
  ServerSettings as(const std::string& user) const;

  // Stops at once, as a crash or a pulled cable would (pg_ctl -m immediate); start() again on the
  // same port with the same data.
  void stop();
  void start();
  bool running() const { return running_; }

  const std::filesystem::path& folder() const { return folder_; }
  // The test certificate authority's certificate (tls only), and a second one that signed nothing.
  std::filesystem::path certificate_authority() const { return folder_ / "ca.crt"; }
  std::filesystem::path other_certificate_authority() const { return folder_ / "other-ca.crt"; }

 private:
  void run(const std::string& what, const std::string& command) const;

  Options options_;
  std::filesystem::path folder_;
  std::filesystem::path bin_;
  int port_ = 0;
  bool running_ = false;
  bool as_postgres_user_ = false;
};

}  // namespace liversim::testing
