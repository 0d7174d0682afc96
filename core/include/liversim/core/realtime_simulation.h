#pragma once
// Runs a simulation on its own thread in step with the wall clock, takes inputs (springs from a
// dragged point) from other threads and publishes snapshots of the node positions.

#include "liversim/core/forces.h"
#include "liversim/core/state.h"
#include "liversim/core/triple_buffer.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

namespace liversim {

struct SimulationSnapshot {
  NodeArray position_m;
  double time_s = 0.0;
  std::uint64_t step_count = 0;
};

struct RealtimeStats {
  double steps_per_second = 0.0;
  double real_time_factor = 0.0;  // simulated seconds per wall-clock second
  double step_s = 0.0;            // current explicit step
  bool behind = false;            // the step budget bit: simulated time runs slower than real time
};

class RealtimeSimulation {
 public:
  struct Options {
    std::size_t spring_capacity = 1024;
    double cycle_s = 1.0 / 120.0;  // simulated time covered per cycle at most (publish rate)
  };

  RealtimeSimulation(std::shared_ptr<const SimModel> model, SimState initial_state);
  RealtimeSimulation(std::shared_ptr<const SimModel> model, SimState initial_state,
                     Options options);
  ~RealtimeSimulation();
  RealtimeSimulation(const RealtimeSimulation&) = delete;
  RealtimeSimulation& operator=(const RealtimeSimulation&) = delete;

  void start();
  void stop();
  bool running() const { return thread_.joinable(); }

  // Replaces the springs acting on the liver (at most spring_capacity; extra ones are dropped and
  // the call returns false).
  bool set_springs(std::span<const NodeSpring> springs);
  void clear_springs() { set_springs({}); }

  // Consumer side (one thread, e.g. the UI): the newest snapshot, if one was published since.
  bool update_snapshot() { return snapshots_.update(); }
  const SimulationSnapshot& snapshot() const { return snapshots_.front(); }

  RealtimeStats stats() const;
  const SimModel& model() const { return *model_; }

 private:
  void run();

  std::shared_ptr<const SimModel> model_;
  SimState state_;
  Options options_;
  TripleBuffer<SimulationSnapshot> snapshots_;

  std::mutex springs_mutex_;  // UI ↔ simulation only; never on the haptic servo path
  std::vector<NodeSpring> pending_springs_;
  bool springs_changed_ = false;
  std::vector<NodeSpring> active_springs_;  // simulation thread's copy

  std::atomic<bool> stop_requested_{false};
  std::atomic<double> steps_per_second_{0.0}, real_time_factor_{0.0}, step_s_{0.0};
  std::atomic<bool> behind_{false};
  std::thread thread_;
};

}  // namespace liversim
