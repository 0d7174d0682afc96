// Cases 1, 2, 5, 6, 7, 9, 10 and 11 of the stability suite (stability_suite.h). Each states its
// checks; the limits come from the case's mathematics, as the comments say.
#include "stability_cases.h"

#include "stability_runner.h"

#include "liversim/engine/mesh_io.h"
#include "liversim/engine/model_building.h"
#include "liversim/meshing/box_mesh.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"

#include <cmath>
#include <limits>

namespace liversim::detail {
namespace {

// Nothing may move farther than the organ is large: a bound no stable run comes near.
double extent_m(const SimModel& model) {
  Eigen::Vector3d low = model.rest_position_m.at(0), high = low;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    low = low.cwiseMin(model.rest_position_m.at(n));
    high = high.cwiseMax(model.rest_position_m.at(n));
  }
  return (high - low).norm();
}

bool all_finite(const NodeArray& force) {
  for (std::size_t n = 0; n < force.size(); ++n)
    if (!force.at(n).allFinite()) return false;
  return true;
}

double min_volume_ratio(const SimModel& model, const NodeArray& position) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < model.tet_count; ++e)
    smallest = std::min(smallest, deformation_gradient(model, position, e).determinant());
  return smallest;
}

// The seed's recipe on one mesh: a 0.75 N pull for 0.1 s in 2 ms intervals, then 0.1 s free.
StabilityRun seed_recipe_run(const TetMesh& mesh, const std::vector<NodeIndex>& fixed,
                             bool average_nodal_pressure, std::string variant) {
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.49, 1060.0};
  options.average_nodal_pressure = average_nodal_pressure;
  options.fixed_nodes = fixed;
  options.integrator.kind = IntegratorKind::rk4;
  options.integrator.step_s = 0.002;
  const SimModel model = build_model(mesh, options);
  BookedRun run(model, std::move(variant));
  const std::vector<PointLoad> pull{{anterior_marked_node(mesh), Eigen::Vector3d(0.0, 0.75, 0.0)}};
  run.advance({pull, {}}, 0.002, 50);
  // The step is outside RK4's stability interval on a real mesh: the engine must substep.
  run.check("steps shortened by the stability limit", run.result().steps.stability_limited_steps,
            1.0, false);
  run.check("smallest stable step met (s)", run.result().steps.smallest_stable_step_s, 0.002);
  const double released = run.held_j();
  double largest_growth = 0.0, previous = released;
  for (int i = 0; i < 50 && run.advance({}, 0.002); ++i) {
    largest_growth = std::max(largest_growth, (run.held_j() - previous) / released);
    previous = run.held_j();
  }
  // Free and damped, a hyperelastic model's energy may not grow beyond round-off. The average
  // nodal pressure has no exact potential, so there the end is compared with the release.
  if (average_nodal_pressure)
    run.check("held energy at the end / at release", run.held_j() / released, 1.0);
  else
    run.check("largest growth of held energy per 2 ms while free / at release", largest_growth,
              1e-9);
  // The books hold to the scheme's accuracy (or, with average nodal pressure, to the difference
  // between its forces and the element-pressure energy): 5 %.
  return run.finish(extent_m(model), kEnergyTolerance);
}

}  // namespace

std::vector<StabilityRun> seed_recipe_case(const StabilitySuiteOptions& options) {
  const ImplicitMeshResult liver = generate_liver_mesh(5406);
  const auto& ligament = liver.mesh.node_sets.at("ligament");
  std::vector<StabilityRun> runs{
      seed_recipe_run(liver.mesh, ligament, false, "built-in liver 5406, element pressure"),
      seed_recipe_run(liver.mesh, ligament, true, "built-in liver 5406, average nodal pressure")};
  if (!options.shared_data_dir.empty()) {
    const TetMesh zhang =
        read_tet_mesh(options.shared_data_dir / "external/zhang-liver/Liver_Iso.inp");
    runs.push_back(seed_recipe_run(zhang, zhang.node_sets.at("FixT&P"), false,
                                   "Zhang liver, element pressure"));
  }
  return runs;
}

// Case 2: ν = 0.499 under large compression (an end traction of 1.2 kPa), explicit and implicit.
std::vector<StabilityRun> near_incompressible_case(const StabilitySuiteOptions&) {
  const double length = 0.04;
  const TetMesh mesh = box_mesh(4, 2, 2, {length, 0.02, 0.02});
  std::vector<PointLoad> loads;
  for (const PointLoad& load : end_face_tension(mesh, -1200.0))
    if (load.force_n.x() < 0.0) loads.push_back(load);  // the free end only
  std::vector<StabilityRun> runs;
  for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::backward_euler}) {
    ModelOptions options;
    options.regions[0].tissue = TissueMaterial{3500.0, 0.499, 1060.0};
    options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
    options.mass_damping_per_s = 20.0;
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 2e-3;
    const SimModel model = build_model(mesh, options);
    BookedRun run(model, std::string(integrator_name(kind)));
    run.advance({loads, {}}, 0.01, 100);
    const double shortening =
        length - mean_coordinate_on_plane(mesh, run.state.position_m, 0, length);
    run.check("shortening / length (a large compression)", shortening / length, 0.1, false);
    // ν = 0.499 keeps the volume: K/μ ≈ 1000, so the pressure of a 30 % shortening costs < 1 %.
    run.check("smallest element volume ratio J", min_volume_ratio(model, run.state.position_m), 0.9,
              false);
    run.check("rollbacks", run.result().rollbacks, 0.0);
    runs.push_back(run.finish(length, kEnergyTolerance));
  }
  return runs;
}

// Case 5: a slab 100× stiffer in the middle of a bar. Its elements set the stable step (√100 = 10×
// shorter than the parenchyma's, less the mass they share with it: at least 3×), and a shear pull
// stays within the books.
std::vector<StabilityRun> stiff_lesion_case(const StabilitySuiteOptions&) {
  TetMesh mesh = box_mesh(4, 2, 2, {0.04, 0.02, 0.02});
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
  options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
  const SimModel soft = build_model(mesh, options);
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    double centre_x = 0.0;
    for (int c = 0; c < 4; ++c) centre_x += 0.25 * mesh.rest_position_m.x[mesh.corner[c][e]];
    if (centre_x > 0.02 && centre_x < 0.03) mesh.region[e] = 1;
  }
  RegionMaterial lesion;
  lesion.tissue = TissueMaterial{350000.0, 0.45, 1060.0};
  options.regions.push_back(lesion);
  const SimModel model = build_model(mesh, options);
  BookedRun run(model, "central-difference");
  run.check("stable step without the lesion / with it",
            soft.stable_time_step_s / model.stable_time_step_s, 3.0, false);
  std::vector<PointLoad> loads;
  for (NodeIndex n : nodes_on_plane(mesh, 0, 0.04)) loads.push_back({n, {0.0, 0.002, 0.0}});
  run.advance({loads, {}}, 0.01, 50);
  run.check("work of the pull (J)", run.balance().tool_work_j, 0.0, false);
  return {run.finish(0.04, kEnergyTolerance)};
}

// Case 6: at λ = 2 with k2 = 50 the fibre energy's exponent k2·(I4 − 1)² is 450 (e^450
// overflows): the guard continues it linearly, so forces stay finite and the stable step,
// re-estimated from the stiffening, is finite and far shorter (the fibre modulus grows by
// e^450-like factors, capped: > 100×). A bar released from λ = 1.5 with k2 = 2 then snaps back.
std::vector<StabilityRun> stiffening_fibres_case(const StabilitySuiteOptions&) {
  const double length = 0.04;
  const TetMesh mesh = box_mesh(4, 1, 1, {length, 0.01, 0.01});
  auto model_with = [&](double k2) {
    ModelOptions options;
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[0].fibres = FibreParameters{500.0, k2};
    options.fibre_field.first_family = {Eigen::Vector3d::UnitX()};
    options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
    options.mass_damping_per_s = 30.0;
    return build_model(mesh, options);
  };
  const SimModel stiff = model_with(50.0);
  SimState stretched = make_rest_state(stiff);
  for (std::size_t n = 0; n < mesh.node_count(); ++n) stretched.position_m.x[n] *= 2.0;
  NodeArray force;
  force.resize(stiff.node_count);
  const ElasticEvaluation seen =
      compute_elastic_forces(stiff, stretched.position_m, stretched.force_scratch, force);
  const double step = stable_time_step_s(stiff, {}, stiffening_since_rest(stiff, seen));

  const SimModel model = model_with(2.0);
  BookedRun run(model, "central-difference, released from λ = 1.5");
  run.check("forces finite at λ = 2, k2 = 50 (1 = yes)", all_finite(force) ? 1.0 : 0.0, 1.0, false);
  run.check("stable step at rest / at λ = 2, k2 = 50", stiff.stable_time_step_s / step, 100.0,
            false);
  for (std::size_t n = 0; n < mesh.node_count(); ++n) run.state.position_m.x[n] *= 1.5;
  run.open_books();
  run.advance({}, 0.01, 50);
  const StabilityRun& so_far = run.result();
  run.check("largest stiffening met", so_far.steps.max_stiffening, 5.0, false);
  run.check("smallest step / stable step at rest",
            so_far.steps.smallest_substep_s / model.stable_time_step_s, 0.5);
  run.check("end stretch (the fibres pulled the bar back)",
            mean_coordinate_on_plane(mesh, run.state.position_m, 0, length) / length, 1.2);
  return {run.finish(length, kEnergyTolerance)};
}

// Case 7: viscoplastic flow with n = 0.3 (its rate n·tⁿ⁻¹ is singular at the onset), loaded to
// exactly the yield limit for 0.3 s, then a sine between 0 and 2σs (period 0.4 s). The flow never
// runs backwards and the books hold with the Maxwell arm's energy counted.
std::vector<StabilityRun> yield_cycles_case(const StabilitySuiteOptions&) {
  const double length = 0.04, yield = 50.0;
  const TetMesh mesh = box_mesh(4, 1, 1, {length, 0.01, 0.01});
  std::vector<PointLoad> unit;
  for (const PointLoad& load : end_face_tension(mesh, 1.0))
    if (load.force_n.x() > 0.0) unit.push_back(load);
  std::vector<StabilityRun> runs;
  for (IntegratorKind kind :
       {IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::backward_euler}) {
    ModelOptions options;
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[0].viscoelastic = kSeedViscoelastic;
    options.regions[0].viscoplastic = ViscoplasticParameters{yield, 500.0, 0.3};
    options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
    options.mass_damping_per_s = 20.0;
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 2e-3;
    const SimModel model = build_model(mesh, options);
    BookedRun run(model, std::string(integrator_name(kind)));
    std::vector<PointLoad> loads = unit;
    double plastic_before = 0.0;
    int backwards = 0;
    for (int k = 0; k < 60; ++k) {
      const double t = 0.02 * k;
      const double sigma = t < 0.3 ? yield : yield * (1.0 + std::sin(2.0 * M_PI * (t - 0.3) / 0.4));
      for (std::size_t i = 0; i < unit.size(); ++i) loads[i].force_n = sigma * unit[i].force_n;
      if (!run.advance({loads, {}}, 0.02)) break;
      double plastic = 0.0;
      for (std::size_t e = 0; e < run.state.viscous_history.size(); ++e)
        plastic = std::max(plastic, run.state.viscous_history.equivalent_plastic_strain(e));
      if (plastic < plastic_before) ++backwards;
      plastic_before = plastic;
    }
    run.check("intervals where plastic strain decreased", backwards, 0.0);
    run.check("equivalent plastic strain at the end (the cycles went through yield)",
              plastic_before, 0.0, false);
    runs.push_back(run.finish(length, kEnergyTolerance));
  }
  return runs;
}

// Case 8: the device's largest force (3.3 N, haptics.md) as a step on one node of the liver (the
// seed's coarsest, 3844 tetrahedra), pulling outward, held 0.1 s, then released. A point load on
// a continuum is singular: the node's elements stretch into a tent far beyond any tissue's tearing
// stretch and the light node moves at tens of m/s, so this tests the numerics, not the tissue.
// The bound: the force is carried by the elements around the node, whose rest cross-section is at
// least h_min² (h_min the smallest element height); a Neo-Hookean column in tension stretches by
// at most F/(μ·A) more, over a length of at least h_min, and a suddenly applied load overshoots
// the static stretch at most twice: |u| ≤ 2·F/(μ·h_min). After release, mass damping α leaves
// e^(−α·t/2) of the motion: the liver must be within 20 × that share of the largest displacement
// of rest (3 s free; 1 s for backward Euler, whose Newton steps through the tent cost more).
std::vector<StabilityRun> force_step_case(const StabilitySuiteOptions&) {
  constexpr double kDeviceMaxForce = 3.3, kHold = 0.1;
  const TetMesh mesh = generate_liver_mesh(kSeedMeshSizes[0]).mesh;
  std::vector<StabilityRun> runs;
  for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::backward_euler}) {
    ModelOptions options;
    options.fixed_nodes = mesh.node_sets.at("ligament");
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 1e-3;
    const SimModel model = build_model(mesh, options);
    BookedRun run(model, std::string(integrator_name(kind)));
    const std::vector<PointLoad> step{
        {anterior_marked_node(mesh), Eigen::Vector3d(0.0, 0.0, kDeviceMaxForce)}};
    run.advance({step, {}}, 0.01, static_cast<int>(std::lround(kHold / 0.01)));
    const double largest = run.result().max_displacement_m;
    const double free_s = is_explicit(kind) ? 3.0 : 1.0;
    run.advance({}, 0.05, static_cast<int>(std::lround(free_s / 0.05)));
    const double mu = model.shear_modulus_pa[0];
    run.check(
        "largest displacement after " + std::to_string(static_cast<int>(free_s)) + " s free (m)",
        max_displacement_m(model, run.state.position_m),
        20.0 * largest * std::exp(-0.5 * model.mass_damping_per_s * free_s));
    runs.push_back(
        run.finish(2.0 * kDeviceMaxForce / (mu * model.min_element_height_m), kEnergyTolerance));
  }
  return runs;
}

// Case 9: a coarse liver (1000 tetrahedra, so that ten simulated minutes take about a minute)
// pulled by 0.2 N for 0.3 s, then free for options.long_run_s. Free, the held energy may never
// grow (beyond round-off), and the liver comes back to rest: mass damping α = 8/s leaves e^(−8·t)
// of the motion, below a micrometre after 5 s. (At 3844 tetrahedra the same run passes too; it
// takes 6.5 minutes.)
std::vector<StabilityRun> free_liver_case(const StabilitySuiteOptions& options) {
  const TetMesh mesh = generate_liver_mesh(1000).mesh;
  ModelOptions model_options;
  model_options.fixed_nodes = mesh.node_sets.at("ligament");  // element pressure: a true energy
  const SimModel model = build_model(mesh, model_options);
  BookedRun run(model, "central-difference, " + std::to_string(model.tet_count) + " tets");
  const std::vector<PointLoad> pull{{anterior_marked_node(mesh), {0.0, 0.0, 0.2}}};
  run.advance({pull, {}}, 0.01, 30);
  const double released = run.held_j();
  double largest = released;
  const int intervals = static_cast<int>(std::ceil(options.long_run_s / 0.05));
  for (int i = 0; i < intervals && run.advance({}, 0.05); ++i)
    largest = std::max(largest, run.held_j());
  run.check("largest held energy while free / at release", largest / released, 1.0 + 1e-6);
  run.check("largest displacement at the end (m)", max_displacement_m(model, run.state.position_m),
            1e-6);
  return {run.finish(extent_m(model), kEnergyTolerance)};
}

// Case 10: a fragment with no fixed node (what a cut leaves floating). Its stiffness is singular
// (rigid motions), but the implicit step's matrix M/β² + … is not: every step converges, and the
// fragment moves off rigidly under a uniform load as F = m·a says: x = a·t²/2 without damping;
// backward Euler gives a·Δt²·n(n+1)/2, 1 % more at n = 100 steps, BDF2 less: within 2 %.
std::vector<StabilityRun> floating_fragment_case(const StabilitySuiteOptions&) {
  const TetMesh mesh = box_mesh(2, 2, 2, {0.02, 0.02, 0.02});
  std::vector<StabilityRun> runs;
  for (IntegratorKind kind : {IntegratorKind::backward_euler, IntegratorKind::bdf2}) {
    ModelOptions options;
    options.mass_damping_per_s = 0.0;
    options.integrator.kind = kind;
    options.integrator.step_s = 1e-3;
    const SimModel model = build_model(mesh, options);
    double mass = 0.0;
    for (double m : model.lumped_mass_kg) mass += m;
    std::vector<PointLoad> loads;  // each node its share of 0.01 N by mass
    for (std::size_t n = 0; n < model.node_count; ++n)
      loads.push_back(
          {NodeIndex(n), Eigen::Vector3d(0.0, 0.0, 0.01 * model.lumped_mass_kg[n] / mass)});
    BookedRun run(model, std::string(integrator_name(kind)));
    run.advance({loads, {}}, 0.01, 10);
    const StabilityRun& so_far = run.result();
    run.check("unconverged implicit steps", so_far.steps.unconverged_steps, 0.0);
    run.check("rollbacks", so_far.rollbacks, 0.0);
    const double expected = 0.5 * (0.01 / mass) * 0.1 * 0.1;
    const double moved = mean_coordinate_on_plane(mesh, run.state.position_m, 2, 0.0);
    run.check("|moved − a·t²/2| / (a·t²/2)", std::abs(moved - expected) / expected, 0.02);
    runs.push_back(run.finish(0.1, kEnergyTolerance));
  }
  return runs;
}

// Case 11: a viscoelastic bar under a pull; mid-run a NaN arrives in the load, then a NaN and an
// infinity are written into the state. The input is refused (the interval is stepped without it),
// the state goes back to the last good one, and the run goes on to its end; every scheme.
std::vector<StabilityRun> non_finite_injection_case(const StabilitySuiteOptions&) {
  const TetMesh mesh = box_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  std::vector<StabilityRun> runs;
  for (IntegratorKind kind : kAllIntegrators) {
    ModelOptions options;
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[0].viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 200.0};
    options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 1e-3;
    const SimModel model = build_model(mesh, options);
    BookedRun run(model, std::string(integrator_name(kind)));
    const std::vector<PointLoad> pull{{NodeIndex(mesh.node_count() - 1), {0.0, 0.01, 0.0}}};
    std::vector<PointLoad> bad = pull;
    bad[0].force_n.y() = std::numeric_limits<double>::quiet_NaN();
    run.advance({pull, {}}, 0.01, 5);
    run.advance({bad, {}}, 0.01);
    run.state.position_m.y[3] = std::numeric_limits<double>::quiet_NaN();
    run.state.velocity_m_per_s.x[5] = std::numeric_limits<double>::infinity();
    run.advance({pull, {}}, 0.01, 5);
    const StabilityRun& so_far = run.result();
    run.check("refused inputs", so_far.rejected_inputs, 1.0, false);
    run.check("rollbacks", so_far.rollbacks, 1.0, false);
    run.check("simulated time reached (s)", run.state.time_s, 0.11 - 1e-12, false);
    runs.push_back(run.finish(0.04, kEnergyTolerance));
  }
  return runs;
}

}  // namespace liversim::detail
