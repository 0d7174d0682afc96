#pragma once
// The one database writer of a session: a thread that drains the servo's frames and the events
// queued by the simulation and UI, and commits them every commit period. A session killed at any
// moment has lost at most the frames of the last period. A storage failure (a full disk, a
// vanished file) stops the recording with its message; what was committed stays.

#include "liversim/sessions/session_store.h"

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace liversim {

class SessionRecorder {
 public:
  struct Options {
    double commit_period_s = 0.05;
  };
  // Takes the next waiting frame into its argument; false when none is waiting (e.g. bound to
  // ServoLoop::next_logged_frame). Called by one thread at a time: the writer, then finish().
  using FrameSource = std::function<bool(ServoFrame&)>;

  // Begins the session in `store` (throws StorageError if it cannot) and starts the writer.
  // `next_left_frame`: the left hand's device's frames, for a session begun with a left hand
  // (SessionStart::left_hand); empty otherwise.
  SessionRecorder(SessionStore& store, const SessionStart& start, FrameSource next_frame,
                  FrameSource next_left_frame, Options options);
  SessionRecorder(SessionStore& store, const SessionStart& start, FrameSource next_frame,
                  Options options)
      : SessionRecorder(store, start, std::move(next_frame), {}, options) {}
  SessionRecorder(SessionStore& store, const SessionStart& start, FrameSource next_frame)
      : SessionRecorder(store, start, std::move(next_frame), {}, Options{}) {}
  ~SessionRecorder();  // as finish() without figures: the session stays incomplete
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  std::int64_t session() const { return session_; }

  // Any thread but the servo's (they take a lock).
  void record_event(SessionEvent event);
  // The simulation's next inputs (RealtimeSimulation::take_input_log), for a session begun with
  // a ReplaySetup; stored with the next commit.
  void record_inputs(std::vector<SimulationInput> inputs);

  // Writes what is waiting, ends the session as complete with these figures (`left_servo`: the
  // left hand's device's, in a two-handed session) and stops the writer. Returns false (see
  // error()) if storage failed at any point.
  bool finish(std::int64_t ended_unix_ms, const SessionServoFigures& servo,
              const std::optional<SessionServoFigures>& left_servo = std::nullopt);

  // Empty while storage works; else what failed, naming the database.
  std::string error() const;
  // The storage failure that stopped the writer, with its kind; none while it writes.
  std::optional<StorageError> failure() const;
  std::int64_t frames_written() const { return frames_written_.load(); }
  std::int64_t left_frames_written() const { return left_frames_written_.load(); }

 private:
  void run();
  // Drains frames and events into the store and commits; false after a storage failure.
  bool write_waiting();
  void stop_writer();

  SessionStore& store_;
  FrameSource next_frame_;
  FrameSource next_left_frame_;
  Options options_;
  std::int64_t session_ = 0;
  std::vector<ServoFrame> frame_batch_;
  std::vector<ServoFrame> left_frame_batch_;
  std::vector<SessionEvent> event_batch_;
  std::vector<SimulationInput> input_batch_;

  mutable std::mutex mutex_;  // guards events_, inputs_, failure_, stop_
  std::condition_variable wake_;
  std::vector<SessionEvent> events_;
  std::vector<SimulationInput> inputs_;
  std::optional<StorageError> failure_;
  bool stop_ = false;
  std::atomic<std::int64_t> frames_written_{0};
  std::atomic<std::int64_t> left_frames_written_{0};
  std::thread writer_;
};

}  // namespace liversim
