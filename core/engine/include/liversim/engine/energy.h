#pragma once
// Energy books of a simulation: what the liver holds (kinetic energy, energy stored in the tissue
// and in the tool springs) against what went in (the energy when the books were opened plus the
// work of loads and tools since). The difference is what viscosity, plastic flow, damping and the
// scheme itself dissipated; a negative difference is energy the numerics created, the sign of an
// instability long before a NaN. See docs/stability.md.

#include "liversim/engine/energy_ledger.h"
#include "liversim/engine/tet_mesh.h"

#include <span>

namespace liversim {

struct NodeSpring;
struct SimModel;
struct SimState;
struct StepInputs;

struct EnergyBalance {
  double kinetic_j = 0.0;
  double tissue_j = 0.0;  // stored in the tissue (tissue_energy_j)
  double spring_j = 0.0;  // stored in the tool springs
  // Gravitational potential relative to rest, −Σ m·g·(x − X) (0 without the gravity effect).
  double gravity_j = 0.0;
  double support_j = 0.0;  // stored in the support's penalty springs (support.h)
  double initial_j = 0.0;
  double tool_work_j = 0.0;
  double viscous_dissipated_j = 0.0;  // part of dissipated_j(): by the Maxwell arms' dashpots

  double held_j() const { return kinetic_j + tissue_j + spring_j + gravity_j + support_j; }
  double supplied_j() const { return initial_j + tool_work_j; }
  // By viscosity, plastic flow, damping and the scheme; negative: energy created.
  double dissipated_j() const { return supplied_j() - held_j(); }
  // Energy created beyond `tolerance` × what was supplied (and beyond round-off).
  bool created_beyond(double tolerance) const {
    return -dissipated_j() > tolerance * supplied_j() + 1e-12;
  }
};

// Energy stored in the tissue. Elastic regions: ψ(F) of their law (with average nodal pressure,
// the λ part at the nodes, whose exact gradient the forces are). Viscous regions:
// the relaxed spring g0·ψ(Fe) at the elastic part Fe = F·Fp⁻¹, fibres ψ(F), and the Maxwell arm's
// spring, ½·g1·H : C⁻¹ : H with C the instantaneous isotropic stiffness (exact at small strain, as
// the seed's 1-D model; the arm's finite-strain law has no closed-form potential). Allocates
// nothing; one pass over the elements.
double tissue_energy_j(const SimModel& model, const SimState& state);
double spring_energy_j(std::span<const NodeSpring> springs, const NodeArray& position);
// −Σ m·g·(x − X) over the nodes: the work gravity would do bringing the organ back to rest.
double gravity_potential_energy_j(const SimModel& model, const NodeArray& position);
// Σ ½·k·d² over the free nodes past the model's support by d along its normal (0 without one).
double support_energy_j(const SimModel& model, const NodeArray& position);

EnergyBalance energy_balance(const SimModel& model, const SimState& state,
                             const StepInputs& inputs);

// Opens the books at the state as it is: initial energy = held energy (with the springs of
// `inputs`), no work yet. make_rest_state opens them at rest.
void open_energy_books(const SimModel& model, SimState& state, const StepInputs& inputs);
void open_energy_books(const SimModel& model, SimState& state);  // no springs

}  // namespace liversim
