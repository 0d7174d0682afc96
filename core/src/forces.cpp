#include "liversim/core/forces.h"

#include "liversim/core/state.h"

#include <Eigen/Dense>

#include <algorithm>
#include <limits>
#include <type_traits>

namespace liversim {

Eigen::Matrix3d element_dm_inverse(const SimModel& model, std::size_t e) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = model.dm_inverse[k][e];
  return m;
}

namespace {

Eigen::Matrix3d deformed_edges(const SimModel& model, const NodeArray& x, std::size_t e) {
  const auto n0 = model.corner[0][e];
  Eigen::Matrix3d ds;
  for (int c = 1; c < 4; ++c) {
    const auto n = model.corner[c][e];
    ds.col(c - 1) = Eigen::Vector3d(x.x[n] - x.x[n0], x.y[n] - x.y[n0], x.z[n] - x.z[n0]);
  }
  return ds;
}

}  // namespace

Eigen::Matrix3d deformation_gradient(const SimModel& model, const NodeArray& position,
                                     std::size_t e) {
  return deformed_edges(model, position, e) * element_dm_inverse(model, e);
}

namespace {

// History-dependent materials of one evaluation: the state to advance and commit, and the step
// constants per region; null when the model has no viscous region.
struct ViscousContext {
  std::vector<ViscousTissueState>* state;
  const std::vector<std::optional<ViscousTissueStep>>* step_by_region;
  const ViscousArmInputs* arm = nullptr;  // set: the arm is carried by the integrator
  double* dissipated_j = nullptr;         // committing: the dashpots' work of the step is added
};

bool in_viscous_region(const SimModel& model, std::size_t e) {
  return model.effects.viscous &&
         model.viscous_parameters[static_cast<std::size_t>(model.region[e])].has_value();
}

// `averaged_lambda_pressure` is used only with average nodal pressure (kAveragedPressure).
template <bool kFibres, bool kViscous, bool kAveragedPressure, bool kMooneyRivlin>
Eigen::Matrix3d stress_of(const SimModel& model, std::size_t e, const Eigen::Matrix3d& F,
                          double averaged_lambda_pressure, ElasticEvaluation& seen,
                          const ViscousContext& viscous) {
  Eigen::Matrix3d P;
  const auto* step = kViscous ? &(*viscous.step_by_region)[model.region[e]] : nullptr;
  if (kViscous && step->has_value()) {
    if (viscous.arm) {
      const ViscousArmInputs& arm = *viscous.arm;
      const auto r = static_cast<std::size_t>(model.region[e]);
      P = viscoelastic_stress_rate_form(F, **step, (*viscous.state)[e].inverse_plastic_deformation,
                                        arm.q_known[e], arm.keep_by_region[r],
                                        arm.elastic_weight_by_region[r], arm.elastic_stress[e]);
    } else {
      // The history committed here spans the step: book its dashpots' work (trapezoid of 2ψ/τ).
      const ViscousTissueStep& s = **step;
      ViscousTissueState& history = (*viscous.state)[e];
      const double before = maxwell_arm_energy_density(history.maxwell_stress_pa, s);
      P = viscous_tissue_update(F, s, history);
      *viscous.dissipated_j += model.rest_volume_m3[e] * s.dt_s / s.relaxation_time_s *
                               (before + maxwell_arm_energy_density(history.maxwell_stress_pa, s));
    }
  } else if (kAveragedPressure && !in_viscous_region(model, e))
    // A viscous region's law works with its element's own volume ratio, so its instantaneous
    // elastic response (what the stable step is estimated from) must too.
    P = neo_hookean::first_piola_stress_given_lambda_pressure(
        F, model.shear_modulus_pa[e], model.lame_lambda_pa[e], averaged_lambda_pressure);
  else
    P = neo_hookean::first_piola_stress(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if constexpr (kMooneyRivlin)
    if (!(kViscous && step->has_value()))
      P += mooney_rivlin::extra_first_piola_stress(F, model.mooney_rivlin_c2_pa[e]);
  if constexpr (kFibres) {
    const FibreParameters& fibres = model.fibre_parameters[e];
    for (const auto& family : model.fibre_direction) {
      const Eigen::Vector3d& a = family[e];
      P += hgo::first_piola_stress(F, a, fibres);
      seen.max_fibre_modulus_pa =
          std::max(seen.max_fibre_modulus_pa, hgo::tangent_modulus_pa(F, a, fibres));
    }
  }
  return P;
}

// Average nodal pressure, first pass: each node's volume-weighted mean J̄ of its elements' J and
// the λ part of the pressure there, p_λ̄(J̄) with λ̄ the volume-weighted mean of their λ. Elements
// of viscous regions keep their own J and take no part. Each element then takes the mean of its
// corners' p_λ̄(J̄): the exact gradient of the nodal energy Σ_n V_n/4·W_λ̄(J̄) (energy.cpp), also
// where λ jumps between regions (p_λ(mean of the corners' J̄) with the element's own λ is not, and
// creates energy at a stiff lesion's boundary).
void average_nodal_volume_ratios(const SimModel& model, const NodeArray& position,
                                 ForceScratch& scratch) {
  for (std::size_t e = 0; e < model.tet_count; ++e)
    scratch.element_volume_ratio[e] = deformation_gradient(model, position, e).determinant();
  const std::size_t tets = model.tet_count;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    double weighted = 0.0, volume = 0.0, lambda_volume = 0.0;
    for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
      const std::size_t e = static_cast<std::size_t>(model.node_slots[s]) % tets;
      if (in_viscous_region(model, e)) continue;
      weighted += model.rest_volume_m3[e] * scratch.element_volume_ratio[e];
      volume += model.rest_volume_m3[e];
      lambda_volume += model.rest_volume_m3[e] * model.lame_lambda_pa[e];
    }
    scratch.nodal_lambda_pressure_pa[n] =
        volume > 0.0 ? neo_hookean::lambda_pressure(weighted / volume, lambda_volume / volume)
                     : 0.0;
  }
}

// One element loop per effect set, chosen once per evaluation rather than tested per element.
template <bool kFibres, bool kViscous, bool kAveragedPressure, bool kMooneyRivlin>
ElasticEvaluation element_forces(const SimModel& model, const NodeArray& position,
                                 ForceScratch& scratch, const ViscousContext& viscous) {
  if constexpr (kAveragedPressure) average_nodal_volume_ratios(model, position, scratch);
  ElasticEvaluation seen{std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity(), 0.0};
  auto& corner_scratch = scratch.corner_force_n;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const Eigen::Matrix3d dm_inv = element_dm_inverse(model, e);
    const Eigen::Matrix3d F = deformed_edges(model, position, e) * dm_inv;
    const double J = F.determinant();
    seen.min_volume_ratio = std::min(seen.min_volume_ratio, J);
    seen.max_volume_ratio = std::max(seen.max_volume_ratio, J);
    double averaged = 0.0;  // the λ part of the pressure, with average nodal pressure
    if constexpr (kAveragedPressure)
      for (int c = 0; c < 4; ++c)
        averaged += 0.25 * scratch.nodal_lambda_pressure_pa[model.corner[c][e]];
    const Eigen::Matrix3d P = stress_of<kFibres, kViscous, kAveragedPressure, kMooneyRivlin>(
        model, e, F, averaged, seen, viscous);
    // Nodal forces of corners 1..3 are the columns of −V·P·Dm⁻ᵀ; corner 0 balances them.
    const Eigen::Matrix3d h = -model.rest_volume_m3[e] * P * dm_inv.transpose();
    const Eigen::Vector3d h0 = -(h.col(0) + h.col(1) + h.col(2));
    corner_scratch[0].x[e] = h0.x();
    corner_scratch[0].y[e] = h0.y();
    corner_scratch[0].z[e] = h0.z();
    for (int c = 1; c < 4; ++c) {
      corner_scratch[c].x[e] = h(0, c - 1);
      corner_scratch[c].y[e] = h(1, c - 1);
      corner_scratch[c].z[e] = h(2, c - 1);
    }
  }
  return seen;
}

// Each node sums its own corner slots, so no two writers share a node (no atomics when threaded).
void gather_corner_forces(const SimModel& model, const ForceScratch& scratch, NodeArray& force) {
  const auto& corner_scratch = scratch.corner_force_n;
  const std::size_t tets = model.tet_count;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    double fx = 0.0, fy = 0.0, fz = 0.0;
    for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
      const auto slot = static_cast<std::size_t>(model.node_slots[s]);
      const auto& c = corner_scratch[slot / tets];
      const std::size_t e = slot % tets;
      fx += c.x[e];
      fy += c.y[e];
      fz += c.z[e];
    }
    force.x[n] = fx;
    force.y[n] = fy;
    force.z[n] = fz;
  }
}

// Picks the element loop compiled for the model's effect set.
template <bool kViscous>
ElasticEvaluation element_forces_for_effects(const SimModel& model, const NodeArray& position,
                                             ForceScratch& scratch, const ViscousContext& viscous) {
  const EffectSet& on = model.effects;
  auto run = [&](auto fibres, auto pressure, auto mooney) {
    return element_forces<decltype(fibres)::value, kViscous, decltype(pressure)::value,
                          decltype(mooney)::value>(model, position, scratch, viscous);
  };
  auto with_mooney = [&](auto fibres, auto pressure) {
    return on.mooney_rivlin ? run(fibres, pressure, std::true_type{})
                            : run(fibres, pressure, std::false_type{});
  };
  auto with_pressure = [&](auto fibres) {
    return on.average_nodal_pressure ? with_mooney(fibres, std::true_type{})
                                     : with_mooney(fibres, std::false_type{});
  };
  return on.fibres ? with_pressure(std::true_type{}) : with_pressure(std::false_type{});
}

}  // namespace

double element_energy_density(const SimModel& model, std::size_t e, const Eigen::Matrix3d& F) {
  double psi = neo_hookean::energy_density(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if (model.effects.mooney_rivlin)
    psi += mooney_rivlin::extra_energy_density(F, model.mooney_rivlin_c2_pa[e]);
  if (model.effects.fibres)
    for (const auto& family : model.fibre_direction)
      psi += hgo::energy_density(F, family[e], model.fibre_parameters[e]);
  return psi;
}

Eigen::Matrix3d element_first_piola_stress(const SimModel& model, std::size_t e,
                                           const Eigen::Matrix3d& F) {
  ElasticEvaluation ignored;
  const double J = F.determinant();  // a single element: its own J is the average
  Eigen::Matrix3d P = model.effects.fibres
                          ? stress_of<true, false, false, false>(model, e, F, J, ignored, {})
                          : stress_of<false, false, false, false>(model, e, F, J, ignored, {});
  if (model.effects.mooney_rivlin)
    P += mooney_rivlin::extra_first_piola_stress(F, model.mooney_rivlin_c2_pa[e]);
  return P;
}

Eigen::Matrix<double, 9, 9> element_stress_tangent(const SimModel& model, std::size_t e,
                                                   const Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 9, 9> tangent =
      neo_hookean::stress_tangent(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if (model.effects.mooney_rivlin)
    tangent += mooney_rivlin::extra_stress_tangent(F, model.mooney_rivlin_c2_pa[e]);
  if (model.effects.fibres)
    for (const auto& family : model.fibre_direction)
      tangent += hgo::stress_tangent(F, family[e], model.fibre_parameters[e]);
  return tangent;
}

ElasticEvaluation compute_elastic_forces(const SimModel& model, const NodeArray& position,
                                         ForceScratch& scratch, NodeArray& force) {
  const ElasticEvaluation seen = element_forces_for_effects<false>(model, position, scratch, {});
  gather_corner_forces(model, scratch, force);
  return seen;
}

ElasticEvaluation compute_internal_forces(const SimModel& model, SimState& state,
                                          double dt_since_last_s) {
  if (!model.effects.viscous)
    return compute_elastic_forces(model, state.position_m, state.force_scratch, state.force_n);
  for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r)
    if (model.viscous_parameters[r])
      state.viscous_step[r].emplace(*model.viscous_parameters[r], dt_since_last_s);
  const ElasticEvaluation seen = element_forces_for_effects<true>(
      model, state.position_m, state.force_scratch,
      {&state.viscous_state, &state.viscous_step, nullptr, &state.energy.viscous_dissipated_j});
  gather_corner_forces(model, state.force_scratch, state.force_n);
  return seen;
}

ElasticEvaluation compute_internal_forces_rate_form(const SimModel& model, SimState& state,
                                                    const NodeArray& position,
                                                    const ViscousArmInputs& arm, NodeArray& force) {
  if (!model.effects.viscous)
    return compute_elastic_forces(model, position, state.force_scratch, force);
  // The rate form needs only the step's moduli, not its length.
  for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r)
    if (model.viscous_parameters[r] && !state.viscous_step[r])
      state.viscous_step[r].emplace(*model.viscous_parameters[r], 0.0);
  const ElasticEvaluation seen = element_forces_for_effects<true>(
      model, position, state.force_scratch, {&state.viscous_state, &state.viscous_step, &arm});
  gather_corner_forces(model, state.force_scratch, force);
  return seen;
}

Eigen::Matrix<double, 9, 9> element_step_tangent(const SimModel& model, const SimState& state,
                                                 const ViscousArmInputs& arm, std::size_t e,
                                                 const Eigen::Matrix3d& F) {
  const auto r = static_cast<std::size_t>(model.region[e]);
  if (model.effects.viscous && model.viscous_parameters[r] && state.viscous_step[r]) {
    Eigen::Matrix<double, 9, 9> tangent = viscoelastic_stress_tangent_rate_form(
        F, *state.viscous_step[r], state.viscous_state[e].inverse_plastic_deformation,
        arm.q_known[e], arm.keep_by_region[r], arm.elastic_weight_by_region[r]);
    if (model.effects.fibres)
      for (const auto& family : model.fibre_direction)
        tangent += hgo::stress_tangent(F, family[e], model.fibre_parameters[e]);
    return tangent;
  }
  return element_stress_tangent(model, e, F);
}

void add_external_forces(const StepInputs& inputs, const NodeArray& position, NodeArray& force) {
  for (const auto& load : inputs.point_loads) {
    force.x[load.node] += load.force_n.x();
    force.y[load.node] += load.force_n.y();
    force.z[load.node] += load.force_n.z();
  }
  for (const auto& spring : inputs.springs) {
    const auto n = spring.node;
    force.x[n] += spring.stiffness_n_per_m * (spring.anchor_m.x() - position.x[n]);
    force.y[n] += spring.stiffness_n_per_m * (spring.anchor_m.y() - position.y[n]);
    force.z[n] += spring.stiffness_n_per_m * (spring.anchor_m.z() - position.z[n]);
  }
}

double strain_energy_j(const SimModel& model, const NodeArray& position) {
  double energy = 0.0;
  for (std::size_t e = 0; e < model.tet_count; ++e)
    energy += model.rest_volume_m3[e] *
              element_energy_density(model, e, deformation_gradient(model, position, e));
  return energy;
}

double kinetic_energy_j(const SimModel& model, const NodeArray& velocity) {
  double energy = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    energy += 0.5 * model.lumped_mass_kg[n] *
              (velocity.x[n] * velocity.x[n] + velocity.y[n] * velocity.y[n] +
               velocity.z[n] * velocity.z[n]);
  }
  return energy;
}

}  // namespace liversim
