#pragma once
// What the storage tests share: fresh database paths, frames that cannot read back right by
// accident, and their exact comparison.

#include "liversim/core/servo_loop.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace liversim::testing {

namespace fs = std::filesystem;

// A fresh path in the test output directory (the file and its WAL side files removed).
inline fs::path fresh_database(const std::string& name, const std::string& folder = "storage") {
  const fs::path file = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / folder / (name + ".sqlite");
  fs::create_directories(file.parent_path());
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file.string() + suffix);
  return file;
}

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

inline void expect_same_frames(const std::vector<ServoFrame>& read,
                               const std::vector<ServoFrame>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    ASSERT_EQ(read[i].time_s, written[i].time_s) << "frame " << i;
    ASSERT_EQ(read[i].sample.position_mm, written[i].sample.position_mm) << "frame " << i;
    ASSERT_EQ(read[i].sample.velocity_mm_per_s, written[i].sample.velocity_mm_per_s) << i;
    ASSERT_EQ(read[i].force_n, written[i].force_n) << "frame " << i;
    ASSERT_EQ(read[i].sample.buttons, written[i].sample.buttons) << "frame " << i;
  }
}

}  // namespace liversim::testing
