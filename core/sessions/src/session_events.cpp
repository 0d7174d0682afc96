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
  const SimulationObservation before = first_ ? SimulationObservation{false,
                                                                      now.topology_version,
                                                                      0.0,
                                                                      now.rollbacks,
                                                                      now.resected_volume_m3,
                                                                      now.specimens_taken_out,
                                                                      now.specimens_taken_out_m3}
                                              : last_;
  first_ = false;
  if (now.grasping != before.grasping)
    out.push_back({time_s, now.grasping ? SessionEventKind::grasp : SessionEventKind::release, ""});
  // A take-out changes the model too: a cut is a change beyond them.
  const int taken_out = now.specimens_taken_out - before.specimens_taken_out;
  if (taken_out > 0)
    out.push_back(
        {time_s, SessionEventKind::specimen_removed,
         text((now.specimens_taken_out_m3 - before.specimens_taken_out_m3) * 1e9, "mm3")});
  if (now.topology_version - before.topology_version > static_cast<std::uint64_t>(taken_out))
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
