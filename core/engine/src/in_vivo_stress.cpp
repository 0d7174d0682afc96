#include "liversim/engine/in_vivo_stress.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/state.h"
#include "liversim/engine/viscous_tissue.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <optional>

namespace liversim {

std::vector<double> in_vivo_stress_pa(const SimModel& model, double settling_time_s) {
  bool any_yields = false;
  for (const auto& law : model.viscous_parameters) any_yields |= law && law->viscoplastic;
  if (!model.effects.gravity || !any_yields) return {};

  // The tissue's stress, whatever the scene integrates with: the explicit scheme at its stable
  // step settles it at the least cost.
  SimModel settling = model;
  settling.in_vivo_stress_pa.clear();
  settling.integrator = IntegratorSettings{};
  for (auto& law : settling.viscous_parameters)
    if (law) law->viscoplastic.reset();
  // The law's stress as committed, read by the law itself: a step of no time changes nothing.
  std::vector<std::optional<ViscousTissueStep>> committed_stress(model.viscous_parameters.size());
  for (std::size_t r = 0; r < committed_stress.size(); ++r)
    if (model.viscous_parameters[r] && model.viscous_parameters[r]->viscoplastic)
      committed_stress[r].emplace(*settling.viscous_parameters[r], 0.0);

  SimState state = make_rest_state(settling);
  std::vector<double> largest_pa(model.tet_count, 0.0);
  constexpr double kSample_s = 2e-3;
  const auto samples = static_cast<long>(std::ceil(settling_time_s / kSample_s));
  for (long i = 0; i < samples; ++i) {
    advance(settling, state, StepInputs{}, kSample_s);
    for (std::size_t e = 0; e < model.tet_count; ++e) {
      const auto& step = committed_stress[static_cast<std::size_t>(model.region[e])];
      if (!step) continue;
      const Eigen::Matrix3d F = deformation_gradient(settling, state.position_m, e);
      ViscousTissueState history = state.viscous_history.load(e);
      const Eigen::Matrix3d kirchhoff = viscous_tissue_stress(F, *step, history, history) *
                                        F.transpose();  // τ = P·Fᵀ (Fp = I: nothing flowed)
      const Eigen::Matrix3d deviator =
          kirchhoff - kirchhoff.trace() / 3.0 * Eigen::Matrix3d::Identity();
      largest_pa[e] = std::max(largest_pa[e], std::sqrt(1.5 * deviator.squaredNorm()));
    }
  }
  return largest_pa;
}

}  // namespace liversim
