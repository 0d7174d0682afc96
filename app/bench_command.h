#pragma once
// liversim-cli bench: the engine's speed and memory (core/performance.h), the seed's Table 1 beside
// our deformation time, and the workstation's peak resident memory, written to
// docs/performance.md.

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `bench` to the app. After parsing, the returned function runs the benchmarks and returns
// the exit code (nothing when `bench` was not on the command line).
std::function<std::optional<int>()> add_bench_command(CLI::App& app);

}  // namespace liversim::cli
