#pragma once
// Time integration of the liver: one interface over several schemes, chosen per scenario
// (SimModel::integrator). Explicit schemes substep inside their stability limit, so none of them
// blows up; implicit schemes solve each step with Newton's method and a sparse Cholesky
// factorisation of a fixed pattern. See docs/integrators.md.

#include "liversim/engine/forces.h"

#include <array>
#include <atomic>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace liversim {

// The time integrators of the engine. IntegratorKind and IntegratorSettings live in model.h
// (a scenario picks them when the model is built); these are the facts about each scheme.
inline constexpr std::array kAllIntegrators{IntegratorKind::central_difference, IntegratorKind::rk4,
                                            IntegratorKind::dopri5, IntegratorKind::backward_euler,
                                            IntegratorKind::bdf2};

// "central-difference", "rk4", "dopri5", "backward-euler", "bdf2".
std::string_view integrator_name(IntegratorKind kind);
std::optional<IntegratorKind> integrator_from_name(std::string_view name);
// Global order of accuracy in the step: 2, 4, 5, 1, 2.
int integrator_order(IntegratorKind kind);
bool is_explicit(IntegratorKind kind);
// Largest ω·Δt for which an undamped oscillator of angular frequency ω stays bounded (the
// scheme's stability interval on the imaginary axis): central difference 2, RK4 2√2, Dormand–
// Prince 5 ≈ 0.997 (its region leaves the imaginary axis early). Infinite for implicit schemes.
double stability_interval(IntegratorKind kind);

// What advancing the state cost and what the integrator had to do.
struct StepReport {
  int substeps = 0;  // accepted steps taken to cover the requested interval
  double smallest_substep_s = 0.0;
  double largest_substep_s = 0.0;
  double max_stiffening = 1.0;  // worst stiffening met (1 = as at rest), explicit schemes
  // Of which (explicit schemes): the smallest element volume ratio J met (compression stiffens
  // the volumetric law as J falls; below 0 an element is inverted) and the largest stiffening a
  // viscoplastic flow had given an element (at most kMaxFlowStiffening).
  double least_volume_ratio = 1.0;
  double max_flow_stiffening = 1.0;
  // Explicit schemes: steps shorter than the requested one because the stability limit (or the
  // node-travel limit) required it, and the smallest such limit met.
  int stability_limited_steps = 0;
  double smallest_stable_step_s = 0.0;  // 0 when no step was limited
  // Central difference: what made the limits met, each the smallest of the interval (infinite
  // when it never applied): the mesh alone with the stiffening its elements reached (without the
  // springs of tools and hands), and the node-travel limit (no node moves more than a tenth of the
  // smallest element height in a step). The limit met is the smaller of the travel limit and the
  // mesh's limit lowered by the springs (stable_time_step_s), so these say which set it.
  double smallest_mesh_limit_s = std::numeric_limits<double>::infinity();
  double smallest_travel_limit_s = std::numeric_limits<double>::infinity();
  // The mesh's limit lowered by the springs (stable_time_step_s with the inputs), the smallest of
  // the interval, whether or not it limited a step.
  double smallest_spring_limit_s = std::numeric_limits<double>::infinity();
  int rejected_steps = 0;      // dopri5: steps redone because the error was too large
  int force_evaluations = 0;   // internal-force evaluations of the whole mesh
  bool gave_up_early = false;  // advance's give_up ended the interval before its end
  // Central difference: the interval ended early because the step it could take had fallen below
  // kCollapsedStepFraction of the model's stable step at rest (see there).
  bool step_collapsed = false;
  int newton_iterations = 0;  // implicit schemes
  int linear_solves = 0;
  int factorizations = 0;
  int unconverged_steps = 0;  // implicit steps whose Newton iteration hit its limit
  // Largest local error estimate (m, node positions) of the steps taken: embedded pairs for RK4
  // (3rd-order FSAL companion) and dopri5, a backward difference of the velocity with the
  // scheme's error constant for the others. NaN when no step gave an estimate (a changed step).
  double error_estimate_m = 0.0;
};

// Adds `part` (a later interval) to `total`.
void accumulate(StepReport& total, const StepReport& part);

// Stable central-difference step for the model with these inputs: springs raise the highest
// frequency (Weyl: ω² ≤ ω²_max·s + max k/m, with s the stiffening of compressed elements and
// stretched fibres relative to rest, see stiffening_since_rest), damping lowers the limit to
// (2/ω)(√(1+ξ²) − ξ), ξ = α/(2ω). Multiplied by model.stable_step_safety.
double stable_time_step_s(const SimModel& model, const StepInputs& inputs, double stiffening = 1.0);

// The highest angular frequency of the model with these inputs and stiffening (see above).
double max_frequency_rad_per_s(const SimModel& model, const StepInputs& inputs,
                               double stiffening = 1.0);

// Stiffening relative to rest of what a force evaluation saw (compression, stretched fibres).
double stiffening_since_rest(const SimModel& model, const ElasticEvaluation& seen);

// Below this fraction of the model's stable step at rest (a stiffening of a million, or a node
// fast enough to cross a tenth of the smallest element within it), central difference ends the
// interval where it is (StepReport::step_collapsed) rather than go on: a real-time cycle's 0.43 ms
// would take a thousand force evaluations or more, and nothing else bounds an interval's work (a
// paced run lifting a specimen under gravity stood still for ten minutes, issue 42). The guard
// takes it as a problem (health.h).
inline constexpr double kCollapsedStepFraction = 1e-3;

// Advances the state by exactly `interval_s` with the model's integrator, in steps of
// model.integrator.step_s (0: the stable step of explicit schemes), shortened where an explicit
// scheme's stability limit requires it, and equalised so that the interval ends exactly. Allocates
// nothing.
//
// whole_step_s > 0 (central difference; the other schemes ignore it): steps of at most
// whole_step_s, each as long as the limits allow, the last not shortened, so the state ends at or
// past the interval's end by less than one step. A real-time loop stepping at a fixed pace asks
// for this: with each of its intervals covered exactly, a limit a little under its step split
// every interval in two, twice the force evaluations for a limit 1 % short (the state's time
// then carries the difference to the next interval).
//
// `give_up` set (central difference): the interval ends early, where the step under way ends, once
// it reads true (StepReport::gave_up_early): a loop asked to stop is not held for the rest of an
// interval whose steps have fallen to microseconds. It also ends early, with step_collapsed, where
// its step falls below kCollapsedStepFraction of model.stable_time_step_s.
StepReport advance(const SimModel& model, SimState& state, const StepInputs& inputs,
                   double interval_s, double whole_step_s = 0.0,
                   const std::atomic<bool>* give_up = nullptr);

// One central-difference step of length dt_s (the caller guarantees stability). Returns what the
// force evaluation of the configuration the step started from saw.
ElasticEvaluation central_difference_step(const SimModel& model, SimState& state,
                                          const StepInputs& inputs, double dt_s);

// Largest eigenvalue of M⁻¹K (free nodes) at `position`, as an angular frequency, by power
// iteration on M^(-1/2) K M^(-1/2) with K·v from central differences of the elastic force.
double estimate_max_frequency_rad_per_s(const SimModel& model, const NodeArray& position,
                                        int iterations = 200);

}  // namespace liversim
