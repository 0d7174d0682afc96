// Explicit Runge–Kutta schemes on the first-order system y = (x, v, Q): ẋ = v,
// v̇ = M⁻¹f(x, Q, v) − αv, Q̇ = (S_e(x) − Q)/τ for the Maxwell arm of viscous elements. Classical
// RK4 (the seed's) at a fixed step with the 3rd-order FSAL companion as error estimate, and
// Dormand–Prince 5(4) with error control.

#include "integrator_internal.h"

#include <limits>

namespace liversim::detail {
namespace {

constexpr int kMaxStages = 7;

struct Tableau {
  int stages;  // evaluations per step, the FSAL one included for dopri5
  double a[kMaxStages][kMaxStages];
  double b[kMaxStages];
  double error[kMaxStages];  // b − b̂ (dopri5); RK4 uses its FSAL companion instead
};

constexpr Tableau kRk4{
    4,
    {{0}, {0.5}, {0, 0.5}, {0, 0, 1.0}},
    {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6},
    {0},
};

// Dormand & Prince (1980); the 7th stage is evaluated at the new state (a₇ⱼ = bⱼ) and is the next
// step's first.
constexpr Tableau kDopri5{
    7,
    {{0},
     {1.0 / 5},
     {3.0 / 40, 9.0 / 40},
     {44.0 / 45, -56.0 / 15, 32.0 / 9},
     {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
     {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
     {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0},
    {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525, -1.0 / 40},
};

// The rate at (x, v, Q) into slot `slot`; returns the stiffening the evaluation saw.
double evaluate_rate(const SimModel& model, SimState& state, const StepInputs& inputs,
                     const NodeArray& x, const NodeArray& v, const std::vector<Voigt6>& q,
                     int slot) {
  IntegratorScratch& s = state.integrator;
  NodeArray& acceleration = s.velocity_rate[slot];
  const ViscousArmInputs arm{q, s.keep_by_region, s.elastic_weight_by_region, s.elastic_stress};
  const ElasticEvaluation seen =
      compute_internal_forces_rate_form(model, state, x, arm, acceleration);
  add_input_forces(model, inputs, x, v, acceleration);
  acceleration_from_force(model, acceleration, v, acceleration);  // in place: per node
  s.position_rate[slot].x = v.x;
  s.position_rate[slot].y = v.y;
  s.position_rate[slot].z = v.z;
  if (model.effects.viscous) {
    auto& rate = s.arm_rate[slot];
    for (std::size_t e = 0; e < model.tet_count; ++e) {
      const auto& parameters = model.viscous_parameters[static_cast<std::size_t>(model.region[e])];
      if (!parameters) continue;
      const double inverse_tau = 1.0 / parameters->viscoelastic.relaxation_time_s();
      for (int k = 0; k < 6; ++k) rate[e][k] = (s.elastic_stress[e][k] - q[e][k]) * inverse_tau;
    }
  }
  return stiffening_since_rest(model, seen);
}

// out = start + h·Σⱼ wⱼ·rate[j] over the first `count` slots.
void combine(const NodeArray& start, double h, const double* weights, int count,
             const std::vector<NodeArray>& rate, NodeArray& out) {
  const std::size_t n = start.size();
  for (std::size_t i = 0; i < n; ++i) {
    double dx = 0.0, dy = 0.0, dz = 0.0;
    for (int j = 0; j < count; ++j) {
      if (weights[j] == 0.0) continue;
      dx += weights[j] * rate[j].x[i];
      dy += weights[j] * rate[j].y[i];
      dz += weights[j] * rate[j].z[i];
    }
    out.x[i] = start.x[i] + h * dx;
    out.y[i] = start.y[i] + h * dy;
    out.z[i] = start.z[i] + h * dz;
  }
}

void combine_arm(const std::vector<Voigt6>& start, double h, const double* weights, int count,
                 const std::vector<std::vector<Voigt6>>& rate, std::vector<Voigt6>& out) {
  for (std::size_t e = 0; e < start.size(); ++e)
    for (int k = 0; k < 6; ++k) {
      double d = 0.0;
      for (int j = 0; j < count; ++j) d += weights[j] * rate[j][e][k];
      out[e][k] = start[e][k] + h * d;
    }
}

// Mixed local error of the step: per node max(|e_x|, h·|e_v|), e = h·Σ wⱼ·kⱼ.
double local_error_m(const SimModel& model, const IntegratorScratch& s, double h,
                     const double* weights, int count) {
  double largest = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    if (model.inverse_mass_per_kg[n] == 0.0) continue;
    double ex = 0, ey = 0, ez = 0, fx = 0, fy = 0, fz = 0;
    for (int j = 0; j < count; ++j) {
      if (weights[j] == 0.0) continue;
      ex += weights[j] * s.position_rate[j].x[n];
      ey += weights[j] * s.position_rate[j].y[n];
      ez += weights[j] * s.position_rate[j].z[n];
      fx += weights[j] * s.velocity_rate[j].x[n];
      fy += weights[j] * s.velocity_rate[j].y[n];
      fz += weights[j] * s.velocity_rate[j].z[n];
    }
    const double position_error = h * std::sqrt(ex * ex + ey * ey + ez * ez);
    const double velocity_error = h * h * std::sqrt(fx * fx + fy * fy + fz * fz);
    largest = std::max(largest, std::max(position_error, velocity_error));
  }
  return largest;
}

bool has_plastic_flow(const SimModel& model) {
  for (const auto& parameters : model.viscous_parameters)
    if (parameters && parameters->viscoplastic) return true;
  return false;
}

}  // namespace

void advance_runge_kutta(const SimModel& model, SimState& state, const StepInputs& inputs,
                         double interval_s, StepReport& report) {
  IntegratorScratch& s = state.integrator;
  const bool adaptive = model.integrator.kind == IntegratorKind::dopri5;
  const Tableau& tableau = adaptive ? kDopri5 : kRk4;
  const int stages = tableau.stages;
  // Inputs may have changed since the last call: the rate at the state must be evaluated again.
  s.first_rate_valid = false;
  const bool flows = has_plastic_flow(model);
  if (adaptive && !(s.adaptive_step_s > 0.0))
    s.adaptive_step_s =
        model.integrator.step_s > 0.0 ? model.integrator.step_s : model.stable_time_step_s;

  double remaining = interval_s;
  while (remaining > 0.0) {
    s.start_position_m = state.position_m;
    s.start_velocity_m_per_s = state.velocity_m_per_s;
    arm_of_committed_state(model, state, s.start_arm);
    if (!s.first_rate_valid) {
      s.first_rate_stiffening = evaluate_rate(model, state, inputs, s.start_position_m,
                                              s.start_velocity_m_per_s, s.start_arm, 0);
      ++report.force_evaluations;
    }
    const double stiffening = s.first_rate_stiffening;
    report.max_stiffening = std::max(report.max_stiffening, stiffening);

    // RK4's error estimate of its previous step: h/6·(k₄ − k₅) with k₅ the rate just evaluated
    // (the 3rd-order companion b̂ = (1/6, 1/3, 1/3, 0, 1/6) shares every stage).
    if (!adaptive && s.error_pending) {
      constexpr double kCompanion[kMaxStages + 1] = {-1.0 / 6, 0, 0, 1.0 / 6};
      // Slot 0 now holds k₅, slot 3 still the previous step's k₄.
      note_error_estimate(report, local_error_m(model, s, s.error_pending_step_s, kCompanion, 4));
      s.error_pending = false;
    }

    double limit =
        explicit_step_limit_s(model, inputs, stiffening, model.integrator.kind) * s.step_scale;
    const double speed = largest_norm(s.start_velocity_m_per_s);
    if (speed > 0.0) limit = std::min(limit, 0.1 * model.min_element_height_m / speed);
    double wanted =
        adaptive ? s.adaptive_step_s
                 : (model.integrator.step_s > 0.0 ? model.integrator.step_s * s.step_scale : limit);
    double h = std::min(wanted, limit);
    if (!adaptive) {
      if (s.chosen_step_s > 0.0) h = std::min(h, kStepGrowth * s.chosen_step_s);
      s.chosen_step_s = h;
    }
    const bool limited = limit < wanted && limit < remaining;
    double steps_left = 1.0;
    if (adaptive) {
      if (h >= remaining * (1.0 - 1e-9)) h = remaining;
    } else {
      steps_left = steps_to_cover(remaining, h);
      h = steps_left <= 1.0 ? remaining : remaining / steps_left;
    }

    for (int stage = 1; stage < stages; ++stage) {
      const double* a = tableau.a[stage];
      combine(s.start_position_m, h, a, stage, s.position_rate, s.stage_position_m);
      combine(s.start_velocity_m_per_s, h, a, stage, s.velocity_rate, s.stage_velocity_m_per_s);
      if (model.effects.viscous) combine_arm(s.start_arm, h, a, stage, s.arm_rate, s.stage_arm);
      evaluate_rate(model, state, inputs, s.stage_position_m, s.stage_velocity_m_per_s, s.stage_arm,
                    stage);
      ++report.force_evaluations;
    }

    if (adaptive) {
      const double error = local_error_m(model, s, h, tableau.error, stages);
      const double ratio = error / model.integrator.tolerance_m;
      // Standard controller: Δt·0.9·ratio^(−1/5), between 0.2× and 5×.
      const double factor = ratio > 0.0 ? std::clamp(0.9 * std::pow(ratio, -0.2), 0.2, 5.0) : 5.0;
      if (!(ratio <= 1.0)) {  // rejected (NaN too): the first rate is still the start's
        ++report.rejected_steps;
        s.adaptive_step_s = h * std::min(factor, 1.0);
        s.first_rate_valid = true;
        if (!(s.adaptive_step_s > 1e-12 * interval_s)) s.adaptive_step_s = 1e-12 * interval_s;
        continue;
      }
      note_error_estimate(report, error);
      // The last stage was evaluated at the new state: it is the next step's first (FSAL).
      state.position_m = s.stage_position_m;
      state.velocity_m_per_s = s.stage_velocity_m_per_s;
      std::swap(s.position_rate[0], s.position_rate[stages - 1]);
      std::swap(s.velocity_rate[0], s.velocity_rate[stages - 1]);
      if (model.effects.viscous) {
        std::swap(s.arm_rate[0], s.arm_rate[stages - 1]);
        commit_arm(model, state, state.position_m, s.stage_arm, h);
      }
      s.first_rate_valid = !flows;  // plastic flow after the step changes the rate
      // Do not let the step the interval's end cut short shrink the next proposal.
      if (h < remaining || factor < 1.0) s.adaptive_step_s = h * factor;
    } else {
      combine(s.start_position_m, h, tableau.b, stages, s.position_rate, state.position_m);
      combine(s.start_velocity_m_per_s, h, tableau.b, stages, s.velocity_rate,
              state.velocity_m_per_s);
      if (model.effects.viscous) {
        combine_arm(s.start_arm, h, tableau.b, stages, s.arm_rate, s.stage_arm);
        commit_arm(model, state, state.position_m, s.stage_arm, h);
      }
      s.first_rate_valid = false;
      s.error_pending = true;
      s.error_pending_step_s = h;
    }

    if (limited) {
      report.smallest_stable_step_s = report.stability_limited_steps > 0
                                          ? std::min(report.smallest_stable_step_s, limit)
                                          : limit;
      ++report.stability_limited_steps;
    }
    state.max_speed_m_per_s = largest_norm(state.velocity_m_per_s);
    state.last_step_s = h;
    state.time_s += h;
    ++state.step_count;
    ++report.substeps;
    report.smallest_substep_s = std::min(report.smallest_substep_s, h);
    report.largest_substep_s = std::max(report.largest_substep_s, h);
    remaining = (adaptive ? h >= remaining : steps_left <= 1.0) ? 0.0 : remaining - h;
  }
}

}  // namespace liversim::detail
