#pragma once
// liversim-cli bench-cut --live: a scalpel stroke scripted through the workstation's own real-time
// loop (the station, the 1 kHz servo, the recorder), timed second by second as a user meets it:
// the real-time factor, the smallest step and what limited it, and every cut update of the run.

#include <filesystem>
#include <optional>
#include <string>

namespace liversim::cli {

struct LiveCutBenchOptions {
  std::optional<std::filesystem::path> scenario;  // none: free practice on the built-in liver
  int tets = 5406;
  std::filesystem::path trajectory;  // the scripted device's, in device millimetres
  // A second scripted device in the left hand (forceps holding the lobe while the scalpel cuts),
  // in the same device frame, and what it holds until its tool column says otherwise.
  std::optional<std::filesystem::path> left_trajectory;
  std::string left_tool = "hand";
  std::filesystem::path output_dir = "docs";
};

// Runs it and writes cutting-live.md into the output folder; the exit code.
int run_live_cut_bench(const LiveCutBenchOptions& options);

}  // namespace liversim::cli
