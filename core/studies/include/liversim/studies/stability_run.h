#pragma once
// What a case of the stability suite (stability_suite.h) returns and is run with: one run per
// integrator it tries, with what it measured and the checks it makes.

#include "liversim/engine/health.h"

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace liversim {

struct StabilityCheck {
  std::string what;  // e.g. "energy created / energy supplied"
  double value = 0.0;
  double limit = 0.0;
  bool at_most = true;  // passes when value ≤ limit (false: when value ≥ limit)
  bool passed() const { return at_most ? value <= limit : value >= limit; }  // NaN fails
};

// One case under one integrator (or one variant of a case).
struct StabilityRun {
  std::string variant;     // what distinguishes this run within its case, e.g. "backward-euler"
  std::string integrator;  // integrator_name of the model's scheme
  double simulated_s = 0.0;
  int intervals = 0;  // guarded advances
  StepReport steps;   // accumulated over the run
  int rollbacks = 0;
  int rejected_inputs = 0;
  bool gave_up = false;      // a guarded advance gave up (the state is its last good one)
  std::string last_problem;  // health_problem_text of the last problem the guard met (if any)
  double gave_up_at_s = 0.0;
  double max_displacement_m = 0.0;
  // Largest energy created over the run, as a fraction of the energy supplied at that moment
  // (energy books, energy.h; ≤ 0: the books show only dissipation).
  double energy_error = 0.0;
  double energy_supplied_j = 0.0;     // at the end of the run
  double energy_held_j = 0.0;         // at the end of the run
  double viscous_dissipated_j = 0.0;  // by the Maxwell arms' dashpots, over the run
  double wall_time_s = 0.0;           // measured, for the report only
  std::vector<StabilityCheck> checks;
  std::string error;  // an exception the run threw (the run failed)
  bool passed() const;
};

struct StabilitySuiteOptions {
  // ../shared/data: cases on external meshes (the Zhang liver) are run only when it is given.
  std::filesystem::path shared_data_dir;
  double long_run_s = 600.0;  // case 9's free run after the pull
  unsigned sweep_seed = 20261121;
  int sweep_samples = 24;  // case 12
};

}  // namespace liversim
