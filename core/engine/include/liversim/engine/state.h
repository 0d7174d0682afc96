#pragma once
// The changing simulation state, with the scratch buffers stepping needs, sized once for a model.

#include "liversim/engine/energy_ledger.h"
#include "liversim/engine/model.h"
#include "liversim/engine/viscous_tissue.h"
#include "liversim/engine/worker_pool.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace liversim {

// What a force evaluation saw that bears on the stable explicit step: the extremes of the element
// volume ratio J = det F (compression stiffens the volumetric response), the smallest nodal
// average of it where the λ pressure is averaged over nodes (it is that average the λ part
// stiffens with), the largest fibre tangent stiffness (stretched fibres stiffen
// exponentially), and the largest stiffening by plastic flow (ViscousHistory::kFlowStiffening).
struct ElasticEvaluation {
  double min_volume_ratio = 1.0;
  double max_volume_ratio = 1.0;
  double max_fibre_modulus_pa = 0.0;
  double min_nodal_volume_ratio = 1.0;
  double max_flow_stiffening = 1.0;
};

// Scratch of one force evaluation, sized once for a model.
struct ForceScratch {
  // Per element corner before the gather: corner c of element e at c·tet_count + e (a slot, as in
  // SimModel::node_slots).
  NodeArray corner_force_n;
  std::vector<double> element_volume_ratio;      // J per element (average nodal pressure only)
  std::vector<double> nodal_lambda_pressure_pa;  // p_λ at that J with the node's mean λ (likewise)
  // The smallest nodal J of each chunk of kNodesPerChunk nodes, and of all (likewise; +inf when
  // the evaluation averaged none).
  std::vector<double> chunk_min_nodal_volume_ratio;
  double min_nodal_volume_ratio = 0.0;
  // Element loops run in fixed chunks of kElementsPerChunk, whatever the thread count, and their
  // results are combined in chunk order, so one thread and two give the same numbers.
  std::vector<ElasticEvaluation> chunk_seen;
  std::vector<double> chunk_dissipated_j;
  // Viscous models: the step's constants per region for the vectorised loop (kRegionConstants
  // per region), and the elements it leaves to the general update (yield, collapse).
  std::vector<double> region_constants;
  std::vector<std::uint8_t> needs_general;
  std::vector<double> no_yield_raise_pa;  // zeros: the kernel's yield raise without in-vivo stress
  // Threads of the loops; null: the calling thread alone. Copies of a state share it (a pool runs
  // one job at a time; a second caller meanwhile runs on its own thread).
  std::shared_ptr<WorkerPool> workers;
};
inline constexpr std::size_t kElementsPerChunk = 256;
inline constexpr std::size_t kNodesPerChunk = 512;
ForceScratch make_force_scratch(const SimModel& model);

class ImplicitSolver;  // sparse tangent and factorisation of the implicit schemes (integrator.cpp)

// Owns an ImplicitSolver. A copy starts without one and sets it up again on its first implicit
// step (a factorisation cannot be shared between states).
class ImplicitSolverHandle {
 public:
  ImplicitSolverHandle();
  ImplicitSolverHandle(const ImplicitSolverHandle&);
  ImplicitSolverHandle& operator=(const ImplicitSolverHandle&);
  ImplicitSolverHandle(ImplicitSolverHandle&&) noexcept;
  ImplicitSolverHandle& operator=(ImplicitSolverHandle&&) noexcept;
  ~ImplicitSolverHandle();
  std::unique_ptr<ImplicitSolver> solver;
};

// Scratch of the integrators other than central difference, sized once for the model's scheme.
struct IntegratorScratch {
  // Runge–Kutta: the state at the start of the step, a stage's state, and the rates of each stage
  // (velocity; acceleration; Q̇ of the Maxwell arm of viscous elements).
  NodeArray start_position_m, start_velocity_m_per_s, stage_position_m, stage_velocity_m_per_s;
  std::vector<NodeArray> position_rate, velocity_rate;
  std::vector<Voigt6> start_arm, stage_arm, elastic_stress;
  std::vector<std::vector<Voigt6>> arm_rate;
  bool first_rate_valid = false;       // stage 1 already holds the rate at the state (FSAL)
  double first_rate_stiffening = 1.0;  // what stage 1's evaluation saw
  double adaptive_step_s = 0.0;        // dopri5: the step the error control proposes next
  // RK4's embedded error needs the rate at the end of its step: the step's last stage, kept
  // until the next step's first stage gives it.
  bool error_pending = false;
  double error_pending_step_s = 0.0;
  // Inputs of the last advance(): a change of load is a kink in time that leapfrog's kick and
  // BDF2's history must not smooth over (see integrator.cpp).
  std::uint64_t inputs_fingerprint = 0;
  bool inputs_changed = false;
  NodeArray external_force_n, previous_external_force_n;  // central difference, per step
  // Explicit fixed-step schemes: the step chosen last, before the equal split of an interval
  // (the next may grow from it by at most kStepGrowth; 0: no limit).
  double chosen_step_s = 0.0;
  // Every step is this fraction of what the scheme would take (guarded_advance's retries).
  double step_scale = 1.0;
  bool factorisation_valid = false;  // implicit: the last factorisation may be reused
  double factorised_beta_s = 0.0;
  int last_newton_iterations = 0;
  // Krylov iterations of the first Newton solve on the current factorisation (0: none yet): the
  // count that the factorisation's own tangent mismatch costs, whatever its age.
  int fresh_krylov_iterations = 0;
  // Error estimate of the fixed-step schemes: the velocity at the end of the last steps.
  std::array<NodeArray, 3> velocity_history;
  int history_count = 0;
  double history_step_s = 0.0;
  // Implicit schemes: the previous step (BDF2), Newton's residual and correction, arm weights.
  NodeArray previous_position_m, previous_velocity_m_per_s, predicted_position_m,
      predicted_velocity_m_per_s;
  std::vector<Voigt6> previous_arm, predicted_arm;
  bool has_previous = false;
  double previous_step_s = 0.0;
  std::vector<double> keep_by_region, elastic_weight_by_region;
  ImplicitSolverHandle implicit;
};

struct SimState {
  NodeArray position_m;
  // Central difference: the leapfrog velocity, half a step behind the next position update
  // (v at t − Δt/2). Other schemes: the velocity at time_s.
  NodeArray velocity_m_per_s;
  NodeArray force_n;  // total nodal force of the last evaluation
  ForceScratch force_scratch;
  std::vector<double> spring_damping_per_s;  // c/m per node from the springs of this step
  double max_speed_m_per_s = 0.0;            // fastest node after the last step
  double last_step_s = 0.0;                  // length of the last step (0 before the first)
  // History of viscous elements, committed at every force evaluation of a step (allocated only
  // when the model's effects.viscous), and the per-region step constants (scratch).
  ViscousHistory viscous_history;
  std::vector<std::optional<ViscousTissueStep>> viscous_step;
  IntegratorScratch integrator;
  EnergyLedger energy;  // books of work in and energy held (energy.h)
  double time_s = 0.0;
  std::uint64_t step_count = 0;
};

// A state at rest in the reference configuration, with all scratch allocated; its force loops run
// on `workers` (null: on the calling thread).
SimState make_rest_state(const SimModel& model, std::shared_ptr<WorkerPool> workers = nullptr);

// The state `old` carried onto another model of the same mesh (a live change of the integrator or
// the tissue; a cut carries its own over, cutting.h): positions, velocities, the fastest node's
// speed (the node-travel limit of the first step), the viscous history where its layout is the
// same, the energy books, the time and the step count. The new scheme starts its own history (a
// multistep scheme its first step, an adaptive one its step size). Throws std::invalid_argument
// when the node counts differ.
SimState carry_state(const SimState& old, const SimModel& model,
                     std::shared_ptr<WorkerPool> workers = nullptr);

}  // namespace liversim
