#pragma once
// liversim-cli bench-servo: the 1 kHz haptic servo's rate and tick jitter, alone and with the
// real-time simulation of the liver loading both cores, written to docs/haptics-servo.md.

#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `bench-servo` to the app. After parsing, the returned function runs the benchmark and
// returns the exit code (nothing when `bench-servo` was not on the command line).
std::function<std::optional<int>()> add_servo_bench_command(CLI::App& app);

}  // namespace liversim::cli
