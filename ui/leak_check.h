// Leak checking of the Qt programs under AddressSanitizer (the asan preset, docs/sanitizers.md).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

namespace liversim {

// Looks for leaks now, while the display is still open, instead of at exit: closing the display
// unloads the GL driver, whose own leaks could then be neither named nor suppressed. Call it
// after the event loop, before the QApplication goes. Does nothing without AddressSanitizer.
inline void checkLeaksWhileTheDisplayIsOpen() {
#if defined(__SANITIZE_ADDRESS__)
  __lsan_do_leak_check();
#endif
}

}  // namespace liversim
