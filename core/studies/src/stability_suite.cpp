#include "liversim/studies/stability_suite.h"

#include "stability_cases.h"

#include <algorithm>
#include <array>
#include <exception>

namespace liversim {

bool StabilityRun::passed() const {
  return error.empty() &&
         std::all_of(checks.begin(), checks.end(), [](const auto& c) { return c.passed(); });
}

std::span<const StabilityCase> stability_cases() {
  using namespace detail;
  static const std::array cases{
      StabilityCase{1, "seed-recipe", "The seed's RK4 at Δt = 2 ms, ν = 0.49, on real livers",
                    seed_recipe_case},
      StabilityCase{2, "near-incompressible-compression", "ν = 0.499 under large compression",
                    near_incompressible_case},
      StabilityCase{3, "sliver-elements",
                    "Sliver and near-degenerate elements, and zero-volume elements in a file",
                    sliver_elements_case},
      StabilityCase{4, "pinch-inversion",
                    "Element inversion under a pinch between two tools; recovery after release",
                    pinch_inversion_case},
      StabilityCase{5, "stiff-lesion", "A lesion 100× stiffer than its surroundings",
                    stiff_lesion_case},
      StabilityCase{6, "stiffening-fibres", "Large stretch along strongly stiffening fibres",
                    stiffening_fibres_case},
      StabilityCase{
          7, "yield-cycles",
          "Viscoplastic flow (n < 1) from exactly the yield limit, then cycles through it",
          yield_cycles_case},
      StabilityCase{8, "force-step",
                    "The device's largest force (3.3 N) as a step on one node, held, released",
                    force_step_case},
      StabilityCase{9, "free-liver", "A free liver after a pull, for a long time", free_liver_case},
      StabilityCase{10, "floating-fragment", "A fragment with no fixed node under implicit steps",
                    floating_fragment_case},
      StabilityCase{11, "non-finite-injection", "A NaN or infinity injected into state and inputs",
                    non_finite_injection_case},
      StabilityCase{12, "parameter-sweep",
                    "Random valid parameter sets, seeded, over the documented ranges",
                    parameter_sweep_case},
  };
  return cases;
}

const StabilityCase* find_stability_case(std::string_view name) {
  for (const StabilityCase& c : stability_cases())
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<StabilityRun> run_stability_case(const StabilityCase& stability_case,
                                             const StabilitySuiteOptions& options) {
  try {
    return stability_case.run(options);
  } catch (const std::exception& error) {
    StabilityRun failed;
    failed.variant = "setup";
    failed.error = error.what();
    return {failed};
  }
}

}  // namespace liversim
