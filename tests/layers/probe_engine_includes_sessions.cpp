// Compiled against the engine alone (tests/layers/CMakeLists.txt): an include of a higher layer's
// header must not compile, since the engine does not link that layer.
#include "liversim/sessions/session_store.h"
