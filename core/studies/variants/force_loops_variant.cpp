// The engine's force loops built without one effect (LIVERSIM_FORCES_VARIANT,
// LIVERSIM_FORCES_WITHOUT: core/studies/CMakeLists.txt), for the benchmark (forces_variants.h).
#include "force_loops.h"
