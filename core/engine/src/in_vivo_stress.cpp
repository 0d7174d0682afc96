#include "liversim/engine/in_vivo_stress.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/state.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace liversim {
namespace {

bool yields(const SimModel& model, std::size_t e) {
  if (!model.effects.viscous) return false;
  const auto& law = model.viscous_parameters[static_cast<std::size_t>(model.region[e])];
  return law && law->viscoplastic;
}

Eigen::Matrix3d from_voigt(const Voigt6& v) {
  Eigen::Matrix3d m;
  m << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  return m;
}

}  // namespace

std::vector<double> in_vivo_stress_pa(const SimModel& model, double settling_time_s) {
  bool any_yields = false;
  for (std::size_t e = 0; e < model.tet_count && !any_yields; ++e) any_yields = yields(model, e);
  if (!model.effects.gravity || !any_yields) return {};

  // The tissue's stress, whatever the scene integrates with: the explicit scheme at its stable
  // step settles it at the least cost.
  SimModel settling = model;
  settling.in_vivo_stress_pa.clear();
  settling.integrator = IntegratorSettings{};
  for (auto& law : settling.viscous_parameters)
    if (law) law->viscoplastic.reset();
  SimState state = make_rest_state(settling);
  std::vector<double> largest_pa(model.tet_count, 0.0);
  constexpr double kSample_s = 1e-3;
  const auto samples = static_cast<long>(std::ceil(settling_time_s / kSample_s));
  for (long i = 0; i < samples; ++i) {
    advance(settling, state, StepInputs{}, kSample_s);
    for (std::size_t e = 0; e < model.tet_count; ++e) {
      if (!yields(model, e)) continue;
      // The law's stress as committed: S = g0·S_e + g1·H (Fp = I: nothing flowed).
      const ViscoelasticParameters& arms =
          settling.viscous_parameters[static_cast<std::size_t>(model.region[e])]->viscoelastic;
      const double g1 = arms.e1_pa / arms.instantaneous_modulus_pa(), g0 = 1.0 - g1;
      const ViscousTissueState history = state.viscous_history.load(e);
      const Eigen::Matrix3d pk2 =
          g0 * from_voigt(history.elastic_stress_pa) + g1 * from_voigt(history.maxwell_stress_pa);
      const Eigen::Matrix3d F = deformation_gradient(settling, state.position_m, e);
      const Eigen::Matrix3d kirchhoff = F * pk2 * F.transpose();
      const Eigen::Matrix3d deviator =
          kirchhoff - kirchhoff.trace() / 3.0 * Eigen::Matrix3d::Identity();
      largest_pa[e] = std::max(largest_pa[e], std::sqrt(1.5 * deviator.squaredNorm()));
    }
  }
  return largest_pa;
}

}  // namespace liversim
