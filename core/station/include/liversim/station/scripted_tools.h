#pragma once
// The tools a scripted trajectory puts in the hand (its tool column, emulated_devices.h), played on
// the servo clock as the Tool panel would change them: `liversim-cli record` and the live cutting
// bench both play a script through it, so that one script can cut with the scalpel and then lift
// the specimen out with the forceps.

#include "liversim/haptics/emulated_devices.h"
#include "liversim/interaction/tools.h"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace liversim {

class Workstation;

class ScriptedTools {
 public:
  // `held`: what the hand holds until the script's first change (none: the hand). Throws
  // std::invalid_argument naming the change (its time) when a tool is unknown or not in
  // `allowed` (empty: any tool).
  ScriptedTools(std::optional<ToolKind> held, std::vector<TrajectoryToolChange> changes,
                const std::vector<ToolKind>& allowed = {});

  // What the hand holds now (none: the hand).
  std::optional<ToolKind> held() const { return held_; }
  // At `elapsed_s` of the script: takes the changes due and, if the tool changed, tells the
  // station (device_tool_changed from servo time `now_s`, and a tool_selected event). True when it
  // changed. Changes at time 0 or before are taken by the constructor.
  bool advance(double elapsed_s, double now_s, Workstation& station);

 private:
  std::optional<ToolKind> held_;
  std::vector<std::pair<double, std::optional<ToolKind>>> changes_;
  std::size_t next_ = 0;
};

}  // namespace liversim
