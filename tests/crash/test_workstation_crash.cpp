// Crash safety of the workstation, the real `liversim` binary recording a scripted device session
// (the tool driven at 1 kHz) under the X server of the test run (xvfb-run in CI):
// - killed with SIGKILL mid-session, it loses at most the last commit period; the next start marks
//   the session incomplete, keeps every frame committed, and runs on;
// - SIGTERM (a logout, a shutdown) ends the session normally;
// - a full disk and a file system turned read-only mid-session stop the recording with the
//   message the trainee sees also in its log, the workstation goes on until it is closed, nothing
//   committed is lost and the next start records again.
#include "process_faults.h"

#include "liversim/storage/sqlite_session_store.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace liversim {
namespace {

namespace fs = std::filesystem;
using crash::expect_frames_in_order;
using crash::fresh_folder;
using crash::read_text;
using crash::wait_for;

// The workstation's command line; its settings go to the test's folder, not the user's.
std::vector<std::string> workstation(const fs::path& folder,
                                     const std::vector<std::string>& arguments) {
  setenv("QT_QPA_PLATFORM", "xcb", 1);
  setenv("XDG_CONFIG_HOME", (folder / "config").c_str(), 1);
  std::vector<std::string> all{LIVERSIM_WORKSTATION};
  all.insert(all.end(), arguments.begin(), arguments.end());
  return all;
}

// The scripted tool held still above the liver for ten minutes: a session recorded at 1 kHz.
fs::path write_trajectory(const fs::path& folder) {
  const fs::path trajectory = folder / "trajectory.txt";
  std::ofstream(trajectory) << "0 5 6 40 0\n600 15 6 40 0\n";
  return trajectory;
}

std::vector<std::string> recording(const fs::path& database, const fs::path& trajectory) {
  return {"--tets", "1000", "--database", database.string(), "--trajectory", trajectory.string()};
}

// Waits until `file` holds `text` (or `patience` has passed); whether it does.
bool wait_for_text(const fs::path& file, const std::string& text, std::chrono::seconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (std::chrono::steady_clock::now() < deadline) {
    if (read_text(file).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// The next start on `database`: the workstation runs three seconds on it, quits normally and has
// recorded a second session, complete.
void expect_the_next_start_records(const fs::path& folder, const fs::path& database) {
  const fs::path next_folder = folder / "next-start";
  fs::create_directories(next_folder);
  std::vector<std::string> arguments = recording(database, write_trajectory(folder));
  arguments.insert(arguments.end(), {"--quit-after", "3"});
  const pid_t next = crash::spawn(workstation(folder, arguments), next_folder);
  ASSERT_GT(next, 0);
  EXPECT_EQ(wait_for(next), 0) << "the next start crashed or failed: "
                               << read_text(next_folder / "stderr.txt");
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_EQ(sessions[1].status, SessionStatus::complete) << "a quit ends its session normally";
  EXPECT_GT(sessions[1].frame_count, 0);
}

// The one session of `database` as the next start finds it: integrity ok, over (incomplete), with
// at least `committed` frames, all readable in time order.
void expect_the_session_kept(const fs::path& database, std::int64_t committed) {
  SqliteSessionStore store(database);  // for writing, as the next start opens it
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_GE(sessions[0].frame_count, committed) << "frames committed before were lost";
  EXPECT_GT(sessions[0].frame_count, 0);
  expect_frames_in_order(store, sessions[0]);
}

class WorkstationCrash : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(std::getenv("DISPLAY"), nullptr) << "run under xvfb-run: the workstation needs X";
  }

  // Starts the workstation recording to folder/sessions.sqlite and waits until it has committed
  // `frames` frames (the scene is built first); what it committed, none (a failure) if it did not.
  std::optional<std::int64_t> startRecording(const fs::path& folder, std::int64_t frames) {
    database_ = folder / "sessions.sqlite";
    running_ =
        crash::spawn(workstation(folder, recording(database_, write_trajectory(folder))), folder);
    if (running_ <= 0) {
      ADD_FAILURE() << "the workstation could not be started";
      return std::nullopt;
    }
    return crash::wait_until_recording(running_, database_, frames, kStartPatience, folder);
  }

  static constexpr std::chrono::seconds kStartPatience{90};  // the scene is built first

  fs::path database_;
  pid_t running_ = -1;
};

TEST_F(WorkstationCrash, KilledMidSessionItLosesNothingCommittedAndTheNextStartRecovers) {
  const fs::path folder = fresh_folder("killed-mid-session");
  // Half a second of frames committed.
  const std::optional<std::int64_t> before = startRecording(folder, 500);
  if (!before) return;
  // The next start (opening for writing): the session is over, not lost.
  crash::kill_and_expect_recovery(running_, database_, *before);
  if (HasFatalFailure()) return;
  expect_the_next_start_records(folder, database_);
}

TEST_F(WorkstationCrash, SigtermEndsTheSessionNormally) {
  const fs::path folder = fresh_folder("sigterm");
  const std::optional<std::int64_t> before = startRecording(folder, 300);
  if (!before) return;
  ASSERT_EQ(kill(running_, SIGTERM), 0);
  EXPECT_EQ(wait_for(running_), 0) << read_text(folder / "stderr.txt");
  EXPECT_NE(read_text(folder / "stderr.txt").find("SIGTERM: closing"), std::string::npos);
  SqliteSessionStore store(database_, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::complete);
  EXPECT_GE(sessions[0].frame_count, *before);
}

// A real full disk: the sessions file on a 256 KiB tmpfs, in a user and mount namespace. The
// workstation runs 12 s (the disk is full within a few), then is closed as --quit-after closes it.
TEST_F(WorkstationCrash, AFullDiskStopsTheRecordingWithItsMessageAndTheWorkstationGoesOn) {
  if (const auto why = crash::namespaces_unavailable()) GTEST_SKIP() << *why;
  const fs::path folder = fresh_folder("workstation-full-disk");
  const fs::path disk = folder / "disk";
  const fs::path database = disk / "sessions.sqlite";
  std::vector<std::string> arguments = recording(database, write_trajectory(folder));
  arguments.insert(arguments.end(), {"--quit-after", "12"});
  ASSERT_EQ(crash::run_on_a_small_disk(workstation(folder, arguments), folder, disk,
                                       "sessions.sqlite", 256),
            0)
      << read_text(folder / "stderr.txt");
  const std::string said = read_text(folder / "stderr.txt");
  EXPECT_EQ(std::stoi(read_text(folder / "rc")), 0) << "the workstation did not go on: " << said;
  EXPECT_NE(said.find("Recording stopped: this session is no longer being saved"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("the disk or the database is full"), std::string::npos) << said;
  EXPECT_NE(said.find(database.string()), std::string::npos) << said;
  // What was committed is in the file, which the next start (with room on its disk) recovers.
  const fs::path kept = folder / "kept" / "sessions.sqlite";
  expect_the_session_kept(kept, 0);
  if (HasFatalFailure()) return;
  expect_the_next_start_records(folder, kept);
}

// Its file system turning read-only under the running workstation (every write to a file then
// fails with EROFS, as after `errors=remount-ro`; crash::ReadOnlyFileSystem).
TEST_F(WorkstationCrash, AFileSystemTurnedReadOnlyStopsTheRecordingWithItsMessage) {
#if !defined(__x86_64__)
  GTEST_SKIP() << "the seccomp filter of this test is written for x86-64";
#endif
  const fs::path folder = fresh_folder("workstation-read-only");
  const fs::path database = folder / "sessions.sqlite";
  crash::ReadOnlyFileSystem file_system;
  std::string problem;
  const pid_t running = file_system.start(
      workstation(folder, recording(database, write_trajectory(folder))), folder, problem);
  if (running < 0) GTEST_SKIP() << problem;
  const std::optional<std::int64_t> before =
      crash::wait_until_recording(running, database, 500, kStartPatience, folder);
  if (!before) return;
  file_system.make_read_only();
  const bool stopped =
      wait_for_text(folder / "stderr.txt", "Recording stopped", std::chrono::seconds(60));
  // Still running after it: closed as a logout closes it.
  const bool running_on = kill(running, 0) == 0;
  kill(running, SIGTERM);
  EXPECT_EQ(wait_for(running), 0) << read_text(folder / "stderr.txt");
  ASSERT_TRUE(stopped) << read_text(folder / "stderr.txt");
  EXPECT_TRUE(running_on);
  const std::string said = read_text(folder / "stderr.txt");
  EXPECT_NE(said.find("this session is no longer being saved"), std::string::npos) << said;
  EXPECT_NE(said.find("read-only"), std::string::npos) << said;
  EXPECT_NE(said.find(database.string()), std::string::npos) << said;
  expect_the_session_kept(database, *before);
  if (HasFatalFailure()) return;
  expect_the_next_start_records(folder, database);
}

}  // namespace
}  // namespace liversim
