#include "liversim/studies/accuracy_study.h"
#include "liversim/engine/model_building.h"

#include "liversim/engine/surface.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/studies/seed_experiments.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace liversim {

std::string_view study_effects_name(StudyEffects effects) {
  switch (effects) {
    case StudyEffects::elastic:
      return "elastic";
    case StudyEffects::viscoelastic:
      return "viscoelastic";
    case StudyEffects::viscoplastic:
      return "viscoplastic";
    case StudyEffects::fibres:
      return "fibres";
  }
  return "unknown";
}

std::optional<StudyEffects> study_effects_from_name(std::string_view name) {
  for (StudyEffects effects : kAllStudyEffects)
    if (study_effects_name(effects) == name) return effects;
  return std::nullopt;
}

double observed_order(const AccuracyStudyRow& coarse, const AccuracyStudyRow& fine) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (coarse.steps.stability_limited_steps > 0 || fine.steps.stability_limited_steps > 0)
    return nan;
  const double e1 = coarse.max_node_error_m, e2 = fine.max_node_error_m;
  if (!(e1 > 0.0 && e2 > 0.0)) return nan;
  const double h1 = coarse.step_s > 0.0 ? coarse.step_s : coarse.tolerance_m;
  const double h2 = fine.step_s > 0.0 ? fine.step_s : fine.tolerance_m;
  if (!(h1 > 0.0 && h2 > 0.0) || h1 == h2) return nan;
  return std::log(e1 / e2) / std::log(h1 / h2);
}

// The study's tissue: the default scene's, with the effect set's additions. Viscous and fibre
// parameters are ASSUMED (no liver data in the seed): E = 3500 Pa split E1 = 2000, E2 = 1500,
// τ = 1 s; yield limit 20 Pa, η2 = 500 Pa·sⁿ, n = 0.5; fibres k1 = 1000 Pa, k2 = 2 along x.
void apply_study_effects(StudyEffects effects, ModelOptions& options) {
  RegionMaterial& region = options.regions.at(0);
  region.tissue = TissueMaterial{3500.0, 0.49, 1060.0};
  switch (effects) {
    case StudyEffects::elastic:
      break;
    case StudyEffects::viscoplastic:
      region.viscoplastic = ViscoplasticParameters{20.0, 500.0, 0.5};
      [[fallthrough]];
    case StudyEffects::viscoelastic:
      region.viscoelastic = kSeedViscoelastic;
      break;
    case StudyEffects::fibres:
      region.fibres = FibreParameters{1000.0, 2.0};
      options.fibre_field.first_family = {Eigen::Vector3d::UnitX()};
      break;
  }
}

namespace {

// Smooth rise x²(3 − 2x) of the tension over the run.
double tension_n(const AccuracyStudyOptions& options, double time_s) {
  const double x = std::clamp(time_s / options.duration_s, 0.0, 1.0);
  return options.peak_force_n * x * x * (3.0 - 2.0 * x);
}

struct RunOutcome {
  NodeArray position_m;
  double wall_s = 0.0;
  StepReport steps;
};

// Reports the run's progress after each load interval; throws StudyCancelled when asked to stop.
using RunProgress = std::function<void(double fraction_of_run)>;

RunOutcome run_case(const SimModel& model, const LoadPatch& patch,
                    const AccuracyStudyOptions& options, double load_interval_s,
                    const std::string& what, const RunProgress& run_progress) {
  SimState state = make_rest_state(model);
  std::vector<PointLoad> loads;
  const auto intervals = static_cast<int>(std::lround(options.duration_s / load_interval_s));
  RunOutcome outcome;
  using Clock = std::chrono::steady_clock;
  for (int k = 0; k < intervals; ++k) {
    // The load of an interval is the tension at its middle: each scheme sees the same forcing.
    spread_load(patch, tension_n(options, (k + 0.5) * load_interval_s) * kSeedPullDirection, loads);
    const auto start = Clock::now();
    accumulate(outcome.steps, advance(model, state, StepInputs{loads, {}}, load_interval_s));
    outcome.wall_s += std::chrono::duration<double>(Clock::now() - start).count();
    if (!state.position_m.at(patch.marked_node).allFinite())
      throw std::runtime_error(
          what + ": the motion stopped being finite at t = " + std::to_string(state.time_s) + " s");
    run_progress(static_cast<double>(k + 1) / intervals);
  }
  outcome.position_m = std::move(state.position_m);
  return outcome;
}

// The element holding material point X (or, outside the mesh, the nearest by barycentric
// coordinates) and X's barycentric coordinates in it.
std::pair<std::size_t, Eigen::Vector4d> locate(const SimModel& model, const Eigen::Vector3d& X) {
  std::size_t best = 0;
  Eigen::Vector4d best_weights = Eigen::Vector4d::Zero();
  double best_min = -std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const Eigen::Vector3d x0 = model.rest_position_m.at(model.corner[0][e]);
    const Eigen::Vector3d l = element_dm_inverse(model, e) * (X - x0);
    const Eigen::Vector4d w(1.0 - l.sum(), l.x(), l.y(), l.z());
    if (w.minCoeff() > best_min) {
      best_min = w.minCoeff();
      best = e;
      best_weights = w;
    }
  }
  return {best, best_weights};
}

Eigen::Vector3d displacement_at(const SimModel& model, const NodeArray& position,
                                const std::pair<std::size_t, Eigen::Vector4d>& where) {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (int c = 0; c < 4; ++c) {
    const NodeIndex n = model.corner[c][where.first];
    u += where.second[c] * (position.at(n) - model.rest_position_m.at(n));
  }
  return u;
}

NodeIndex nearest_surface_node(const TetMesh& mesh, const Eigen::Vector3d& point) {
  const BoundarySurface surface = extract_surface(mesh);
  NodeIndex best = surface.nodes.front();
  double best_distance = std::numeric_limits<double>::infinity();
  for (NodeIndex n : surface.nodes) {
    const double distance = (mesh.rest_position_m.at(n) - point).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best = n;
    }
  }
  return best;
}

void validate(const AccuracyStudyOptions& options, double load_interval_s) {
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  if (options.tet_counts.empty()) fail("the study needs at least one mesh size");
  if (options.effects.empty()) fail("the study needs at least one effect set");
  if (options.integrators.empty()) fail("the study needs at least one integrator");
  if (!(options.duration_s > 0.0) || !std::isfinite(options.duration_s))
    fail("the duration must be a finite time > 0 s");
  if (!std::isfinite(options.peak_force_n)) fail("the peak force must be finite");
  if (!(options.reference_refinement >= 2)) fail("the reference refinement must be at least 2");
  for (double step : options.steps_s) {
    if (!(step > 0.0) || !std::isfinite(step)) {
      std::ostringstream message;
      message << "step " << step << " s is invalid: expected a finite value > 0";
      fail(message.str());
    }
    const double ratio = load_interval_s / step;
    if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
      std::ostringstream message;
      message << "step " << step << " s does not divide the load interval " << load_interval_s
              << " s (the largest step): use steps that halve it";
      fail(message.str());
    }
  }
  for (double tolerance : options.tolerances_m)
    if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
      std::ostringstream message;
      message << "tolerance " << tolerance << " m is invalid: expected a finite value > 0";
      fail(message.str());
    }
  const double intervals = options.duration_s / load_interval_s;
  if (std::abs(intervals - std::round(intervals)) > 1e-9 * intervals || intervals < 1.0)
    fail("the duration must be a whole number of load intervals (the largest step)");
}

}  // namespace

AccuracyStudyResult run_accuracy_study(const AccuracyStudyOptions& options,
                                       const StudyProgress& progress) {
  const bool fixed_step_schemes =
      std::any_of(options.integrators.begin(), options.integrators.end(),
                  [](IntegratorKind k) { return k != IntegratorKind::dopri5; });
  if (fixed_step_schemes && options.steps_s.empty())
    throw std::invalid_argument("the study needs at least one step for its fixed-step schemes");
  const double largest_step =
      options.steps_s.empty() ? 1e-3
                              : *std::max_element(options.steps_s.begin(), options.steps_s.end());
  const double smallest_step =
      options.steps_s.empty() ? 1e-3
                              : *std::min_element(options.steps_s.begin(), options.steps_s.end());
  validate(options, largest_step);

  int runs_per_mesh = 1;  // the reference
  for (IntegratorKind kind : options.integrators)
    runs_per_mesh += static_cast<int>(kind == IntegratorKind::dopri5 ? options.tolerances_m.size()
                                                                     : options.steps_s.size());
  const int total =
      runs_per_mesh * static_cast<int>(options.tet_counts.size() * options.effects.size());
  StudyProgressReport report{0, total, {}, 0.0};
  auto report_progress = [&](double fraction_of_run) {
    report.fraction_of_run = fraction_of_run;
    if (progress && !progress(report)) throw StudyCancelled();
  };
  auto start_run = [&](std::string what) {
    report.running = std::move(what);
    report_progress(0.0);
  };

  // The finest mesh first: its marked node is the material point of the mesh comparison.
  std::vector<int> tet_counts = options.tet_counts;
  std::stable_sort(tet_counts.begin(), tet_counts.end(), std::greater<>());
  std::optional<Eigen::Vector3d> material_point;

  AccuracyStudyResult result;
  for (int tets : tet_counts) {
    const SceneSetup scene = default_scene(tets);
    // Every mesh is loaded at the same place: the finest mesh's marked point, or the surface
    // node of this mesh nearest to it.
    if (!material_point)
      material_point = scene.mesh.rest_position_m.at(anterior_marked_node(scene.mesh));
    const NodeIndex marked = nearest_surface_node(scene.mesh, *material_point);
    for (StudyEffects effects : options.effects) {
      ModelOptions base = scene.model_options;
      apply_study_effects(effects, base);
      std::ostringstream label;
      label << scene.mesh.tet_count() << " tets, " << study_effects_name(effects);

      ModelOptions reference_options = base;
      reference_options.integrator.kind = IntegratorKind::rk4;
      reference_options.integrator.step_s = smallest_step / options.reference_refinement;
      start_run(label.str() + ": reference");
      const SimModel reference_model = build_model(scene.mesh, reference_options);
      const LoadPatch patch =
          make_load_patch(scene.mesh, reference_model, marked, options.load_radius_m);
      const RunOutcome reference = run_case(reference_model, patch, options, largest_step,
                                            label.str() + " reference", report_progress);
      ++report.runs_done;
      MeshConvergenceRow mesh_row;
      mesh_row.requested_tets = tets;
      mesh_row.tet_count = scene.mesh.tet_count();
      mesh_row.effects = effects;
      mesh_row.displacement_m = displacement_at(reference_model, reference.position_m,
                                                locate(reference_model, *material_point));
      mesh_row.reference_wall_s = reference.wall_s;
      result.mesh_rows.push_back(mesh_row);

      for (IntegratorKind kind : options.integrators) {
        const bool adaptive = kind == IntegratorKind::dopri5;
        const std::vector<double>& settings = adaptive ? options.tolerances_m : options.steps_s;
        for (double setting : settings) {
          ModelOptions run_options = base;
          run_options.integrator.kind = kind;
          run_options.integrator.step_s = adaptive ? 0.0 : setting;
          if (adaptive) run_options.integrator.tolerance_m = setting;
          std::ostringstream what;
          what << label.str() << ", " << integrator_name(kind)
               << (adaptive ? ", tolerance " : ", step ") << setting << (adaptive ? " m" : " s");
          start_run(what.str());
          const SimModel model = build_model(scene.mesh, run_options);
          const RunOutcome run =
              run_case(model, patch, options, largest_step, what.str(), report_progress);
          ++report.runs_done;
          AccuracyStudyRow row;
          row.requested_tets = tets;
          row.tet_count = scene.mesh.tet_count();
          row.effects = effects;
          row.integrator = kind;
          row.step_s = adaptive ? 0.0 : setting;
          row.tolerance_m = adaptive ? setting : 0.0;
          row.marked_point_error_m =
              (run.position_m.at(marked) - reference.position_m.at(marked)).norm();
          for (std::size_t n = 0; n < model.node_count; ++n)
            row.max_node_error_m = std::max(
                row.max_node_error_m, (run.position_m.at(n) - reference.position_m.at(n)).norm());
          row.displacement_m =
              (run.position_m.at(marked) - scene.mesh.rest_position_m.at(marked)).norm();
          row.wall_s = run.wall_s;
          row.steps = run.steps;
          result.rows.push_back(row);
        }
      }
    }
  }
  // Differences from the finest mesh of the same effects.
  for (MeshConvergenceRow& row : result.mesh_rows)
    for (const MeshConvergenceRow& finest : result.mesh_rows)
      if (finest.effects == row.effects && finest.requested_tets == tet_counts.front())
        row.difference_from_finest_m = (row.displacement_m - finest.displacement_m).norm();
  start_run("done");
  return result;
}

std::vector<bool> pareto_front(const std::vector<const AccuracyStudyRow*>& runs) {
  std::vector<bool> on_front(runs.size(), true);
  for (std::size_t i = 0; i < runs.size(); ++i)
    for (std::size_t j = 0; j < runs.size(); ++j)
      if (i != j && runs[j]->max_node_error_m <= runs[i]->max_node_error_m &&
          runs[j]->wall_s <= runs[i]->wall_s &&
          (runs[j]->max_node_error_m < runs[i]->max_node_error_m ||
           runs[j]->wall_s < runs[i]->wall_s))
        on_front[i] = false;
  return on_front;
}

void write_accuracy_study_csv(std::ostream& csv, const AccuracyStudyOptions& options,
                              const AccuracyStudyResult& result) {
  csv << "tets,effects,integrator,step_s,tolerance_m,mean_step_s,stability_limited_steps,"
         "smallest_stable_step_s,marked_point_error_m,max_node_error_m,displacement_m,wall_s,"
         "wall_per_simulated_s,force_evaluations,linear_solves,factorizations,newton_iterations,"
         "rejected_steps,unconverged_steps,error_estimate_m\n";
  const auto precision = csv.precision(8);
  for (const AccuracyStudyRow& row : result.rows)
    csv << row.tet_count << ',' << study_effects_name(row.effects) << ','
        << integrator_name(row.integrator) << ',' << row.step_s << ',' << row.tolerance_m << ','
        << row.mean_step_s(options) << ',' << row.steps.stability_limited_steps << ','
        << row.steps.smallest_stable_step_s << ',' << row.marked_point_error_m << ','
        << row.max_node_error_m << ',' << row.displacement_m << ',' << row.wall_s << ','
        << row.wall_per_simulated_s(options) << ',' << row.steps.force_evaluations << ','
        << row.steps.linear_solves << ',' << row.steps.factorizations << ','
        << row.steps.newton_iterations << ',' << row.steps.rejected_steps << ','
        << row.steps.unconverged_steps << ',' << row.steps.error_estimate_m << '\n';
  csv.precision(precision);
}

}  // namespace liversim
