#include "liversim/station/scripted_tools.h"

#include "liversim/station/workstation.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace liversim {

ScriptedTools::ScriptedTools(std::optional<ToolKind> held,
                             std::vector<TrajectoryToolChange> changes,
                             const std::vector<ToolKind>& allowed)
    : held_(held) {
  for (const TrajectoryToolChange& change : changes) {
    std::optional<ToolKind> kind;
    if (change.tool != "hand") {
      kind = tool_kind(change.tool);
      std::ostringstream at;
      at << "the trajectory's tool at " << change.time_s << " s, " << change.tool;
      if (!kind) throw std::invalid_argument(at.str() + ", is no tool");
      if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), *kind) == allowed.end())
        throw std::invalid_argument(at.str() + ", is not a tool the scenario allows");
    }
    changes_.emplace_back(change.time_s, kind);
  }
  // A tool the script sets at its start is held from the start.
  while (next_ < changes_.size() && changes_[next_].first <= 0.0) held_ = changes_[next_++].second;
}

bool ScriptedTools::advance(double elapsed_s, double now_s, Workstation& station) {
  const std::optional<ToolKind> before = held_;
  while (next_ < changes_.size() && elapsed_s >= changes_[next_].first)
    held_ = changes_[next_++].second;
  if (held_ == before) return false;
  station.device_tool_changed(now_s);
  station.record_tool_choice();
  return true;
}

}  // namespace liversim
