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

// The tools a scenario allows the hand, and the scenario's name for messages.
struct AllowedTools {
  std::vector<ToolKind> tools;
  std::string scenario;
};
// The tool `name` names for the hand (hand, probe, forceps, scalpel; none: the hand), checked
// against the tools a scenario allows (none: any). Throws std::invalid_argument beginning with
// `what` (where the name was given) and saying what is expected.
std::optional<ToolKind> tool_for_the_hand(const std::string& name,
                                          const std::optional<AllowedTools>& allowed,
                                          const std::string& what);

class ScriptedTools {
 public:
  // `held`: what the hand holds until the script's first change (none: the hand). Throws
  // std::invalid_argument naming the change (its time) when a tool is unknown or not in
  // `allowed` (none: any tool; tool_for_the_hand).
  ScriptedTools(std::optional<ToolKind> held, const std::vector<TrajectoryToolChange>& changes,
                const std::optional<AllowedTools>& allowed = std::nullopt, Hand hand = Hand::right);

  // What the hand holds now (none: the hand).
  std::optional<ToolKind> held() const { return held_; }
  // At `elapsed_s` of the script: takes the changes due and, if the tool changed, tells the
  // station (device_tool_changed of its hand from servo time `now_s`, and for the right hand a
  // tool_selected event: events do not name a hand yet). True when it changed. Changes at time 0
  // or before are taken by the constructor.
  bool advance(double elapsed_s, double now_s, Workstation& station);

 private:
  std::optional<ToolKind> held_;
  Hand hand_;
  std::vector<std::pair<double, std::optional<ToolKind>>> changes_;
  std::size_t next_ = 0;
};

}  // namespace liversim
