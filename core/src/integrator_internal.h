#pragma once
// Pieces shared by the integrators (integrator.cpp, runge_kutta.cpp, implicit_integrator.cpp).

#include "liversim/core/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace liversim::detail {

// A hash of the inputs' values: advance() compares it with the last call's to see a change.
std::uint64_t fingerprint(const StepInputs& inputs);

// Sizes the scratch of the model's integrator (allocation happens here, never while stepping).
void prepare_integrator_scratch(const SimModel& model, IntegratorScratch& scratch);

// Adds the external forces of `inputs` at `position` to `force` and the springs' damping force
// at `velocity`.
void add_input_forces(const StepInputs& inputs, const NodeArray& position,
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

// The node-travel limit of explicit steps, 0.1·h_min over the speed envelope: the fastest node
// speed, decaying by 2 % per step. A limit that followed the speed itself would change the step
// in step with an oscillation and pump it (parametric resonance of variable-step leapfrog: a free
// liver rang on at 1 m/s instead of coming to rest); the envelope varies slowly.
inline double travel_limit_s(const SimModel& model, IntegratorScratch& scratch, double speed) {
  scratch.speed_envelope_m_per_s = std::max(speed, 0.98 * scratch.speed_envelope_m_per_s);
  return scratch.speed_envelope_m_per_s > 0.0
             ? 0.1 * model.min_element_height_m / scratch.speed_envelope_m_per_s
             : std::numeric_limits<double>::infinity();
}

// The stability limit may fall at once but rises by at most 2 % per step: a limit that followed
// the compression (or speed) of an oscillating mode would change the step in step with it and
// pump it, as above. The smoothing is of the limit itself, so a shorter requested or adaptive step
// is not affected.
inline double smoothed_limit_s(IntegratorScratch& scratch, double limit_s) {
  if (scratch.smoothed_limit_s > 0.0) limit_s = std::min(limit_s, 1.02 * scratch.smoothed_limit_s);
  scratch.smoothed_limit_s = limit_s;
  return limit_s;
}

// Number of equal steps of at most `step_s` that cover `interval_s` (a step within 1e-9 of a
// divisor counts as one).
inline double steps_to_cover(double interval_s, double step_s) {
  return std::max(1.0, std::ceil(interval_s / step_s * (1.0 - 1e-9)));
}

}  // namespace liversim::detail
