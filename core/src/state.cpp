#include "liversim/core/state.h"

namespace liversim {

SimState make_rest_state(const SimModel& model) {
  SimState state;
  state.position_m = model.rest_position_m;
  state.velocity_m_per_s.resize(model.node_count);
  state.force_n.resize(model.node_count);
  for (auto& corner : state.corner_force_n) corner.resize(model.tet_count);
  state.spring_damping_per_s.assign(model.node_count, 0.0);
  if (model.effects.viscous) {
    state.viscous_state.resize(model.tet_count);
    state.viscous_step.resize(model.viscous_parameters.size());
  }
  return state;
}

}  // namespace liversim
