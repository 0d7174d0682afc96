#pragma once
// Nodal forces and energies of the elastic liver, and the external inputs of a step.

#include "liversim/engine/model.h"
#include "liversim/engine/state.h"

#include <Eigen/Core>

#include <span>
#include <string_view>

namespace liversim {

struct PointLoad {
  NodeIndex node;
  Eigen::Vector3d force_n;
};

// A damped spring pulling a node toward an anchor point: how a dragged point (mouse, forceps)
// acts. The damping is integrated implicitly, so a stiff coupling on a light node stays stable.
struct NodeSpring {
  NodeIndex node;
  Eigen::Vector3d anchor_m;
  double stiffness_n_per_m;
  double damping_n_s_per_m = 0.0;
};

// The damping that makes a spring of stiffness k on a node of mass m critically damped: 2√(k·m).
double critical_damping_n_s_per_m(double stiffness_n_per_m, double mass_kg);

// The force the springs' nodes exert on whatever holds the anchors (a tool, a handle), in newtons:
// Σ k·(x − anchor). Damping is left out: it vanishes at rest.
Eigen::Vector3d spring_reaction_force_n(std::span<const NodeSpring> springs,
                                        const NodeArray& position);

struct StepInputs {
  std::span<const PointLoad> point_loads;
  std::span<const NodeSpring> springs;
};

// Writes the elastic (internal) nodal forces at `position` into `force`, using `corner_scratch`
// for per-element values. The element kernel is the one for the model's effect set. Allocates
// nothing.
ElasticEvaluation compute_elastic_forces(const SimModel& model, const NodeArray& position,
                                         ForceScratch& scratch, NodeArray& force);

// The internal forces of a step at the state's positions, into state.force_n. History-dependent
// (viscous) elements advance their state by dt_since_last_s, the time since the last evaluation,
// and commit it; without viscous regions this is compute_elastic_forces. Allocates nothing.
ElasticEvaluation compute_internal_forces(const SimModel& model, SimState& state,
                                          double dt_since_last_s);

// The tissue's own forces on its nodes, into state.force_n: the internal forces and, with gravity,
// each node's weight and its support's push (what a force evaluation of a step computes before the
// inputs'). What the benchmark of an effect left off times on each build (forces_variants.h).
ElasticEvaluation compute_tissue_forces(const SimModel& model, SimState& state,
                                        double dt_since_last_s);

// compute_internal_forces' type, for benchmarks that time another build of it (forces_variants.h).
using InternalForcesFunction = ElasticEvaluation (*)(const SimModel&, SimState&, double);

// The instruction set of the vectorised element loops this process runs ("avx2+fma" or
// "generic"), chosen once from the processor.
std::string_view element_kernel_instruction_set();

// The Maxwell arm of viscous elements as carried by an integrator (viscoelastic_stress_rate_form):
// Q at the evaluation is keep·q_known + elastic_weight·S_e, the weights per region.
struct ViscousArmInputs {
  std::span<const Voigt6> q_known;  // per element (read for viscous elements only)
  std::span<const double> keep_by_region;
  std::span<const double> elastic_weight_by_region;
  std::span<Voigt6> elastic_stress;  // out: S_e per element
};

// Internal forces at `position` with the viscous arm given by `arm` (plastic deformation as
// committed in state.viscous_history); scratch from `state`. The committed viscous state is not
// changed. Without viscous regions this is compute_elastic_forces. Allocates nothing.
ElasticEvaluation compute_internal_forces_rate_form(const SimModel& model, SimState& state,
                                                    const NodeArray& position,
                                                    const ViscousArmInputs& arm, NodeArray& force);

// ∂P/∂F of element e at F for an implicit step: the element's elastic tangent, or for a viscous
// element the rate-form tangent with the arm weights of `arm` (the average nodal pressure is not
// differentiated: its elements get their own-pressure tangent, so Newton is inexact there).
Eigen::Matrix<double, 9, 9> element_step_tangent(const SimModel& model, const SimState& state,
                                                 const ViscousArmInputs& arm, std::size_t e,
                                                 const Eigen::Matrix3d& F);

// Dm⁻¹ of element e: its rows are the reference gradients of the shape functions of corners 1–3.
Eigen::Matrix3d element_dm_inverse(const SimModel& model, std::size_t e);

// Strain energy density and first Piola–Kirchhoff stress of element e at deformation F (the
// instantaneous elastic response for viscous regions, whose E is E1 + E2).
double element_energy_density(const SimModel& model, std::size_t e, const Eigen::Matrix3d& F);
Eigen::Matrix3d element_first_piola_stress(const SimModel& model, std::size_t e,
                                           const Eigen::Matrix3d& F);
// ∂P/∂F of element e at F, 9×9 over row-major flattened indices.
Eigen::Matrix<double, 9, 9> element_stress_tangent(const SimModel& model, std::size_t e,
                                                   const Eigen::Matrix3d& F);

// Adds point loads and spring forces at `position` to `force` (spring damping is applied by the
// integrator).
void add_external_forces(const StepInputs& inputs, const NodeArray& position, NodeArray& force);

// Adds each node's weight m·g to `force` when the model's gravity effect is on; nothing otherwise.
void add_gravity_forces(const SimModel& model, NodeArray& force);

// The support's contact damping rate 2·ζ·ω_s (1/s; 0 without a support; support.h).
double support_damping_per_s(const SimModel& model);
// Where the contact damping of add_support_forces goes: added to each touching node's rate (the
// leapfrog integrates it implicitly), or as forces −c·v from these velocities; neither: none.
struct SupportDamping {
  std::vector<double>* rate_per_s = nullptr;
  const NodeArray* velocity = nullptr;
};
// Adds the push and hold of the model's support (support.h) on the free nodes touching it at
// `position`, and its damping as `damping` says; nothing without a support.
void add_support_forces(const SimModel& model, const NodeArray& position, NodeArray& force,
                        const SupportDamping& damping = {});

double strain_energy_j(const SimModel& model, const NodeArray& position);
double kinetic_energy_j(const SimModel& model, const NodeArray& velocity);

// Deformation gradient F of element e at `position`.
Eigen::Matrix3d deformation_gradient(const SimModel& model, const NodeArray& position,
                                     std::size_t e);

}  // namespace liversim
