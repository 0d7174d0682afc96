// How long a GUI test waits for something before it calls it hung. Waits are no measure of
// speed: the limits only have to outlast the slowest build they run in.
#pragma once

namespace liversim::test {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
// AddressSanitizer's checked memory and llvmpipe's instrumented neighbours run the GUI several
// times slower (a replay's seek to the end of a cut: 20 s in Release, over 90 s under ASan).
inline constexpr int kSanitizerSlowdown = 4;
#else
inline constexpr int kSanitizerSlowdown = 1;
#endif

constexpr int waitLimitMs(int release_limit_ms) {
  return release_limit_ms * kSanitizerSlowdown;
}

}  // namespace liversim::test
