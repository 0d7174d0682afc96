#pragma once
// The haptic servo: about 1 kHz, on its own thread (or the device's scheduler), never blocking and
// never allocating. Each tick it reads the device (each hand's, when there are two), takes the
// newest force model the simulation published for it (lock-free), renders a safe force
// (HapticRenderer) and writes it. It hands each device's newest frame to the simulation and its
// statistics to the UI the same way, and queues every frame for the session log. The force is zero
// on pause, on a device error and on shutdown.

#include "liversim/haptics/haptic_device.h"
#include "liversim/haptics/haptics.h"
#include "liversim/haptics/spsc_ring.h"
#include "liversim/haptics/triple_buffer.h"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
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
    WorkspaceMapping mapping;            // the right hand's device's (the only one's)
    WorkspaceMapping left_mapping;       // the left hand's device's, when there is one
    std::size_t log_capacity = 1 << 14;  // frames queued for the session log (16 s at 1 kHz)
    bool real_time_priority = true;      // ask for SCHED_FIFO (ignored when not allowed)
  };

  // One device, in the right hand. Throws std::invalid_argument naming a bad setting.
  ServoLoop(HapticDevice& device, Options options);
  // A device in each hand (two Omnis, an Omni and the mouse, two scripts): one schedule reads both
  // and drives each with its own force, in the same tick.
  ServoLoop(HapticDevice& right, HapticDevice& left, Options options);
  ~ServoLoop();  // stops
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  void start();
  void stop();  // the last command is a zero force
  bool running() const { return running_.load(); }
  void set_paused(bool paused) { paused_.store(paused); }

  // The servo clock, seconds since construction (steady).
  double now_s() const;

  bool has_device(Hand hand) const { return channels_[hand_index(hand)] != nullptr; }

  // Simulation thread: a new force model in the scene frame for the device in `hand` (no device
  // there: ignored), stamped now (or at `published_s` on the servo clock, for a session replayed
  // on a clock of its own). Without a hand: the right one.
  void publish(Hand hand, const LocalForceModel& model) { publish(hand, model, now_s()); }
  void publish(Hand hand, LocalForceModel model, double published_s);
  void publish(const LocalForceModel& model) { publish(Hand::right, model); }
  void publish(LocalForceModel model, double published_s) {
    publish(Hand::right, std::move(model), published_s);
  }
  // Simulation thread: the newest frame of the device in `hand`; false when there is none yet.
  bool newest_frame(Hand hand, ServoFrame& frame);
  bool newest_frame(ServoFrame& frame) { return newest_frame(Hand::right, frame); }
  // The mapping of the device in `hand` (the right one's when that hand has none).
  const WorkspaceMapping& mapping(Hand hand = Hand::right) const;
  const HapticSafetySettings& safety() const { return options_.safety; }

  // UI thread: the statistics of the device in `hand` as of the last twentieth of a second (no
  // device there: empty).
  ServoStats stats(Hand hand = Hand::right);
  // Why the device in `hand` stopped, empty while it is fine (a fatal fault stops its force for
  // good; the other hand's device goes on).
  std::string device_fault(Hand hand = Hand::right);

  // The session logger's thread: the frames of the device in `hand` in order, as many as are
  // waiting.
  bool next_logged_frame(Hand hand, ServoFrame& frame);
  bool next_logged_frame(ServoFrame& frame) { return next_logged_frame(Hand::right, frame); }
  std::uint64_t dropped_log_frames(Hand hand = Hand::right) const;

  // One tick at servo time `now_s` (the thread and device schedulers call this; tests may too).
  void tick(double now_s);

 private:
  // One device and what the servo keeps of it.
  struct Channel {
    Channel(HapticDevice& device, const WorkspaceMapping& mapping, const Options& options);
    HapticDevice& device;
    WorkspaceMapping mapping;
    HapticRenderer renderer;
    TripleBuffer<DeviceForceModel> models{DeviceForceModel{}};
    TripleBuffer<ServoFrame> frames{ServoFrame{}};
    TripleBuffer<ServoStats> stats{ServoStats{}};
    SpscRing<ServoFrame> log;
    std::atomic<bool> fatal{false};
    std::atomic<const char*> fault_message{""};
    bool have_frame = false;          // simulation side
    std::uint64_t device_faults = 0;  // servo side
  };
  void run();
  static void tick_from_device(void* self);
  void tick(Channel& channel, double now_s, bool paused, bool publish_stats);

  Options options_;
  std::array<std::unique_ptr<Channel>, kHands.size()> channels_;
  HapticDevice* own_clock_device_ = nullptr;  // the device whose scheduler ticks, if any
  std::chrono::steady_clock::time_point epoch_;
  std::mutex stats_reader_;  // UI side only: the servo never takes it
  std::atomic<bool> running_{false}, stop_requested_{false}, paused_{false}, own_clock_{false};
  double last_stats_s_ = -1.0;
  std::thread thread_;
};

}  // namespace liversim
