#include "liversim/engine/integrator.h"

#include "integrator_internal.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/in_vivo_stress.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace liversim {
namespace {

ElasticEvaluation evaluate_forces(const SimModel& model, SimState& state,
                                  const StepInputs& inputs) {
  // The configuration was reached by the last step, so history-dependent materials advance by it.
  const ElasticEvaluation seen = compute_internal_forces(model, state, state.last_step_s);
  // The external force is kept apart too: a kick across a change of inputs needs both sides.
  NodeArray& external = state.integrator.external_force_n;
  std::fill(external.x.begin(), external.x.end(), 0.0);
  std::fill(external.y.begin(), external.y.end(), 0.0);
  std::fill(external.z.begin(), external.z.end(), 0.0);
  add_external_forces(inputs, state.position_m, external);
  add_gravity_forces(model, external);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    state.force_n.x[n] += external.x[n];
    state.force_n.y[n] += external.y[n];
    state.force_n.z[n] += external.z[n];
  }
  // The support's push depends on where the nodes are, as the tissue's does: not an input whose
  // change the kick splits.
  add_support_forces(model, state.position_m, state.force_n, {&state.spring_damping_per_s});
  for (const auto& spring : inputs.springs)
    state.spring_damping_per_s[spring.node] +=
        spring.damping_n_s_per_m * model.inverse_mass_per_kg[spring.node];
  return seen;
}

// Leapfrog kick and drift with the forces in state.force_n. Damping (mass-proportional α plus
// the springs' c/m) taken at the mid-step velocity keeps the scheme explicit, second order and
// stable for any damping: v⁺ = ((1 − αΔt/2) v⁻ + Δt M⁻¹ f) / (1 + αΔt/2).
void kick_drift(const SimModel& model, SimState& state, const StepInputs& inputs, double dt_s,
                bool inputs_changed = false) {
  // With a changing step the velocity lives at the midpoints, so the kick spans half of the last
  // step and half of this one; kicking by Δt alone would pump energy whenever the step changes.
  // The first step starts from v(t₀) (what a user sets), so it kicks by half a step only.
  const double kick_s = 0.5 * (state.last_step_s + dt_s);
  // Inputs that changed at this instant act on the first half of the kick with their old value:
  // kicking both halves with the new one is a first-order error at every change of load.
  const double old_share = inputs_changed ? 0.5 * state.last_step_s / kick_s : 0.0;
  const NodeArray& old_external = state.integrator.previous_external_force_n;
  const NodeArray& new_external = state.integrator.external_force_n;
  auto& x = state.position_m;
  auto& v = state.velocity_m_per_s;
  const auto& f = state.force_n;
  double max_speed_sq = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const double w = model.inverse_mass_per_kg[n];
    if (w == 0.0) continue;  // fixed node
    const double half_damping =
        0.5 * (model.mass_damping_per_s + state.spring_damping_per_s[n]) * kick_s;
    const double keep = (1.0 - half_damping) / (1.0 + half_damping);
    const double gain = kick_s * w / (1.0 + half_damping);
    double fx = f.x[n], fy = f.y[n], fz = f.z[n];
    if (old_share > 0.0) {
      fx += old_share * (old_external.x[n] - new_external.x[n]);
      fy += old_share * (old_external.y[n] - new_external.y[n]);
      fz += old_share * (old_external.z[n] - new_external.z[n]);
    }
    v.x[n] = keep * v.x[n] + gain * fx;
    v.y[n] = keep * v.y[n] + gain * fy;
    v.z[n] = keep * v.z[n] + gain * fz;
    x.x[n] += dt_s * v.x[n];
    x.y[n] += dt_s * v.y[n];
    x.z[n] += dt_s * v.z[n];
    max_speed_sq = std::max(max_speed_sq, v.x[n] * v.x[n] + v.y[n] * v.y[n] + v.z[n] * v.z[n]);
  }
  for (const auto& spring : inputs.springs) state.spring_damping_per_s[spring.node] = 0.0;
  if (model.support)  // the support's rates, on the nodes it touched
    std::fill(state.spring_damping_per_s.begin(), state.spring_damping_per_s.end(), 0.0);
  std::swap(state.integrator.previous_external_force_n, state.integrator.external_force_n);
  state.max_speed_m_per_s = std::sqrt(max_speed_sq);
  state.last_step_s = dt_s;
  state.time_s += dt_s;
  ++state.step_count;
}

}  // namespace

std::string_view integrator_name(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::central_difference:
      return "central-difference";
    case IntegratorKind::rk4:
      return "rk4";
    case IntegratorKind::dopri5:
      return "dopri5";
    case IntegratorKind::backward_euler:
      return "backward-euler";
    case IntegratorKind::bdf2:
      return "bdf2";
  }
  return "unknown";
}

std::optional<IntegratorKind> integrator_from_name(std::string_view name) {
  for (IntegratorKind kind : kAllIntegrators)
    if (integrator_name(kind) == name) return kind;
  return std::nullopt;
}

int integrator_order(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::central_difference:
      return 2;
    case IntegratorKind::rk4:
      return 4;
    case IntegratorKind::dopri5:
      return 5;
    case IntegratorKind::backward_euler:
      return 1;
    case IntegratorKind::bdf2:
      return 2;
  }
  return 0;
}

bool is_explicit(IntegratorKind kind) {
  return kind == IntegratorKind::central_difference || kind == IntegratorKind::rk4 ||
         kind == IntegratorKind::dopri5;
}

double stability_interval(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::central_difference:
      return 2.0;
    case IntegratorKind::rk4:
      return 2.0 * std::sqrt(2.0);
    // |R(iy)| ≤ 1 holds only up to y ≈ 0.997 for Dormand–Prince 5 (checked numerically from
    // its tableau); beyond it undamped oscillations grow, by 3 % per step at y = 1.5.
    case IntegratorKind::dopri5:
      return 0.99;
    case IntegratorKind::backward_euler:
    case IntegratorKind::bdf2:
      return std::numeric_limits<double>::infinity();
  }
  return 0.0;
}

void accumulate(StepReport& total, const StepReport& part) {
  total.gave_up_early |= part.gave_up_early;
  total.step_collapsed |= part.step_collapsed;
  if (part.substeps == 0) return;
  if (total.substeps == 0) {
    total.smallest_substep_s = part.smallest_substep_s;
    total.largest_substep_s = part.largest_substep_s;
  } else {
    total.smallest_substep_s = std::min(total.smallest_substep_s, part.smallest_substep_s);
    total.largest_substep_s = std::max(total.largest_substep_s, part.largest_substep_s);
  }
  total.substeps += part.substeps;
  total.max_stiffening = std::max(total.max_stiffening, part.max_stiffening);
  total.least_volume_ratio = std::min(total.least_volume_ratio, part.least_volume_ratio);
  total.max_flow_stiffening = std::max(total.max_flow_stiffening, part.max_flow_stiffening);
  if (part.stability_limited_steps > 0)
    total.smallest_stable_step_s =
        total.stability_limited_steps > 0
            ? std::min(total.smallest_stable_step_s, part.smallest_stable_step_s)
            : part.smallest_stable_step_s;
  total.stability_limited_steps += part.stability_limited_steps;
  total.smallest_mesh_limit_s = std::min(total.smallest_mesh_limit_s, part.smallest_mesh_limit_s);
  total.smallest_travel_limit_s =
      std::min(total.smallest_travel_limit_s, part.smallest_travel_limit_s);
  total.smallest_spring_limit_s =
      std::min(total.smallest_spring_limit_s, part.smallest_spring_limit_s);
  total.rejected_steps += part.rejected_steps;
  total.force_evaluations += part.force_evaluations;
  total.newton_iterations += part.newton_iterations;
  total.linear_solves += part.linear_solves;
  total.factorizations += part.factorizations;
  total.unconverged_steps += part.unconverged_steps;
  if (std::isnan(total.error_estimate_m) || !(part.error_estimate_m <= total.error_estimate_m))
    total.error_estimate_m =
        std::isnan(part.error_estimate_m) ? total.error_estimate_m : part.error_estimate_m;
}

double max_frequency_rad_per_s(const SimModel& model, const StepInputs& inputs, double stiffening) {
  double max_spring_omega_sq = 0.0;
  for (const auto& spring : inputs.springs) {
    max_spring_omega_sq = std::max(
        max_spring_omega_sq, spring.stiffness_n_per_m * model.inverse_mass_per_kg[spring.node]);
  }
  // The support's penalty adds its ω² to any node it pushes (Weyl: the largest eigenvalue of a
  // sum is at most the sum of the largest).
  return std::sqrt(model.max_frequency_rad_per_s * model.max_frequency_rad_per_s *
                       std::max(1.0, stiffening) +
                   max_spring_omega_sq + model.support_stiffness_per_kg);
}

double stable_time_step_s(const SimModel& model, const StepInputs& inputs, double stiffening) {
  const double omega = max_frequency_rad_per_s(model, inputs, stiffening);
  if (!(omega > 0.0)) return std::numeric_limits<double>::infinity();
  const double xi = model.mass_damping_per_s / (2.0 * omega);
  return model.stable_step_safety * (2.0 / omega) * (std::sqrt(1.0 + xi * xi) - xi);
}

ElasticEvaluation central_difference_step(const SimModel& model, SimState& state,
                                          const StepInputs& inputs, double dt_s) {
  const ElasticEvaluation seen = evaluate_forces(model, state, inputs);
  kick_drift(model, state, inputs, dt_s);
  return seen;
}

double stiffening_since_rest(const SimModel& model, const ElasticEvaluation& seen) {
  // Where every element averages its λ pressure over nodes (no viscous region keeps its own), the
  // λ part stiffens with the smallest nodal J, only the −μ/J part with the element's: a small
  // element crushed under a blade barely stiffens its nodes, whose J averages it with their other
  // elements' (the whole volumetric stiffening of the smallest J had set the step 4–8 times too
  // small while a blade pressed on a cut's small parts).
  const bool nodal = model.effects.average_nodal_pressure && !model.effects.viscous &&
                     std::isfinite(seen.min_nodal_volume_ratio);
  double stiffening = 1.0;
  for (const RegionMaterial& region : model.regions) {
    const double mu = region.tissue.shear_modulus_pa(), lambda = region.tissue.lame_lambda_pa();
    stiffening = std::max(
        stiffening, nodal ? neo_hookean::split_volumetric_stiffening(
                                seen.min_nodal_volume_ratio, seen.min_volume_ratio, mu, lambda)
                          : neo_hookean::volumetric_stiffening(seen.min_volume_ratio, mu, lambda));
    stiffening = std::max(stiffening, 1.0 + seen.max_fibre_modulus_pa / (lambda + 2.0 * mu));
  }
  // Each element's stiffness is at most its flow's stiffening times its unflowed one, so the
  // assembled ω² is at most the largest of them times the rest's: without it an element that has
  // flowed is stepped with its rest shape's limit.
  return stiffening * seen.max_flow_stiffening;
}

namespace detail {

std::uint64_t fingerprint(const StepInputs& inputs) {
  // FNV-1a over the values (not the bytes: structs have padding).
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&](std::uint64_t value) {
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (value >> (8 * byte)) & 0xffu;
      hash *= 1099511628211ull;
    }
  };
  auto mix_double = [&](double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    mix(bits);
  };
  mix(inputs.point_loads.size());
  for (const PointLoad& load : inputs.point_loads) {
    mix(static_cast<std::uint64_t>(load.node));
    for (int k = 0; k < 3; ++k) mix_double(load.force_n[k]);
  }
  mix(inputs.springs.size());
  for (const NodeSpring& spring : inputs.springs) {
    mix(static_cast<std::uint64_t>(spring.node));
    for (int k = 0; k < 3; ++k) mix_double(spring.anchor_m[k]);
    mix_double(spring.stiffness_n_per_m);
    mix_double(spring.damping_n_s_per_m);
  }
  return hash;
}

double explicit_step_limit_s(const SimModel& model, const StepInputs& inputs, double stiffening,
                             IntegratorKind kind) {
  if (kind == IntegratorKind::central_difference)
    return stable_time_step_s(model, inputs, stiffening);
  const double omega = max_frequency_rad_per_s(model, inputs, stiffening);
  double limit =
      omega > 0.0 ? stability_interval(kind) / omega : std::numeric_limits<double>::infinity();
  // Damping is explicit in Runge–Kutta: a decay rate d needs d·Δt inside the real-axis
  // interval (RK4 2.785, Dormand–Prince 3.31; checked from the tableaus).
  double decay_per_s = model.mass_damping_per_s + support_damping_per_s(model);
  for (const auto& spring : inputs.springs)
    decay_per_s = std::max(decay_per_s,
                           model.mass_damping_per_s +
                               spring.damping_n_s_per_m * model.inverse_mass_per_kg[spring.node]);
  const double real_interval = kind == IntegratorKind::rk4 ? 2.785 : 3.31;
  if (decay_per_s > 0.0) limit = std::min(limit, real_interval / decay_per_s);
  return model.stable_step_safety * limit;
}

double history_error_estimate(const SimModel& model, IntegratorScratch& scratch,
                              const NodeArray& velocity, double dt_s, IntegratorKind kind) {
  // Local position error C·Δt^(p+1)·x^(p+1) ≈ C·Δt·|Δᵖv| with Δᵖ the p-th backward difference of
  // the end-of-step velocity; C is the scheme's error constant: backward Euler ½, BDF2 2/9,
  // central difference (Störmer–Verlet, p counted on positions: Δt⁴x⁗/12) 1/12 with Δ³v.
  int differences = 0;
  double constant = 0.0;
  switch (kind) {
    case IntegratorKind::backward_euler:
      differences = 1, constant = 0.5;
      break;
    case IntegratorKind::bdf2:
      differences = 2, constant = 2.0 / 9.0;
      break;
    case IntegratorKind::central_difference:
      differences = 3, constant = 1.0 / 12.0;
      break;
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
  const bool same_step = std::abs(dt_s - scratch.history_step_s) <= 1e-9 * dt_s;
  if (!same_step) scratch.history_count = 0;
  double estimate = std::numeric_limits<double>::quiet_NaN();
  auto& h = scratch.velocity_history;  // h[0] the previous step's, h[1] the one before, ...
  if (scratch.history_count >= differences) {
    // Binomial weights of Δᵏ: (1, −1), (1, −2, 1), (1, −3, 3, −1).
    static constexpr double kWeights[3][3] = {{-1, 0, 0}, {-2, 1, 0}, {-3, 3, -1}};
    const double* w = kWeights[differences - 1];
    double largest_sq = 0.0;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      if (model.inverse_mass_per_kg[n] == 0.0) continue;
      double dx = velocity.x[n], dy = velocity.y[n], dz = velocity.z[n];
      for (int k = 0; k < differences; ++k) {
        dx += w[k] * h[k].x[n];
        dy += w[k] * h[k].y[n];
        dz += w[k] * h[k].z[n];
      }
      largest_sq = std::max(largest_sq, dx * dx + dy * dy + dz * dz);
    }
    estimate = constant * dt_s * std::sqrt(largest_sq);
  }
  std::rotate(h.begin(), h.end() - 1, h.end());  // swaps buffers; no allocation
  h[0].x = velocity.x;
  h[0].y = velocity.y;
  h[0].z = velocity.z;
  scratch.history_count = std::min(scratch.history_count + 1, 3);
  scratch.history_step_s = dt_s;
  return estimate;
}

void prepare_integrator_scratch(const SimModel& model, IntegratorScratch& scratch) {
  const std::size_t n = model.node_count;
  const IntegratorKind kind = model.integrator.kind;
  for (auto& history : scratch.velocity_history) history.resize(n);
  scratch.external_force_n.resize(n);
  scratch.previous_external_force_n.resize(n);
  const std::size_t arm_count = model.effects.viscous ? model.tet_count : 0;
  // The arm as an explicit stage reads it: Q = 1·q + 0·S_e (implicit steps set their own).
  scratch.keep_by_region.assign(model.regions.size(), 1.0);
  scratch.elastic_weight_by_region.assign(model.regions.size(), 0.0);
  if (kind == IntegratorKind::rk4 || kind == IntegratorKind::dopri5) {
    const int stages = kind == IntegratorKind::rk4 ? 4 : 7;
    scratch.start_position_m.resize(n);
    scratch.start_velocity_m_per_s.resize(n);
    scratch.stage_position_m.resize(n);
    scratch.stage_velocity_m_per_s.resize(n);
    scratch.position_rate.assign(stages + 1, NodeArray{});  // + the next step's first (FSAL)
    scratch.velocity_rate.assign(stages + 1, NodeArray{});
    for (auto& rate : scratch.position_rate) rate.resize(n);
    for (auto& rate : scratch.velocity_rate) rate.resize(n);
    scratch.start_arm.assign(arm_count, Voigt6{});
    scratch.stage_arm.assign(arm_count, Voigt6{});
    scratch.elastic_stress.assign(arm_count, Voigt6{});
    scratch.arm_rate.assign(stages + 1, std::vector<Voigt6>(arm_count));
  }
  if (!is_explicit(kind)) {
    scratch.previous_position_m.resize(n);
    scratch.previous_velocity_m_per_s.resize(n);
    scratch.predicted_position_m.resize(n);
    scratch.predicted_velocity_m_per_s.resize(n);
    scratch.start_arm.assign(arm_count, Voigt6{});
    scratch.stage_arm.assign(arm_count, Voigt6{});
    scratch.previous_arm.assign(arm_count, Voigt6{});
    scratch.predicted_arm.assign(arm_count, Voigt6{});
    scratch.elastic_stress.assign(arm_count, Voigt6{});
    prepare_implicit_solver(model, scratch.implicit);
  }
}

void add_input_forces(const SimModel& model, const StepInputs& inputs, const NodeArray& position,
                      const NodeArray& velocity, NodeArray& force) {
  add_external_forces(inputs, position, force);
  add_gravity_forces(model, force);
  add_support_forces(model, position, force, {nullptr, &velocity});
  for (const auto& spring : inputs.springs) {
    const auto n = spring.node;
    force.x[n] -= spring.damping_n_s_per_m * velocity.x[n];
    force.y[n] -= spring.damping_n_s_per_m * velocity.y[n];
    force.z[n] -= spring.damping_n_s_per_m * velocity.z[n];
  }
}

void acceleration_from_force(const SimModel& model, const NodeArray& force,
                             const NodeArray& velocity, NodeArray& acceleration) {
  const double alpha = model.mass_damping_per_s;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const double w = model.inverse_mass_per_kg[n];
    acceleration.x[n] = w == 0.0 ? 0.0 : w * force.x[n] - alpha * velocity.x[n];
    acceleration.y[n] = w == 0.0 ? 0.0 : w * force.y[n] - alpha * velocity.y[n];
    acceleration.z[n] = w == 0.0 ? 0.0 : w * force.z[n] - alpha * velocity.z[n];
  }
}

void arm_of_committed_state(const SimModel& model, const SimState& state,
                            std::vector<Voigt6>& arm) {
  if (!model.effects.viscous) return;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    if (!model.viscous_parameters[static_cast<std::size_t>(model.region[e])]) continue;
    const ViscousHistory& history = state.viscous_history;
    for (int k = 0; k < 6; ++k)
      arm[e][k] = history.value(ViscousHistory::kElasticStress + k, e) -
                  history.value(ViscousHistory::kMaxwellStress + k, e);
  }
}

void commit_arm(const SimModel& model, SimState& state, const NodeArray& position,
                const std::vector<Voigt6>& arm, double dt_s) {
  if (!model.effects.viscous) return;
  for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r)
    if (model.viscous_parameters[r])
      state.viscous_step[r] =
          ViscousTissueStep::plastic_flow_only(*model.viscous_parameters[r], dt_s);
  double dissipated_j = 0.0;  // the dashpots' work over the step (trapezoid of 2ψ_arm/τ)
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const auto r = static_cast<std::size_t>(model.region[e]);
    if (!model.viscous_parameters[r]) continue;
    const ViscousTissueStep& step = *state.viscous_step[r];
    ViscousTissueState committed = state.viscous_history.load(e);
    const double arm_before = maxwell_arm_energy_density(committed.maxwell_stress_pa, step);
    const Eigen::Matrix3d F = deformation_gradient(model, position, e);
    Voigt6 elastic;
    viscoelastic_stress_rate_form(F, step, committed.inverse_plastic_deformation, arm[e], 1.0, 0.0,
                                  elastic);
    for (int k = 0; k < 6; ++k) {
      committed.elastic_stress_pa[k] = elastic[k];
      committed.maxwell_stress_pa[k] = elastic[k] - arm[e][k];
    }
    // Plastic flow after the step, the arm's Q held (g = h = 1): first order in the flow, exact
    // under a held stress as the seed's Eq. 4.
    if (step.viscoplastic) viscous_tissue_update(F, step, committed, yield_raise_pa(model, e));
    dissipated_j += model.rest_volume_m3[e] / step.relaxation_time_s *
                    (arm_before + maxwell_arm_energy_density(committed.maxwell_stress_pa, step));
    state.viscous_history.store(e, committed);
  }
  state.energy.viscous_dissipated_j += dt_s * dissipated_j;
}

}  // namespace detail

namespace {

// Returns the time it advanced: the interval, or with whole steps (whole_step_s > 0) at least it.
double advance_central_difference(const SimModel& model, SimState& state, const StepInputs& inputs,
                                  double interval_s, double whole_step_s,
                                  const std::atomic<bool>* give_up, StepReport& report) {
  const bool whole_steps = whole_step_s > 0.0;
  const double requested_s = whole_steps ? whole_step_s : model.integrator.step_s;
  double advanced_s = 0.0;
  if (whole_steps) report.smallest_substep_s = std::numeric_limits<double>::infinity();
  double remaining = interval_s;
  bool first = true;
  while (remaining > 0.0) {
    if (give_up && give_up->load(std::memory_order_relaxed)) {
      report.gave_up_early = true;
      return advanced_s;
    }
    const ElasticEvaluation seen = evaluate_forces(model, state, inputs);
    const double stiffening = stiffening_since_rest(model, seen);
    ++report.force_evaluations;
    report.max_stiffening = std::max(report.max_stiffening, stiffening);
    report.least_volume_ratio = std::min(report.least_volume_ratio, seen.min_volume_ratio);
    report.max_flow_stiffening = std::max(report.max_flow_stiffening, seen.max_flow_stiffening);
    double limit = stable_time_step_s(model, inputs, stiffening);
    report.smallest_spring_limit_s = std::min(report.smallest_spring_limit_s, limit);
    report.smallest_mesh_limit_s =
        std::min(report.smallest_mesh_limit_s,
                 inputs.springs.empty() ? limit : stable_time_step_s(model, {}, stiffening));
    if (state.max_speed_m_per_s > 0.0) {
      const double travel_limit = 0.1 * model.min_element_height_m / state.max_speed_m_per_s;
      report.smallest_travel_limit_s = std::min(report.smallest_travel_limit_s, travel_limit);
      limit = std::min(limit, travel_limit);
    }
    if (limit < kCollapsedStepFraction * model.stable_time_step_s) {
      report.step_collapsed = true;
      return advanced_s;
    }
    double step = limit;
    if (requested_s > 0.0) {
      step = std::min(requested_s, limit);
      if (limit < requested_s) {
        report.smallest_stable_step_s = report.stability_limited_steps > 0
                                            ? std::min(report.smallest_stable_step_s, limit)
                                            : limit;
        ++report.stability_limited_steps;
      }
    }
    step *= state.integrator.step_scale;
    // The chosen step may fall at once but grows slowly (detail::kStepGrowth); the equal split
    // of an interval below does not feed back into it.
    if (state.integrator.chosen_step_s > 0.0)
      step = std::min(step, detail::kStepGrowth * state.integrator.chosen_step_s);
    state.integrator.chosen_step_s = step;
    // Equal steps over what is left, so the interval ends exactly where asked; or whole steps.
    const double steps_left = detail::steps_to_cover(remaining, step);
    const double dt = whole_steps ? step : (steps_left <= 1.0 ? remaining : remaining / steps_left);
    kick_drift(model, state, inputs, dt, first && state.integrator.inputs_changed);
    first = false;
    detail::note_error_estimate(
        report, detail::history_error_estimate(model, state.integrator, state.velocity_m_per_s, dt,
                                               IntegratorKind::central_difference));
    advanced_s += dt;
    if (whole_steps)
      remaining = remaining - dt > 1e-9 * dt ? remaining - dt : 0.0;
    else
      remaining = steps_left <= 1.0 ? 0.0 : remaining - dt;
    ++report.substeps;
    report.smallest_substep_s = std::min(report.smallest_substep_s, dt);
    report.largest_substep_s = std::max(report.largest_substep_s, dt);
  }
  return whole_steps ? advanced_s : interval_s;
}

}  // namespace

StepReport advance(const SimModel& model, SimState& state, const StepInputs& inputs,
                   double interval_s, double whole_step_s, const std::atomic<bool>* give_up) {
  StepReport report;
  if (!(interval_s > 0.0)) return report;
  report.smallest_substep_s = interval_s;
  report.error_estimate_m = std::numeric_limits<double>::quiet_NaN();
  const double start_time = state.time_s;
  double end_time = start_time + interval_s;
  const std::uint64_t fingerprint = detail::fingerprint(inputs);
  state.integrator.inputs_changed = fingerprint != state.integrator.inputs_fingerprint;
  state.integrator.inputs_fingerprint = fingerprint;
  // Work of the inputs: a moved spring anchor did the work of the energy it added; point loads are
  // constant over the interval, so F·(x_end − x_start) is their exact work.
  EnergyLedger& books = state.energy;
  books.tool_work_j += spring_energy_j(inputs.springs, state.position_m) - books.spring_energy_j;
  for (const PointLoad& load : inputs.point_loads)
    books.tool_work_j -= load.force_n.dot(state.position_m.at(load.node));
  switch (model.integrator.kind) {
    case IntegratorKind::central_difference:
      // No drift from summing substeps: the time they covered, added once.
      end_time = start_time + advance_central_difference(model, state, inputs, interval_s,
                                                         whole_step_s, give_up, report);
      break;
    case IntegratorKind::rk4:
    case IntegratorKind::dopri5:
      detail::advance_runge_kutta(model, state, inputs, interval_s, report);
      break;
    case IntegratorKind::backward_euler:
    case IntegratorKind::bdf2:
      detail::advance_implicit(model, state, inputs, interval_s, report);
      break;
  }
  for (const PointLoad& load : inputs.point_loads)
    books.tool_work_j += load.force_n.dot(state.position_m.at(load.node));
  books.spring_energy_j = spring_energy_j(inputs.springs, state.position_m);
  state.time_s = end_time;  // no drift from summing substeps
  return report;
}

double estimate_max_frequency_rad_per_s(const SimModel& model, const NodeArray& position,
                                        int iterations) {
  const std::size_t n = model.node_count;
  ForceScratch scratch = make_force_scratch(model);
  NodeArray probe = position, force_plus, force_minus;
  force_plus.resize(n);
  force_minus.resize(n);

  // Work in mass-scaled coordinates u = M^(1/2) v, where A = M^(-1/2) K M^(-1/2) is symmetric.
  std::vector<double> u(3 * n), au(3 * n), inv_sqrt_mass(n);
  for (std::size_t i = 0; i < n; ++i) inv_sqrt_mass[i] = std::sqrt(model.inverse_mass_per_kg[i]);
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (std::size_t i = 0; i < 3 * n; ++i) u[i] = inv_sqrt_mass[i / 3] > 0 ? uniform(random) : 0;

  double characteristic_length = 0.0;
  for (double v : model.rest_volume_m3) characteristic_length = std::max(characteristic_length, v);
  characteristic_length = std::cbrt(characteristic_length);

  double eigenvalue = 0.0;
  for (int it = 0; it < iterations; ++it) {
    double norm = 0.0;
    for (double value : u) norm += value * value;
    norm = std::sqrt(norm);
    if (norm == 0.0) return 0.0;
    for (double& value : u) value /= norm;
    // K·v by central differences of the elastic force along v = M^(-1/2) u.
    double max_v = 0.0;
    for (std::size_t i = 0; i < 3 * n; ++i)
      max_v = std::max(max_v, std::abs(u[i] * inv_sqrt_mass[i / 3]));
    const double h = 1e-6 * characteristic_length / max_v;
    auto displace = [&](double sign) {
      for (std::size_t i = 0; i < n; ++i) {
        probe.x[i] = position.x[i] + sign * h * u[3 * i] * inv_sqrt_mass[i];
        probe.y[i] = position.y[i] + sign * h * u[3 * i + 1] * inv_sqrt_mass[i];
        probe.z[i] = position.z[i] + sign * h * u[3 * i + 2] * inv_sqrt_mass[i];
      }
    };
    displace(+1.0);
    compute_elastic_forces(model, probe, scratch, force_plus);
    displace(-1.0);
    compute_elastic_forces(model, probe, scratch, force_minus);
    double rayleigh = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double s = inv_sqrt_mass[i] / (2.0 * h);  // K v = −(f(x+hv) − f(x−hv)) / 2h
      au[3 * i] = -s * (force_plus.x[i] - force_minus.x[i]);
      au[3 * i + 1] = -s * (force_plus.y[i] - force_minus.y[i]);
      au[3 * i + 2] = -s * (force_plus.z[i] - force_minus.z[i]);
      rayleigh +=
          u[3 * i] * au[3 * i] + u[3 * i + 1] * au[3 * i + 1] + u[3 * i + 2] * au[3 * i + 2];
    }
    eigenvalue = rayleigh;
    u.swap(au);
  }
  return std::sqrt(std::max(eigenvalue, 0.0));
}

}  // namespace liversim
