#pragma once
// liversim-cli record: a session recorded headless as the workstation records one. A scripted
// trajectory device drives the tool through the 1 kHz haptic servo on a scenario's scene (or free
// practice on the built-in liver) for a set wall time; frames, events, the simulation's input log
// and, at the end, the servo's figures and the metrics go to a sessions database. For unattended
// soaks (memory, rate), demonstrations and the crash-safety tests.

#include "liversim/station/scripted_tools.h"
#include "liversim/station/workstation.h"

#include <Eigen/Geometry>

#include <filesystem>
#include <functional>
#include <optional>

namespace CLI {
class App;
}

namespace liversim::cli {

// Adds `record` to the app. After parsing, the returned function runs it and returns the exit
// code (nothing when `record` was not on the command line): 0 for a session recorded to its end
// or ended by SIGINT or SIGTERM, 1 when storage failed (what was committed stays), 2 for bad input.
std::function<std::optional<int>()> add_record_command(CLI::App& app);

// The scenario a headless run plays (none: free practice), read as the workstation reads one.
// Throws std::runtime_error naming the file and each of its errors.
std::optional<OpenedScenario> open_scenario_to_run(
    const std::optional<std::filesystem::path>& file);

// What a scripted hand holds now (none: nothing), held as the workstation holds a device's tool in
// its opening view (`view_axes`: opening_view_device_axes).
std::optional<DeviceToolSettings> scripted_tool_held(const std::optional<ScriptedTools>& hand,
                                                     const Eigen::Quaterniond& view_axes);

}  // namespace liversim::cli
