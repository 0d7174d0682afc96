#pragma once
// liversim-cli study stability: runs the stability suite (core/stability_suite.h) and writes its
// report (docs/stability-report.md).

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `stability` under the `study` subcommand. After parsing, the returned function runs the
// suite and returns its exit code (1 when a check failed; nothing when it was not asked for).
std::function<std::optional<int>()> add_stability_study(CLI::App& study);

}  // namespace liversim::cli
