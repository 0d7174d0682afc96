#pragma once
// Where the training centre's PostgreSQL server is: the connection setting that the GUI's
// settings and the CLI's --server flag hold. It never holds a password (docs/training-centre.md):
// that is given when connecting, or found by libpq in the user's password file (~/.pgpass, which
// libpq refuses to read unless only its owner can) or a client certificate.

#include <filesystem>
#include <string>
#include <string_view>

namespace liversim {

struct ServerSettings {
  std::string host;  // name or address; a path starting with '/' is a Unix socket's folder
  int port = 5432;
  std::string database = "liversim";
  std::string user;  // the workstation's or the instructor's server role
  // TLS, passed to libpq as they are: disable, allow, prefer, require, verify-ca, verify-full.
  std::string ssl_mode = "prefer";
  std::filesystem::path ssl_root_cert;  // the certificate authority that signed the server's
  std::filesystem::path ssl_cert;       // the client certificate and its key, when the server
  std::filesystem::path ssl_key;        // asks for one
  int connect_timeout_s = 5;

  bool operator==(const ServerSettings&) const = default;
};

// "postgresql://user@host:port/database?sslmode=verify-full&sslrootcert=/path/ca.crt" (also
// "postgres://"; sslcert, sslkey and connect_timeout too). Throws std::invalid_argument naming
// what is wrong; a password in the URL is refused, so that none is written to settings.
ServerSettings parse_server_url(std::string_view url);
// The URL of the settings (no password: they hold none), which parse_server_url reads back.
std::string server_url(const ServerSettings& settings);
// "user@host:port/database", for messages.
std::string server_name(const ServerSettings& settings);

}  // namespace liversim
