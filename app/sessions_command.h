#pragma once
// liversim-cli sessions: what a sessions database holds (list), and one session's frames and
// events as CSV (export), for instructors and for scripts.

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `sessions` to the app. After parsing, the returned function runs it and returns the exit
// code (nothing when `sessions` was not on the command line).
std::function<std::optional<int>()> add_sessions_command(CLI::App& app);

}  // namespace liversim::cli
