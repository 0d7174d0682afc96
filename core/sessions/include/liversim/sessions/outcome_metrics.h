#pragma once
// Gradable metrics that need the simulation, not only the servo trace: tissue damage, resected
// volume, each lesion's margin and breach, the cut's deviation from the planned plane, and task
// success. Defined precisely in docs/session-metrics.md. Geometry is measured in the rest
// (material) configuration, where a scenario places its lesions and planned plane: a margin is a
// property of the tissue, not of how it happens to be stretched at the end.

#include "liversim/engine/model.h"
#include "liversim/engine/tet_mesh.h"
#include "liversim/interaction/cutting.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_store.h"
#include "liversim/simulation/tissue_outcome.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace liversim {

// How a session's outcome is measured at its end (the tissue damage is followed while it runs,
// tissue_outcome.h).
struct OutcomeSettings {
  // Cut triangles are sampled this finely for a lesion's margin, which is then at most this much
  // above the exact least distance (never below it).
  double margin_sample_spacing_mm = 0.5;
  // Palpation: a mark locates the lesion when it is no farther from the lesion than the lesion's
  // shallowest depth under the organ's surface plus this.
  double mark_tolerance_mm = 5.0;
};

// An axis-aligned ellipsoid (a lesion), metres.
struct Ellipsoid {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d radii_m = Eigen::Vector3d::Ones();
};
Ellipsoid lesion_ellipsoid(const LesionSpec& lesion);

// Distance from a point to the ellipsoid (0 inside or on it): the exact nearest point on its
// surface, by bisection on the Lagrange multiplier (to round-off).
double distance_to_ellipsoid_m(const Eigen::Vector3d& point_m, const Ellipsoid& ellipsoid);
// Whether the triangle touches the solid ellipsoid (exact: closest point of the triangle to the
// centre once the ellipsoid is scaled to a unit ball).
bool triangle_meets_ellipsoid(const std::array<Eigen::Vector3d, 3>& triangle_m,
                              const Ellipsoid& ellipsoid);

// The faces made by cuts, in rest coordinates (each cut leaves two coincident faces, one per
// side; both are listed, which changes no minimum or mean).
std::vector<std::array<Eigen::Vector3d, 3>> cut_surface_at_rest_m(const SimModel& model);

// The area-weighted mean of |distance| from the plane over the triangles (exact for flat
// triangles); none without triangles of positive area.
std::optional<double> mean_plane_distance_m(std::span<const std::array<Eigen::Vector3d, 3>> tris,
                                            const PlaneSpec& plane);

struct LesionMargin {
  double margin_m = 0.0;  // least distance from the triangles to the lesion; 0 when breached
  bool breached = false;  // a triangle enters the lesion
};
// None without triangles.
std::optional<LesionMargin> lesion_margin(std::span<const std::array<Eigen::Vector3d, 3>> tris,
                                          const Ellipsoid& lesion, double sample_spacing_m);

// The rest point of the organ's surface nearest to `point_m` in the deformed configuration
// `position_m` (e.g. under a probe's tip): the nearest point of the deformed boundary, carried to
// rest by its barycentric weights. Where a trainee marks a lesion.
Eigen::Vector3d rest_point_nearest(const SimModel& model, const NodeArray& position_m,
                                   const Eigen::Vector3d& point_m);

struct LesionOutcome {
  std::string name;
  std::optional<LesionMargin> margin;  // none before any cut
  bool removed = false;                // none of its elements remain in the organ
};

// A specimen (a piece a cut freed, taken out or still in the field) and each lesion with tissue in
// it: whether the whole lesion is in it (none of the lesion's elements anywhere else), and the
// least distance from the lesion to the specimen's cut faces at rest (breached: they meet it).
struct SpecimenLesion {
  std::string name;
  bool whole = false;
  std::optional<LesionMargin> margin;
};
struct SpecimenOutcome {
  double volume_mm3 = 0.0;  // at rest
  bool taken_out = false;   // out of the field; else still in it at the end
  std::vector<SpecimenLesion> lesions;
};

struct OutcomeMetrics {
  double tissue_damage_mm3 = 0.0;
  double resected_volume_mm3 = 0.0;
  std::vector<LesionOutcome> lesions;        // in the scenario's order
  std::vector<SpecimenOutcome> specimens;    // taken out in order, then those still in the field
  std::optional<double> plane_deviation_mm;  // with a planned plane and a cut
  double lift_mm = 0.0;                      // retraction: the largest lift of the grasp point
  std::optional<bool> task_success;          // none without a scenario
};

// At the end of a session. `final_model` is the organ as it ends (after its cuts; lesions are
// regions 1, 2, … in the scenario's order, as build_scene makes them); `initial_model` before any
// cut; `marks_m`: the rest points the trainee marked (palpation). Without a scenario (free
// practice) there is no lesion, plane or task.
OutcomeMetrics compute_outcome_metrics(const SimModel& initial_model, const SimModel& final_model,
                                       const OutcomeTracker& tracker, const Scenario* scenario,
                                       std::span<const Eigen::Vector3d> marks_m,
                                       const OutcomeSettings& settings = {});

// Under their gradable names (gradable_metrics()): the task's lesion (or, with none named, the
// least margin and any breach over all lesions) as lesion_margin_mm and lesion_breached, and each
// lesion again as "lesion_margin_mm:NAME" and "lesion_breached:NAME". The specimen: its volume
// (all specimens), whether the task's lesion (with none named: every lesion) is whole in one
// (specimen_contains_lesion), its margin there (specimen_margin_mm, and per lesion
// "specimen_margin_mm:NAME"), and for a resection task whether that is R0 (specimen_r0: whole, not
// breached, margin at least the task's). Metrics that are undefined (no cut: no margin or plane
// deviation; no lesion whole in a specimen: no specimen margin) are left out.
std::vector<MetricValue> outcome_metric_values(const OutcomeMetrics& metrics,
                                               const Scenario* scenario);
// The specimen's of them.
void append_specimen_values(const OutcomeMetrics& metrics, const Scenario* scenario,
                            std::vector<MetricValue>& values);

}  // namespace liversim
