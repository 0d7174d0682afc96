#pragma once
// What a running simulation takes besides its own stepping, in the order it took it: replayed in
// order on the same model from the same state, it gives the same states to the last bit (the
// engine's loops are deterministic whatever the thread count). A recorded session stores it
// (docs/session-storage.md, "Input chunks") so that it can be replayed in the viewport.

#include "liversim/engine/forces.h"
#include "liversim/engine/model.h"
#include "liversim/interaction/tools.h"

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace liversim {

struct SimulationInput {
  // take_out_specimens: every free body (cutting.h) taken out of the field (Session ▸ Remove
  // Specimen).
  enum class Kind : std::uint8_t { tool, springs, cycle, take_out_specimens };
  Kind kind = Kind::cycle;
  std::optional<Tool> tool;         // tool: the hand's tool from then on (none: taken away)
  std::vector<NodeSpring> springs;  // springs: the set springs from then on
  int steps = 0;                    // cycle: whole steps taken
  bool check_energy = false;        // cycle: the energy books were closed at its first step
  // cycle: the haptic servo's clock when the cycle began (the clock of the session's frames and
  // events), NaN without a servo. Not used to step: a replay places its cycles on the timeline.
  double servo_time_s = std::numeric_limits<double>::quiet_NaN();
  Hand hand = Hand::right;  // tool: the hand that holds it
};

// How a session's scene was built, so that a replay builds the same model: the session's
// scenario (its stored text, its organ file looked for in `scenario_folder`), or free practice on
// the built-in liver at `built_in_liver_tets` elements asked for; and the integrator in use when
// the session began (the Accuracy panel may have changed the scenario's).
struct ReplaySetup {
  std::optional<int> built_in_liver_tets;  // free practice; none: the session's scenario
  std::string scenario_folder;
  IntegratorSettings integrator;
  // The real-time loop's step the session was recorded with (a cycle of the input log is a count
  // of these); none for a session recorded before it was kept, whose loop stepped by the model's
  // integrator step, or else its stable step (legacy_loop_step_s).
  std::optional<double> loop_step_s;
};

}  // namespace liversim
