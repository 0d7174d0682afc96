#include "liversim/sessions/session_replay.h"
#include "liversim/engine/model_building.h"

#include "liversim/engine/state.h"
#include "liversim/engine/worker_pool.h"
#include "liversim/scenario/scenario.h"

#include <cmath>
#include <stdexcept>

namespace liversim {

std::unique_ptr<RealtimeSimulation> make_scene_simulation(std::shared_ptr<const SimModel> model,
                                                          const BoundarySurface& surface,
                                                          double loop_step_s) {
  SimState rest = make_rest_state(*model, realtime_worker_pool());
  RealtimeSimulation::Options options;
  options.loop_step_s = loop_step_s;
  auto simulation =
      std::make_unique<RealtimeSimulation>(std::move(model), std::move(rest), options);
  simulation->enable_tools(surface);
  simulation->enable_cutting();
  return simulation;
}

SceneSetup replay_scene(const ReplaySetup& setup, const std::string& scenario_text) {
  SceneSetup scene;
  if (setup.built_in_liver_tets) {
    scene = default_scene(*setup.built_in_liver_tets);
  } else {
    const ScenarioReading reading = read_scenario(scenario_text);
    if (!reading.scenario) {
      std::string message = "the session's scenario does not read any more:";
      for (const auto& error : reading.errors) message += "\n  " + error.text();
      throw std::runtime_error(message);
    }
    try {
      scene = build_scene(*reading.scenario, setup.scenario_folder);
    } catch (const std::exception& e) {
      throw std::runtime_error(
          "the session's scene cannot be built again (organ files are "
          "looked for in " +
          setup.scenario_folder + "): " + e.what());
    }
  }
  scene.model_options.integrator = setup.integrator;
  return scene;
}

SessionReplay::SessionReplay(SceneSetup scene, std::vector<SimulationInput> inputs,
                             std::optional<double> loop_step_s)
    : scene_(std::move(scene)), inputs_(std::move(inputs)) {
  bool any_cycle = false;
  for (const SimulationInput& input : inputs_) {
    if (input.kind != SimulationInput::Kind::cycle || !std::isfinite(input.servo_time_s)) continue;
    if (!any_cycle) begin_s_ = input.servo_time_s;
    end_s_ = input.servo_time_s;
    any_cycle = true;
  }
  if (!any_cycle) throw std::invalid_argument("the session's input log holds no timed cycle");
  model_ = std::make_shared<const SimModel>(build_model(scene_.mesh, scene_.model_options));
  loop_step_s_ = loop_step_s ? *loop_step_s : legacy_loop_step_s(*model_);
  if (!(loop_step_s_ > 0.0) || !std::isfinite(loop_step_s_))
    throw std::invalid_argument("the session's stored loop step is " +
                                std::to_string(loop_step_s_) +
                                " s: it cannot be replayed (a step is a positive time)");
  restart();
}

void SessionReplay::restart() {
  simulation_ = make_scene_simulation(model_, scene_.visual.surface, loop_step_s_);
  next_ = 0;
  time_s_ = begin_s_;
}

bool SessionReplay::advance_to(double servo_time_s, int max_cycles) {
  if (servo_time_s < time_s_ && next_ > 0) restart();  // back in time: from rest again
  // Inputs come in groups: what the live loop took before a cycle, then the cycle. Whole groups
  // are taken.
  std::size_t end = next_;  // one past the last input to take
  int cycles = 0;
  bool arrived = true;
  std::size_t i = next_;
  for (; i < inputs_.size(); ++i) {
    const SimulationInput& input = inputs_[i];
    if (input.kind != SimulationInput::Kind::cycle) continue;
    if (input.servo_time_s > servo_time_s) break;
    if (cycles == max_cycles) {
      arrived = false;
      break;
    }
    ++cycles;
    end = i + 1;
    time_s_ = input.servo_time_s;
  }
  if (i == inputs_.size()) end = i;  // no cycle left: what the log ends with, too
  simulation_->replay(std::span(inputs_).subspan(next_, end - next_));
  next_ = end;
  return arrived;
}

}  // namespace liversim
