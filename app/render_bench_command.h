#pragma once
// liversim-cli render-bench: the frame rate of the liver's picture as the workstation draws it
// (the surface moved every frame), solid and seen through, with and without ambient occlusion,
// written to docs/rendering-performance.md.

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `render-bench` to the app. After parsing, the returned function runs the benchmark and
// returns the exit code (nothing when `render-bench` was not on the command line).
std::function<std::optional<int>()> add_render_bench_command(CLI::App& app);

}  // namespace liversim::cli
