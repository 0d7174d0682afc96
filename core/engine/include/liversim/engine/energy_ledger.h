#pragma once
// The energy books a simulation state keeps (energy.h computes and checks them).

namespace liversim {

// Kept in SimState (and rolled back with it). advance() books the work of its inputs: point loads
// are constant over an interval, so their work F·Δx is exact; a spring anchor that moved between
// intervals did the work of the spring energy it added.
struct EnergyLedger {
  double initial_j = 0.0;        // held energy when the books were opened (0 at rest)
  double tool_work_j = 0.0;      // work done on the liver by loads and tools since
  double spring_energy_j = 0.0;  // in the tool springs at the end of the last advance
  // Dissipated by the Maxwell arms' dashpots since: each committed step adds the trapezoid of
  // their rate 2ψ_arm/τ (maxwell_arm_energy_density) at its start and end, booked by the loop
  // that commits the history (no pass of its own).
  double viscous_dissipated_j = 0.0;
};

}  // namespace liversim
