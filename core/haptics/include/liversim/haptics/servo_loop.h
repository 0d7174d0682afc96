#pragma once
// The haptic servo: about 1 kHz, on its own thread (or the device's scheduler), never blocking and
// never allocating. Each tick it reads the device, takes the newest force model the simulation
// published (lock-free), renders a safe force (HapticRenderer) and writes it. It hands the device's
// newest frame to the simulation and its statistics to the UI the same way, and queues every frame
// for the session log. The force is zero on pause, on a device error and on shutdown.

#include "liversim/haptics/haptic_device.h"
#include "liversim/haptics/haptics.h"
#include "liversim/haptics/spsc_ring.h"
#include "liversim/haptics/triple_buffer.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace liversim {

// One servo tick: where the device was and what it was told.
struct ServoFrame {
  double time_s = 0.0;  // servo clock
  DeviceSample sample;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();  // commanded, device frame
};

class ServoLoop {
 public:
  struct Options {
    HapticSafetySettings safety;
    WorkspaceMapping mapping;
    std::size_t log_capacity = 1 << 14;  // frames queued for the session log (16 s at 1 kHz)
    bool real_time_priority = true;      // ask for SCHED_FIFO (ignored when not allowed)
  };

  // Throws std::invalid_argument naming a bad setting.
  ServoLoop(HapticDevice& device, Options options);
  ~ServoLoop();  // stops
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  void start();
  void stop();  // the last command is a zero force
  bool running() const { return running_.load(); }
  void set_paused(bool paused) { paused_.store(paused); }

  // The servo clock, seconds since construction (steady).
  double now_s() const;

  // Simulation thread: a new force model in the scene frame, stamped now (or at `published_s` on
  // the servo clock, for a session replayed on a clock of its own).
  void publish(const LocalForceModel& model) { publish(model, now_s()); }
  void publish(LocalForceModel model, double published_s);
  // Simulation thread: the device's newest frame; false when there is none yet.
  bool newest_frame(ServoFrame& frame);
  const WorkspaceMapping& mapping() const { return options_.mapping; }
  const HapticSafetySettings& safety() const { return options_.safety; }

  // UI thread: the statistics as of the last twentieth of a second.
  ServoStats stats();
  // Why the device stopped, empty while it is fine (a fatal fault stops the force for good).
  std::string device_fault();

  // The session logger's thread: frames in order, as many as are waiting.
  bool next_logged_frame(ServoFrame& frame) { return log_.pop(frame); }
  std::uint64_t dropped_log_frames() const { return log_.dropped(); }

  // One tick at servo time `now_s` (the thread and device schedulers call this; tests may too).
  void tick(double now_s);

 private:
  void run();
  static void tick_from_device(void* self);

  HapticDevice& device_;
  Options options_;
  HapticRenderer renderer_;
  std::chrono::steady_clock::time_point epoch_;
  TripleBuffer<DeviceForceModel> models_{DeviceForceModel{}};
  TripleBuffer<ServoFrame> frames_{ServoFrame{}};
  TripleBuffer<ServoStats> stats_{ServoStats{}};
  std::mutex stats_reader_;  // UI side only: the servo never takes it
  SpscRing<ServoFrame> log_;
  std::atomic<bool> running_{false}, stop_requested_{false}, paused_{false}, own_clock_{false};
  std::atomic<bool> fatal_{false};
  std::atomic<const char*> fault_message_{""};
  bool have_frame_ = false;          // simulation side
  std::uint64_t device_faults_ = 0;  // servo side
  double last_stats_s_ = -1.0;
  std::thread thread_;
};

}  // namespace liversim
