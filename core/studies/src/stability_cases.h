#pragma once
// The cases of the stability suite, one function each (registered in stability_suite.cpp).

#include "liversim/studies/stability_run.h"

namespace liversim::detail {

std::vector<StabilityRun> seed_recipe_case(const StabilitySuiteOptions& options);           // 1
std::vector<StabilityRun> near_incompressible_case(const StabilitySuiteOptions& options);   // 2
std::vector<StabilityRun> sliver_elements_case(const StabilitySuiteOptions& options);       // 3
std::vector<StabilityRun> pinch_inversion_case(const StabilitySuiteOptions& options);       // 4
std::vector<StabilityRun> stiff_lesion_case(const StabilitySuiteOptions& options);          // 5
std::vector<StabilityRun> stiffening_fibres_case(const StabilitySuiteOptions& options);     // 6
std::vector<StabilityRun> yield_cycles_case(const StabilitySuiteOptions& options);          // 7
std::vector<StabilityRun> force_step_case(const StabilitySuiteOptions& options);            // 8
std::vector<StabilityRun> free_liver_case(const StabilitySuiteOptions& options);            // 9
std::vector<StabilityRun> floating_fragment_case(const StabilitySuiteOptions& options);     // 10
std::vector<StabilityRun> non_finite_injection_case(const StabilitySuiteOptions& options);  // 11
std::vector<StabilityRun> parameter_sweep_case(const StabilitySuiteOptions& options);       // 12

}  // namespace liversim::detail
