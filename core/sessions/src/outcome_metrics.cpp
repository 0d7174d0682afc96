#include "liversim/sessions/outcome_metrics.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/surface.h"
#include "liversim/interaction/tools.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace liversim {

namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

double triangle_area(const Triangle& t) {
  return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
}

std::optional<std::size_t> lesion_index(const Scenario& scenario, const std::string& name) {
  for (std::size_t i = 0; i < scenario.lesions.size(); ++i)
    if (scenario.lesions[i].name == name) return i;
  return std::nullopt;
}

// The organ's outer surface (not cut faces) of a model before any cut, at rest.
std::vector<Triangle> outer_surface_at_rest_m(const SimModel& model) {
  const BoundarySurface surface = boundary_surface(model);
  const std::vector<std::uint8_t> cut = cut_face_flags(model, surface);
  std::vector<Triangle> triangles;
  for (std::size_t i = 0; i < surface.triangles.size(); ++i) {
    if (!cut.empty() && cut[i]) continue;
    Triangle t;
    for (int k = 0; k < 3; ++k)
      t[k] = model.rest_position_m.at(surface.nodes[surface.triangles[i][k]]);
    triangles.push_back(t);
  }
  return triangles;
}

// The lesion of each region (regions 1, 2, … are the scenario's lesions in order), or none.
const LesionSpec* lesion_of_region(const Scenario& scenario, std::int32_t region) {
  if (region < 1 || static_cast<std::size_t>(region) > scenario.lesions.size()) return nullptr;
  return &scenario.lesions[static_cast<std::size_t>(region - 1)];
}

std::vector<Triangle> cut_faces_of(const Specimen& specimen) {
  std::vector<Triangle> triangles;
  for (std::size_t e = 0; e < specimen.rest_corners_m.size(); ++e)
    for (int face = 0; face < 4; ++face)
      if (specimen.cut_face_mask[e] & (1u << face)) {
        Triangle t;
        for (int k = 0; k < 3; ++k) t[k] = specimen.rest_corners_m[e][kTetFace[face][k]];
        triangles.push_back(t);
      }
  return triangles;
}

std::vector<SpecimenOutcome> measure_specimens(const SimModel& final_model,
                                               const OutcomeTracker& tracker,
                                               const Scenario& scenario, double spacing_m) {
  std::vector<Specimen> specimens = tracker.specimens_taken_out();
  const std::size_t taken_out = specimens.size();
  for (const FreeBody& body : free_bodies(final_model))
    specimens.push_back(specimen_of(final_model, body.elements));
  // Where each lesion's elements are: the organ, and each specimen.
  const std::size_t lesions = scenario.lesions.size();
  std::vector<std::size_t> in_organ(lesions, 0);
  const std::vector<std::uint8_t> organ = organ_elements(final_model);
  for (std::size_t e = 0; e < final_model.tet_count; ++e)
    if (organ[e] && lesion_of_region(scenario, final_model.region[e]))
      ++in_organ[static_cast<std::size_t>(final_model.region[e] - 1)];
  std::vector<std::vector<std::size_t>> in_specimen(specimens.size(),
                                                    std::vector<std::size_t>(lesions, 0));
  for (std::size_t s = 0; s < specimens.size(); ++s)
    for (const std::int32_t region : specimens[s].region)
      if (lesion_of_region(scenario, region))
        ++in_specimen[s][static_cast<std::size_t>(region - 1)];

  std::vector<SpecimenOutcome> outcomes;
  for (std::size_t s = 0; s < specimens.size(); ++s) {
    SpecimenOutcome outcome;
    outcome.volume_mm3 = specimens[s].rest_volume_m3 * 1e9;
    outcome.taken_out = s < taken_out;
    const std::vector<Triangle> cut_faces = cut_faces_of(specimens[s]);
    for (std::size_t l = 0; l < lesions; ++l) {
      if (in_specimen[s][l] == 0) continue;
      SpecimenLesion lesion;
      lesion.name = scenario.lesions[l].name;
      std::size_t elsewhere = in_organ[l];
      for (std::size_t other = 0; other < specimens.size(); ++other)
        if (other != s) elsewhere += in_specimen[other][l];
      lesion.whole = elsewhere == 0;
      lesion.margin = lesion_margin(cut_faces, lesion_ellipsoid(scenario.lesions[l]), spacing_m);
      outcome.lesions.push_back(lesion);
    }
    outcomes.push_back(std::move(outcome));
  }
  return outcomes;
}

}  // namespace

Ellipsoid lesion_ellipsoid(const LesionSpec& lesion) {
  Ellipsoid e;
  for (int k = 0; k < 3; ++k) {
    e.centre_m[k] = lesion.centre_mm[k] * 1e-3;
    e.radii_m[k] = lesion.radii_mm[k] * 1e-3;
  }
  return e;
}

double distance_to_ellipsoid_m(const Eigen::Vector3d& point_m, const Ellipsoid& ellipsoid) {
  // In the ellipsoid's frame, by symmetry in the first octant: y ≥ 0.
  const Eigen::Vector3d y = (point_m - ellipsoid.centre_m).cwiseAbs();
  const Eigen::Vector3d& r = ellipsoid.radii_m;
  if (y.cwiseQuotient(r).squaredNorm() <= 1.0) return 0.0;
  // The nearest surface point is x_k = r_k² y_k / (t + r_k²) for the root t > 0 of
  // g(t) = Σ (r_k y_k / (t + r_k²))² − 1, which decreases from g(0) > 0 (outside) to
  // g(r_max·|y|) ≤ 0. Bisection to round-off.
  auto g = [&](double t) {
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double q = r[k] * y[k] / (t + r[k] * r[k]);
      sum += q * q;
    }
    return sum - 1.0;
  };
  double low = 0.0, high = r.maxCoeff() * y.norm();
  for (int i = 0; i < 200; ++i) {
    const double middle = 0.5 * (low + high);
    if (middle <= low || middle >= high) break;
    (g(middle) > 0.0 ? low : high) = middle;
  }
  const double t = 0.5 * (low + high);
  Eigen::Vector3d x;
  for (int k = 0; k < 3; ++k) x[k] = r[k] * r[k] * y[k] / (t + r[k] * r[k]);
  return (y - x).norm();
}

bool triangle_meets_ellipsoid(const Triangle& triangle_m, const Ellipsoid& ellipsoid) {
  // Scaling by 1/r maps the ellipsoid to the unit ball and the triangle to a triangle.
  Triangle scaled;
  for (int k = 0; k < 3; ++k)
    scaled[k] = (triangle_m[k] - ellipsoid.centre_m).cwiseQuotient(ellipsoid.radii_m);
  std::array<double, 3> weight;
  return closest_point_on_triangle(Eigen::Vector3d::Zero(), scaled[0], scaled[1], scaled[2], weight)
             .squaredNorm() <= 1.0;
}

std::vector<Triangle> cut_surface_at_rest_m(const SimModel& model) {
  std::vector<Triangle> triangles;
  if (model.cut_face_mask.empty()) return triangles;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const std::uint8_t mask = model.cut_face_mask[e];
    if (mask == 0) continue;
    for (int face = 0; face < 4; ++face) {
      if (!(mask & (1u << face))) continue;
      Triangle t;
      for (int k = 0; k < 3; ++k)
        t[k] = model.rest_position_m.at(model.corner[kTetFace[face][k]][e]);
      triangles.push_back(t);
    }
  }
  return triangles;
}

std::optional<double> mean_plane_distance_m(std::span<const Triangle> triangles,
                                            const PlaneSpec& plane) {
  const Eigen::Vector3d n =
      Eigen::Vector3d(plane.normal[0], plane.normal[1], plane.normal[2]).normalized();
  const Eigen::Vector3d origin(plane.point_mm[0] * 1e-3, plane.point_mm[1] * 1e-3,
                               plane.point_mm[2] * 1e-3);
  double area_sum = 0.0, integral = 0.0;
  for (const Triangle& t : triangles) {
    const double area = triangle_area(t);
    if (!(area > 0.0)) continue;
    std::array<double, 3> d;
    for (int k = 0; k < 3; ++k) d[k] = n.dot(t[k] - origin);
    // ∫|d| over a flat triangle, d linear: with one sign, area·|mean of the corners|. Where the
    // zero line crosses it, the corner of the odd sign cuts off a triangle of area fraction
    // s_a·s_b (s: where the zero falls along its two edges), over which ∫d = area·s_a·s_b·d/3.
    int odd = -1;
    for (int k = 0; k < 3; ++k) {
      const double a = d[(k + 1) % 3], b = d[(k + 2) % 3];
      if ((d[k] > 0.0 && a <= 0.0 && b <= 0.0) || (d[k] < 0.0 && a >= 0.0 && b >= 0.0)) odd = k;
    }
    const double whole = area * (d[0] + d[1] + d[2]) / 3.0;
    if (odd < 0) {
      integral += std::abs(whole);
    } else {
      const double c = d[odd], a = d[(odd + 1) % 3], b = d[(odd + 2) % 3];
      const double piece = area * (c / (c - a)) * (c / (c - b)) * c / 3.0;
      integral += std::abs(piece) + std::abs(whole - piece);
    }
    area_sum += area;
  }
  if (!(area_sum > 0.0)) return std::nullopt;
  return integral / area_sum;
}

std::optional<LesionMargin> lesion_margin(std::span<const Triangle> triangles,
                                          const Ellipsoid& lesion, double sample_spacing_m) {
  if (triangles.empty()) return std::nullopt;
  LesionMargin result;
  result.margin_m = std::numeric_limits<double>::infinity();
  for (const Triangle& t : triangles) {
    if (triangle_meets_ellipsoid(t, lesion)) return LesionMargin{0.0, true};
    // Distance to a convex set is 1-Lipschitz: a triangle whose farthest corner from its centroid
    // is R cannot come nearer than d(centroid) − R.
    const Eigen::Vector3d centroid = (t[0] + t[1] + t[2]) / 3.0;
    double reach = 0.0;
    for (const Eigen::Vector3d& corner : t) reach = std::max(reach, (corner - centroid).norm());
    if (distance_to_ellipsoid_m(centroid, lesion) - reach >= result.margin_m) continue;
    // A grid of n subdivisions: every point of the triangle is within its longest edge / n
    // (≤ the spacing) of a grid point, so the least sampled distance overstates by at most that.
    const double longest =
        std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / sample_spacing_m)));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
        const Eigen::Vector3d p = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
        result.margin_m = std::min(result.margin_m, distance_to_ellipsoid_m(p, lesion));
      }
  }
  return result;
}

Eigen::Vector3d rest_point_nearest(const SimModel& model, const NodeArray& position_m,
                                   const Eigen::Vector3d& point_m) {
  const BoundarySurface surface = boundary_surface(model);
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d rest = point_m;
  for (const auto& t : surface.triangles) {
    std::array<NodeIndex, 3> node;
    for (int k = 0; k < 3; ++k) node[k] = surface.nodes[t[k]];
    std::array<double, 3> weight;
    const Eigen::Vector3d nearest = closest_point_on_triangle(
        point_m, position_m.at(node[0]), position_m.at(node[1]), position_m.at(node[2]), weight);
    const double d = (nearest - point_m).squaredNorm();
    if (d >= best) continue;
    best = d;
    rest = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) rest += weight[k] * model.rest_position_m.at(node[k]);
  }
  return rest;
}

OutcomeMetrics compute_outcome_metrics(const SimModel& initial_model, const SimModel& final_model,
                                       const OutcomeTracker& tracker, const Scenario* scenario,
                                       std::span<const Eigen::Vector3d> marks_m,
                                       const OutcomeSettings& settings) {
  OutcomeMetrics m;
  m.tissue_damage_mm3 = tracker.damaged_volume_m3(final_model) * 1e9;
  m.resected_volume_mm3 = tracker.resected_volume_m3() * 1e9;
  m.lift_mm = tracker.largest_lift_m() * 1e3;
  if (scenario == nullptr) return m;

  const std::vector<Triangle> cut_surface = cut_surface_at_rest_m(final_model);
  const std::vector<std::uint8_t> organ = organ_elements(final_model);
  const double spacing_m = settings.margin_sample_spacing_mm * 1e-3;
  for (std::size_t i = 0; i < scenario->lesions.size(); ++i) {
    LesionOutcome lesion;
    lesion.name = scenario->lesions[i].name;
    lesion.margin = lesion_margin(cut_surface, lesion_ellipsoid(scenario->lesions[i]), spacing_m);
    const auto region = static_cast<std::int32_t>(i + 1);
    const bool initially_there = std::find(initial_model.region.begin(), initial_model.region.end(),
                                           region) != initial_model.region.end();
    // Out of the organ: taken out, or in a free body (a specimen still in the field).
    bool in_organ = false;
    for (std::size_t e = 0; e < final_model.tet_count && !in_organ; ++e)
      in_organ = organ[e] && final_model.region[e] == region;
    lesion.removed = initially_there && !in_organ;
    m.lesions.push_back(lesion);
  }
  m.specimens = measure_specimens(final_model, tracker, *scenario, spacing_m);
  const TaskSpec& task = scenario->task;
  if (task.planned_plane)
    if (const auto deviation = mean_plane_distance_m(cut_surface, *task.planned_plane))
      m.plane_deviation_mm = *deviation * 1e3;

  const std::optional<std::size_t> target = lesion_index(*scenario, task.lesion);
  switch (task.kind) {
    case TaskKind::palpate_lesion: {
      bool located = false;
      if (target) {
        const Ellipsoid lesion = lesion_ellipsoid(scenario->lesions[*target]);
        const std::vector<Triangle> outer = outer_surface_at_rest_m(initial_model);
        const std::optional<LesionMargin> depth = lesion_margin(outer, lesion, spacing_m);
        const double reach_m = (depth ? depth->margin_m : 0.0) + settings.mark_tolerance_mm * 1e-3;
        for (const Eigen::Vector3d& mark : marks_m)
          located = located || distance_to_ellipsoid_m(mark, lesion) <= reach_m;
      }
      m.task_success = located;
      break;
    }
    case TaskKind::retract_lobe:
      m.task_success = m.lift_mm >= task.lift_mm;
      break;
    case TaskKind::resect_lesion: {
      bool success = false;
      if (target) {
        const LesionOutcome& lesion = m.lesions[*target];
        success = lesion.removed && lesion.margin && !lesion.margin->breached &&
                  lesion.margin->margin_m * 1e3 >= task.margin_mm;
      }
      m.task_success = success;
      break;
    }
  }
  return m;
}

std::vector<MetricValue> outcome_metric_values(const OutcomeMetrics& m, const Scenario* scenario) {
  std::vector<MetricValue> values{{"tissue_damage_mm3", m.tissue_damage_mm3},
                                  {"resected_volume_mm3", m.resected_volume_mm3}};
  std::optional<LesionMargin> graded;  // the task's lesion, or the least over all
  for (const LesionOutcome& lesion : m.lesions) {
    if (!lesion.margin) continue;
    values.push_back({"lesion_margin_mm:" + lesion.name, lesion.margin->margin_m * 1e3});
    values.push_back({"lesion_breached:" + lesion.name, lesion.margin->breached ? 1.0 : 0.0});
    const bool task_lesion = scenario != nullptr && scenario->task.lesion == lesion.name;
    if (task_lesion) {
      graded = lesion.margin;
    } else if (scenario == nullptr || scenario->task.lesion.empty()) {
      if (!graded) graded = lesion.margin;
      graded->margin_m = std::min(graded->margin_m, lesion.margin->margin_m);
      graded->breached = graded->breached || lesion.margin->breached;
    }
  }
  if (graded) {
    values.push_back({"lesion_margin_mm", graded->margin_m * 1e3});
    values.push_back({"lesion_breached", graded->breached ? 1.0 : 0.0});
  }
  append_specimen_values(m, scenario, values);
  if (m.plane_deviation_mm) values.push_back({"plane_deviation_mm", *m.plane_deviation_mm});
  if (m.task_success) values.push_back({"task_success", *m.task_success ? 1.0 : 0.0});
  return values;
}

void append_specimen_values(const OutcomeMetrics& m, const Scenario* scenario,
                            std::vector<MetricValue>& values) {
  if (scenario == nullptr) return;
  double volume_mm3 = 0.0;
  for (const SpecimenOutcome& specimen : m.specimens) volume_mm3 += specimen.volume_mm3;
  if (!m.specimens.empty()) values.push_back({"specimen_volume_mm3", volume_mm3});
  if (scenario->lesions.empty()) return;
  // Each lesion: the specimen holding it whole, if any.
  auto whole_in_specimen = [&](const std::string& name) -> const SpecimenLesion* {
    for (const SpecimenOutcome& specimen : m.specimens)
      for (const SpecimenLesion& lesion : specimen.lesions)
        if (lesion.name == name && lesion.whole) return &lesion;
    return nullptr;
  };
  const std::string& task_lesion = scenario->task.lesion;
  bool contains = true;
  std::optional<LesionMargin> graded;
  for (const LesionSpec& spec : scenario->lesions) {
    const bool graded_lesion = task_lesion.empty() || spec.name == task_lesion;
    const SpecimenLesion* lesion = whole_in_specimen(spec.name);
    if (graded_lesion) contains = contains && lesion != nullptr;
    if (lesion == nullptr || !lesion->margin) continue;
    values.push_back({"specimen_margin_mm:" + spec.name, lesion->margin->margin_m * 1e3});
    if (!graded_lesion) continue;
    if (!graded) graded = lesion->margin;
    graded->margin_m = std::min(graded->margin_m, lesion->margin->margin_m);
    graded->breached = graded->breached || lesion->margin->breached;
  }
  values.push_back({"specimen_contains_lesion", contains ? 1.0 : 0.0});
  if (contains && graded) values.push_back({"specimen_margin_mm", graded->margin_m * 1e3});
  if (scenario->task.kind == TaskKind::resect_lesion)
    values.push_back({"specimen_r0", contains && graded && !graded->breached &&
                                             graded->margin_m * 1e3 >= scenario->task.margin_mm
                                         ? 1.0
                                         : 0.0});
}

}  // namespace liversim
