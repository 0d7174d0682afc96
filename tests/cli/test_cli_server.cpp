// liversim-cli against the training centre's server (a throwaway PostgreSQL cluster on loopback):
// the administrator sets it up and adds logins, a workstation uploads its sessions exactly once,
// an instructor lists and exports them from the server and publishes a scenario that workstations
// pull; a bad URL, a wrong password, a server that is down or not set up each fail with the reason
// and the server named. Passwords go in on standard input, as a script would give them.
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"
#include "recorded_session.h"
#include "storage_test_support.h"
#include "throwaway_postgres.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace liversim {
namespace {

namespace fs = std::filesystem;
using testing::ThrowawayPostgres;

constexpr const char* kWorkstationPassword = "workstation password 7";
constexpr const char* kInstructorPassword = "instructor password 7";

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "cli-server" / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

// Runs liversim-cli with `arguments`, `input` on its standard input (a file: not a terminal, so
// passwords are read a line each).
CliRun run_cli(const fs::path& folder, std::vector<std::string> arguments,
               const std::string& input) {
  const fs::path in = folder / "stdin.txt", out = folder / "stdout.txt",
                 err = folder / "stderr.txt";
  std::ofstream(in, std::ios::binary) << input;
  arguments.insert(arguments.begin(), LIVERSIM_CLI);
  std::vector<char*> argv;
  for (std::string& a : arguments) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 0, in.c_str(), O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t child = 0;
  const int spawned = posix_spawn(&child, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  CliRun run;
  if (spawned != 0) {
    run.err = "cannot start " + std::string(LIVERSIM_CLI);
    return run;
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = read_text(out);
  run.err = read_text(err);
  return run;
}

std::string url_of(const ServerSettings& s) {
  return "postgresql://" + s.user + "@" + s.host + ":" + std::to_string(s.port) + "/" + s.database +
         "?sslmode=disable";
}

// The server set up by the administrator with a workstation's and an instructor's login, through
// the command line.
class CliServer : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fresh_folder(::testing::UnitTest::GetInstance()->current_test_info()->name());
    const std::string admin = url_of(server_.administrator());
    const std::string admin_password =
        std::string(ThrowawayPostgres::kAdministratorPassword) + "\n";
    CliRun r = run_cli(folder_, {"server", "set-up", "--server", admin}, admin_password);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("LiverSim schema version " +
                         std::to_string(PostgresSessionStore::kSchemaVersion)),
              std::string::npos)
        << r.out;
    r = run_cli(folder_, {"server", "add-login", "--server", admin, "ws01", "--workstation"},
                admin_password + kWorkstationPassword + "\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("added the workstation login ws01"), std::string::npos) << r.out;
    r = run_cli(folder_, {"server", "add-login", "--server", admin, "dr_grey", "--instructor"},
                admin_password + kInstructorPassword + "\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }

  std::string workstation_url() const { return url_of(server_.as("ws01")); }
  std::string instructor_url() const { return url_of(server_.as("dr_grey")); }

  ThrowawayPostgres server_;
  fs::path folder_;
};

TEST_F(CliServer, AWorkstationUploadsOnceAndTheInstructorReadsTheSessionFromTheServer) {
  const fs::path database = folder_ / "ws01.sqlite";
  {
    SqliteSessionStore local(database);
    testing::record_session(local, "Trainee \"Q\", the second", 2000, 11);
  }
  const std::string password = std::string(kWorkstationPassword) + "\n";
  CliRun r =
      run_cli(folder_, {"server", "upload", "--server", workstation_url(), "--database", database},
              password);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("uploaded 1 sessions"), std::string::npos) << r.out;
  r = run_cli(folder_, {"server", "upload", "--server", workstation_url(), "--database", database},
              password);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("uploaded 0 sessions"), std::string::npos) << r.out;

  // The same listing and the same export, to the digit, from the server as from the file.
  const std::string instructor_password = std::string(kInstructorPassword) + "\n";
  const CliRun local_list = run_cli(folder_, {"sessions", "list", "--database", database}, "");
  ASSERT_EQ(local_list.exit_code, 0) << local_list.err;
  const CliRun server_list =
      run_cli(folder_, {"sessions", "list", "--server", instructor_url()}, instructor_password);
  ASSERT_EQ(server_list.exit_code, 0) << server_list.err;
  EXPECT_EQ(server_list.out, local_list.out);
  EXPECT_NE(server_list.out.find("\"Trainee \"\"Q\"\", the second\""), std::string::npos)
      << server_list.out;
  const fs::path local_csv = folder_ / "local.csv", server_csv = folder_ / "server.csv";
  r = run_cli(
      folder_,
      {"sessions", "export", "--database", database, "--session", "1", "--frames", local_csv}, "");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_cli(folder_,
              {"sessions", "export", "--server", instructor_url(), "--session", "1", "--frames",
               server_csv},
              instructor_password);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string exported = read_text(server_csv);
  EXPECT_EQ(std::count(exported.begin(), exported.end(), '\n'), 2001);  // a header, 2000 frames
  EXPECT_EQ(exported, read_text(local_csv));
}

TEST_F(CliServer, AnInstructorPublishesAScenarioAndAWorkstationPullsIt) {
  const fs::path scenario = fs::path(LIVERSIM_TEST_DATA_DIR) / "scenario-small-resection.json";
  CliRun r = run_cli(folder_,
                     {"server", "publish-scenario", "--server", instructor_url(), "--instructor",
                      "dr_grey", scenario},
                     std::string(kInstructorPassword) + "\n" + kInstructorPassword + "\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("published scenario-small-resection"), std::string::npos) << r.out;
  // The instructor's own password is asked: a wrong one publishes nothing.
  r = run_cli(folder_,
              {"server", "publish-scenario", "--server", workstation_url(), "--instructor",
               "dr_grey", scenario},
              std::string(kWorkstationPassword) + "\nnot the instructor's password\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("refused the log-in of the instructor dr_grey"), std::string::npos) << r.err;

  const fs::path pulled = folder_ / "scenarios";
  r = run_cli(folder_,
              {"server", "pull-scenarios", "--server", workstation_url(), "--folder", pulled},
              std::string(kWorkstationPassword) + "\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("1 scenarios new or changed"), std::string::npos) << r.out;
  EXPECT_EQ(read_text(pulled / "scenario-small-resection.json"), read_text(scenario));
  r = run_cli(folder_,
              {"server", "pull-scenarios", "--server", workstation_url(), "--folder", pulled},
              std::string(kWorkstationPassword) + "\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("0 scenarios new or changed"), std::string::npos) << r.out;
}

TEST_F(CliServer, ABadURLAWrongPasswordAndADownServerAreNamedAndChangeNothing) {
  const fs::path database = folder_ / "ws01.sqlite";
  {
    SqliteSessionStore local(database);
    testing::record_session(local, "Trainee A", 100, 12);
  }
  const auto upload = [&](const std::string& url, const std::string& password) {
    return run_cli(folder_, {"server", "upload", "--server", url, "--database", database},
                   password + "\n");
  };
  // A password in the URL is refused, and not repeated in the message.
  const ServerSettings ws = server_.as("ws01");
  CliRun r =
      upload("postgresql://ws01:hunter2@" + ws.host + ":" + std::to_string(ws.port) + "/liversim",
             kWorkstationPassword);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("holds a password"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("hunter2"), std::string::npos) << r.err;

  r = upload(workstation_url(), "not the password");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("server ws01@" + ws.host + ":" + std::to_string(ws.port) +
                       "/liversim: the server refused the login"),
            std::string::npos)
      << r.err;

  // A database with no LiverSim schema: the message says who sets it up.
  const CliRun other =
      run_cli(folder_,
              {"sessions", "list", "--server",
               url_of(server_.administrator())
                   .replace(url_of(server_.administrator()).find("/liversim?"), 10, "/postgres?")},
              std::string(ThrowawayPostgres::kAdministratorPassword) + "\n");
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("server set-up"), std::string::npos) << other.err;

  server_.stop();
  r = upload(workstation_url(), kWorkstationPassword);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cannot connect"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::to_string(ws.port)), std::string::npos) << r.err;
  {
    SqliteSessionStore local(database);
    EXPECT_EQ(local.sessions_to_upload(server_name(ws)).size(), 1u)
        << "a failed upload counted the session as uploaded";
  }
  server_.start();
  r = upload(workstation_url(), kWorkstationPassword);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("uploaded 1 sessions"), std::string::npos) << r.out;

  // Bad files: a database that is not there (not created), a scenario that does not validate (its
  // errors named, nothing published), a folder that cannot be made.
  r = run_cli(
      folder_,
      {"server", "upload", "--server", workstation_url(), "--database", folder_ / "no-such.sqlite"},
      std::string(kWorkstationPassword) + "\n");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no-such.sqlite"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(folder_ / "no-such.sqlite"));
  const fs::path broken = folder_ / "broken.json";
  std::ofstream(broken) << "{\"title\": \"no liver, no task\"}";
  r = run_cli(folder_,
              {"server", "publish-scenario", "--server", instructor_url(), "--instructor",
               "dr_grey", broken},
              std::string(kInstructorPassword) + "\n" + kInstructorPassword + "\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("broken"), std::string::npos) << r.err;
  r = run_cli(folder_,
              {"server", "pull-scenarios", "--server", workstation_url(), "--folder",
               folder_ / "stdin.txt" / "scenarios"},
              std::string(kWorkstationPassword) + "\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("scenario folder"), std::string::npos) << r.err;

  // Usage errors: exit code 2 from the parser or the command, before any password is asked.
  r = run_cli(folder_, {"server", "add-login", "--server", workstation_url(), "someone"}, "");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--workstation and --instructor"), std::string::npos) << r.err;
  r = run_cli(folder_, {"sessions", "list"}, "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--database and --server"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace liversim
