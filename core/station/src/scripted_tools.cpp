#include "liversim/station/scripted_tools.h"

#include "liversim/station/workstation.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace liversim {

std::optional<ToolKind> tool_for_the_hand(const std::string& name,
                                          const std::optional<AllowedTools>& allowed,
                                          const std::string& what) {
  if (name == "hand") return std::nullopt;
  const std::optional<ToolKind> kind = tool_kind(name);
  if (!kind)
    throw std::invalid_argument(what + " " + name +
                                " is unknown: expected hand, probe, forceps or scalpel");
  if (allowed &&
      std::find(allowed->tools.begin(), allowed->tools.end(), *kind) == allowed->tools.end()) {
    std::string listed = "hand";
    for (const ToolKind tool : allowed->tools) listed += ", " + std::string(tool_name(tool));
    throw std::invalid_argument(what + " " + name + " is not a tool the scenario " +
                                (allowed->scenario.empty() ? "" : allowed->scenario + " ") +
                                "allows (it allows: " + listed + ")");
  }
  return kind;
}

ScriptedTools::ScriptedTools(std::optional<ToolKind> held,
                             const std::vector<TrajectoryToolChange>& changes,
                             const std::optional<AllowedTools>& allowed, Hand hand)
    : held_(held), hand_(hand) {
  for (const TrajectoryToolChange& change : changes) {
    std::ostringstream at;
    at << "the trajectory's tool at " << change.time_s << " s:";
    changes_.emplace_back(change.time_s, tool_for_the_hand(change.tool, allowed, at.str()));
  }
  // A tool the script sets at its start is held from the start.
  while (next_ < changes_.size() && changes_[next_].first <= 0.0) held_ = changes_[next_++].second;
}

bool ScriptedTools::advance(double elapsed_s, double now_s, Workstation& station) {
  const std::optional<ToolKind> before = held_;
  while (next_ < changes_.size() && elapsed_s >= changes_[next_].first)
    held_ = changes_[next_++].second;
  if (held_ == before) return false;
  station.device_tool_changed(hand_, now_s);
  station.record_tool_choice(hand_);
  return true;
}

}  // namespace liversim
