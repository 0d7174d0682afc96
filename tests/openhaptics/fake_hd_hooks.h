#pragma once
// The fake OpenHaptics runtime's test hooks (fake_hd.cpp), looked up in the library the driver
// loaded from LIVERSIM_FAKE_HD_LIBRARY (null before it is loaded).

#include <dlfcn.h>

namespace liversim::test {

template <class Function>
Function fakeHook(const char* name) {
  void* library = dlopen(LIVERSIM_FAKE_HD_LIBRARY, RTLD_NOW | RTLD_NOLOAD);
  if (library == nullptr) return nullptr;
  auto function = reinterpret_cast<Function>(dlsym(library, name));
  dlclose(library);  // still loaded: the driver never unloads it
  return function;
}

}  // namespace liversim::test
