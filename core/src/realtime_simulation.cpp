#include "liversim/core/realtime_simulation.h"

#include "liversim/core/integrator.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace liversim {
namespace {

SimulationSnapshot snapshot_of(const SimState& state) {
  return {state.position_m, state.time_s, state.step_count};
}

}  // namespace

RealtimeSimulation::RealtimeSimulation(std::shared_ptr<const SimModel> model,
                                       SimState initial_state)
    : RealtimeSimulation(std::move(model), std::move(initial_state), Options{}) {}

RealtimeSimulation::RealtimeSimulation(std::shared_ptr<const SimModel> model,
                                       SimState initial_state, Options options)
    : model_(std::move(model)),
      state_(std::move(initial_state)),
      options_(options),
      snapshots_(snapshot_of(state_)) {
  pending_springs_.reserve(options_.spring_capacity);
  active_springs_.reserve(options_.spring_capacity);
}

RealtimeSimulation::~RealtimeSimulation() {
  stop();
}

void RealtimeSimulation::start() {
  if (thread_.joinable()) return;
  stop_requested_ = false;
  thread_ = std::thread([this] { run(); });
}

void RealtimeSimulation::stop() {
  stop_requested_ = true;
  if (thread_.joinable()) thread_.join();
}

bool RealtimeSimulation::set_springs(std::span<const NodeSpring> springs) {
  const std::size_t count = std::min(springs.size(), options_.spring_capacity);
  std::lock_guard lock(springs_mutex_);
  pending_springs_.assign(springs.begin(), springs.begin() + static_cast<std::ptrdiff_t>(count));
  springs_changed_ = true;
  return count == springs.size();
}

RealtimeStats RealtimeSimulation::stats() const {
  return {steps_per_second_.load(), real_time_factor_.load(), step_s_.load(), behind_.load()};
}

void RealtimeSimulation::run() {
  using Clock = std::chrono::steady_clock;
  const SimModel& model = *model_;
  auto wall_anchor = Clock::now();
  double sim_anchor_s = state_.time_s;
  auto window_start = wall_anchor;
  double window_sim_start_s = state_.time_s;
  std::uint64_t window_start_steps = state_.step_count;
  bool behind = false;
  double step_s = model.stable_time_step_s;

  while (!stop_requested_.load(std::memory_order_relaxed)) {
    {
      std::lock_guard lock(springs_mutex_);
      if (springs_changed_) {
        active_springs_.assign(pending_springs_.begin(), pending_springs_.end());  // no realloc
        springs_changed_ = false;
      }
    }
    const StepInputs inputs{{}, active_springs_};
    const auto cycle_start = Clock::now();
    const double due_s = sim_anchor_s +
                         std::chrono::duration<double>(cycle_start - wall_anchor).count() -
                         state_.time_s;
    if (due_s >= 0.5 * step_s) {
      const double interval_s = std::min(due_s, options_.cycle_s);
      const StepReport report = advance(model, state_, inputs, interval_s);
      step_s = report.smallest_substep_s;
      // Slower than real time when the cycle took longer than the simulated time it covered:
      // drop the backlog so simulated time slows down instead of the loop spiralling.
      const double wall_s = std::chrono::duration<double>(Clock::now() - cycle_start).count();
      behind = due_s > options_.cycle_s && wall_s > interval_s;
      if (behind) {
        wall_anchor = Clock::now();
        sim_anchor_s = state_.time_s;
      }
      SimulationSnapshot& out = snapshots_.back();
      out.position_m.x = state_.position_m.x;  // same size: copies without allocating
      out.position_m.y = state_.position_m.y;
      out.position_m.z = state_.position_m.z;
      out.time_s = state_.time_s;
      out.step_count = state_.step_count;
      snapshots_.publish();
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }

    const auto now = Clock::now();
    const double window_s = std::chrono::duration<double>(now - window_start).count();
    if (window_s >= 0.25) {
      steps_per_second_ = static_cast<double>(state_.step_count - window_start_steps) / window_s;
      real_time_factor_ = (state_.time_s - window_sim_start_s) / window_s;
      step_s_ = step_s;
      behind_ = behind;
      window_start = now;
      window_sim_start_s = state_.time_s;
      window_start_steps = state_.step_count;
    }
  }
}

}  // namespace liversim
