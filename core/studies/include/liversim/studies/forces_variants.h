#pragma once
// Builds of the engine's force loops (core/engine/src/force_loops.h) that do not contain one
// effect at all, for the benchmark: what an effect costs when a scene leaves it off is the time of
// the engine's build against the build without it, on the same scene. The engine's own build
// knows nothing of them.

#include "liversim/engine/forces.h"
#include "liversim/engine/model.h"
#include "liversim/engine/state.h"

#include <span>

namespace liversim {

// Bits of LIVERSIM_FORCES_WITHOUT.
inline constexpr unsigned kWithoutFibres = 1;
inline constexpr unsigned kWithoutViscous = 2;
inline constexpr unsigned kWithoutAverageNodalPressure = 4;
inline constexpr unsigned kWithoutMooneyRivlin = 8;
inline constexpr unsigned kWithoutGravity = 16;

struct ForcesVariant {
  const char* effect;  // the effect the build leaves out
  unsigned without;    // its bit
  // compute_tissue_forces of that build; throws std::invalid_argument for a model with the
  // effect on.
  InternalForcesFunction compute_tissue_forces;
};

// One build per effect, each without that effect.
std::span<const ForcesVariant> forces_variants();

}  // namespace liversim
