#pragma once
// The stability suite: named hard cases (issue 5), each run through the guards with the energy
// books kept. A case returns one run per integrator it tries, with what the run measured and the
// checks it makes (a value against a limit derived from the case's mathematics). The tests assert
// the checks; `liversim-cli study stability` writes them to docs/stability-report.md.

#include "liversim/studies/stability_run.h"

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

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
