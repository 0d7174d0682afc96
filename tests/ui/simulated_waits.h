// Waits on the simulation's own clock: what a GUI test waits for while the liver moves, never the
// wall clock (a loaded machine makes the wait longer, not the test red).
#pragma once

#include "liversim/simulation/realtime_simulation.h"

#include <QTest>
#include <QWidget>

namespace liversim::test {

// Until `simulation` has gone `seconds` of simulated time on; false after `limit_ms` (a hang).
inline bool waitSimulated(const RealtimeSimulation& simulation, double seconds, int limit_ms) {
  const double until_s = simulation.snapshot().time_s + seconds;
  return QTest::qWaitFor([&] { return simulation.snapshot().time_s >= until_s; }, limit_ms);
}

// Shows `window` and waits until it is on screen and `simulation` has begun to run.
inline bool showRunning(QWidget& window, const RealtimeSimulation& simulation, int limit_ms) {
  window.show();
  return QTest::qWaitForWindowExposed(&window) &&
         QTest::qWaitFor([&] { return simulation.snapshot().time_s > 0.0; }, limit_ms);
}

}  // namespace liversim::test
