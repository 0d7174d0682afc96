#pragma once
// Pieces shared by the integrators (integrator.cpp, runge_kutta.cpp, implicit_integrator.cpp).

#include "liversim/engine/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace liversim::detail {

// A hash of the inputs' values: advance() compares it with the last call's to see a change.
std::uint64_t fingerprint(const StepInputs& inputs);

// Sizes the scratch of the model's integrator (allocation happens here, never while stepping).
void prepare_integrator_scratch(const SimModel& model, IntegratorScratch& scratch);

// Adds the external forces of `inputs` at `position` to `force`, the model's gravity, and the
// springs' damping force at `velocity`.
void add_input_forces(const SimModel& model, const StepInputs& inputs, const NodeArray& position,
                      const NodeArray& velocity, NodeArray& force);

// Acceleration of each node from the total force and the velocity (mass-proportional damping
// taken explicitly); zero on fixed nodes.
void acceleration_from_force(const SimModel& model, const NodeArray& force,
                             const NodeArray& velocity, NodeArray& acceleration);

// Q = S_e − H of every viscous element's committed state, into `arm`.
void arm_of_committed_state(const SimModel& model, const SimState& state, std::vector<Voigt6>& arm);

// Commits the Maxwell arm `arm` at `position` (H = S_e − Q) and applies the viscoplastic flow of
// a step of dt_s after it.
void commit_arm(const SimModel& model, SimState& state, const NodeArray& position,
                const std::vector<Voigt6>& arm, double dt_s);

// Largest explicit step of `kind` for the model with these inputs and stiffening, before the
// node-travel limit: the stability interval on the imaginary axis for the oscillations and,
// except for central difference (whose damping is implicit), the real-axis limit for damping.
double explicit_step_limit_s(const SimModel& model, const StepInputs& inputs, double stiffening,
                             IntegratorKind kind);

// Local error indicator of a fixed-step scheme of order p from the last p + 1 end-of-step
// velocities: C·Δt·|Δᵖ⁺¹…| (see integrator.cpp), NaN while the history is too short or the step
// changed. Then pushes `velocity` into the history.
double history_error_estimate(const SimModel& model, IntegratorScratch& scratch,
                              const NodeArray& velocity, double dt_s, IntegratorKind kind);

// Scheme-specific advances over `interval_s`, adding to `report`.
void advance_runge_kutta(const SimModel& model, SimState& state, const StepInputs& inputs,
                         double interval_s, StepReport& report);
void advance_implicit(const SimModel& model, SimState& state, const StepInputs& inputs,
                      double interval_s, StepReport& report);

void prepare_implicit_solver(const SimModel& model, ImplicitSolverHandle& handle);

// Keeps the largest error estimate of the steps (NaN: the step gave none).
inline void note_error_estimate(StepReport& report, double estimate_m) {
  if (std::isnan(estimate_m)) return;
  if (std::isnan(report.error_estimate_m) || estimate_m > report.error_estimate_m)
    report.error_estimate_m = estimate_m;
}

// Largest Euclidean norm of the per-node vectors (e.g. the fastest node's speed).
inline double largest_norm(const NodeArray& a) {
  double largest_sq = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n)
    largest_sq = std::max(largest_sq, a.x[n] * a.x[n] + a.y[n] * a.y[n] + a.z[n] * a.z[n]);
  return std::sqrt(largest_sq);
}

// Explicit fixed-step schemes let the chosen step fall at once but grow by at most this factor per
// step (0.1 %: a dip recovers by 2× in ≈ 700 steps). A step that followed the compression or
// speed of an oscillating mode (through the stiffening or node-travel limits) changed in step with
// it and pumped it — parametric resonance of variable-step leapfrog, whose threshold is of the
// order of the modal damping ratio (α/2ω ≈ 0.1 % for the stiffest modes): a free liver rang on at
// 1 m/s instead of coming to rest. 2 % per step was not slow enough.
inline constexpr double kStepGrowth = 1.001;

// Number of equal steps of at most `step_s` that cover `interval_s` (a step within 1e-9 of a
// divisor counts as one).
inline double steps_to_cover(double interval_s, double step_s) {
  return std::max(1.0, std::ceil(interval_s / step_s * (1.0 - 1e-9)));
}

}  // namespace liversim::detail
