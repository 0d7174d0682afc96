#include "throwaway_postgres.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace liversim::testing {

namespace fs = std::filesystem;

namespace {

// The newest /usr/lib/postgresql/N/bin that has initdb.
fs::path server_programs() {
  std::vector<fs::path> found;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator("/usr/lib/postgresql", error))
    if (fs::exists(entry.path() / "bin" / "initdb")) found.push_back(entry.path() / "bin");
  if (found.empty())
    throw std::runtime_error(
        "no PostgreSQL server programs in /usr/lib/postgresql/*/bin: install Debian's "
        "postgresql package (packaging/setup-debian.sh does)");
  std::sort(found.begin(), found.end(), [](const fs::path& a, const fs::path& b) {
    return std::stoi(a.parent_path().filename()) < std::stoi(b.parent_path().filename());
  });
  return found.back();
}

int free_loopback_port() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  if (s < 0 || bind(s, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      getsockname(s, reinterpret_cast<sockaddr*>(&address), &size) != 0)
    throw std::runtime_error("no free loopback port");
  close(s);
  return ntohs(address.sin_port);
}

std::string file_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

ThrowawayPostgres::ThrowawayPostgres(Options options) : options_(options), bin_(server_programs()) {
  std::string pattern = (fs::temp_directory_path() / "liversim-postgres-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  folder_ = pattern;
  as_postgres_user_ = geteuid() == 0;
  try {
    std::ofstream(folder_ / "password") << kAdministratorPassword << '\n';
    if (options_.tls) {
      // A certificate authority, a server certificate it signs for localhost and 127.0.0.1, and
      // another authority that signed nothing (a client trusting it must refuse the server).
      std::ofstream(folder_ / "san.cnf") << "subjectAltName=DNS:localhost,IP:127.0.0.1\n";
      const std::string f = folder_.string();
      const std::string key = " -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes";
      run("making the test certificate authority",
          "openssl req -x509" + key + " -keyout " + f + "/ca.key -out " + f +
              "/ca.crt -days 2 -subj /CN=LiverSim-test-CA");
      run("making the other certificate authority",
          "openssl req -x509" + key + " -keyout " + f + "/other-ca.key -out " + f +
              "/other-ca.crt -days 2 -subj /CN=Somebody-else");
      run("making the server's certificate request", "openssl req" + key + " -keyout " + f +
                                                         "/server.key -out " + f +
                                                         "/server.csr -subj /CN=localhost");
      run("signing the server's certificate", "openssl x509 -req -in " + f + "/server.csr -CA " +
                                                  f + "/ca.crt -CAkey " + f +
                                                  "/ca.key -CAcreateserial -out " + f +
                                                  "/server.crt -days 2 -extfile " + f + "/san.cnf");
      fs::permissions(folder_ / "server.key", fs::perms::owner_read | fs::perms::owner_write);
    }
    if (as_postgres_user_) {
      const passwd* user = getpwnam("postgres");
      if (user == nullptr) throw std::runtime_error("there is no user postgres to run the server");
      for (const auto& entry : fs::recursive_directory_iterator(folder_))
        if (chown(entry.path().c_str(), user->pw_uid, user->pw_gid) != 0)
          throw std::runtime_error("cannot give " + entry.path().string() + " to postgres");
      if (chown(folder_.c_str(), user->pw_uid, user->pw_gid) != 0)
        throw std::runtime_error("cannot give " + folder_.string() + " to postgres");
    }
    run("initdb", (bin_ / "initdb").string() + " -D " + (folder_ / "data").string() +
                      " -U liversim_admin --pwfile=" + (folder_ / "password").string() +
                      " --auth=scram-sha-256 -E UTF8 --locale=C.UTF-8 --no-sync");
    port_ = free_loopback_port();
    start();
    run("creating the database", "PGPASSWORD='" + std::string(kAdministratorPassword) + "' " +
                                     (bin_ / "createdb").string() + " -h 127.0.0.1 -p " +
                                     std::to_string(port_) + " -U liversim_admin liversim");
  } catch (...) {
    if (running_) stop();
    fs::remove_all(folder_);
    throw;
  }
}

ThrowawayPostgres::~ThrowawayPostgres() {
  try {
    if (running_) stop();
  } catch (...) {
  }
  std::error_code ignored;
  fs::remove_all(folder_, ignored);
}

void ThrowawayPostgres::run(const std::string& what, const std::string& command) const {
  const fs::path log = folder_ / "commands.log";
  const std::string line = command + " >>" + log.string() + " 2>&1";
  const bool server_program = command.starts_with(bin_.string());
  const std::string full =
      as_postgres_user_ && server_program ? "runuser -u postgres -- " + line : line;
  if (std::system(full.c_str()) != 0)
    throw std::runtime_error(what + " failed (" + command + "):\n" + file_text(log) +
                             file_text(folder_ / "server.log"));
}

void ThrowawayPostgres::start() {
  std::string settings = "-p " + std::to_string(port_) + " -k " + folder_.string() +
                         " -c listen_addresses=127.0.0.1 -c max_connections=60";
  if (!options_.durable) settings += " -c fsync=off";
  if (options_.tls)
    settings += " -c ssl=on -c ssl_cert_file=" + (folder_ / "server.crt").string() +
                " -c ssl_key_file=" + (folder_ / "server.key").string();
  run("starting the server", (bin_ / "pg_ctl").string() + " -D " + (folder_ / "data").string() +
                                 " -l " + (folder_ / "server.log").string() + " -w -o \"" +
                                 settings + "\" start");
  running_ = true;
}

void ThrowawayPostgres::stop() {
  run("stopping the server",
      (bin_ / "pg_ctl").string() + " -D " + (folder_ / "data").string() + " -m immediate -w stop");
  running_ = false;
}

ServerSettings ThrowawayPostgres::as(const std::string& user) const {
  ServerSettings settings;
  settings.host = "127.0.0.1";
  settings.port = port_;
  settings.database = "liversim";
  settings.user = user;
  settings.ssl_mode = options_.tls ? "verify-full" : "disable";
  if (options_.tls) settings.ssl_root_cert = certificate_authority();
  settings.connect_timeout_s = 3;
  return settings;
}

}  // namespace liversim::testing
