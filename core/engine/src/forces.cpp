// The engine's force loops, with every effect (force_loops.h).
#include "liversim/engine/forces.h"

#include "force_loops.h"
