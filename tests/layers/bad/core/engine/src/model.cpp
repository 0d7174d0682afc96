// A source of the engine that includes a header of a layer above it: check_layers.py names it.
#include "liversim/sessions/session_store.h"
