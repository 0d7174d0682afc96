#pragma once
// Explicit central-difference (leapfrog) time integration with lumped mass, mass-proportional
// damping and automatic substepping inside the stable step.

#include "liversim/core/forces.h"

namespace liversim {

struct StepReport {
  int substeps = 0;  // steps taken to cover the requested interval
  double smallest_substep_s = 0.0;
  double largest_substep_s = 0.0;
  double max_stiffening = 1.0;  // worst volumetric stiffening met (1 = as at rest)
};

// Stable explicit step for the model with these inputs: springs raise the highest frequency
// (Weyl: ω² ≤ ω²_max·s + max k/m, with s the stiffening of compressed elements and stretched
// fibres relative to rest, see stiffening_since_rest),
// damping lowers the limit to (2/ω)(√(1+ξ²) − ξ), ξ = α/(2ω).
double stable_time_step_s(const SimModel& model, const StepInputs& inputs, double stiffening = 1.0);

// Advances the state by exactly `interval_s` in central-difference steps, each within the stable
// step of the configuration it starts from (compression shortens it). Allocates nothing.
StepReport advance(const SimModel& model, SimState& state, const StepInputs& inputs,
                   double interval_s);

// One central-difference step of length dt_s (the caller guarantees stability). Returns what the
// force evaluation of the configuration the step started from saw.
ElasticEvaluation central_difference_step(const SimModel& model, SimState& state,
                                          const StepInputs& inputs, double dt_s);

// Largest eigenvalue of M⁻¹K (free nodes) at `position`, as an angular frequency, by power
// iteration on M^(-1/2) K M^(-1/2) with K·v from central differences of the elastic force.
double estimate_max_frequency_rad_per_s(const SimModel& model, const NodeArray& position,
                                        int iterations = 200);

}  // namespace liversim
