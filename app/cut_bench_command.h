#pragma once
// liversim-cli bench-cut: the cost of a scalpel stroke's updates on the built-in liver (cut, the
// surface re-extracted, the contact hierarchy rebuilt), written to docs/cutting-performance.md.

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `bench-cut` to the app. After parsing, the returned function runs the benchmark and
// returns the exit code (nothing when `bench-cut` was not on the command line).
std::function<std::optional<int>()> add_cut_bench_command(CLI::App& app);

}  // namespace liversim::cli
