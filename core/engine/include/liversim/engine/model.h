#pragma once
// The constant simulation model, built once from a mesh and a scenario's settings. Everything that
// changes while simulating lives in SimState (state.h); stepping reads the model and never writes
// it.

#include "liversim/engine/fibres.h"
#include "liversim/engine/material.h"
#include "liversim/engine/support.h"
#include "liversim/engine/tet_mesh.h"
#include "liversim/engine/viscous_tissue.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace liversim {

// What one region of the organ is made of: the parenchyma (region 0) or a lesion.
struct RegionMaterial {
  TissueMaterial tissue;
  std::optional<FibreParameters> fibres;  // none: isotropic
  // Seed Eq. 1–3. When given, tissue.youngs_modulus_pa must be the instantaneous modulus E1 + E2
  // and tissue.mooney_rivlin_fraction 0 (the viscous law's elastic base is Neo-Hookean).
  std::optional<ViscoelasticParameters> viscoelastic;
  // Seed Eq. 4, in series; needs `viscoelastic`.
  std::optional<ViscoplasticParameters> viscoplastic;
  // The energy to make new cut surface in it (J/m², ≥ 0): what a blade's edge is held back by per
  // metre of it in the region, and what breaks a blade in (interaction/cutting.h). Porcine liver
  // cut by a scalpel: 187–225 J/m² (Chanthasopeephan, Desai & Lau 2006).
  double fracture_toughness_j_per_m2 = 200.0;
  // The friction on a blade's sides per metre of its edge in the region (N/m, ≥ 0), against the
  // blade's motion in any direction, while it cuts (interaction/cutting.h). Assumed, not measured
  // for liver: a third of the toughness's force, as friction was 21 % and tearing 61 % of a
  // needle's insertion force in porcine tissue (Barnett, Lee & Moore 2015).
  double blade_friction_n_per_m = 70.0;
};

// Reference fibre directions (normalised when the model is built): empty for no family, one vector
// for a uniform direction, or one per element.
struct FibreField {
  std::vector<Eigen::Vector3d> first_family;
  std::vector<Eigen::Vector3d> second_family;
};

// Effects the model computes; the element kernel is chosen from these once, and an effect that is
// off costs nothing in the step.
struct EffectSet {
  bool fibres = false;
  bool viscous = false;  // viscoelasticity (and viscoplasticity) in some region
  // Near-incompressibility on linear tetrahedra: the λ part of the pressure is taken from the
  // average nodal volume ratio (Joldes, Wittek & Miller 2009; NiftySim's T4ANP), not the element's.
  bool average_nodal_pressure = false;
  bool mooney_rivlin = false;  // some region has a Mooney–Rivlin I2 term
  // A uniform body force m·g on every node (SimModel::gravity_m_per_s2); off, nothing is added.
  bool gravity = false;
};

// Time integrators (facts about each in integrator.h).
enum class IntegratorKind {
  central_difference,  // explicit, 2nd order, TLED style (the default)
  rk4,                 // classical Runge–Kutta, explicit, 4th order (the seed's)
  dopri5,              // Dormand–Prince 5(4), explicit, adaptive step with error control
  backward_euler,      // implicit, 1st order, Newton + sparse Cholesky
  bdf2,                // implicit, 2nd order (BE for its first step and after a step change)
};

struct IntegratorSettings {
  IntegratorKind kind = IntegratorKind::central_difference;
  // Requested step. Explicit schemes take the largest stable step when 0, and shorten a requested
  // step that is not stable (and report it). Implicit schemes need a step > 0. dopri5 starts from
  // it and adapts.
  double step_s = 0.0;
  // dopri5: tolerated local error per step (m; positions, and velocities times the step).
  double tolerance_m = 1e-6;
  // Implicit schemes: Newton stops when no node moves more than this in an iteration.
  double newton_tolerance_m = 1e-9;
  int max_newton_iterations = 25;
  bool operator==(const IntegratorSettings&) const = default;
};

// The default SimModel::plastic_flow_interval_s: two haptic servo periods. At 1 ms the scalar flow
// update was still about a fifth of a stroke's time on the wedge scenario (perf); a flow taken
// every 2 ms lags that of every step by at most (σ − σs)/η2·(2 ms)ⁿ (docs/viscous-tissue.md).
inline constexpr double kPlasticFlowIntervalS = 0.002;

struct ModelOptions {
  // Region r of the mesh (TetMesh::region) is made of regions[r]; region 0 is the parenchyma.
  std::vector<RegionMaterial> regions = std::vector<RegionMaterial>(1);
  FibreField fibre_field;
  bool average_nodal_pressure = false;  // see EffectSet
  std::vector<NodeIndex> fixed_nodes;   // held at their rest position (e.g. ligament attachment)
  double mass_damping_per_s = 8.0;      // Rayleigh mass-proportional damping coefficient α
  double stable_step_safety = 0.8;      // fraction of the central-difference limit actually used
  double plastic_flow_interval_s = kPlasticFlowIntervalS;  // see SimModel
  // Gravitational acceleration in the mesh's axes (m/s²); zero: no gravity (the effect is off).
  Eigen::Vector3d gravity_m_per_s2 = Eigen::Vector3d::Zero();
  // What the organ rests on (support.h); none: nothing. Its contact frequency is this fraction of
  // the mesh's highest at rest, so that it lowers the stable step by about f²/2 (2 % at 0.2).
  std::shared_ptr<const SupportSurface> support;
  double support_frequency_fraction = 0.2;
  // The support's contact damping as a fraction of critical (support.h); ≥ 0.
  double support_damping_ratio = 1.0;
  // How hard the bed holds the organ where it lay, as a friction coefficient (support.h); ≥ 0.
  double support_friction_coefficient = 0.5;
  IntegratorSettings integrator;
};

struct SimModel {
  std::size_t node_count = 0;
  std::size_t tet_count = 0;
  std::array<std::vector<NodeIndex>, 4> corner;  // corner[c][e]
  // Total-Lagrangian shape-function data: Dm⁻¹ per element, row-major entry k at dm_inverse[k][e],
  // where Dm = [X1−X0, X2−X0, X3−X0] in the rest configuration.
  std::array<std::vector<double>, 9> dm_inverse;
  std::vector<double> rest_volume_m3;
  std::vector<double> shear_modulus_pa;  // μ per element
  std::vector<double> lame_lambda_pa;    // λ per element
  // Mooney–Rivlin c2 per element (allocated only when effects.mooney_rivlin); shear_modulus_pa
  // then holds the Neo-Hookean part 2c1 = (1 − f) μ.
  std::vector<double> mooney_rivlin_c2_pa;
  std::vector<std::int32_t> region;  // region per element
  std::vector<RegionMaterial> regions;
  EffectSet effects;
  // Fibre data per element, allocated only when effects.fibres: HGO parameters (k1 = 0 where the
  // region has none) and the unit reference direction of each family (zero vector: no family).
  std::vector<FibreParameters> fibre_parameters;
  std::array<std::vector<Eigen::Vector3d>, 2> fibre_direction;
  // Per region, the viscous law of regions that have one (allocated only when effects.viscous).
  std::vector<std::optional<ViscousTissueParameters>> viscous_parameters;
  // Per element, the von Mises stress (Pa) it bears in vivo: the largest as the organ settles
  // under its own weight on its support (in_vivo_stress.h). Its yield limit is measured above it:
  // tissue that has borne its weight yields under what an instrument adds, not under its weight.
  // Empty: none (no gravity, or no region that yields).
  std::vector<double> in_vivo_stress_pa;
  NodeArray rest_position_m;
  std::vector<double> lumped_mass_kg;
  std::vector<double> inverse_mass_per_kg;  // 0 on fixed nodes, so they never move
  std::vector<std::uint8_t> is_fixed;
  // Node → element-corner incidence (CSR) for gathering element forces without atomics. A slot s
  // names corner s / tet_count of element s % tet_count.
  std::vector<std::int32_t> node_slot_begin;  // size node_count + 1
  std::vector<std::int32_t> node_slots;
  std::vector<std::int32_t> node_slot_element;  // the element of each entry of node_slots
  double mass_damping_per_s = 0.0;
  // Gravitational acceleration (m/s², the mesh's axes); acts only when effects.gravity.
  Eigen::Vector3d gravity_m_per_s2 = Eigen::Vector3d::Zero();
  // The support the organ rests on (none: nothing) and its penalty's stiffness per unit of a node's
  // mass, ω² (1/s²): kept through cuts (a freed piece lands on the same tray).
  std::shared_ptr<const SupportSurface> support;
  double support_frequency_fraction = 0.2;  // ModelOptions'
  double support_stiffness_per_kg = 0.0;
  double support_damping_ratio = 1.0;         // ModelOptions'
  double support_friction_coefficient = 0.5;  // ModelOptions'
  // Largest eigenfrequency of M⁻¹K at rest (free nodes), from power iteration, and the explicit
  // step used: safety · 2/ω_max (reduced for damping).
  double max_frequency_rad_per_s = 0.0;
  double stable_time_step_s = 0.0;
  // That frequency as the materials were last set (build_model, set_region_materials): a cut's
  // mass scaling holds the frequency to it, so that cut after cut it does not creep up.
  double uncut_frequency_rad_per_s = 0.0;
  double stable_step_safety = 0.8;
  // Central difference takes the viscoplastic flow once per this much simulated time (0: every
  // step), with the increment of the whole interval (exact under a held stress, unconditionally
  // stable), and the steps between hold Fp: an element that yields takes the scalar update, which
  // costs ~17 times the vectorised law, and a blade makes hundreds yield at once.
  double plastic_flow_interval_s = kPlasticFlowIntervalS;
  IntegratorSettings integrator;
  // Smallest element height at rest: no node may travel more than a tenth of it in one step, which
  // keeps fast, large distortions (a yank, an inversion) from jumping past the stiffening.
  double min_element_height_m = 0.0;
  // The smallest element height of the mesh as built: no element a cut moves or makes may be
  // thinner (CuttingSettings::min_part_height_m aside).
  double reference_element_height_m = 0.0;
  // Mass added to nodes so that a cut does not raise the mesh's highest frequency (selective mass
  // scaling, cutting.h), in lumped_mass_kg; empty until a cut adds some. And its total.
  std::vector<double> node_added_mass_kg;
  double added_mass_kg = 0.0;
  // Faces made by cuts (cutting.h), per element: bit c for the face opposite corner c. Empty until
  // the first cut.
  std::vector<std::uint8_t> cut_face_mask;
  // Faces on the boundary (the organ's surface and cut faces), per element, bit c as above; kept
  // by cuts so that a cut surface is read off the elements instead of hashed again. Empty until
  // the first cut.
  std::vector<std::uint8_t> boundary_face_mask;
  // Mass of each element, kept through cuts (a node snapped onto a cut on a curved surface
  // changes its elements' volumes a little, never the mass). Empty until the first cut: density
  // times rest volume.
  std::vector<double> element_mass_kg;
};

// Throws std::invalid_argument naming the first integrator setting out of range.
void validate_integrator(const IntegratorSettings& settings);

// Fills the model's node → element-corner incidence (node_slot_*) from its corners.
void build_node_incidence(SimModel& model);

}  // namespace liversim
