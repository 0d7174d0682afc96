#pragma once
// Servo frames for storage tests and benches.

#include "liversim/haptics/servo_loop.h"

#include <cstdint>
#include <random>
#include <vector>

namespace liversim::testing {

// Frames of a 1 kHz servo with every field distinct, not round numbers: an exact read-back
// cannot pass by accident.
inline std::vector<ServoFrame> synthetic_frames(std::size_t count, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> value(-50.0, 50.0);
  std::vector<ServoFrame> frames(count);
  for (std::size_t i = 0; i < count; ++i) {
    ServoFrame& f = frames[i];
    f.time_s = 1e-3 * static_cast<double>(i) + 1e-7 * value(random);
    f.sample.position_mm = {value(random), value(random), value(random)};
    f.sample.velocity_mm_per_s = {value(random), value(random), value(random)};
    f.force_n = {0.01 * value(random), 0.01 * value(random), 0.01 * value(random)};
    f.sample.buttons = static_cast<std::uint32_t>(random() & 3u);
  }
  return frames;
}

}  // namespace liversim::testing
