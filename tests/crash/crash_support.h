#pragma once
// What the crash tests share: a fresh folder for a test's files, how a child process ended, and a
// sessions database read as another process reads it while it is being written.
#include "liversim/storage/sqlite_session_store.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace liversim::crash {

inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path folder =
      std::filesystem::path(LIVERSIM_TEST_OUTPUT_DIR) / "crash" / name;
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  return folder;
}

// Its exit code, or minus the signal that ended it.
inline int wait_for(pid_t child) {
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

// The first session's frame count as committed so far; none before the file or its session is
// there.
inline std::optional<std::int64_t> committed_frames(const std::filesystem::path& database) {
  try {
    SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
    const std::vector<SessionSummary> sessions = store.sessions();
    if (sessions.empty()) return std::nullopt;
    return sessions.front().frame_count;
  } catch (const StorageError&) {
    return std::nullopt;  // not created yet, or mid-migration
  }
}

// Waits until the first session has committed `frames` frames (or `patience` has passed: the
// scene is built first); what it has committed.
inline std::optional<std::int64_t> wait_for_committed(const std::filesystem::path& database,
                                                      std::int64_t frames,
                                                      std::chrono::seconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  std::optional<std::int64_t> seen;
  while (std::chrono::steady_clock::now() < deadline) {
    seen = committed_frames(database);
    if (seen && *seen >= frames) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return seen;
}

// The session's frames read back whole and in time order.
inline void expect_frames_in_order(SqliteSessionStore& store, const SessionSummary& session) {
  const std::vector<ServoFrame> frames = store.frames(session.id);
  ASSERT_EQ(static_cast<std::int64_t>(frames.size()), session.frame_count);
  for (std::size_t i = 1; i < frames.size(); ++i)
    ASSERT_GT(frames[i].time_s, frames[i - 1].time_s) << "frame " << i;
}

// Kills the writer with SIGKILL once it has committed `committed` frames, then opens its database
// for writing as its next start does: integrity ok, the one session over (incomplete) and none of
// its committed frames lost.
inline void kill_and_expect_recovery(pid_t writer, const std::filesystem::path& database,
                                     std::int64_t committed) {
  ASSERT_EQ(kill(writer, SIGKILL), 0);
  ASSERT_EQ(wait_for(writer), -SIGKILL);
  SqliteSessionStore store(database);
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_GE(sessions[0].frame_count, committed) << "frames committed before the kill were lost";
  expect_frames_in_order(store, sessions[0]);
}

}  // namespace liversim::crash
