#pragma once
// Guards of the step: cheap health checks, a checkpoint of the last good state, and an advance()
// that rolls back and retries with shorter steps when a step goes bad (a NaN, a runaway node), or
// refuses inputs that are not finite. Nothing here allocates after the checkpoint is made.

#include "liversim/engine/energy.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/state.h"

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace liversim {

enum class HealthProblem : std::uint8_t {
  none,
  non_finite_input,     // a load or spring with a NaN or infinite value (rejected, not stepped)
  non_finite_position,  // the step produced a NaN or infinite position
  non_finite_velocity,  // ... or velocity
  runaway_speed,        // a node moved faster than the speed limit (a backstop)
  runaway_energy,       // a node held more kinetic energy than was ever supplied
  solver_failed,        // an implicit step's Newton iteration did not converge
  step_collapsed,       // the explicit step fell below kCollapsedStepFraction of its rest value
};
std::string_view health_problem_text(HealthProblem problem);

struct GuardOptions {
  // A blow-up is told apart from fast motion by energy, not speed: no node can hold more kinetic
  // energy than the books say was supplied (energy.h), with what gravity has released as the organ
  // came down, however light it is and however hard it is pulled (a device's full force on one
  // node moves it at tens of m/s). The slack covers
  // leapfrog's half-step velocities and the books' O(Δt²). The speed limit is only a backstop.
  double kinetic_energy_slack = 0.1;
  double speed_limit_m_per_s = 1000.0;
  int max_retries = 4;  // each retry halves the step
  // Close the energy books after the advance (one pass over the elements; a caller stepping at
  // 1 kHz asks every so many steps). Energy created beyond `energy_tolerance` × the energy
  // supplied is reported, not rolled back: it builds up over many steps, so the last checkpoint
  // would not undo it, and leapfrog's energy oscillates by O(Δt²) around the true one.
  bool check_energy = false;
  double energy_tolerance = 0.05;
  // Whether the good state is saved as the checkpoint on entry (unless saved already) and after a
  // good advance (after one that had to roll back, always). A caller stepping one cycle step by
  // step saves on entry to its first step and after its last only: a full copy of the state (its
  // viscous history above all) after every 0.43 ms step was a tenth of the loop's time while a tool
  // acted. A bad step in between goes back to the cycle's start.
  bool checkpoint_on_entry = true;
  bool checkpoint_after_advance = true;
  // advance's whole_step_s (integrator.h): > 0, central difference ends at or past the interval's
  // end in steps of at most this.
  double whole_step_s = 0.0;
  // advance's give_up (integrator.h): set, the advance may end early when it reads true.
  const std::atomic<bool>* give_up = nullptr;
};

// Finite positions and velocities, no node faster than the speed limit, none with more kinetic
// energy than (1 + slack) × the energy supplied. O(nodes), allocates nothing.
HealthProblem check_health(const SimModel& model, const SimState& state,
                           const GuardOptions& options = {});
bool inputs_finite(const StepInputs& inputs);

// What a rollback restores: the evolving state (not scratch). Sized once by make_checkpoint.
struct StateCheckpoint {
  NodeArray position_m, velocity_m_per_s;
  ViscousHistory viscous_history;
  EnergyLedger energy;
  double time_s = 0.0;
  std::uint64_t step_count = 0;
  bool valid = false;
  // Not restored: the guard's memory of the step scale that last succeeded. A hard stretch (a
  // yank, a stiffening spike) usually lasts many advances; starting each from the full step
  // would fail and roll back every time. It doubles back after each clean advance.
  double step_scale = 1.0;
};
StateCheckpoint make_checkpoint(const SimModel& model);
void save_checkpoint(const SimState& state, StateCheckpoint& checkpoint);
// Restores the state; the integrators restart their history (BDF2, error estimates, FSAL), and
// leapfrog takes the restored velocity as the velocity at that time.
void restore_checkpoint(const StateCheckpoint& checkpoint, SimState& state);

struct GuardedReport {
  StepReport steps;                             // of the attempt that was kept
  int rollbacks = 0;                            // attempts undone
  HealthProblem problem = HealthProblem::none;  // the last problem met (none: clean)
  double step_scale = 1.0;                      // the step scale that succeeded
  bool gave_up = false;                         // every retry failed: the state is the checkpoint's
  bool inputs_rejected = false;
  std::optional<EnergyBalance> energy;  // when options.check_energy: the books after the advance
  bool energy_created = false;          // the books show energy created beyond the tolerance
};

// advance() with a checkpoint: saves the state, advances, checks its health; on a problem restores
// the checkpoint and retries with the step halved, up to max_retries times, starting from the
// scale that last succeeded (checkpoint.step_scale). Non-finite inputs are
// not stepped at all (the state advances with no inputs and the report says so). Allocates
// nothing once `checkpoint` is made for the model.
GuardedReport guarded_advance(const SimModel& model, SimState& state, const StepInputs& inputs,
                              double interval_s, StateCheckpoint& checkpoint,
                              const GuardOptions& options = {});

}  // namespace liversim
