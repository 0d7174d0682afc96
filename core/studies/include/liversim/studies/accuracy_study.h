#pragma once
// "What accuracy costs in time": runs the seed's loaded-liver experiment over a grid of
// integrator × step (or tolerance) × mesh size × enabled effects, and measures each run's error
// against a reference and its cost. The CLI's `study accuracy` writes the results as CSV, plots
// and a report (docs/accuracy-study.md).

#include "liversim/engine/integrator.h"

#include <functional>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

// Which effects the study's tissue has (docs/accuracy-study.md gives the assumed parameters).
enum class StudyEffects {
  elastic,       // Neo-Hookean, ν = 0.49, average nodal pressure (the default scene)
  viscoelastic,  // + the seed's three-element viscoelasticity (Eq. 1–3)
  viscoplastic,  // + viscoplastic flow above a yield limit (Eq. 4): non-smooth at the yield
  fibres,        // elastic + one HGO fibre family (Eq. 5–6)
};
inline constexpr StudyEffects kAllStudyEffects[] = {
    StudyEffects::elastic, StudyEffects::viscoelastic, StudyEffects::viscoplastic,
    StudyEffects::fibres};
std::string_view study_effects_name(StudyEffects effects);
std::optional<StudyEffects> study_effects_from_name(std::string_view name);
// Sets region 0's tissue to the study's (E = 3500 Pa, ν = 0.49) and adds the effect set's laws;
// adds to what `options` already has, so sets can be combined (viscoplastic, then fibres).
void apply_study_effects(StudyEffects effects, ModelOptions& options);

struct AccuracyStudyOptions {
  std::vector<int> tet_counts{3841};  // built-in liver sizes; the last (largest) is the finest
  std::vector<StudyEffects> effects{StudyEffects::elastic};
  std::vector<IntegratorKind> integrators{std::begin(kAllIntegrators), std::end(kAllIntegrators)};
  std::vector<double> steps_s{1e-3, 5e-4, 2.5e-4};      // fixed-step schemes
  std::vector<double> tolerances_m{1e-7, 1e-9, 1e-11};  // dopri5
  // The seed's tension at the marked point, rising smoothly (C¹, x²(3 − 2x)) from 0 to the peak
  // over the whole run. It is updated once per load interval (the largest step), so every step
  // divides it and each scheme sees the same forcing, piecewise constant.
  double duration_s = 0.05;
  double peak_force_n = 0.63;
  double load_radius_m = 0.02;
  // The reference of each mesh: RK4 at the smallest step / reference_refinement.
  int reference_refinement = 64;
};

struct AccuracyStudyRow {
  int requested_tets = 0;
  std::size_t tet_count = 0;
  StudyEffects effects = StudyEffects::elastic;
  IntegratorKind integrator = IntegratorKind::central_difference;
  double step_s = 0.0;       // requested (fixed-step schemes; 0 for dopri5)
  double tolerance_m = 0.0;  // dopri5
  // Position error at the end: of the marked point, and the largest over all nodes.
  double marked_point_error_m = 0.0;
  double max_node_error_m = 0.0;
  double displacement_m = 0.0;  // |u| of the marked point at the end
  double wall_s = 0.0;          // wall time of the advance() calls only
  StepReport steps;
  double wall_per_simulated_s(const AccuracyStudyOptions& options) const {
    return wall_s / options.duration_s;
  }
  // The step the scheme actually took on average (stability-limited explicit steps are shorter
  // than requested).
  double mean_step_s(const AccuracyStudyOptions& options) const {
    return options.duration_s / steps.substeps;
  }
};

// Discretisation error in space: the reference answer of each mesh against the finest mesh's, at
// the same material point (the finest mesh's marked node, interpolated in each mesh). Every mesh
// is loaded at its surface node nearest to that point.
struct MeshConvergenceRow {
  int requested_tets = 0;
  std::size_t tet_count = 0;
  StudyEffects effects = StudyEffects::elastic;
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero();  // at the material point, reference
  double difference_from_finest_m = 0.0;                     // |u − u_finest|
  double reference_wall_s = 0.0;
};

struct AccuracyStudyResult {
  std::vector<AccuracyStudyRow> rows;
  std::vector<MeshConvergenceRow> mesh_rows;
};

// Observed order between two runs of one scheme: log(e₁/e₂)/log(Δt₁/Δt₂). NaN if either error is
// not positive or either run was stability-limited (its step was not the requested one).
double observed_order(const AccuracyStudyRow& coarse, const AccuracyStudyRow& fine);

// Where a study is: runs finished, runs in all, the run under way and how far it has got (0 at
// its start, then after each load interval), so a reference run of many small steps still shows
// progress and can be cancelled.
struct StudyProgressReport {
  int runs_done = 0;
  int runs_total = 0;
  std::string running;  // "3841 tets, elastic, rk4, step 0.0005 s"; "done" at the end
  double fraction_of_run = 0.0;
};
// Returning false cancels the study (StudyCancelled).
using StudyProgress = std::function<bool(const StudyProgressReport&)>;

struct StudyCancelled : std::runtime_error {
  StudyCancelled() : std::runtime_error("the accuracy study was cancelled") {}
};

// Throws std::invalid_argument naming a bad option (empty lists, non-positive steps or
// tolerances, a step that does not divide the load interval), std::runtime_error when a run
// stops being finite, and StudyCancelled when `progress` returns false.
AccuracyStudyResult run_accuracy_study(const AccuracyStudyOptions& options,
                                       const StudyProgress& progress = {});

// The runs of one mesh and effect set that no other run of theirs beats in both error (largest
// over the nodes) and cost (wall time): the best trade-offs. True at the index of each.
std::vector<bool> pareto_front(const std::vector<const AccuracyStudyRow*>& runs);

// One line per run, with a header: what `study accuracy` writes to accuracy-study.csv.
void write_accuracy_study_csv(std::ostream& csv, const AccuracyStudyOptions& options,
                              const AccuracyStudyResult& result);

}  // namespace liversim
