// Crash safety of the workstation: killed with SIGKILL in the middle of a recorded session (a
// scripted device driving the tool at 1 kHz), it loses at most the last commit period; the next
// start marks the session incomplete, keeps every frame committed, and runs on.
// Runs the real `liversim` binary under the X server of the test run (xvfb-run in CI).
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
#include <thread>
#include <vector>

extern char** environ;

namespace liversim {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "crash" / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

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

int wait_for(pid_t child) {
  int status = 0;
  waitpid(child, &status, 0);
  return status;
}

// The session's frame count as committed so far (the file read as another process would).
std::optional<std::int64_t> committed_frames(const fs::path& database) {
  try {
    SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
    const std::vector<SessionSummary> sessions = store.sessions();
    if (sessions.empty()) return std::nullopt;
    return sessions.front().frame_count;
  } catch (const StorageError&) {
    return std::nullopt;  // not created yet, or mid-migration
  }
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
  const auto deadline = Clock::now() + std::chrono::seconds(90);
  std::optional<std::int64_t> before;
  while (Clock::now() < deadline) {
    before = committed_frames(database);
    if (before && *before >= 500) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(before && *before >= 500) << "the workstation recorded no session";
  ASSERT_EQ(kill(workstation, SIGKILL), 0);
  const int status = wait_for(workstation);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

  // The next start (opening for writing): the session is over, not lost.
  {
    SqliteSessionStore store(database);
    EXPECT_EQ(store.integrity_check(), "ok");
    const std::vector<SessionSummary> sessions = store.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
    EXPECT_GE(sessions[0].frame_count, *before) << "frames committed before the kill were lost";
    const std::vector<ServoFrame> frames = store.frames(sessions[0].id);
    ASSERT_EQ(static_cast<std::int64_t>(frames.size()), sessions[0].frame_count);
    for (std::size_t i = 1; i < frames.size(); ++i)
      ASSERT_GT(frames[i].time_s, frames[i - 1].time_s) << "frame " << i;
  }
  // And the workstation itself starts on that file and records again.
  const pid_t next =
      start_workstation(folder, {"--tets", "1000", "--database", database.string(), "--trajectory",
                                 trajectory.string(), "--quit-after", "3"});
  ASSERT_GT(next, 0);
  const int next_status = wait_for(next);
  ASSERT_TRUE(WIFEXITED(next_status)) << "the next start crashed";
  EXPECT_EQ(WEXITSTATUS(next_status), 0);
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_EQ(sessions[1].status, SessionStatus::complete) << "a quit ends its session normally";
  EXPECT_GT(sessions[1].frame_count, 0);
}

}  // namespace
}  // namespace liversim
