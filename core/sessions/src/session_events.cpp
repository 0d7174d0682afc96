#include "liversim/sessions/session_events.h"

#include <sstream>

namespace liversim {

namespace {

std::string text(double value, const char* unit) {
  std::ostringstream out;
  out.precision(3);
  out << value << ' ' << unit;
  return out.str();
}

}  // namespace

SessionEventDetector::SessionEventDetector(double safe_force_n, double rearm_fraction)
    : safe_force_n_(safe_force_n), rearm_force_n_(safe_force_n * rearm_fraction) {}

void SessionEventDetector::observe(double time_s, const SimulationObservation& now,
                                   std::vector<SessionEvent>& out) {
  const SimulationObservation before =
      first_ ? SimulationObservation{false, now.topology_version, 0.0, now.rollbacks,
                                     now.resected_volume_m3}
             : last_;
  first_ = false;
  if (now.grasping != before.grasping)
    out.push_back({time_s, now.grasping ? SessionEventKind::grasp : SessionEventKind::release, ""});
  if (now.topology_version != before.topology_version)
    out.push_back(
        {time_s, SessionEventKind::cut,
         "resected " + text((now.resected_volume_m3 - before.resected_volume_m3) * 1e9, "mm3")});
  if (!excessive_ && now.tool_force_n > safe_force_n_) {
    excessive_ = true;
    out.push_back({time_s, SessionEventKind::excessive_force, text(now.tool_force_n, "N")});
  } else if (excessive_ && now.tool_force_n < rearm_force_n_) {
    excessive_ = false;
  }
  if (now.rollbacks > before.rollbacks)
    out.push_back({time_s, SessionEventKind::simulation_recovery,
                   std::to_string(now.rollbacks - before.rollbacks) + " rollback(s)"});
  last_ = now;
}

}  // namespace liversim
