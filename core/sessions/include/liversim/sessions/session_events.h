#pragma once
// The events of a session that the simulation shows (grasp, release, cut, excessive force,
// simulation recovery, a specimen taken out), found by comparing what it showed at successive
// display frames. Lesion breaches and device faults are recorded where they are known (a cut's
// geometry, the servo).

#include "liversim/sessions/session_store.h"

#include <cstdint>
#include <vector>

namespace liversim {

// What a display frame shows of the simulation.
struct SimulationObservation {
  bool grasping = false;
  std::uint64_t topology_version = 0;  // raised by each cut
  double tool_force_n = 0.0;           // |force of the tissue on the tool|
  int rollbacks = 0;                   // the guard's recoveries since the start
  double resected_volume_m3 = 0.0;     // since the start
  // Free bodies taken out of the field since the start (each also raises topology_version), and
  // their rest volume.
  int specimens_taken_out = 0;
  double specimens_taken_out_m3 = 0.0;
};

class SessionEventDetector {
 public:
  // `safe_force_n`: a force above it is excessive; the next excessive-force event needs the force
  // to have dropped below `rearm_fraction` of it first (no storm of events at the threshold).
  explicit SessionEventDetector(double safe_force_n = 1.5, double rearm_fraction = 0.9);

  // The events between the previous observation and this one, at `time_s` (servo clock). The
  // first observation sets the baseline (and reports a grasp or an excessive force already on).
  void observe(double time_s, const SimulationObservation& now, std::vector<SessionEvent>& out);

 private:
  double safe_force_n_, rearm_force_n_;
  bool first_ = true;
  bool excessive_ = false;
  SimulationObservation last_;
};

}  // namespace liversim
