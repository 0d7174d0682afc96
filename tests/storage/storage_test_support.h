#pragma once
// What the storage tests share: fresh database paths, frames that cannot read back right by
// accident, and their exact comparison.

#include "liversim/haptics/servo_loop.h"
#include "synthetic_frames.h"

#include <gtest/gtest.h>

#include <filesystem>
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

inline void expect_same_frames(const std::vector<ServoFrame>& read,
                               const std::vector<ServoFrame>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    ASSERT_EQ(read[i].time_s, written[i].time_s) << "frame " << i;
    ASSERT_EQ(read[i].sample.position_mm, written[i].sample.position_mm) << "frame " << i;
    ASSERT_EQ(read[i].sample.velocity_mm_per_s, written[i].sample.velocity_mm_per_s) << i;
    ASSERT_EQ(read[i].force_n, written[i].force_n) << "frame " << i;
    ASSERT_EQ(read[i].sample.buttons, written[i].sample.buttons) << "frame " << i;
    ASSERT_EQ(read[i].sample.orientation.has_value(), written[i].sample.orientation.has_value())
        << "frame " << i;
    if (read[i].sample.orientation) {
      ASSERT_EQ(read[i].sample.orientation->coeffs(), written[i].sample.orientation->coeffs())
          << "frame " << i;
    }
  }
}

}  // namespace liversim::testing
