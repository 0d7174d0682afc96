#pragma once
// The changing simulation state, with the scratch buffers stepping needs, sized once for a model.

#include "liversim/core/model.h"
#include "liversim/core/viscous_tissue.h"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace liversim {

// Scratch of one force evaluation, sized once for a model.
struct ForceScratch {
  std::array<NodeArray, 4> corner_force_n;   // per element corner, before the gather
  std::vector<double> element_volume_ratio;  // J per element (average nodal pressure only)
  std::vector<double> nodal_volume_ratio;    // volume-weighted mean J per node (likewise)
};
ForceScratch make_force_scratch(const SimModel& model);

struct SimState {
  NodeArray position_m;
  // Leapfrog velocity, half a step behind the next position update (v at t − Δt/2).
  NodeArray velocity_m_per_s;
  NodeArray force_n;  // total nodal force of the last evaluation
  ForceScratch force_scratch;
  std::vector<double> spring_damping_per_s;  // c/m per node from the springs of this step
  double max_speed_m_per_s = 0.0;            // fastest node after the last step
  double last_step_s = 0.0;                  // length of the last step (0 before the first)
  // History of viscous elements, committed at every force evaluation of a step (allocated only
  // when the model's effects.viscous), and the per-region step constants (scratch).
  std::vector<ViscousTissueState> viscous_state;
  std::vector<std::optional<ViscousTissueStep>> viscous_step;
  double time_s = 0.0;
  std::uint64_t step_count = 0;
};

// A state at rest in the reference configuration, with all scratch allocated.
SimState make_rest_state(const SimModel& model);

}  // namespace liversim
