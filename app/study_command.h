#pragma once
// liversim-cli study accuracy: what accuracy costs in time (core/accuracy_study.h), written as
// CSV, PNG plots and a markdown report (docs/accuracy-study.md).

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `study` with its subcommand `accuracy` to the app. After parsing, the returned function
// runs the study and returns its exit code (nothing when `study` was not on the command line).
std::function<std::optional<int>()> add_study_command(CLI::App& app);

}  // namespace liversim::cli
