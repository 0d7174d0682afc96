#pragma once
// Gradable metrics that need the simulation, not only the servo trace: tissue damage, resected
// volume, each lesion's margin and breach, the cut's deviation from the planned plane, and task
// success. Defined precisely in docs/session-metrics.md. Geometry is measured in the rest
// (material) configuration, where a scenario places its lesions and planned plane: a margin is a
// property of the tissue, not of how it happens to be stretched at the end.

#include "liversim/core/cutting.h"
#include "liversim/core/model.h"
#include "liversim/core/scenario.h"
#include "liversim/core/session_log.h"
#include "liversim/core/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace liversim {

struct OutcomeSettings {
  // An element is damaged once a principal stretch exceeds 1 + tension strain (tissue tears in
  // tension: the parenchyma's failure strain is of this order) or falls below 1 − compression
  // strain (it crushes only at larger strains). Assumed values, not fitted to data.
  double damage_tension_strain = 0.3;
  double damage_compression_strain = 0.5;
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

// Whether a principal stretch of the deformation gradient leaves [1 − compression, 1 + tension].
bool strained_beyond(const Eigen::Matrix3d& deformation_gradient, double tension_strain,
                     double compression_strain);

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

// Follows a session's simulation for what its end alone cannot tell: which tissue was ever
// strained past the damage strain, how far the retraction point was lifted, what cuts took out.
// Observed once per published simulation cycle (not per step); observe() allocates nothing.
class OutcomeTracker {
 public:
  // `lift_point_m`: the retraction task's grasp point (rest), followed through the node nearest to
  // it; none for other tasks.
  OutcomeTracker(const SimModel& model, std::optional<Eigen::Vector3d> lift_point_m,
                 OutcomeSettings settings = {});

  void observe(const SimModel& model, const NodeArray& position_m);
  // After a cut replaced the model: damage follows each element's origin; the node followed for
  // the lift, its first copy; the resected volume adds up.
  void carry_over(const CutResult& cut);

  // Rest volume of the model's elements that were ever damaged (taken-out pieces no longer count).
  double damaged_volume_m3(const SimModel& model) const;
  double resected_volume_m3() const { return resected_volume_m3_; }
  double largest_lift_m() const { return largest_lift_m_; }
  const OutcomeSettings& settings() const { return settings_; }
  // Per element of the current model: ever damaged.
  std::span<const std::uint8_t> damaged() const { return damaged_; }

 private:
  OutcomeSettings settings_;
  std::vector<std::uint8_t> damaged_;
  double resected_volume_m3_ = 0.0;
  std::optional<NodeIndex> lift_node_;
  double largest_lift_m_ = 0.0;
};

struct LesionOutcome {
  std::string name;
  std::optional<LesionMargin> margin;  // none before any cut
  bool removed = false;                // none of its elements remain in the organ
};

struct OutcomeMetrics {
  double tissue_damage_mm3 = 0.0;
  double resected_volume_mm3 = 0.0;
  std::vector<LesionOutcome> lesions;        // in the scenario's order
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
                                       std::span<const Eigen::Vector3d> marks_m);

// Under their gradable names (gradable_metrics()): the task's lesion (or, with none named, the
// least margin and any breach over all lesions) as lesion_margin_mm and lesion_breached, and each
// lesion again as "lesion_margin_mm:NAME" and "lesion_breached:NAME". Metrics that are undefined
// (no cut: no margin or plane deviation) are left out.
std::vector<MetricValue> outcome_metric_values(const OutcomeMetrics& metrics,
                                               const Scenario* scenario);

}  // namespace liversim
