#pragma once
// What every case of the stability suite does: step a model through the guard with the energy
// books open, track the extremes, and add the checks every case makes (stability_suite.h).

#include "liversim/studies/stability_run.h"

#include <chrono>

namespace liversim::detail {

// The books' tolerance of every case: energy created at most this share of the energy supplied.
// Central difference conserves a modified energy to O(Δt²) (and its kinetic energy is taken half
// a step behind); with damping its books close within a few per cent at the stable step. The
// other schemes are dissipative or far more accurate.
inline constexpr double kEnergyTolerance = 0.05;

class BookedRun {
 public:
  BookedRun(const SimModel& model, std::string variant);

  const SimModel& model;
  SimState state;  // at rest; a case may set it before open_books()

  // Opens the energy books at the state as it is (done at rest by the constructor).
  void open_books(const StepInputs& inputs = {});
  // `intervals` guarded advances of `interval_s` with constant inputs, books closed after each.
  // Returns false (and stops) if the guard gave up.
  bool advance(const StepInputs& inputs, double interval_s, int intervals = 1);
  // Energy held at the last close of the books (kinetic + tissue + springs).
  double held_j() const { return last_balance_.held_j(); }
  const EnergyBalance& balance() const { return last_balance_; }

  const StabilityRun& result() const { return run_; }  // so far

  void check(std::string what, double value, double limit, bool at_most = true);
  // Adds the checks of every case (finite state, no give-up, energy created at most
  // `energy_tolerance` of the energy supplied, displacement at most `displacement_bound_m`) and
  // returns the run.
  StabilityRun finish(double displacement_bound_m, double energy_tolerance);

  GuardOptions guard;

 private:
  StateCheckpoint checkpoint_;
  StabilityRun run_;
  EnergyBalance last_balance_;
  std::chrono::steady_clock::time_point start_;
};

// The largest distance of any node from its rest position.
double max_displacement_m(const SimModel& model, const NodeArray& position);

}  // namespace liversim::detail
