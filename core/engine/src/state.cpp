#include "liversim/engine/state.h"

#include "integrator_internal.h"

#include <stdexcept>
#include <string>

namespace liversim {

ForceScratch make_force_scratch(const SimModel& model) {
  ForceScratch scratch;
  scratch.corner_force_n.resize(4 * model.tet_count);
  const std::size_t chunks = (model.tet_count + kElementsPerChunk - 1) / kElementsPerChunk;
  scratch.chunk_seen.resize(chunks);
  scratch.chunk_dissipated_j.resize(chunks);
  if (model.effects.viscous) {
    scratch.region_constants.resize(10 * model.viscous_parameters.size());
    scratch.needs_general.resize(model.tet_count);
    scratch.no_yield_raise_pa.assign(model.tet_count, 0.0);
  }
  if (model.effects.average_nodal_pressure) {
    scratch.element_volume_ratio.resize(model.tet_count);
    scratch.nodal_lambda_pressure_pa.resize(model.node_count);
    scratch.chunk_min_nodal_volume_ratio.resize((model.node_count + kNodesPerChunk - 1) /
                                                kNodesPerChunk);
  }
  return scratch;
}

SimState make_rest_state(const SimModel& model, std::shared_ptr<WorkerPool> workers) {
  SimState state;
  state.position_m = model.rest_position_m;
  state.velocity_m_per_s.resize(model.node_count);
  state.force_n.resize(model.node_count);
  state.force_scratch = make_force_scratch(model);
  state.force_scratch.workers = std::move(workers);
  state.spring_damping_per_s.assign(model.node_count, 0.0);
  if (model.effects.viscous) {
    state.viscous_history = ViscousHistory(model.tet_count);
    state.viscous_step.resize(model.viscous_parameters.size());
  }
  detail::prepare_integrator_scratch(model, state.integrator);
  return state;
}

SimState carry_state(const SimState& old, const SimModel& model,
                     std::shared_ptr<WorkerPool> workers) {
  if (old.position_m.size() != model.node_count)
    throw std::invalid_argument("carry_state: the state has " +
                                std::to_string(old.position_m.size()) + " nodes, the model " +
                                std::to_string(model.node_count));
  SimState state = make_rest_state(model, std::move(workers));
  state.position_m = old.position_m;
  state.velocity_m_per_s = old.velocity_m_per_s;
  state.max_speed_m_per_s = old.max_speed_m_per_s;
  if (state.viscous_history.size() == old.viscous_history.size())
    state.viscous_history = old.viscous_history;
  state.energy = old.energy;  // the books go on (the guard bounds kinetic energy by them)
  state.time_s = old.time_s;
  state.step_count = old.step_count;
  return state;
}

}  // namespace liversim
