#pragma once
// A recorded session played back: its scene built again (ReplaySetup and the stored scenario
// text) and its simulation input log taken cycle by cycle, on the servo's timeline. The engine is
// deterministic, so the replay goes through the states the trainee saw, to the last bit.

#include "liversim/interaction/simulation_input.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/simulation/realtime_simulation.h"

#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace liversim {

// The simulation of a workstation scene: from rest, tools on `surface` (the model's boundary)
// with the default contact and grasp, cutting on, stepping by `loop_step_s` (0: realtime_step_s).
// The workstation and a replay both start here.
std::unique_ptr<RealtimeSimulation> make_scene_simulation(std::shared_ptr<const SimModel> model,
                                                          const BoundarySurface& surface,
                                                          double loop_step_s = 0.0);

// The scene of a recorded session, built again: free practice's built-in liver, or the stored
// scenario (its organ file looked for in the setup's folder), with the integrator of the
// session's start. Throws std::runtime_error naming what is wrong (a scenario that no longer
// reads, a missing organ file).
SceneSetup replay_scene(const ReplaySetup& setup, const std::string& scenario_text);

class SessionReplay {
 public:
  // Builds the model (seconds on a large mesh); its loop steps by `loop_step_s`, the one the
  // session was recorded with (ReplaySetup::loop_step_s; none: legacy_loop_step_s). Throws
  // std::invalid_argument when the log holds no cycle.
  SessionReplay(SceneSetup scene, std::vector<SimulationInput> inputs,
                std::optional<double> loop_step_s);

  const SceneSetup& scene() const { return scene_; }
  std::span<const SimulationInput> inputs() const { return inputs_; }
  // The servo times of the first and the last cycle: the replay's timeline.
  double begin_s() const { return begin_s_; }
  double end_s() const { return end_s_; }
  // The servo time of the last cycle replayed (begin_s() before the first).
  double time_s() const { return time_s_; }
  bool at_end() const { return next_ == inputs_.size(); }
  // Inputs taken since rest: it changes whenever the replayed state does.
  std::size_t taken() const { return next_; }

  // Replays the inputs up to the last cycle at or before `servo_time_s`, taking at most
  // `max_cycles` cycles (a UI keeps its frames short this way); true when it got there. Going
  // back in time starts again from rest: a seek backwards replays from the start.
  bool advance_to(double servo_time_s, int max_cycles = std::numeric_limits<int>::max());
  void restart();  // back to rest, before the first input

  // The replaying simulation (stopped): its snapshot shows the cycle last replayed.
  RealtimeSimulation& simulation() { return *simulation_; }

 private:
  SceneSetup scene_;
  std::shared_ptr<const SimModel> model_;
  std::vector<SimulationInput> inputs_;
  std::unique_ptr<RealtimeSimulation> simulation_;
  double loop_step_s_ = 0.0;
  std::size_t next_ = 0;  // the next input to take
  double begin_s_ = 0.0, end_s_ = 0.0, time_s_ = 0.0;
};

}  // namespace liversim
