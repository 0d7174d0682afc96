#pragma once
// liversim-cli bench-cut --live: a scalpel stroke scripted through the workstation's own real-time
// loop (the station, the 1 kHz servo, the recorder), timed second by second as a user meets it:
// the real-time factor, the smallest step and what limited it, and every cut update of the run.

#include <filesystem>
#include <optional>

namespace liversim::cli {

struct LiveCutBenchOptions {
  std::optional<std::filesystem::path> scenario;  // none: free practice on the built-in liver
  int tets = 5406;
  std::filesystem::path trajectory;  // the scripted device's, in device millimetres
  std::filesystem::path output_dir = "docs";
};

// Runs it and writes cutting-live.md into the output folder; the exit code.
int run_live_cut_bench(const LiveCutBenchOptions& options);

}  // namespace liversim::cli
