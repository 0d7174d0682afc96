#include "liversim/core/forces_variants.h"

#include <array>

// compute_internal_forces of each build of forces.cpp without an effect (core/CMakeLists.txt).
#define LIVERSIM_DECLARE_VARIANT(name)                                           \
  namespace liversim::name {                                                     \
  ElasticEvaluation compute_internal_forces(const SimModel&, SimState&, double); \
  }
LIVERSIM_DECLARE_VARIANT(forces_without_fibres)
LIVERSIM_DECLARE_VARIANT(forces_without_viscous)
LIVERSIM_DECLARE_VARIANT(forces_without_average_nodal_pressure)
LIVERSIM_DECLARE_VARIANT(forces_without_mooney_rivlin)
#undef LIVERSIM_DECLARE_VARIANT

namespace liversim {

std::span<const ForcesVariant> forces_variants() {
  static constexpr std::array<ForcesVariant, 4> variants{{
      {"fibres", kWithoutFibres, forces_without_fibres::compute_internal_forces},
      {"viscous tissue", kWithoutViscous, forces_without_viscous::compute_internal_forces},
      {"average nodal pressure", kWithoutAverageNodalPressure,
       forces_without_average_nodal_pressure::compute_internal_forces},
      {"Mooney–Rivlin term", kWithoutMooneyRivlin,
       forces_without_mooney_rivlin::compute_internal_forces},
  }};
  return variants;
}

}  // namespace liversim
