#include "server_command.h"

#include "liversim/storage/session_upload.h"
#include "liversim/storage/sqlite_session_store.h"

#include <termios.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <array>
#include <fstream>
#include <iostream>
#include <sstream>

namespace liversim::cli {

std::string read_password(const std::string& prompt) {
  if (!isatty(STDIN_FILENO)) {
    std::string line;
    std::getline(std::cin, line);
    return line;
  }
  std::cerr << prompt << ": " << std::flush;
  termios old{};
  tcgetattr(STDIN_FILENO, &old);
  termios quiet = old;
  quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO);
  tcsetattr(STDIN_FILENO, TCSANOW, &quiet);
  std::string line;
  std::getline(std::cin, line);
  tcsetattr(STDIN_FILENO, TCSANOW, &old);
  std::cerr << '\n';
  return line;
}

void add_server_connection_options(CLI::App& command, ServerConnectionOptions& options,
                                   bool required) {
  CLI::Option* url =
      command.add_option("--server", options.url,
                         "The training centre's server: postgresql://LOGIN@HOST:PORT/DATABASE"
                         "?sslmode=...");
  if (required) url->required();
  command.add_flag("--pgpass", options.pgpass,
                   "Ask no password: libpq's ~/.pgpass or a client certificate");
}

std::string login_password(const ServerSettings& settings, bool pgpass) {
  return pgpass ? std::string() : read_password("password of " + server_name(settings));
}

std::unique_ptr<PostgresSessionStore> connect_to_server(const ServerConnectionOptions& options) {
  const ServerSettings settings = parse_server_url(options.url);
  return std::make_unique<PostgresSessionStore>(settings, login_password(settings, options.pgpass));
}

namespace {

struct ServerOptions {
  ServerConnectionOptions server;
  std::string name;
  bool workstation = false, instructor = false;
  std::filesystem::path database, folder, scenario_file;
  std::string instructor_name;
};

// Reads a scenario file whole; nullopt (and the reason on stderr) when it cannot.
std::optional<std::string> read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) {
    std::cerr << "error: cannot read " << file.string() << '\n';
    return std::nullopt;
  }
  return text.str();
}

int run(const std::string& which, const ServerOptions& o) {
  const ServerSettings settings = parse_server_url(o.server.url);
  if (which == "add-login" && o.workstation == o.instructor) {
    std::cerr << "error: add-login needs one of --workstation and --instructor\n";
    return 2;
  }
  std::optional<std::string> scenario_text;
  if (which == "publish-scenario" && !(scenario_text = read_text(o.scenario_file))) return 1;
  const std::string password = login_password(settings, o.server.pgpass);
  if (which == "set-up") {
    PostgresSessionStore::set_up_server(settings, password);
    PostgresSessionStore store(settings, password);
    std::cout << "server " << server_name(settings) << ": LiverSim schema version "
              << store.schema_version() << '\n';
    return 0;
  }
  if (which == "add-login") {
    const std::string new_password = read_password("password for the new login " + o.name);
    PostgresSessionStore::add_server_login(
        settings, password, o.name, new_password,
        o.instructor ? ServerLoginKind::instructor : ServerLoginKind::workstation);
    std::cout << "added the " << (o.instructor ? "instructor" : "workstation") << " login "
              << o.name << " on " << server_name(settings) << '\n';
    return 0;
  }
  PostgresSessionStore central(settings, password);
  if (which == "upload") {
    SqliteSessionStore local(o.database);
    const SyncReport report = synchronise(local, central);
    std::cout << "uploaded " << report.uploaded << " sessions (" << report.chunk_bytes_sent
              << " bytes of chunks) to " << server_name(settings) << ", already there "
              << report.already_there << ", waiting " << report.waiting << ", grades pulled "
              << report.grades_pulled << '\n';
    if (report.problem) {
      std::cerr << "error: the upload stopped: " << *report.problem
                << " (what is not uploaded goes with the next upload)\n";
      return 3;
    }
    return 0;
  }
  if (which == "pull-scenarios") {
    const std::vector<std::string> written = pull_scenarios(central, o.folder);
    for (const std::string& name : written)
      std::cout << "pulled " << (o.folder / (name + ".json")).string() << '\n';
    std::cout << written.size() << " scenarios new or changed from " << server_name(settings)
              << '\n';
    return 0;
  }
  // publish-scenario
  const std::string instructor_password = read_password("password of " + o.instructor_name);
  const std::optional<Instructor> by =
      central.log_in_instructor(o.instructor_name, instructor_password);
  if (!by) {
    std::cerr << "error: " << server_name(settings) << " refused the log-in of the instructor "
              << o.instructor_name << '\n';
    return 1;
  }
  const std::string name = o.scenario_file.stem().string();
  central.publish_scenario(*by, name, *scenario_text);
  std::cout << "published " << name << " on " << server_name(settings) << '\n';
  return 0;
}

}  // namespace

std::function<std::optional<int>()> add_server_command(CLI::App& app) {
  auto options = std::make_shared<ServerOptions>();
  auto* server = app.add_subcommand("server", "The training centre's PostgreSQL server");
  server->require_subcommand(1);
  const auto common = [&](CLI::App* sub) {
    add_server_connection_options(*sub, options->server, true);
  };
  auto* set_up = server->add_subcommand("set-up", "Create or migrate the schema (administrator)");
  common(set_up);
  auto* add_login =
      server->add_subcommand("add-login", "Add a workstation's or instructor's login");
  common(add_login);
  add_login->add_option("name", options->name, "The login's name")->required();
  add_login->add_flag("--workstation", options->workstation);
  add_login->add_flag("--instructor", options->instructor);
  auto* upload = server->add_subcommand("upload", "Upload finished sessions, pull grades");
  common(upload);
  upload->add_option("--database", options->database, "The workstation's sessions database")
      ->required()
      ->check(CLI::ExistingFile);
  auto* pull =
      server->add_subcommand("pull-scenarios", "Write the published scenarios to a folder");
  common(pull);
  pull->add_option("--folder", options->folder)->required();
  auto* publish = server->add_subcommand("publish-scenario", "Publish a scenario file");
  common(publish);
  publish->add_option("--instructor", options->instructor_name)->required();
  publish->add_option("file", options->scenario_file)->required()->check(CLI::ExistingFile);
  const std::array<CLI::App*, 5> subs{set_up, add_login, upload, pull, publish};
  return [options, subs]() -> std::optional<int> {
    for (CLI::App* sub : subs) {
      if (!sub->parsed()) continue;
      try {
        return run(sub->get_name(), *options);
      } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << '\n';
        return 1;
      }
    }
    return std::nullopt;
  };
}

}  // namespace liversim::cli
