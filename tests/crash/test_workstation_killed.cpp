// Crash safety of the workstation: killed with SIGKILL in the middle of a recorded session (a
// scripted device driving the tool at 1 kHz), it loses at most the last commit period; the next
// start marks the session incomplete, keeps every frame committed, and runs on.
// Runs the real `liversim` binary under the X server of the test run (xvfb-run in CI).
#include "crash_support.h"
#include "liversim/storage/sqlite_session_store.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

extern char** environ;

namespace liversim {
namespace {

namespace fs = std::filesystem;
using crash::fresh_folder;
using crash::wait_for;

// The workstation's settings go to the test's folder, not the user's.
pid_t start_workstation(const fs::path& folder, const std::vector<std::string>& arguments) {
  std::vector<std::string> all{LIVERSIM_WORKSTATION};
  all.insert(all.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  setenv("QT_QPA_PLATFORM", "xcb", 1);
  setenv("XDG_CONFIG_HOME", (folder / "config").c_str(), 1);
  pid_t child = 0;
  if (posix_spawn(&child, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return child;
}

TEST(WorkstationKilled, MidSessionItLosesNothingCommittedAndTheNextStartRecovers) {
  ASSERT_NE(std::getenv("DISPLAY"), nullptr) << "run under xvfb-run: the workstation needs X";
  const fs::path folder = fresh_folder("killed-mid-session");
  const fs::path database = folder / "sessions.sqlite";
  const fs::path trajectory = folder / "trajectory.txt";
  std::ofstream(trajectory) << "0 5 6 40 0\n600 15 6 40 0\n";

  const pid_t workstation = start_workstation(
      folder,
      {"--tets", "1000", "--database", database.string(), "--trajectory", trajectory.string()});
  ASSERT_GT(workstation, 0);
  // Recording: at least half a second of frames committed.
  const std::optional<std::int64_t> before =
      crash::wait_for_committed(database, 500, std::chrono::seconds(90));
  ASSERT_TRUE(before && *before >= 500) << "the workstation recorded no session";
  // The next start (opening for writing): the session is over, not lost.
  crash::kill_and_expect_recovery(workstation, database, *before);
  if (HasFatalFailure()) return;
  // And the workstation itself starts on that file and records again.
  const pid_t next =
      start_workstation(folder, {"--tets", "1000", "--database", database.string(), "--trajectory",
                                 trajectory.string(), "--quit-after", "3"});
  ASSERT_GT(next, 0);
  EXPECT_EQ(wait_for(next), 0) << "the next start crashed or failed";
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_EQ(sessions[1].status, SessionStatus::complete) << "a quit ends its session normally";
  EXPECT_GT(sessions[1].frame_count, 0);
}

}  // namespace
}  // namespace liversim
