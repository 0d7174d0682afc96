#pragma once
// The status bar's account of the running simulation: frame rate, steps, real-time factor, the
// step, the integrator with its error estimate and cost, what the step guards did, the pull and
// the resected volume. Translated in the main window's context.

#include "liversim/engine/health.h"
#include "liversim/simulation/realtime_simulation.h"

#include <QString>

#include <optional>

namespace liversim {

struct SimulationStatus {
  double framesPerSecond = 0.0;
  RealtimeStats stats;
  std::optional<double> pullingForce_n;  // while the hand grabs
  double resectedVolume_m3 = 0.0;
  int freeBodies = 0;         // pieces cut free, still in the field
  int specimensTakenOut = 0;  // taken out of it
};

QString simulationStatusText(const SimulationStatus& status);
// The integrator, its error estimate and its cost: "Central difference · error ≈ 2.1 µm · …".
QString accuracyStatusText(const RealtimeStats& stats);
QString healthProblemText(HealthProblem problem);
// An error estimate in the unit that suits it: "≈ 2.1 µm"; below a picometre, "< 1 pm".
QString formatError(double error_m);

}  // namespace liversim
