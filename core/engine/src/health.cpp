#include "liversim/engine/health.h"

#include "liversim/engine/energy.h"

#include "integrator_internal.h"

#include <algorithm>
#include <cmath>

namespace liversim {

std::string_view health_problem_text(HealthProblem problem) {
  switch (problem) {
    case HealthProblem::none:
      return "healthy";
    case HealthProblem::non_finite_input:
      return "an input (load or tool) was not finite";
    case HealthProblem::non_finite_position:
      return "a node position became NaN or infinite";
    case HealthProblem::non_finite_velocity:
      return "a node velocity became NaN or infinite";
    case HealthProblem::runaway_speed:
      return "a node moved faster than the speed limit";
    case HealthProblem::runaway_energy:
      return "a node held more kinetic energy than was ever supplied";
    case HealthProblem::solver_failed:
      return "an implicit step did not converge";
    case HealthProblem::step_collapsed:
      return "the explicit step fell below a thousandth of the mesh's at rest (tissue drawn or "
             "crushed past what the step can follow)";
  }
  return "unknown";
}

HealthProblem check_health(const SimModel& model, const SimState& state,
                           const GuardOptions& options) {
  const double limit_sq = options.speed_limit_m_per_s * options.speed_limit_m_per_s;
  // Twice the kinetic energy a node may hold (1e-12 J above zero: round-off at rest). Gravity
  // supplies what its potential has fallen by since rest (energy.h's gravity_j, negated).
  double supplied = state.energy.initial_j + state.energy.tool_work_j;
  if (model.effects.gravity)
    supplied += std::max(0.0, -gravity_potential_energy_j(model, state.position_m));
  const double twice_allowed_j =
      2.0 * ((1.0 + options.kinetic_energy_slack) * std::max(supplied, 0.0) + 1e-12);
  const auto& x = state.position_m;
  const auto& v = state.velocity_m_per_s;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    // A sum is NaN if any term is NaN or infinities of opposite sign meet; check each.
    if (!std::isfinite(x.x[n]) || !std::isfinite(x.y[n]) || !std::isfinite(x.z[n]))
      return HealthProblem::non_finite_position;
    if (!std::isfinite(v.x[n]) || !std::isfinite(v.y[n]) || !std::isfinite(v.z[n]))
      return HealthProblem::non_finite_velocity;
    const double speed_sq = v.x[n] * v.x[n] + v.y[n] * v.y[n] + v.z[n] * v.z[n];
    if (speed_sq > limit_sq) return HealthProblem::runaway_speed;
    if (model.lumped_mass_kg[n] * speed_sq > twice_allowed_j) return HealthProblem::runaway_energy;
  }
  return HealthProblem::none;
}

bool inputs_finite(const StepInputs& inputs) {
  for (const PointLoad& load : inputs.point_loads)
    if (!load.force_n.allFinite()) return false;
  for (const NodeSpring& spring : inputs.springs)
    if (!spring.anchor_m.allFinite() || !std::isfinite(spring.stiffness_n_per_m) ||
        !std::isfinite(spring.damping_n_s_per_m))
      return false;
  return true;
}

StateCheckpoint make_checkpoint(const SimModel& model) {
  StateCheckpoint checkpoint;
  checkpoint.position_m.resize(model.node_count);
  checkpoint.velocity_m_per_s.resize(model.node_count);
  if (model.effects.viscous) checkpoint.viscous_history = ViscousHistory(model.tet_count);
  return checkpoint;
}

void save_checkpoint(const SimState& state, StateCheckpoint& checkpoint) {
  checkpoint.position_m = state.position_m;
  checkpoint.velocity_m_per_s = state.velocity_m_per_s;
  checkpoint.viscous_history = state.viscous_history;
  checkpoint.energy = state.energy;
  checkpoint.time_s = state.time_s;
  checkpoint.step_count = state.step_count;
  checkpoint.valid = true;
}

void restore_checkpoint(const StateCheckpoint& checkpoint, SimState& state) {
  state.position_m = checkpoint.position_m;
  state.velocity_m_per_s = checkpoint.velocity_m_per_s;
  state.viscous_history = checkpoint.viscous_history;
  state.energy = checkpoint.energy;
  state.time_s = checkpoint.time_s;
  state.step_count = checkpoint.step_count;
  // Restart: no step behind the restored velocity, no multistep history, no reused rates.
  state.last_step_s = 0.0;
  IntegratorScratch& s = state.integrator;
  s.has_previous = false;
  s.history_count = 0;
  s.first_rate_valid = false;
  s.error_pending = false;
  s.inputs_fingerprint = 0;
  s.chosen_step_s = 0.0;
  state.max_speed_m_per_s = detail::largest_norm(state.velocity_m_per_s);
}

GuardedReport guarded_advance(const SimModel& model, SimState& state, const StepInputs& inputs,
                              double interval_s, StateCheckpoint& checkpoint,
                              const GuardOptions& options) {
  GuardedReport report;
  // The checkpoint is the last good state (saved after every good advance, and here only if the
  // state was stepped or set elsewhere since and is still good): a state that went bad since (a
  // NaN written into it) goes back to it rather than being saved.
  const HealthProblem on_entry = check_health(model, state, options);
  const bool saved_already = checkpoint.valid && checkpoint.step_count == state.step_count &&
                             checkpoint.time_s == state.time_s;
  if (on_entry == HealthProblem::none || !checkpoint.valid) {
    if (!saved_already && (options.checkpoint_on_entry || !checkpoint.valid))
      save_checkpoint(state, checkpoint);
  } else {
    report.problem = on_entry;
    ++report.rollbacks;
    restore_checkpoint(checkpoint, state);
  }
  StepInputs effective = inputs;
  if (!inputs_finite(inputs)) {
    report.inputs_rejected = true;
    report.problem = HealthProblem::non_finite_input;
    effective = StepInputs{};  // step as if the tool let go, never with the bad values
  }
  double scale = checkpoint.step_scale;
  for (int attempt = 0; attempt <= options.max_retries; ++attempt) {
    state.integrator.step_scale = scale;
    const StepReport steps =
        advance(model, state, effective, interval_s, options.whole_step_s, options.give_up);
    // An unconverged implicit step is not a solution, however finite it looks.
    const HealthProblem problem = steps.unconverged_steps > 0 ? HealthProblem::solver_failed
                                  : steps.step_collapsed      ? HealthProblem::step_collapsed
                                                              : check_health(model, state, options);
    if (problem == HealthProblem::none) {
      // Newest good. After a rollback always: a caller saving seldom (the real-time loop, every 5
      // ms) would otherwise go back to the same old state at each failure and never get past it.
      if (options.checkpoint_after_advance || report.rollbacks > 0)
        save_checkpoint(state, checkpoint);
      report.steps = steps;
      report.step_scale = scale;
      checkpoint.step_scale = std::min(1.0, 2.0 * scale);
      if (options.check_energy) {
        report.energy = energy_balance(model, state, effective);
        report.energy_created = report.energy->created_beyond(options.energy_tolerance);
      }
      state.integrator.step_scale = 1.0;
      return report;
    }
    report.problem = problem;
    ++report.rollbacks;
    restore_checkpoint(checkpoint, state);
    scale *= 0.5;
  }
  state.integrator.step_scale = 1.0;
  checkpoint.step_scale = 1.0;  // what failed at every scale is not a reason to start small
  report.gave_up = true;
  return report;
}

}  // namespace liversim
