#pragma once
// The stability suite: named hard cases (issue 5), each run through the guards with the energy
// books kept. A case returns one run per integrator it tries, with what the run measured and the
// checks it makes (a value against a limit derived from the case's mathematics). The tests assert
// the checks; `liversim-cli study stability` writes them to docs/stability-report.md.

#include "liversim/core/health.h"

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
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

struct StabilityCase {
  int number;             // in issue 5's list (1–12); later additions continue it
  std::string_view name;  // e.g. "near-incompressible-compression" (the CLI's --case)
  std::string_view title;
  std::function<std::vector<StabilityRun>(const StabilitySuiteOptions&)> run;
};

// Every case of the suite, in number order.
std::span<const StabilityCase> stability_cases();
const StabilityCase* find_stability_case(std::string_view name);

// Runs one case; a run that throws is reported with its error, never propagated.
std::vector<StabilityRun> run_stability_case(const StabilityCase& stability_case,
                                             const StabilitySuiteOptions& options);

}  // namespace liversim
