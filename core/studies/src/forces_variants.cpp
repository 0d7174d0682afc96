#include "liversim/studies/forces_variants.h"

#include "force_loop_bits.h"  // core/engine/src

#include <array>

static_assert(liversim::kWithoutFibres == liversim::force_loop_bits::fibres &&
              liversim::kWithoutViscous == liversim::force_loop_bits::viscous &&
              liversim::kWithoutAverageNodalPressure ==
                  liversim::force_loop_bits::average_nodal_pressure &&
              liversim::kWithoutMooneyRivlin == liversim::force_loop_bits::mooney_rivlin &&
              liversim::kWithoutGravity == liversim::force_loop_bits::gravity);

// compute_tissue_forces of each build of the force loops without an effect
// (core/studies/CMakeLists.txt).
#define LIVERSIM_DECLARE_VARIANT(name)                                         \
  namespace liversim::name {                                                   \
  ElasticEvaluation compute_tissue_forces(const SimModel&, SimState&, double); \
  }
LIVERSIM_DECLARE_VARIANT(forces_without_fibres)
LIVERSIM_DECLARE_VARIANT(forces_without_viscous)
LIVERSIM_DECLARE_VARIANT(forces_without_average_nodal_pressure)
LIVERSIM_DECLARE_VARIANT(forces_without_mooney_rivlin)
LIVERSIM_DECLARE_VARIANT(forces_without_gravity)
#undef LIVERSIM_DECLARE_VARIANT

namespace liversim {

std::span<const ForcesVariant> forces_variants() {
  static constexpr std::array<ForcesVariant, 5> variants{{
      {"fibres", kWithoutFibres, forces_without_fibres::compute_tissue_forces},
      {"viscous tissue", kWithoutViscous, forces_without_viscous::compute_tissue_forces},
      {"average nodal pressure", kWithoutAverageNodalPressure,
       forces_without_average_nodal_pressure::compute_tissue_forces},
      {"Mooney–Rivlin term", kWithoutMooneyRivlin,
       forces_without_mooney_rivlin::compute_tissue_forces},
      {"gravity", kWithoutGravity, forces_without_gravity::compute_tissue_forces},
  }};
  return variants;
}

}  // namespace liversim
