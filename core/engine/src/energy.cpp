#include "liversim/engine/energy.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/state.h"
#include "liversim/engine/support.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>

namespace liversim {
namespace {

// Σ term(i) over [0, count) in kChunks fixed chunks added in chunk order, so the sum is the same
// on any number of threads; on `workers` when given. Allocates nothing.
template <typename Term>
double chunked_sum(std::size_t count, WorkerPool* workers, const Term& term) {
  constexpr std::size_t kChunks = 64;
  std::array<double, kChunks> partial{};
  const std::size_t per_chunk = (count + kChunks - 1) / kChunks;
  auto run_chunk = [&](std::size_t chunk) {
    double sum = 0.0;
    const std::size_t end = std::min(count, (chunk + 1) * per_chunk);
    for (std::size_t i = chunk * per_chunk; i < end; ++i) sum += term(i);
    partial[chunk] = sum;
  };
  if (workers)
    workers->run(kChunks, run_chunk);
  else
    for (std::size_t chunk = 0; chunk < kChunks; ++chunk) run_chunk(chunk);
  double total = 0.0;
  for (double value : partial) total += value;
  return total;
}

double viscous_element_energy_density(const SimModel& model, const SimState& state,
                                      const ViscousTissueParameters& law, std::size_t e,
                                      const Eigen::Matrix3d& F) {
  const ViscousTissueState history = state.viscous_history.load(e);
  const double mu = model.shear_modulus_pa[e], lambda = model.lame_lambda_pa[e];
  const double instantaneous = law.viscoelastic.instantaneous_modulus_pa();
  const double relaxed_fraction = law.viscoelastic.e2_pa / instantaneous;
  const double arm_fraction = law.viscoelastic.e1_pa / instantaneous;
  double psi = relaxed_fraction *
               neo_hookean::energy_density(F * history.inverse_plastic_deformation, mu, lambda);
  psi += maxwell_arm_energy_density(history.maxwell_stress_pa, arm_fraction, mu, lambda);
  if (model.effects.fibres)
    for (const auto& family : model.fibre_direction)
      psi += hgo::energy_density(F, family[e], model.fibre_parameters[e]);
  return psi;
}

bool is_viscous(const SimModel& model, std::size_t e) {
  return model.effects.viscous &&
         model.viscous_parameters[static_cast<std::size_t>(model.region[e])].has_value();
}

// Average nodal pressure: the λ part of the volumetric energy sits at the nodes, W_λ(J̄) with J̄
// the volume-weighted mean of the node's element volume ratios, each element handing a quarter
// of its volume to each corner (elements of viscous regions keep their own J and take no part).
// The forces are this potential's exact gradient (forces.cpp). Each element's J is recomputed
// once per corner rather than stored, so nothing is allocated.
double nodal_lambda_energy_j(const SimModel& model, const NodeArray& position,
                             WorkerPool* workers) {
  return chunked_sum(model.node_count, workers, [&](std::size_t n) {
    double energy = 0.0;
    double weighted = 0.0, volume = 0.0;
    for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
      const auto e = static_cast<std::size_t>(model.node_slot_element[s]);
      if (is_viscous(model, e)) continue;
      weighted += model.rest_volume_m3[e] * deformation_gradient(model, position, e).determinant();
      volume += model.rest_volume_m3[e];
    }
    const double averaged = volume > 0.0 ? weighted / volume : 1.0;
    for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
      const auto e = static_cast<std::size_t>(model.node_slot_element[s]);
      if (is_viscous(model, e)) continue;
      energy += 0.25 * model.rest_volume_m3[e] *
                neo_hookean::lambda_energy_density(averaged, model.lame_lambda_pa[e]);
    }
    return energy;
  });
}

}  // namespace

double tissue_energy_j(const SimModel& model, const SimState& state) {
  const bool averaged_pressure = model.effects.average_nodal_pressure;
  WorkerPool* workers = state.force_scratch.workers.get();
  double energy = chunked_sum(model.tet_count, workers, [&](std::size_t e) {
    const Eigen::Matrix3d F = deformation_gradient(model, state.position_m, e);
    if (is_viscous(model, e)) {
      const auto& law = *model.viscous_parameters[static_cast<std::size_t>(model.region[e])];
      return model.rest_volume_m3[e] * viscous_element_energy_density(model, state, law, e, F);
    }
    double psi = element_energy_density(model, e, F);
    if (averaged_pressure)  // its λ part is at the nodes
      psi -= neo_hookean::lambda_energy_density(F.determinant(), model.lame_lambda_pa[e]);
    return model.rest_volume_m3[e] * psi;
  });
  if (averaged_pressure) energy += nodal_lambda_energy_j(model, state.position_m, workers);
  return energy;
}

double spring_energy_j(std::span<const NodeSpring> springs, const NodeArray& position) {
  double energy = 0.0;
  for (const NodeSpring& s : springs)
    energy += 0.5 * s.stiffness_n_per_m * (s.anchor_m - position.at(s.node)).squaredNorm();
  return energy;
}

double gravity_potential_energy_j(const SimModel& model, const NodeArray& position) {
  if (!model.effects.gravity) return 0.0;
  const Eigen::Vector3d& g = model.gravity_m_per_s2;
  const NodeArray& rest = model.rest_position_m;
  double energy = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n)
    energy -= model.lumped_mass_kg[n] *
              (g.x() * (position.x[n] - rest.x[n]) + g.y() * (position.y[n] - rest.y[n]) +
               g.z() * (position.z[n] - rest.z[n]));
  return energy;
}

double support_energy_j(const SimModel& model, const NodeArray& position) {
  if (!model.support) return 0.0;
  double energy = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    if (model.is_fixed[n]) continue;
    energy += support_contact(*model.support, position.at(n), model.rest_position_m.at(n),
                              model.lumped_mass_kg[n] * model.support_stiffness_per_kg,
                              model.support_friction_coefficient)
                  .energy_j;
  }
  return energy;
}

EnergyBalance energy_balance(const SimModel& model, const SimState& state,
                             const StepInputs& inputs) {
  EnergyBalance balance;
  balance.kinetic_j = kinetic_energy_j(model, state.velocity_m_per_s);
  balance.tissue_j = tissue_energy_j(model, state);
  balance.spring_j = spring_energy_j(inputs.springs, state.position_m);
  balance.gravity_j = gravity_potential_energy_j(model, state.position_m);
  balance.support_j = support_energy_j(model, state.position_m);
  balance.initial_j = state.energy.initial_j;
  balance.tool_work_j = state.energy.tool_work_j;
  balance.viscous_dissipated_j = state.energy.viscous_dissipated_j;
  return balance;
}

void open_energy_books(const SimModel& model, SimState& state, const StepInputs& inputs) {
  state.energy = EnergyLedger{};
  const EnergyBalance now = energy_balance(model, state, inputs);
  state.energy.initial_j = now.held_j();
  state.energy.spring_energy_j = now.spring_j;
}

void open_energy_books(const SimModel& model, SimState& state) {
  open_energy_books(model, state, StepInputs{});
}

}  // namespace liversim
