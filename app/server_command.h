#pragma once
// liversim-cli server: the training centre's PostgreSQL server (docs/training-centre.md).
//   server set-up --server URL                  create or migrate the schema (administrator)
//   server add-login --server URL NAME --workstation|--instructor
//   server upload --server URL --database FILE  upload finished sessions, pull grades
//   server pull-scenarios --server URL --folder DIR
//   server publish-scenario --server URL --instructor NAME FILE
// Passwords are read from the terminal without echo, or one per line from standard input when
// it is not a terminal; --pgpass leaves the connection's password to libpq (~/.pgpass, a client
// certificate). No password is ever taken from the command line, where `ps` would show it.

#include "liversim/storage/postgres_session_store.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace CLI {
class App;
}

namespace liversim::cli {

std::function<std::optional<int>()> add_server_command(CLI::App& app);

// A password from the terminal (without echo) or the next line of standard input.
std::string read_password(const std::string& prompt);

// The options naming a server: --server URL and --pgpass.
struct ServerConnectionOptions {
  std::string url;
  bool pgpass = false;
};
// Adds them to a command; --server required or not.
void add_server_connection_options(CLI::App& command, ServerConnectionOptions& options,
                                   bool required);

// The password of the login of `settings`: none with --pgpass (libpq finds it), else asked.
std::string login_password(const ServerSettings& settings, bool pgpass);

// Connects to the server of `options.url` (parse_server_url), asking the login's password unless
// --pgpass. Throws StorageError or std::invalid_argument naming what is wrong.
std::unique_ptr<PostgresSessionStore> connect_to_server(const ServerConnectionOptions& options);

}  // namespace liversim::cli
