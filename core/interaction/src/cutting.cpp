#include "liversim/interaction/cutting.h"
#include "liversim/engine/validation_message.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/model_building.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <span>
#include <stdexcept>
#include <utility>

namespace liversim {

std::optional<std::string> validate(const CuttingSettings& settings) {
  auto out_of_range = [](const char* name, double value, const char* expected) {
    return std::optional<std::string>(
        out_of_range_message(std::string("cutting setting ") + name, value, expected));
  };
  if (!std::isfinite(settings.cutting_stress_pa) || settings.cutting_stress_pa < 0.0)
    return out_of_range("cutting stress (Pa)", settings.cutting_stress_pa, "a finite value >= 0");
  if (!(settings.full_resistance_speed_m_per_s > 0.0) ||
      !std::isfinite(settings.full_resistance_speed_m_per_s))
    return out_of_range("full resistance speed (m/s)", settings.full_resistance_speed_m_per_s,
                        "a finite value > 0");
  if (!(settings.snap_fraction >= 0.0 && settings.snap_fraction <= 0.5))
    return out_of_range("snap fraction", settings.snap_fraction, "a value in [0, 0.5]");
  if (!(settings.snap_min_shape_fraction > 0.0 && settings.snap_min_shape_fraction < 1.0))
    return out_of_range("snap shape fraction", settings.snap_min_shape_fraction,
                        "a value in (0, 1)");
  if (!(settings.split_min_fraction > 0.0 && settings.split_min_fraction <= 0.5))
    return out_of_range("split fraction", settings.split_min_fraction, "a value in (0, 0.5]");
  if (!(settings.refine_edge_m >= 0.0) || !std::isfinite(settings.refine_edge_m))
    return out_of_range("refinement edge (m)", settings.refine_edge_m, "a finite value >= 0");
  if (!(settings.refine_over_stroke_m >= 0.0))  // infinity: all along
    return out_of_range("refinement stretch (m)", settings.refine_over_stroke_m,
                        "a value >= 0 (infinity: all along the stroke)");
  if (!(settings.min_part_height_m > 0.0) || !std::isfinite(settings.min_part_height_m))
    return out_of_range("smallest part height (m)", settings.min_part_height_m,
                        "a finite value > 0");
  if (!(settings.max_added_mass_fraction >= 0.0 && settings.max_added_mass_fraction <= 0.05))
    return out_of_range("added mass fraction", settings.max_added_mass_fraction,
                        "a value in [0, 0.05]");
  if (!(settings.min_free_body_volume_m3 >= 0.0))  // infinity: every piece taken out
    return out_of_range("smallest free body (m³)", settings.min_free_body_volume_m3,
                        "a value >= 0 (infinity: take every freed piece out)");
  if (!(settings.groove_guide_m >= 0.0) || !std::isfinite(settings.groove_guide_m))
    return out_of_range("groove guide (m)", settings.groove_guide_m, "a finite value >= 0");
  if (!(settings.hole_angle_deg >= 0.0 && settings.hole_angle_deg <= 45.0))
    return out_of_range("hole angle (°)", settings.hole_angle_deg, "a value in [0, 45]");
  return std::nullopt;
}

std::array<Eigen::Vector3d, 2> blade_edge_m(const Tool& scalpel) {
  std::array<Capsule, 3> parts;
  Tool blade = scalpel;
  blade.kind = ToolKind::scalpel;
  const int count = tool_capsules(blade, parts);
  const Capsule& edge = parts[count - 1];  // shaft, then blade
  return {edge.a_m, edge.b_m};
}

std::array<Eigen::Vector3d, 2> cutting_edge_m(const Tool& scalpel) {
  return {scalpel.pose.to_scene({0.0, 0.0, scalpel.geometry.shaft_length_m}),
          blade_edge_m(scalpel)[1]};
}

double element_cutting_stress_pa(const SimModel& model, const SimState& state, std::size_t e) {
  Eigen::Matrix3d F = deformation_gradient(model, state.position_m, e);
  if (model.effects.viscous && model.viscous_parameters[model.region[e]])
    F = F * state.viscous_history.inverse_plastic_deformation(e);
  const double J = F.determinant();
  if (!(J > 0.0)) return std::numeric_limits<double>::infinity();  // crushed: it gives way
  const Eigen::Matrix3d sigma = element_first_piola_stress(model, e, F) * F.transpose() / J;
  const Eigen::Matrix3d deviator = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * deviator.squaredNorm());
}

TetMesh model_mesh(const SimModel& model) {
  TetMesh mesh;
  mesh.rest_position_m = model.rest_position_m;
  mesh.corner = model.corner;
  mesh.region = model.region;
  return mesh;
}

BoundarySurface boundary_surface(const SimModel& model) {
  if (model.boundary_face_mask.empty()) return extract_surface(model_mesh(model));
  BoundarySurface surface;
  std::vector<std::int32_t> local(model.node_count, -1);
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int f = 0; f < 4; ++f)
      if ((model.boundary_face_mask[e] >> f) & 1)
        for (int k = 0; k < 3; ++k) local[model.corner[kTetFace[f][k]][e]] = 0;
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (local[n] == 0) {
      local[n] = static_cast<std::int32_t>(surface.nodes.size());
      surface.nodes.push_back(static_cast<NodeIndex>(n));
    }
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int f = 0; f < 4; ++f)
      if ((model.boundary_face_mask[e] >> f) & 1) {
        surface.triangles.push_back({local[model.corner[kTetFace[f][0]][e]],
                                     local[model.corner[kTetFace[f][1]][e]],
                                     local[model.corner[kTetFace[f][2]][e]]});
        surface.triangle_tet.push_back(static_cast<TetIndex>(e));
      }
  return surface;
}

std::vector<std::uint8_t> cut_face_flags(const SimModel& model, const BoundarySurface& surface) {
  std::vector<std::uint8_t> flags(surface.triangles.size(), 0);
  if (model.cut_face_mask.empty()) return flags;
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto e = static_cast<std::size_t>(surface.triangle_tet[t]);
    const std::uint8_t mask = model.cut_face_mask[e];
    if (mask == 0) continue;
    // The triangle is the face opposite the corner that is none of its nodes.
    for (int c = 0; c < 4; ++c) {
      const NodeIndex node = model.corner[c][e];
      bool on_triangle = false;
      for (auto local : surface.triangles[t]) on_triangle |= surface.nodes[local] == node;
      if (!on_triangle) flags[t] = (mask >> c) & 1;
    }
  }
  return flags;
}

namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;
constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

// The stroke's triangles, with the tolerance within which a point counts as on them, and a tree
// of boxes over runs of them in stroke order (neighbours in a stroke are neighbours in space):
// every query of a long stroke would otherwise visit all of its triangles.
struct SweepSurface {
  std::vector<Triangle> triangle;
  std::vector<Eigen::Vector3d> unit_normal;
  std::vector<Aabb> box;
  double tolerance_m = 0.0;

  // Node k covers triangles [first, end); its children are nodes child and child + 1 (0: leaf).
  struct RunNode {
    Aabb box;
    std::size_t first = 0, end = 0, child = 0;
  };
  std::vector<RunNode> run;
  static constexpr std::size_t kLeafTriangles = 4;

  std::size_t size() const { return triangle.size(); }

  void build_runs() {
    run.assign(1, RunNode{{}, 0, size(), 0});
    for (std::size_t k = 0; k < run.size(); ++k) {
      const std::size_t first = run[k].first, end = run[k].end;
      for (std::size_t t = first; t < end; ++t) run[k].box.grow(box[t]);
      if (end - first <= kLeafTriangles) continue;
      const std::size_t middle = first + (end - first) / 2;
      run[k].child = run.size();
      run.push_back(RunNode{{}, first, middle, 0});
      run.push_back(RunNode{{}, middle, end, 0});
    }
  }

  // Calls visit(t) for the triangles whose box overlaps `query`, in stroke order, until it
  // returns true; returns whether one did.
  template <typename Visit>
  bool first_overlapping(const Aabb& query, Visit&& visit, std::size_t k = 0) const {
    if (run.empty() || !run[k].box.overlaps(query)) return false;
    if (run[k].child == 0) {
      for (std::size_t t = run[k].first; t < run[k].end; ++t)
        if (box[t].overlaps(query) && visit(t)) return true;
      return false;
    }
    return first_overlapping(query, visit, run[k].child) ||
           first_overlapping(query, visit, run[k].child + 1);
  }

  double triangle_distance_m(std::size_t t, const Eigen::Vector3d& p) const {
    std::array<double, 3> weight;
    return (closest_point_on_triangle(p, triangle[t][0], triangle[t][1], triangle[t][2], weight) -
            p)
        .norm();
  }
  // Distance to the nearest triangle, and which it is (the first in stroke order of those as
  // near).
  std::pair<double, std::size_t> nearest(const Eigen::Vector3d& p) const {
    std::pair<double, std::size_t> best{std::numeric_limits<double>::infinity(), 0};
    if (!run.empty()) nearest_in(0, p, best);
    return best;
  }
  // Signed distance to the plane of the triangle nearest p.
  double side_distance_m(const Eigen::Vector3d& p, std::size_t nearest_triangle) const {
    return (p - triangle[nearest_triangle][0]).dot(unit_normal[nearest_triangle]);
  }
  double side_distance_m(const Eigen::Vector3d& p) const {
    return side_distance_m(p, nearest(p).second);
  }
  // Where segment [a, b] passes through a triangle (the first in stroke order), as the parameter
  // along it; none when it does not, or only within the tolerance at an end.
  std::optional<double> crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    std::optional<double> found;
    first_overlapping(Aabb::around(a, b, tolerance_m), [&](std::size_t t) {
      const double da = (a - triangle[t][0]).dot(unit_normal[t]);
      const double db = (b - triangle[t][0]).dot(unit_normal[t]);
      if (std::abs(da) <= tolerance_m || std::abs(db) <= tolerance_m || (da > 0.0) == (db > 0.0))
        return false;
      const double s = da / (da - db);
      if (triangle_distance_m(t, a + s * (b - a)) > tolerance_m) return false;
      found = s;
      return true;
    });
    return found;
  }

 private:
  static double box_distance_sq(const Aabb& b, const Eigen::Vector3d& p) {
    return (b.min_m - p).cwiseMax(p - b.max_m).cwiseMax(0.0).squaredNorm();
  }
  // Nearer child first; a box farther than the best so far cannot hold a nearer triangle (one as
  // near with a smaller index can only lie in a box as near, which is still visited).
  void nearest_in(std::size_t k, const Eigen::Vector3d& p,
                  std::pair<double, std::size_t>& best) const {
    if (box_distance_sq(run[k].box, p) > best.first * best.first) return;
    if (run[k].child == 0) {
      for (std::size_t t = run[k].first; t < run[k].end; ++t) {
        if (box_distance_sq(box[t], p) > best.first * best.first) continue;
        const double d = triangle_distance_m(t, p);
        if (d < best.first || (d == best.first && t < best.second)) best = {d, t};
      }
      return;
    }
    const std::size_t left = run[k].child, right = left + 1;
    const bool right_first = box_distance_sq(run[right].box, p) < box_distance_sq(run[left].box, p);
    nearest_in(right_first ? right : left, p, best);
    nearest_in(right_first ? left : right, p, best);
  }
};

// The blade's edge at one instant, heel to tip: its two ends, or more points where it follows a
// groove (bend_onto_grooves).
using EdgePoints = std::vector<Eigen::Vector3d>;

// The stroke's triangles, oriented alike (a stroke that turns back keeps one side one side);
// degenerate ones (the blade still, or moving along itself) are left out. Between two instants
// given by their ends, the triangles (heel_i, tip_i, tip_i+1) and (heel_i, tip_i+1, heel_i+1);
// between instants bent onto a groove (as many points each), those of each stretch, on the side
// of the straight ones (a stretch that climbs from a groove to the blade's own plane stands across
// it, and its own normal says nothing of the stroke's sides).
SweepSurface sweep_surface(const std::vector<EdgePoints>& edges,
                           std::span<const std::array<Eigen::Vector3d, 2>> straight) {
  SweepSurface surface;
  double extent = 0.0;
  auto normal_of = [](const Triangle& tri, double& longest) -> std::optional<Eigen::Vector3d> {
    const Eigen::Vector3d normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    longest =
        std::max({(tri[1] - tri[0]).norm(), (tri[2] - tri[1]).norm(), (tri[0] - tri[2]).norm()});
    if (!(longest > 0.0) || !(normal.norm() > 1e-12 * longest * longest)) return std::nullopt;
    return normal.normalized();
  };
  auto add = [&](const Triangle& tri, const Eigen::Vector3d* side) {
    double longest = 0.0;
    auto unit = normal_of(tri, longest);
    if (!unit) return;
    extent = std::max(extent, longest);
    if (side) {
      if (unit->dot(*side) < 0.0) *unit = -*unit;
    } else if (!surface.unit_normal.empty() && unit->dot(surface.unit_normal.front()) < 0.0) {
      *unit = -*unit;
    }
    surface.triangle.push_back(tri);
    surface.unit_normal.push_back(*unit);
  };
  // A bent edge's points by their parameter along the straight edge (0 at the heel, 1 at the tip:
  // a point is bent across the edge, so its parameter stays), and where it is at `t`.
  auto parameters = [](const EdgePoints& edge, const std::array<Eigen::Vector3d, 2>& straight) {
    const Eigen::Vector3d along = straight[1] - straight[0];
    std::vector<double> t(edge.size());
    for (std::size_t k = 0; k < edge.size(); ++k)
      t[k] = k == 0 ? 0.0
             : k + 1 == edge.size()
                 ? 1.0
                 : std::clamp((edge[k] - straight[0]).dot(along) / along.squaredNorm(), 0.0, 1.0);
    return t;
  };
  auto point_at = [](const EdgePoints& edge, const std::vector<double>& t, double at) {
    const auto k = static_cast<std::size_t>(
        std::clamp<std::ptrdiff_t>(std::upper_bound(t.begin(), t.end(), at) - t.begin(), 1,
                                   static_cast<std::ptrdiff_t>(t.size()) - 1));
    const double span = t[k] - t[k - 1];
    const double w = span > 0.0 ? (at - t[k - 1]) / span : 0.0;
    return Eigen::Vector3d(edge[k - 1] + w * (edge[k] - edge[k - 1]));
  };
  std::vector<double> ta, tb, at;
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    if (edges[i].size() == 2 && edges[i + 1].size() == 2) {
      const Eigen::Vector3d &heel0 = edges[i][0], &tip0 = edges[i][1];
      const Eigen::Vector3d &heel1 = edges[i + 1][0], &tip1 = edges[i + 1][1];
      add({heel0, tip0, tip1}, nullptr);
      add({heel0, tip1, heel1}, nullptr);
      continue;
    }
    // Both edges at the parameters of either's points.
    ta = parameters(edges[i], straight[i]);
    tb = parameters(edges[i + 1], straight[i + 1]);
    at.assign(ta.begin(), ta.end());
    at.insert(at.end(), tb.begin(), tb.end());
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    const EdgePoints &a0 = edges[i], &b0 = edges[i + 1];
    double longest = 0.0;
    auto side = normal_of({a0.front(), a0.back(), b0.back()}, longest);
    if (!side) side = normal_of({a0.front(), b0.back(), b0.front()}, longest);
    if (!side) continue;
    if (!surface.unit_normal.empty() && side->dot(surface.unit_normal.front()) < 0.0)
      *side = -*side;
    for (std::size_t k = 0; k + 1 < at.size(); ++k) {
      const Eigen::Vector3d a = point_at(a0, ta, at[k]), a1 = point_at(a0, ta, at[k + 1]);
      const Eigen::Vector3d b = point_at(b0, tb, at[k]), b1 = point_at(b0, tb, at[k + 1]);
      add({a, a1, b1}, &*side);
      add({a, b1, b}, &*side);
    }
  }
  surface.tolerance_m = 1e-9 * extent;
  for (const Triangle& tri : surface.triangle) {
    Aabb box;
    for (const auto& p : tri) box.grow(p);
    box.min_m.array() -= surface.tolerance_m;
    box.max_m.array() += surface.tolerance_m;
    surface.box.push_back(box);
  }
  surface.build_runs();
  return surface;
}

// The stroke's edges, each bent onto a cut already made where it runs beside one: a point of the
// edge within `guide_m` of a cut face's plane (along the sweep's normal there), the face within
// 10° of parallel to the sweep, is moved along that normal onto the plane, fully over the face and
// less the farther beyond its border (to nothing at `guide_m`), so that the stroke continues the
// cut from its front rather than cutting a sheet beside it. Points every kGuideSpacingM along the
// edge; an edge near no cut face keeps its two ends. Instants `first` on, appended to `edges`.
void bend_onto_grooves(const SimModel& model, const NodeArray& position_m,
                       const BladeStroke& stroke, std::size_t first, double guide_m,
                       std::vector<EdgePoints>& edges) {
  for (std::size_t i = first; i < stroke.edges_m.size(); ++i)
    edges.push_back({stroke.edges_m[i][0], stroke.edges_m[i][1]});
  if (!(guide_m > 0.0) || model.cut_face_mask.empty() || stroke.edges_m.size() < 2 ||
      first >= stroke.edges_m.size())
    return;
  Aabb stroke_box;
  for (std::size_t i = first; i < stroke.edges_m.size(); ++i)
    stroke_box.grow(Aabb::around(stroke.edges_m[i][0], stroke.edges_m[i][1], guide_m));
  struct CutFace {
    Triangle corner;
    Eigen::Vector3d unit_normal;  // outward from its element
    Aabb near;                    // its box grown by guide_m
  };
  std::vector<CutFace> faces;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const std::uint8_t mask = model.cut_face_mask[e];
    if (mask == 0) continue;
    for (int f = 0; f < 4; ++f) {
      if (!((mask >> f) & 1)) continue;
      CutFace face;
      for (int k = 0; k < 3; ++k) face.corner[k] = position_m.at(model.corner[kTetFace[f][k]][e]);
      face.near = Aabb::around(face.corner[0], face.corner[1], guide_m);
      face.near.grow(Aabb::around(face.corner[2], face.corner[2], guide_m));
      if (!face.near.overlaps(stroke_box)) continue;
      const Eigen::Vector3d normal =
          (face.corner[1] - face.corner[0]).cross(face.corner[2] - face.corner[0]);
      if (!(normal.norm() > 0.0)) continue;
      // Outward from its element: away from the corner across from it.
      const Eigen::Vector3d across = position_m.at(model.corner[f][e]) - face.corner[0];
      face.unit_normal = (across.dot(normal) > 0.0 ? -normal : normal).normalized();
      faces.push_back(face);
    }
  }
  if (faces.empty()) return;
  constexpr double kGuideSpacingM = 0.002;
  const double kCosGuideAngle = std::cos(std::numbers::pi / 18.0);  // 10°
  double longest_edge_m = 0.0;
  for (std::size_t i = first; i < stroke.edges_m.size(); ++i)
    longest_edge_m = std::max(longest_edge_m, (stroke.edges_m[i][1] - stroke.edges_m[i][0]).norm());
  const auto stretches =
      static_cast<std::size_t>(std::clamp(std::ceil(longest_edge_m / kGuideSpacingM), 1.0, 256.0));
  std::vector<const CutFace*> near;
  const std::size_t count = stroke.edges_m.size();
  for (std::size_t i = first; i < count; ++i) {
    const auto& [heel, tip] = stroke.edges_m[i];
    // The sweep's normal at this instant: the edge across its direction of travel.
    const auto& before = stroke.edges_m[i == 0 ? 0 : i - 1];
    const auto& after = stroke.edges_m[std::min(i + 1, count - 1)];
    const Eigen::Vector3d travel = (after[0] + after[1]) - (before[0] + before[1]);
    const Eigen::Vector3d across = (tip - heel).cross(travel);
    if (!(across.norm() > 1e-12 * (tip - heel).norm() * travel.norm())) continue;
    const Eigen::Vector3d normal = across.normalized();
    const Aabb edge_box = Aabb::around(heel, tip, 0.0);
    near.clear();
    for (const CutFace& face : faces)
      if (face.near.overlaps(edge_box) && std::abs(face.unit_normal.dot(normal)) >= kCosGuideAngle)
        near.push_back(&face);
    if (near.empty()) continue;
    EdgePoints points(stretches + 1);
    bool moved = false;
    for (std::size_t k = 0; k <= stretches; ++k) {
      const Eigen::Vector3d q = heel + (double(k) / double(stretches)) * (tip - heel);
      double best_score = std::numeric_limits<double>::infinity(), offset_m = 0.0;
      for (const CutFace* face : near) {
        // In front of the face (in the gap the blade holds open, or out of the tissue), the
        // edge is in the groove already; behind it, in the tissue beside the cut.
        const double behind_m = (q - face->corner[0]).dot(face->unit_normal);
        if (behind_m > 0.0) continue;
        const double d = behind_m / face->unit_normal.dot(normal);
        if (std::abs(d) > guide_m) continue;
        const Eigen::Vector3d on_plane = q - d * normal;
        std::array<double, 3> weight;
        const double beyond_m =
            (closest_point_on_triangle(on_plane, face->corner[0], face->corner[1], face->corner[2],
                                       weight) -
             on_plane)
                .norm();
        if (beyond_m >= guide_m) continue;
        const double score = beyond_m + std::abs(d);
        if (score < best_score) {
          best_score = score;
          offset_m = (1.0 - beyond_m / guide_m) * d;
        }
      }
      points[k] = q - offset_m * normal;
      moved |= offset_m != 0.0;
    }
    if (!moved) continue;
    // Points in line with their neighbours say nothing: the sweep keeps its triangles few.
    EdgePoints kept{points.front()};
    for (std::size_t k = 1; k + 1 < points.size(); ++k) {
      const Eigen::Vector3d chord = points[k + 1] - kept.back();
      const Eigen::Vector3d off = points[k] - kept.back();
      if ((off - off.dot(chord) / chord.squaredNorm() * chord).norm() > 1e-7)
        kept.push_back(points[k]);
    }
    kept.push_back(points.back());
    edges[edges.size() - (count - i)] = std::move(kept);
  }
}

// The stroke's edges as they cut: those it keeps bent, the rest bent now.
std::vector<EdgePoints> cutting_edges(const SimModel& model, const NodeArray& position_m,
                                      const BladeStroke& stroke, double guide_m) {
  std::vector<EdgePoints> edges(stroke.cutting_edges_m.begin(), stroke.cutting_edges_m.end());
  bend_onto_grooves(model, position_m, stroke, edges.size(), guide_m, edges);
  return edges;
}

// Whether the tetrahedron p touches the sweep: an edge of one meets a face of the other, or the
// sweep lies inside it.
bool tet_touches_sweep(const std::array<Eigen::Vector3d, 4>& p, const Aabb& tet_box,
                       const SweepSurface& sweep) {
  return sweep.first_overlapping(tet_box, [&](std::size_t t) {
    const Triangle& tri = sweep.triangle[t];
    // All corners off the triangle's plane on one side: it cannot touch.
    bool above = true, below = true;
    for (const auto& corner : p) {
      const double height = (corner - tri[0]).dot(sweep.unit_normal[t]);
      above &= height > sweep.tolerance_m;
      below &= height < -sweep.tolerance_m;
    }
    if (above || below) return false;
    // Separating axes of a tetrahedron and a triangle: the face normals of both and the cross
    // products of their edges. They meet (within the tolerance) when no axis separates them.
    auto separated_along = [&](const Eigen::Vector3d& axis) {
      const double length = axis.norm();
      if (length < 1e-30) return false;
      double tet_min = std::numeric_limits<double>::infinity(), tet_max = -tet_min;
      for (const auto& corner : p) {
        const double at = corner.dot(axis);
        tet_min = std::min(tet_min, at);
        tet_max = std::max(tet_max, at);
      }
      double tri_min = std::numeric_limits<double>::infinity(), tri_max = -tri_min;
      for (const auto& corner : tri) {
        const double at = corner.dot(axis);
        tri_min = std::min(tri_min, at);
        tri_max = std::max(tri_max, at);
      }
      const double slack = sweep.tolerance_m * length;
      return tet_max < tri_min - slack || tri_max < tet_min - slack;
    };
    bool apart = false;
    for (const auto& face : kTetFace) {
      apart = separated_along((p[face[1]] - p[face[0]]).cross(p[face[2]] - p[face[0]]));
      if (apart) break;
    }
    for (int i = 0; i < 3 && !apart; ++i) {
      const Eigen::Vector3d side = tri[(i + 1) % 3] - tri[i];
      for (const auto& edge : kEdge)
        if ((apart = separated_along(side.cross(p[edge[1]] - p[edge[0]])))) break;
    }
    return !apart;
  });
}

std::array<Eigen::Vector3d, 4> corners_at(const SimModel& model, const NodeArray& position,
                                          std::size_t e) {
  return {position.at(model.corner[0][e]), position.at(model.corner[1][e]),
          position.at(model.corner[2][e]), position.at(model.corner[3][e])};
}

// Elements incident to node n (from the model's node → corner incidence).
template <typename Visit>
void for_each_element_of(const SimModel& model, NodeIndex n, Visit&& visit) {
  for (std::int32_t s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s)
    visit(static_cast<std::size_t>(model.node_slot_element[s]));
}

bool element_has_node(const SimModel& model, std::size_t e, NodeIndex n) {
  for (int c = 0; c < 4; ++c)
    if (model.corner[c][e] == n) return true;
  return false;
}

// The copy of node n that element e (one of n's elements) has in `corner`, its corners after the
// split; -1 if e does not have n.
NodeIndex copy_in(const SimModel& model, const std::array<std::vector<NodeIndex>, 4>& corner,
                  std::size_t e, NodeIndex n) {
  for (int c = 0; c < 4; ++c)
    if (model.corner[c][e] == n) return corner[c][e];
  return -1;
}

// The element across face `face` of element e, if the face is interior.
std::optional<std::size_t> find_neighbour_across(const SimModel& model, std::size_t e, int face) {
  const NodeIndex a = model.corner[kTetFace[face][0]][e], b = model.corner[kTetFace[face][1]][e],
                  c = model.corner[kTetFace[face][2]][e];
  std::optional<std::size_t> found;
  for_each_element_of(model, a, [&](std::size_t other) {
    if (other != e && element_has_node(model, other, b) && element_has_node(model, other, c))
      found = other;
  });
  return found;
}

// The elements across the faces of the elements a cut looks at, found once each.
class FaceNeighbours {
 public:
  explicit FaceNeighbours(const SimModel& model)
      : model_(model), across_(model.tet_count, {kUnknown, kUnknown, kUnknown, kUnknown}) {}
  std::optional<std::size_t> operator()(std::size_t e, int face) {
    std::int32_t& known = across_[e][face];
    if (known == kUnknown) {
      const auto found = find_neighbour_across(model_, e, face);
      known = found ? static_cast<std::int32_t>(*found) : kNone;
    }
    if (known == kNone) return std::nullopt;
    return static_cast<std::size_t>(known);
  }

 private:
  static constexpr std::int32_t kUnknown = -2, kNone = -1;
  const SimModel& model_;
  std::vector<std::array<std::int32_t, 4>> across_;
};

using FaceKey = std::array<NodeIndex, 3>;  // sorted node indices
FaceKey face_key(const SimModel& model, std::size_t e, int face) {
  FaceKey key{model.corner[kTetFace[face][0]][e], model.corner[kTetFace[face][1]][e],
              model.corner[kTetFace[face][2]][e]};
  std::sort(key.begin(), key.end());
  return key;
}

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// A mesh's connected pieces (elements joined through shared nodes), over elements given by their
// corners: each node's piece root, and per root whether it holds a fixed node and its rest volume.
// The organ is the pieces holding a fixed node, or with none anywhere, the largest piece.
struct Pieces {
  const std::array<std::vector<NodeIndex>, 4>* corner;
  UnionFind joined;
  std::vector<std::uint8_t> fixed;
  std::vector<double> volume_m3;
  std::int32_t organ_root = -1;  // with no fixed node: the largest piece

  // `is_fixed(n)` for each of the `nodes`; `volume_m3` per element.
  template <class IsFixed>
  Pieces(const std::array<std::vector<NodeIndex>, 4>& corners, std::size_t nodes,
         const std::vector<double>& element_volume_m3, IsFixed is_fixed)
      : corner(&corners), joined(nodes), fixed(nodes, 0), volume_m3(nodes, 0.0) {
    const std::size_t tets = corners[0].size();
    for (std::size_t e = 0; e < tets; ++e)
      for (int c = 1; c < 4; ++c) joined.unite(corners[0][e], corners[c][e]);
    bool any_fixed = false;
    for (std::size_t n = 0; n < nodes; ++n)
      if (is_fixed(n)) {
        fixed[joined.find(static_cast<std::int32_t>(n))] = 1;
        any_fixed = true;
      }
    for (std::size_t e = 0; e < tets; ++e)
      volume_m3[joined.find(corners[0][e])] += element_volume_m3[e];
    if (any_fixed) return;
    for (std::size_t n = 0; n < nodes; ++n)
      if (volume_m3[n] > 0.0 && (organ_root < 0 || volume_m3[n] > volume_m3[organ_root]))
        organ_root = static_cast<std::int32_t>(n);
  }
  explicit Pieces(const SimModel& model)
      : Pieces(model.corner, model.node_count, model.rest_volume_m3,
               [&](std::size_t n) { return model.is_fixed[n] != 0; }) {}

  std::int32_t of_element(std::size_t e) { return joined.find((*corner)[0][e]); }
  bool in_organ(std::int32_t root) const {
    return organ_root < 0 ? fixed[root] != 0 : root == organ_root;
  }
};

// Whether the edge (n, m) lies on the boundary: a face holding it has no element across.
bool edge_on_boundary(const SimModel& model, FaceNeighbours& neighbours, NodeIndex n, NodeIndex m) {
  bool boundary = false;
  for_each_element_of(model, n, [&](std::size_t e) {
    if (!element_has_node(model, e, m)) return;
    for (int f = 0; f < 4; ++f) {
      bool holds_edge = false;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          holds_edge |=
              model.corner[kTetFace[f][i]][e] == n && model.corner[kTetFace[f][j]][e] == m;
      if (holds_edge && !neighbours(e, f)) boundary = true;
    }
  });
  return boundary;
}

bool on_boundary(const SimModel& model, FaceNeighbours& neighbours, NodeIndex n) {
  bool boundary = false;
  for_each_element_of(model, n, [&](std::size_t e) {
    for (int f = 0; f < 4; ++f) {
      bool holds_node = false;
      for (int i = 0; i < 3; ++i) holds_node |= model.corner[kTetFace[f][i]][e] == n;
      if (holds_node && !neighbours(e, f)) boundary = true;
    }
  });
  return boundary;
}

// Whether the arcs b → c of the triangles around a vertex chain into one closed cycle (the
// vertex's boundary is one fan: a manifold surface there).
bool arcs_form_one_cycle(const std::vector<std::array<NodeIndex, 2>>& arcs) {
  std::size_t steps = 0;
  NodeIndex at = arcs.front()[0];
  do {
    if (std::count_if(arcs.begin(), arcs.end(), [&](const auto& arc) { return arc[0] == at; }) != 1)
      return false;
    at = std::find_if(arcs.begin(), arcs.end(), [&](const auto& arc) {
           return arc[0] == at;
         })->at(1);
    ++steps;
  } while (at != arcs.front()[0] && steps <= arcs.size());
  return steps == arcs.size() && at == arcs.front()[0];
}

struct ElementShape {
  double volume_m3, min_height_m;
};
// Signed volume and smallest height (3V over the largest face), without tet_shape's angles.
ElementShape shape_of(const std::array<Eigen::Vector3d, 4>& p) {
  const double volume = signed_tet_volume(p[0], p[1], p[2], p[3]);
  double largest_face_area = 0.0;
  for (const auto& face : kTetFace)
    largest_face_area = std::max(
        largest_face_area, 0.5 * (p[face[1]] - p[face[0]]).cross(p[face[2]] - p[face[0]]).norm());
  return {volume, 3.0 * std::abs(volume) / largest_face_area};
}

// The working geometry of a cut: rest and current positions with the snapped nodes moved.
struct Geometry {
  NodeArray rest_m, position_m, velocity_m_per_s;
  std::vector<double> element_mass_kg;
};

double density_kg_per_m3(const SimModel& model, std::size_t e) {
  return model.regions[model.region[e]].tissue.density_kg_per_m3;
}

// The model's geometry and element masses as they are (density times rest volume before a cut).
Geometry geometry_as_is(const SimModel& model, const SimState& state) {
  Geometry geometry{model.rest_position_m, state.position_m, state.velocity_m_per_s,
                    model.element_mass_kg};
  if (geometry.element_mass_kg.empty()) {
    geometry.element_mass_kg.resize(model.tet_count);
    for (std::size_t e = 0; e < model.tet_count; ++e)
      geometry.element_mass_kg[e] = density_kg_per_m3(model, e) * model.rest_volume_m3[e];
  }
  return geometry;
}

// Moves node n to parameter s along its edge to node m, at rest and deformed (a point on an edge
// is the same material point in every element holding the edge), when every element of n keeps
// its shape. Returns whether it moved.
bool try_snap(const SimModel& model, FaceNeighbours& neighbours, Geometry& geometry, NodeIndex n,
              NodeIndex m, double s, double min_fraction, double floor_m) {
  // A node on the surface moves only along the surface, so the organ keeps its shape; one where
  // regions meet (a lesion's boundary, a layer's) only along an edge where they meet too, so no
  // tissue passes from one region to another (a lesion's margin is measured on them).
  if (on_boundary(model, neighbours, n) && !edge_on_boundary(model, neighbours, n, m)) return false;
  if (!model.region.empty()) {
    int around = -1, along = -1;
    bool regions_meet = false, edge_between = false;
    for_each_element_of(model, n, [&](std::size_t e) {
      const int region = model.region[e];
      if (around >= 0 && region != around) regions_meet = true;
      around = region;
      if (!element_has_node(model, e, m)) return;
      if (along >= 0 && region != along) edge_between = true;
      along = region;
    });
    if (regions_meet && !edge_between) return false;
  }
  const NodeArray* configurations[2] = {&geometry.rest_m, &geometry.position_m};
  std::array<Eigen::Vector3d, 2> moved;
  for (int k = 0; k < 2; ++k) {
    const NodeArray& x = *configurations[k];
    moved[k] = x.at(n) + s * (x.at(m) - x.at(n));
  }
  bool keeps_shape = true;
  for_each_element_of(model, n, [&](std::size_t e) {
    for (int k = 0; k < 2 && keeps_shape; ++k) {
      auto p = corners_at(model, *configurations[k], e);
      const ElementShape before = shape_of(p);
      for (int c = 0; c < 4; ++c)
        if (model.corner[c][e] == n) p[c] = moved[k];
      const ElementShape after = shape_of(p);
      keeps_shape = after.volume_m3 >= min_fraction * before.volume_m3 &&
                    after.min_height_m >= min_fraction * before.min_height_m &&
                    (k == 1 || after.min_height_m >= std::min(floor_m, before.min_height_m)) &&
                    after.volume_m3 > 0.0;
    }
  });
  if (!keeps_shape) return false;
  // The elements around n keep their mass between them, shared by their new volumes (exactly
  // density × volume inside the organ, where their volumes only move between them).
  double mass = 0.0, weight = 0.0;
  for_each_element_of(model, n, [&](std::size_t e) {
    mass += geometry.element_mass_kg[e];
    auto p = corners_at(model, geometry.rest_m, e);
    for (int c = 0; c < 4; ++c)
      if (model.corner[c][e] == n) p[c] = moved[0];
    weight += density_kg_per_m3(model, e) * shape_of(p).volume_m3;
  });
  for_each_element_of(model, n, [&](std::size_t e) {
    auto p = corners_at(model, geometry.rest_m, e);
    for (int c = 0; c < 4; ++c)
      if (model.corner[c][e] == n) p[c] = moved[0];
    geometry.element_mass_kg[e] =
        mass * density_kg_per_m3(model, e) * shape_of(p).volume_m3 / weight;
  });
  geometry.rest_m.set(n, moved[0]);
  geometry.position_m.set(n, moved[1]);
  const NodeArray& v = geometry.velocity_m_per_s;
  geometry.velocity_m_per_s.set(n, v.at(n) + s * (v.at(m) - v.at(n)));
  return true;
}

bool averages_pressure(const SimModel& model, std::size_t e) {
  return model.effects.average_nodal_pressure &&
         !(model.effects.viscous && model.viscous_parameters[model.region[e]]);
}

// Reference gradients of element e's shape functions, corner by corner.
std::array<Eigen::Vector3d, 4> shape_gradients(const SimModel& model, std::size_t e) {
  const Eigen::Matrix3d dm_inv = element_dm_inverse(model, e);
  std::array<Eigen::Vector3d, 4> g;
  for (int c = 1; c < 4; ++c) g[c] = dm_inv.row(c - 1).transpose();
  g[0] = -(g[1] + g[2] + g[3]);
  return g;
}

// Stiffness matrix of element e in its rest shape over its corners' displacements (12 × 12):
// K_e = V·Gᵀ·A·G with A = ∂P/∂F and G the map from corner displacements to F (F_ij gains g_aj
// per unit displacement of corner a along i), g_a the reference shape-function gradients. With
// average nodal pressure the λ part is left to the nodes (local_max_frequency_rad_per_s).
Eigen::Matrix<double, 12, 12> element_rest_stiffness(const SimModel& model, std::size_t e) {
  const auto g = shape_gradients(model, e);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 9, 9> A = element_stress_tangent(model, e, I);
  if (averages_pressure(model, e))
    A -= neo_hookean::stress_tangent(I, 0.0, model.lame_lambda_pa[e]);
  Eigen::Matrix<double, 9, 12> G = Eigen::Matrix<double, 9, 12>::Zero();
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) G(3 * i + j, 3 * a + i) = g[a](j);
  const Eigen::Matrix<double, 9, 12> AG = A.lazyProduct(G);
  const Eigen::Matrix<double, 12, 12> K = model.rest_volume_m3[e] * G.transpose().lazyProduct(AG);
  return 0.5 * (K + K.transpose());
}

}  // namespace

namespace {

// local_top_mode, with the block's element stiffness kept in `stiffness` between calls on the same
// nodes of the same model (only the masses may change): computing it was most of an estimate's
// time, and the mass scaling estimates the same block round after round.
LocalMode top_mode_of_block(const SimModel& model, const std::vector<NodeIndex>& nodes,
                            std::vector<Eigen::Matrix<double, 12, 12>>& stiffness) {
  LocalMode mode;
  std::vector<std::int32_t> local(model.node_count, -1);
  std::vector<double> inv_sqrt_mass;
  for (NodeIndex n : nodes)
    if (local[n] < 0 && model.inverse_mass_per_kg[n] > 0.0) {
      local[n] = static_cast<std::int32_t>(inv_sqrt_mass.size());
      inv_sqrt_mass.push_back(std::sqrt(model.inverse_mass_per_kg[n]));
    }
  if (inv_sqrt_mass.empty()) return mode;
  std::vector<std::size_t> elements;
  std::vector<std::uint8_t> taken(model.tet_count, 0);
  for (NodeIndex n : nodes)
    for (std::int32_t s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
      const auto e = static_cast<std::size_t>(model.node_slot_element[s]);
      if (!taken[e]) elements.push_back(e), taken[e] = 1;
    }
  // A = M^(-1/2)·K·M^(-1/2) on the block, held element by element with the mass scaling taken
  // in: a corner off the block reads and writes the padding dofs past the block's end (zero
  // scaling), so the product has no branches.
  const std::size_t dofs = 3 * inv_sqrt_mass.size();
  const auto padding = static_cast<std::int32_t>(inv_sqrt_mass.size());
  std::vector<Eigen::Matrix<double, 12, 12>> scaled_stiffness(elements.size());
  std::vector<std::array<std::int32_t, 4>> element_local(elements.size());
  for (std::size_t i = 0; i < elements.size(); ++i) {
    Eigen::Matrix<double, 12, 1> scale;
    for (int c = 0; c < 4; ++c) {
      const std::int32_t at = local[model.corner[c][elements[i]]];
      element_local[i][c] = at >= 0 ? at : padding;
      scale.segment<3>(3 * c).setConstant(at >= 0 ? inv_sqrt_mass[at] : 0.0);
    }
    if (stiffness.size() < elements.size())
      stiffness.push_back(element_rest_stiffness(model, elements[i]));
    scaled_stiffness[i] = scale.asDiagonal() * stiffness[i] * scale.asDiagonal();
  }
  // Average nodal pressure: the volumetric energy Σ_n V_n·λ_n/2·δJ_n² of node n's volume-averaged
  // J (V_n = W_n/4, W_n its elements' volume) adds λ_n/(4 W_n)·c_n·c_nᵀ, c_n = Σ_e V_e·∂J_e/∂u,
  // for every node whose elements reach the free nodes. Held as (node, coefficient, c_n).
  struct NodalVolumetric {
    double coefficient;
    std::vector<std::pair<std::int32_t, Eigen::Vector3d>> c;  // free local node, its part of c_n
  };
  std::vector<NodalVolumetric> volumetric;
  if (model.effects.average_nodal_pressure) {
    std::vector<std::array<Eigen::Vector3d, 4>> gradients(elements.size());
    std::vector<std::int32_t> patch_index(model.tet_count, -1);
    for (std::size_t i = 0; i < elements.size(); ++i) {
      gradients[i] = shape_gradients(model, elements[i]);
      patch_index[elements[i]] = static_cast<std::int32_t>(i);
    }
    std::vector<std::uint8_t> seen(model.node_count, 0);
    for (std::size_t e : elements)
      for (int k = 0; k < 4; ++k) {
        const NodeIndex n = model.corner[k][e];
        if (seen[n]) continue;
        seen[n] = 1;
        NodalVolumetric term{0.0, {}};
        double volume = 0.0, lambda_volume = 0.0;
        for (std::int32_t s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
          const auto around = static_cast<std::size_t>(model.node_slot_element[s]);
          if (!averages_pressure(model, around)) continue;
          volume += model.rest_volume_m3[around];
          lambda_volume += model.rest_volume_m3[around] * model.lame_lambda_pa[around];
          if (!taken[around]) continue;  // no free corner
          const auto& g = gradients[patch_index[around]];
          for (int c = 0; c < 4; ++c) {
            const std::int32_t at = local[model.corner[c][around]];
            if (at >= 0) term.c.emplace_back(at, model.rest_volume_m3[around] * g[c]);
          }
        }
        if (volume <= 0.0 || term.c.empty()) continue;
        term.coefficient = lambda_volume / volume / (4.0 * volume);
        for (auto& [at, c] : term.c) c *= inv_sqrt_mass[at];
        volumetric.push_back(std::move(term));
      }
  }

  // The product with A (u and au have the padding dofs at their end, u's zero).
  auto apply = [&](const Eigen::VectorXd& u, Eigen::VectorXd& au) {
    au.setZero();
    for (std::size_t i = 0; i < elements.size(); ++i) {
      const auto& at = element_local[i];
      Eigen::Matrix<double, 12, 1> v;
      for (int c = 0; c < 4; ++c) v.segment<3>(3 * c) = u.segment<3>(3 * at[c]);
      const Eigen::Matrix<double, 12, 1> kv = scaled_stiffness[i].lazyProduct(v);
      for (int c = 0; c < 4; ++c) au.segment<3>(3 * at[c]) += kv.segment<3>(3 * c);
    }
    for (const NodalVolumetric& term : volumetric) {
      double c_dot_v = 0.0;
      for (const auto& [at, c] : term.c) c_dot_v += c.dot(u.segment<3>(3 * at));
      for (const auto& [at, c] : term.c) au.segment<3>(3 * at) += term.coefficient * c_dot_v * c;
    }
    au.tail<3>().setZero();
  };
  // Lanczos: the largest Ritz value is a lower bound on A's largest eigenvalue that converges far
  // faster than power iteration. The cut's top modes stand well apart: it settles to rounding
  // within 10-20 steps (measured on the bench-cut stroke), so it stops once five more steps have
  // not moved it by 1e-10, or after 40.
  constexpr int kMaxSteps = 40, kCheckEvery = 5;
  constexpr double kSettled = 1e-10;
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(dofs + 3), current(dofs + 3), next(dofs + 3);
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (std::size_t i = 0; i < dofs; ++i) current[i] = uniform(random);
  current.tail<3>().setZero();
  current.normalize();
  std::vector<double> alpha, beta;
  std::vector<Eigen::VectorXd> basis;  // the Lanczos vectors, for the mode
  auto tridiagonal = [&] {
    const int k = static_cast<int>(alpha.size());
    Eigen::MatrixXd t = Eigen::MatrixXd::Zero(k, k);
    for (int i = 0; i < k; ++i) {
      t(i, i) = alpha[i];
      if (i + 1 < k) t(i, i + 1) = t(i + 1, i) = beta[i];
    }
    return t;
  };
  auto largest_ritz_value = [&] {
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(tridiagonal(), Eigen::EigenvaluesOnly)
        .eigenvalues()
        .maxCoeff();
  };
  double previous_beta = 0.0, checked = 0.0;
  std::optional<double> settled;
  for (int step = 0; step < kMaxSteps && step < static_cast<int>(dofs); ++step) {
    basis.push_back(current);
    apply(current, next);
    next -= previous_beta * previous;
    alpha.push_back(next.dot(current));
    next -= alpha.back() * current;
    previous_beta = next.norm();
    if (!(previous_beta > 1e-12 * std::abs(alpha.back()))) break;
    if ((step + 1) % kCheckEvery == 0) {
      const double now = largest_ritz_value();
      if (std::abs(now - checked) <= kSettled * std::abs(now)) {
        settled = now;
        break;
      }
      checked = now;
    }
    beta.push_back(previous_beta);
    previous.swap(current);
    current = next / previous_beta;
  }
  // The Ritz vector of the largest value, and each node's share of its energy (|ψ_n|², ψ the
  // eigenvector of A: the mode's kinetic energy goes as m_n·|φ_n|² = |ψ_n|²).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(tridiagonal());
  Eigen::Index top = 0;
  ritz.eigenvalues().maxCoeff(&top);
  mode.frequency_rad_per_s = std::sqrt(std::max(settled ? *settled : ritz.eigenvalues()[top], 0.0));
  Eigen::VectorXd psi = Eigen::VectorXd::Zero(dofs + 3);
  for (Eigen::Index k = 0; k < ritz.eigenvectors().rows(); ++k)
    psi += ritz.eigenvectors()(k, top) * basis[k];
  const double norm = psi.head(dofs).squaredNorm();
  mode.node.resize(inv_sqrt_mass.size());
  mode.energy_share.resize(inv_sqrt_mass.size());
  for (NodeIndex n : nodes)
    if (local[n] >= 0) {
      mode.node[local[n]] = n;
      mode.energy_share[local[n]] =
          norm > 0.0 ? psi.segment<3>(3 * local[n]).squaredNorm() / norm : 0.0;
    }
  return mode;
}

}  // namespace

LocalMode local_top_mode(const SimModel& model, const std::vector<NodeIndex>& nodes) {
  std::vector<Eigen::Matrix<double, 12, 12>> stiffness;
  return top_mode_of_block(model, nodes, stiffness);
}

double local_max_frequency_rad_per_s(const SimModel& model, const std::vector<NodeIndex>& nodes) {
  return local_top_mode(model, nodes).frequency_rad_per_s;
}

double scale_masses_to_frequency(SimModel& model, const std::vector<NodeIndex>& nodes,
                                 double ceiling_rad_per_s, double max_added_mass_fraction,
                                 NodeArray* velocity_m_per_s) {
  constexpr int kMaxRounds = 24;
  constexpr double kTolerance = 1e-3, kAmplitudeFraction = 0.5;
  const double budget_kg = max_added_mass_fraction * tissue_mass_kg(model);
  double added_kg = 0.0;
  std::vector<Eigen::Matrix<double, 12, 12>> stiffness;
  LocalMode mode = top_mode_of_block(model, nodes, stiffness);
  for (int round = 0; round < kMaxRounds && model.added_mass_kg < budget_kg &&
                      mode.frequency_rad_per_s > (1.0 + kTolerance) * ceiling_rad_per_s;
       ++round) {
    // Mass slows the mode most where it moves most: the nodes whose displacement in it
    // (|φ_n|² = share_n / m_n, φ mass-normalised) is at least half the largest. Their masses times
    // s, the mode's shape kept, its Rayleigh quotient is ω² / (1 + (s − 1)·E), E their share of
    // its energy: s brings it to the ceiling.
    auto amplitude = [&](std::size_t k) {
      return mode.energy_share[k] / model.lumped_mass_kg[mode.node[k]];
    };
    double largest = 0.0;
    for (std::size_t k = 0; k < mode.node.size(); ++k) largest = std::max(largest, amplitude(k));
    double held = 0.0, moving_kg = 0.0;
    for (std::size_t k = 0; k < mode.node.size(); ++k)
      if (amplitude(k) >= kAmplitudeFraction * largest) {
        held += mode.energy_share[k];
        moving_kg += model.lumped_mass_kg[mode.node[k]];
      }
    const double ratio = (mode.frequency_rad_per_s * mode.frequency_rad_per_s) /
                         (ceiling_rad_per_s * ceiling_rad_per_s);
    const double more = (ratio - 1.0) / held * (1.0 + kTolerance);  // s − 1
    if (!(more > 0.0) || !(moving_kg > 0.0)) break;
    // What is left of the budget, shared alike.
    const double share = std::min(1.0, (budget_kg - model.added_mass_kg) / (more * moving_kg));
    if (model.node_added_mass_kg.empty()) model.node_added_mass_kg.assign(model.node_count, 0.0);
    // (lumped_mass_kg changes only with lump_node_masses below.)
    for (std::size_t k = 0; k < mode.node.size(); ++k) {
      if (amplitude(k) < kAmplitudeFraction * largest) continue;
      const NodeIndex n = mode.node[k];
      const double more_kg = share * more * model.lumped_mass_kg[n];
      // Momentum kept: the mass brings no energy.
      if (velocity_m_per_s)
        velocity_m_per_s->set(n, velocity_m_per_s->at(n) * (model.lumped_mass_kg[n] /
                                                            (model.lumped_mass_kg[n] + more_kg)));
      model.node_added_mass_kg[n] += more_kg;
      added_kg += more_kg;
    }
    lump_node_masses(model);
    mode = top_mode_of_block(model, nodes, stiffness);
  }
  model.max_frequency_rad_per_s = std::max(model.max_frequency_rad_per_s, mode.frequency_rad_per_s);
  model.stable_time_step_s = stable_time_step_s(model, StepInputs{});
  return added_kg;
}

namespace {

// A per-element (or per-node) array of the new model: entry i from entry origin[i] of the old
// (left empty when empty).
template <class Values, class Index>
void take_from_origin(Values& values, const std::vector<Index>& origin) {
  if (values.empty()) return;
  Values kept(origin.size());
  for (std::size_t i = 0; i < origin.size(); ++i) kept[i] = values[origin[i]];
  values = std::move(kept);
}

// Each per-element array of the model (its material, shape and fibres; not the face marks) for the
// elements of the new model, each from its element `origin[i]` of the old.
void take_element_data(SimModel& m, const std::vector<TetIndex>& origin) {
  auto take = [&](auto& per_element) { take_from_origin(per_element, origin); };
  for (auto& entry : m.dm_inverse) take(entry);
  take(m.rest_volume_m3);
  take(m.shear_modulus_pa);
  take(m.lame_lambda_pa);
  take(m.mooney_rivlin_c2_pa);
  take(m.region);
  take(m.fibre_parameters);
  for (auto& family : m.fibre_direction) take(family);
  take(m.in_vivo_stress_pa);
}

// Dm⁻¹ and rest volume of element i from its corners' rest positions.
void reshape_element(SimModel& m, std::size_t i) {
  const Eigen::Vector3d x0 = m.rest_position_m.at(m.corner[0][i]);
  Eigen::Matrix3d dm;
  for (int c = 1; c < 4; ++c) dm.col(c - 1) = m.rest_position_m.at(m.corner[c][i]) - x0;
  const Eigen::Matrix3d inverse = dm.inverse();
  for (int k = 0; k < 9; ++k) m.dm_inverse[k][i] = inverse(k / 3, k % 3);
  m.rest_volume_m3[i] = dm.determinant() / 6.0;
}

// Lumped and inverse masses from the element masses (the mass scaling's too), and the node
// incidence.
void lump_masses(SimModel& m) {
  lump_node_masses(m);
  build_node_incidence(m);
}

// The state on a cut's new model: these positions and velocities, each element's viscous history
// from its origin, the old clock and step; the energy books open again when `open_books` (a whole
// pass over the elements: not for the model a cut only runs on).
SimState carried_state(const SimModel& m, const SimState& old, NodeArray position_m,
                       NodeArray velocity_m_per_s, const std::vector<TetIndex>& element_origin,
                       bool open_books) {
  SimState next = make_rest_state(m, old.force_scratch.workers);
  next.position_m = std::move(position_m);
  next.velocity_m_per_s = std::move(velocity_m_per_s);
  if (m.effects.viscous)
    for (std::size_t i = 0; i < m.tet_count; ++i)
      next.viscous_history.copy_element(old.viscous_history,
                                        static_cast<std::size_t>(element_origin[i]), i);
  next.viscous_history.flow_pending_s = old.viscous_history.flow_pending_s;
  next.time_s = old.time_s;
  next.step_count = old.step_count;
  next.last_step_s = old.last_step_s;
  next.max_speed_m_per_s = old.max_speed_m_per_s;
  if (open_books) open_energy_books(m, next);
  return next;
}

// A cut's (or a take-out's) new model and its state from `old`, with the origins of its nodes and
// elements, into `result`; the energy books open again.
void complete(CutResult& result, std::shared_ptr<SimModel> next, const SimState& old,
              NodeArray position_m, NodeArray velocity_m_per_s, std::vector<NodeIndex> node_origin,
              std::vector<TetIndex> element_origin) {
  result.state = carried_state(*next, old, std::move(position_m), std::move(velocity_m_per_s),
                               element_origin, true);
  result.model = std::move(next);
  result.node_origin = std::move(node_origin);
  result.element_origin = std::move(element_origin);
}

// A node made on the edge (a, b), a < b, at parameter s along it from a.
struct EdgeSplit {
  NodeIndex a = 0, b = 0;
  double s = 0.0;
  bool operator<(const EdgeSplit& other) const {
    return std::tie(a, b) < std::tie(other.a, other.b);
  }
};

// The children of an element with corners `parent` bisected on its edges `mine` (indices into
// `splits`, ascending), one after another; a node made on split k is node old_nodes + k.
void bisect(const std::array<NodeIndex, 4>& parent, const std::vector<EdgeSplit>& splits,
            const std::vector<std::ptrdiff_t>& mine, std::size_t old_nodes,
            std::vector<std::array<NodeIndex, 4>>& children) {
  children.assign(1, parent);
  for (const std::ptrdiff_t k : mine) {
    const NodeIndex a = splits[k].a, b = splits[k].b;
    const auto made = static_cast<NodeIndex>(old_nodes + static_cast<std::size_t>(k));
    for (std::size_t i = 0, count = children.size(); i < count; ++i) {
      const auto at_a = std::find(children[i].begin(), children[i].end(), a) - children[i].begin();
      const auto at_b = std::find(children[i].begin(), children[i].end(), b) - children[i].begin();
      if (at_a == 4 || at_b == 4) continue;
      // The node made replaces one end in each half: both keep the parent's orientation.
      std::array<NodeIndex, 4> other = children[i];
      children[i][at_a] = made;
      other[at_b] = made;
      children.push_back(other);
    }
  }
}

// The split edges of element e (indices into `splits`, ascending).
void splits_of(const SimModel& model, std::size_t e, const std::vector<EdgeSplit>& splits,
               std::vector<std::ptrdiff_t>& mine) {
  mine.clear();
  for (const auto& edge : kEdge) {
    const NodeIndex a = model.corner[edge[0]][e], b = model.corner[edge[1]][e];
    const EdgeSplit key{std::min(a, b), std::max(a, b), 0.0};
    const auto it = std::lower_bound(splits.begin(), splits.end(), key);
    if (it != splits.end() && it->a == key.a && it->b == key.b) mine.push_back(it - splits.begin());
  }
  std::sort(mine.begin(), mine.end());
}

// Leaves out of `splits` the edges of every element that would have a part thinner at rest than
// `min_fraction` of its own smallest height or than `floor_m` (the explicit step goes with the
// smallest height), until none would.
void refuse_thin_parts(const SimModel& model, const NodeArray& rest_m, double min_fraction,
                       double floor_m, std::vector<EdgeSplit>& splits,
                       const std::vector<std::uint8_t>* half_floor = nullptr) {
  // The elements `half_floor` marks may have parts down to half the floor (see cut_along, 6b).
  // Not in viscous regions: each element there keeps its own pressure, and its thin parts'
  // frequencies were 2–4 times the mesh's; a 45 mm-deep stroke through the wedge scenario's liver
  // spent the whole mass budget on them and the step fell to 0.14 ms.
  auto floor_of = [&](std::size_t e) {
    const bool viscous = model.effects.viscous && model.viscous_parameters[model.region[e]];
    return !viscous && half_floor && half_floor->size() == model.tet_count && (*half_floor)[e]
               ? 0.5 * floor_m
               : floor_m;
  };
  auto rest_at = [&](NodeIndex n) -> Eigen::Vector3d {
    if (n < static_cast<NodeIndex>(model.node_count)) return rest_m.at(n);
    const EdgeSplit& split = splits[n - static_cast<NodeIndex>(model.node_count)];
    return rest_m.at(split.a) + split.s * (rest_m.at(split.b) - rest_m.at(split.a));
  };
  auto has_thin_part = [&](std::size_t e, const std::vector<std::ptrdiff_t>& mine,
                           std::vector<std::array<NodeIndex, 4>>& parts) {
    std::array<NodeIndex, 4> parent;
    for (int c = 0; c < 4; ++c) parent[c] = model.corner[c][e];
    const double parent_height_m = shape_of(corners_at(model, rest_m, e)).min_height_m;
    bisect(parent, splits, mine, model.node_count, parts);
    for (const auto& part : parts) {
      std::array<Eigen::Vector3d, 4> p;
      for (int c = 0; c < 4; ++c) p[c] = rest_at(part[c]);
      const double height_m = shape_of(p).min_height_m;
      const bool halved = floor_of(e) < floor_m;
      if (height_m < (halved ? 0.5 : 1.0) * min_fraction * parent_height_m ||
          height_m < floor_of(e))
        return true;
    }
    return false;
  };
  std::vector<std::ptrdiff_t> mine;
  std::vector<std::array<NodeIndex, 4>> parts;
  std::vector<std::array<NodeIndex, 2>> refused;
  std::vector<std::size_t> affected;
  while (!splits.empty()) {
    affected.clear();
    for (const EdgeSplit& split : splits)
      for_each_element_of(model, split.a, [&](std::size_t e) {
        if (element_has_node(model, e, split.b)) affected.push_back(e);
      });
    std::sort(affected.begin(), affected.end());
    affected.erase(std::unique(affected.begin(), affected.end()), affected.end());
    refused.clear();
    for (std::size_t e : affected) {
      splits_of(model, e, splits, mine);
      if (has_thin_part(e, mine, parts))
        for (std::ptrdiff_t k : mine) refused.push_back({splits[k].a, splits[k].b});
    }
    if (refused.empty()) return;
    std::sort(refused.begin(), refused.end());
    std::erase_if(splits, [&](const EdgeSplit& split) {
      return std::binary_search(refused.begin(), refused.end(),
                                std::array<NodeIndex, 2>{split.a, split.b});
    });
  }
}

struct Refinement {
  std::shared_ptr<SimModel> model;
  SimState state;
  std::vector<TetIndex> element_origin;
  // Per node: a corner of a split element's part or of an element a snap moved, around which the
  // mesh's frequency may have risen (its estimate is left to the cut that runs on this model).
  std::vector<std::uint8_t> reshaped_around;
};

// The model and state with `geometry`'s snapped nodes and a node made on each edge of `splits`
// (sorted): every element holding split edges is bisected on them one after another, in the order
// of `splits` in every element, so two elements divide the face they share alike and the mesh
// stays conforming. A node on an edge is the same material point in each element holding it, and
// the children of a linear element have its deformation gradient: stress, forces and viscous
// history are those of the parent, only where a cut can run has changed. The new nodes follow the
// old ones (node_count of the old model on); each child keeps its parent's share of the mass by
// its rest volume.
Refinement split_edges(const SimModel& model, const SimState& state, const Geometry& geometry,
                       const std::vector<std::uint8_t>& snapped,
                       const std::vector<EdgeSplit>& splits) {
  const std::size_t old_nodes = model.node_count, tets = model.tet_count;

  // The children of each element, with the corners of its own each of their nodes lies between
  // (a bit per corner), to tell which of its faces a child's face lies on.
  Refinement refined;
  std::vector<std::array<NodeIndex, 4>> child_corners;
  std::vector<std::array<std::uint8_t, 4>> child_support;
  std::vector<std::uint8_t> split_parent(tets, 0);
  std::vector<std::array<NodeIndex, 4>> work;
  std::vector<std::ptrdiff_t> mine;
  for (std::size_t e = 0; e < tets; ++e) {
    std::array<NodeIndex, 4> parent;
    for (int c = 0; c < 4; ++c) parent[c] = model.corner[c][e];
    splits_of(model, e, splits, mine);
    bisect(parent, splits, mine, old_nodes, work);
    split_parent[e] = !mine.empty();
    for (const auto& child : work) {
      std::array<std::uint8_t, 4> support{};
      for (int c = 0; c < 4; ++c) {
        const NodeIndex n = child[c];
        for (int k = 0; k < 4; ++k) {
          const bool on_end =
              n < static_cast<NodeIndex>(old_nodes)
                  ? parent[k] == n
                  : parent[k] == splits[n - old_nodes].a || parent[k] == splits[n - old_nodes].b;
          if (on_end) support[c] |= std::uint8_t(1u << k);
        }
      }
      child_corners.push_back(child);
      child_support.push_back(support);
      refined.element_origin.push_back(static_cast<TetIndex>(e));
    }
  }

  auto next = std::make_shared<SimModel>(model);
  SimModel& m = *next;
  m.node_count = old_nodes + splits.size();
  m.tet_count = child_corners.size();
  const std::vector<TetIndex>& origin = refined.element_origin;
  take_element_data(m, origin);
  // A child's face on a face of its parent is what that face was (surface, cut); the others are
  // inside the parent.
  for (auto* mask : {&m.cut_face_mask, &m.boundary_face_mask}) {
    if (mask->empty()) continue;
    std::vector<std::uint8_t> kept(origin.size(), 0);
    for (std::size_t i = 0; i < origin.size(); ++i)
      for (int f = 0; f < 4; ++f) {
        std::uint8_t on = 0;
        for (int k = 0; k < 3; ++k) on |= child_support[i][kTetFace[f][k]];
        for (int g = 0; g < 4; ++g)
          if (on == (0xF & ~(1u << g)) && ((*mask)[origin[i]] >> g & 1u))
            kept[i] |= std::uint8_t(1u << f);
      }
    *mask = std::move(kept);
  }
  for (int c = 0; c < 4; ++c) {
    m.corner[c].resize(m.tet_count);
    for (std::size_t i = 0; i < m.tet_count; ++i) m.corner[c][i] = child_corners[i][c];
  }
  m.rest_position_m.resize(m.node_count);
  m.is_fixed.resize(m.node_count);
  NodeArray position, velocity;
  position.resize(m.node_count);
  velocity.resize(m.node_count);
  for (std::size_t n = 0; n < old_nodes; ++n) {
    m.rest_position_m.set(n, geometry.rest_m.at(n));
    position.set(n, geometry.position_m.at(n));
    velocity.set(n, geometry.velocity_m_per_s.at(n));
  }
  auto between = [](const NodeArray& x, const EdgeSplit& split) {
    return Eigen::Vector3d(x.at(split.a) + split.s * (x.at(split.b) - x.at(split.a)));
  };
  for (std::size_t k = 0; k < splits.size(); ++k) {
    const std::size_t n = old_nodes + k;
    m.rest_position_m.set(n, between(geometry.rest_m, splits[k]));
    position.set(n, between(geometry.position_m, splits[k]));
    velocity.set(n, between(geometry.velocity_m_per_s, splits[k]));
    m.is_fixed[n] = model.is_fixed[splits[k].a] && model.is_fixed[splits[k].b];
  }
  if (!m.node_added_mass_kg.empty()) m.node_added_mass_kg.resize(m.node_count, 0.0);

  // Shapes of the children and of the elements a snap moved; masses by rest volume.
  std::vector<double> parent_volume(tets, 0.0);
  std::vector<std::uint8_t> reshaped(m.tet_count, 0);
  for (std::size_t i = 0; i < m.tet_count; ++i) {
    const std::size_t e = origin[i];
    bool moved = split_parent[e] != 0;
    for (int c = 0; c < 4 && !moved; ++c) moved = snapped[model.corner[c][e]] != 0;
    reshaped[i] = moved;
    if (!moved) continue;
    reshape_element(m, i);
    parent_volume[e] += m.rest_volume_m3[i];
  }
  m.element_mass_kg.resize(m.tet_count);
  for (std::size_t i = 0; i < m.tet_count; ++i) {
    const std::size_t e = origin[i];
    m.element_mass_kg[i] =
        split_parent[e] ? geometry.element_mass_kg[e] * m.rest_volume_m3[i] / parent_volume[e]
                        : geometry.element_mass_kg[e];
  }
  lump_masses(m);

  // The smaller parts raise the mesh's frequency around them: the cut that runs on this model
  // estimates it with its own (one estimate, and none when it parts nothing).
  refined.reshaped_around.assign(m.node_count, 0);
  for (std::size_t i = 0; i < m.tet_count; ++i) {
    if (!reshaped[i]) continue;
    std::array<Eigen::Vector3d, 4> p;
    for (int c = 0; c < 4; ++c) {
      refined.reshaped_around[m.corner[c][i]] = 1;
      p[c] = m.rest_position_m.at(m.corner[c][i]);
    }
    m.min_element_height_m = std::min(m.min_element_height_m, shape_of(p).min_height_m);
  }

  refined.state = carried_state(m, state, std::move(position), std::move(velocity), origin, false);
  refined.model = std::move(next);
  return refined;
}

// The stretch [t_in, t_out] of the segment heel + t·(tip − heel), t in [0, 1], inside element e
// with its faces pushed out by `reach_m` (in by −reach_m), by Cyrus–Beck clipping; empty when
// t_in > t_out.
std::pair<double, double> edge_within_element(const std::array<Eigen::Vector3d, 4>& p,
                                              const std::array<Eigen::Vector3d, 2>& edge_m,
                                              double reach_m) {
  const Eigen::Vector3d along = edge_m[1] - edge_m[0];
  double t_in = 0.0, t_out = 1.0;
  for (int f = 0; f < 4 && t_in <= t_out; ++f) {
    const auto& face = kTetFace[f];
    const Eigen::Vector3d& a = p[face[0]];
    Eigen::Vector3d normal = (p[face[1]] - a).cross(p[face[2]] - a).normalized();
    if ((p[f] - a).dot(normal) > 0.0) normal = -normal;  // outward: away from the fourth corner
    const double height = normal.dot(edge_m[0] - a) - reach_m;  // > 0 outside the pushed face
    const double rate = normal.dot(along);
    if (rate == 0.0) {
      if (height > 0.0) t_out = -1.0;
    } else if (rate < 0.0) {
      t_in = std::max(t_in, -height / rate);
    } else {
      t_out = std::min(t_out, -height / rate);
    }
  }
  return {t_in, t_out};
}

}  // namespace

double blade_edge_in_contact_m(const PartContact& blade, const ToolGeometry& geometry) {
  return (blade.touched_to - blade.touched_from) * geometry.blade_length_m +
         2.0 * geometry.blade_half_thickness_m;
}

EdgeInTissue edge_in_tissue(const SimModel& model, const NodeArray& position_m,
                            const std::array<Eigen::Vector3d, 2>& edge_m, double reach_m,
                            double margin_m, std::vector<std::uint8_t>* node_scratch) {
  // Each element's stretch of the edge, its faces pushed out by the margin so that an edge lying
  // along faces (its own cut, faces snapped onto it) is in; overlaps counted once.
  struct Stretch {
    double from, to, toughness, friction;
  };
  constexpr std::size_t kMostStretches = 128;  // elements along one edge: a few dozen at most
  std::array<Stretch, kMostStretches> stretches;
  std::size_t count = 0;
  EdgeInTissue in;
  const Aabb edge_box = Aabb::around(edge_m[0], edge_m[1], std::max(reach_m, margin_m));
  // Each node's side of the edge's box on each axis (Cohen–Sutherland outcodes: bit 2k below the
  // box along axis k, bit 2k + 1 above it). An element's box misses the edge's exactly when all
  // its corners are past the same side: the AND of their codes is not 0. A walk over the nodes'
  // coordinates and the elements' corner indices instead of gathering every element's corners
  // (that walk was 9.6 % of a live bimanual resection's samples, perf).
  std::vector<std::uint8_t> own_scratch;
  std::vector<std::uint8_t>& outcode = node_scratch ? *node_scratch : own_scratch;
  if (outcode.size() < model.node_count) outcode.resize(model.node_count);
  const double* coordinate[3] = {position_m.x.data(), position_m.y.data(), position_m.z.data()};
  for (std::size_t n = 0; n < model.node_count; ++n) {
    std::uint8_t code = 0;
    for (int k = 0; k < 3; ++k)
      code |= static_cast<std::uint8_t>((coordinate[k][n] < edge_box.min_m[k] ? 1 : 0) << (2 * k) |
                                        (coordinate[k][n] > edge_box.max_m[k] ? 2 : 0) << (2 * k));
    outcode[n] = code;
  }
  for (std::size_t e = 0; e < model.tet_count && count < kMostStretches; ++e) {
    if ((outcode[model.corner[0][e]] & outcode[model.corner[1][e]] & outcode[model.corner[2][e]] &
         outcode[model.corner[3][e]]) != 0)
      continue;
    const auto p = corners_at(model, position_m, e);
    if (!in.within_reach) {
      const auto [t_in, t_out] = edge_within_element(p, edge_m, reach_m);
      in.within_reach = t_in <= t_out;
    }
    const auto [t_in, t_out] = edge_within_element(p, edge_m, margin_m);
    if (t_in < t_out) {
      const RegionMaterial& region = model.regions[static_cast<std::size_t>(model.region[e])];
      stretches[count++] = {t_in, t_out, region.fracture_toughness_j_per_m2,
                            region.blade_friction_n_per_m};
    }
  }
  std::sort(stretches.begin(), stretches.begin() + static_cast<std::ptrdiff_t>(count),
            [](const Stretch& a, const Stretch& b) { return a.from < b.from; });
  const double edge_length_m = (edge_m[1] - edge_m[0]).norm();
  double covered_to = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double new_m =
        std::max(0.0, stretches[i].to - std::max(stretches[i].from, covered_to)) * edge_length_m;
    in.length_m += new_m;
    in.resistance_n += stretches[i].toughness * new_m;
    in.friction_n += stretches[i].friction * new_m;
    covered_to = std::max(covered_to, stretches[i].to);
  }
  return in;
}

namespace {

// What a cut on a model refined by the cut before it (nodes made on edges, or the mesh refined at
// the blade's front) knows from that cut.
struct AfterSplitting {
  // Per element: part of one the sweep touched (empty: every element may touch it).
  std::vector<std::uint8_t> may_touch;
  std::vector<std::uint8_t> reshaped_around;  // per node: Refinement's
  bool may_make_nodes = false;                // after the front's refinement, not after a split
};

// Per node: whether it lies on a face an earlier cut made.
std::vector<std::uint8_t> nodes_on_cut_faces(const SimModel& model) {
  std::vector<std::uint8_t> on_cut(model.node_count, 0);
  if (model.cut_face_mask.empty()) return on_cut;
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int f = 0; f < 4; ++f)
      if (model.cut_face_mask[e] >> f & 1u)
        for (int k = 0; k < 3; ++k) on_cut[model.corner[kTetFace[f][k]][e]] = 1;
  return on_cut;
}

// Holes in the cut (CuttingSettings::hole_angle_deg): an interior face whose three nodes all lie
// on cut faces (made by earlier updates, or separated by this one) and that lies in the cut's
// surface there (within the angle of parallel to a cut face at each of its nodes, and in that cut
// face's plane to within a millimetre) is a remnant of the cut that its rules for settling
// elements left joined: where two strokes meet end to end (a resection's passes entering at one
// place), neither passed all the way through the elements at the seam, and after four passes a
// 56 cm³ lobe hung by one such face of 35 mm². Such faces are added to `separated` (sorted), so the
// cut is exact to within one face. Parting them makes no node newly on the cut, so this does not
// spread along a cut's front.
void add_holes_in_the_cut(const SimModel& model, const NodeArray& rest_m,
                          FaceNeighbours& neighbours, double angle_deg,
                          std::vector<FaceKey>& separated) {
  const std::size_t tets = model.tet_count;
  const bool earlier_cuts = !model.cut_face_mask.empty();
  if (angle_deg <= 0.0 || (!earlier_cuts && separated.empty())) return;
  auto is_cut_face = [&](std::size_t e, int f) {
    return (earlier_cuts && (model.cut_face_mask[e] >> f & 1u)) ||
           std::binary_search(separated.begin(), separated.end(), face_key(model, e, f));
  };
  std::vector<std::uint8_t> on_cut = nodes_on_cut_faces(model);
  for (const FaceKey& key : separated)
    for (NodeIndex n : key) on_cut[n] = 1;
  auto unit_normal = [&](std::size_t e, int f) {
    const Eigen::Vector3d a = rest_m.at(model.corner[kTetFace[f][0]][e]),
                          b = rest_m.at(model.corner[kTetFace[f][1]][e]),
                          c = rest_m.at(model.corner[kTetFace[f][2]][e]);
    return (b - a).cross(c - a).normalized();
  };
  const double least_cos = std::cos(angle_deg * std::numbers::pi / 180.0);
  // A cut face at node n within the angle of parallel to the candidate, whose plane holds the
  // candidate's corners to within kHoleOffPlaneM: the candidate lies in that sheet of the cut,
  // not across the slab between two sheets a few millimetres apart.
  constexpr double kHoleOffPlaneM = 0.001;
  auto in_a_cut_face_plane_at = [&](NodeIndex n, const Eigen::Vector3d& normal,
                                    const std::array<Eigen::Vector3d, 3>& corners) {
    bool found = false;
    for_each_element_of(model, n, [&](std::size_t e) {
      for (int f = 0; f < 4 && !found; ++f) {
        bool holds_n = false;
        for (int k = 0; k < 3; ++k) holds_n |= model.corner[kTetFace[f][k]][e] == n;
        if (!holds_n || !is_cut_face(e, f)) continue;
        const Eigen::Vector3d cut_normal = unit_normal(e, f);
        if (std::abs(cut_normal.dot(normal)) < least_cos) continue;
        bool on_plane = true;
        for (const Eigen::Vector3d& p : corners)
          on_plane &= std::abs(cut_normal.dot(p - rest_m.at(n))) <= kHoleOffPlaneM;
        found = on_plane;
      }
    });
    return found;
  };
  std::vector<FaceKey> holes;
  for (std::size_t e = 0; e < tets; ++e)
    for (int f = 0; f < 4; ++f) {
      bool all_on_cut = true;
      for (int k = 0; k < 3; ++k) all_on_cut &= on_cut[model.corner[kTetFace[f][k]][e]] != 0;
      if (!all_on_cut) continue;
      const auto across = neighbours(e, f);
      if (!across || *across < e || is_cut_face(e, f)) continue;  // each interior face once
      const Eigen::Vector3d normal = unit_normal(e, f);
      std::array<Eigen::Vector3d, 3> corners;
      for (int k = 0; k < 3; ++k) corners[k] = rest_m.at(model.corner[kTetFace[f][k]][e]);
      bool in_the_cut = true;
      for (int k = 0; k < 3 && in_the_cut; ++k)
        in_the_cut = in_a_cut_face_plane_at(model.corner[kTetFace[f][k]][e], normal, corners);
      if (in_the_cut) holes.push_back(face_key(model, e, f));
    }
  if (holes.empty()) return;
  separated.insert(separated.end(), holes.begin(), holes.end());
  std::sort(separated.begin(), separated.end());
}

// The frequency a cut's mass scaling holds the model to: the uncut model's.
double frequency_ceiling(const SimModel& model) {
  return model.uncut_frequency_rad_per_s > 0.0 ? model.uncut_frequency_rad_per_s
                                               : model.max_frequency_rad_per_s;
}

CutResult separate_faces(const SimModel& model, const SimState& state, FaceNeighbours& neighbours,
                         Geometry geometry, const std::vector<std::uint8_t>& snapped,
                         std::vector<FaceKey> separated, const CuttingSettings& settings,
                         const AfterSplitting* after, CutReport so_far,
                         const std::vector<std::uint8_t>* left_whole,
                         std::vector<std::uint8_t>* rerun_thinner, bool keep_pinched = false);

// cut_tissue on a sweep. Unless `after` says otherwise, nodes may be made on edges, and the cut
// then runs again on the model with them, given what this one found.

CutResult cut_along(const SimModel& model, const SimState& state, const SweepSurface& surface,
                    const CuttingSettings& settings, const AfterSplitting* after,
                    const SweepSurface* front = nullptr,
                    const std::vector<std::uint8_t>* half_floor = nullptr,
                    const SweepSurface* recent = nullptr) {
  CutResult result;
  CutReport& report = result.report;
  FaceNeighbours neighbours(model);
  // No element a cut moves, splits or refines may be thinner than this (the explicit step goes
  // with the smallest height, and the mass that keeps it with its inverse square), unless the mesh
  // already had one as thin; on a coarse mesh, not thinner than kLeastPartOfReference of its
  // thinnest element either.
  constexpr double kLeastPartOfReference = 0.4;
  const double reference_m = model.reference_element_height_m > 0.0
                                 ? model.reference_element_height_m
                                 : model.min_element_height_m;
  const double floor_m = std::min(
      reference_m, std::max(settings.min_part_height_m, kLeastPartOfReference * reference_m));

  // 1. The elements the sweep touches, and those of them stressed past the threshold.
  // (Elements the stroke touched since the last update but a few instants, when the stroke says
  // which those are: those it passed before were cut then, and looking at them again cost an
  // update of a long, deep stroke tens of milliseconds.)
  const SweepSurface& zone_sweep = recent ? *recent : surface;
  Aabb sweep_box;
  for (const Aabb& box : zone_sweep.box) sweep_box.grow(box);
  const std::size_t tets = model.tet_count;
  std::vector<std::uint8_t> swept(tets, 0), over_threshold(tets, 0);
  std::vector<std::size_t> zone;
  auto is_over_threshold = [&](std::size_t e) -> std::uint8_t {
    return settings.cutting_stress_pa == 0.0 ||
           element_cutting_stress_pa(model, state, e) >= settings.cutting_stress_pa;
  };
  for (std::size_t e = 0; e < tets; ++e) {
    if (after && !after->may_touch.empty() && !after->may_touch[e]) continue;
    const auto p = corners_at(model, state.position_m, e);
    Aabb box;
    for (const auto& q : p) box.grow(q);
    if (!box.overlaps(sweep_box) || !tet_touches_sweep(p, box, zone_sweep)) continue;
    swept[e] = 1;
    zone.push_back(e);
    over_threshold[e] = is_over_threshold(e);
    report.elements_over_threshold += over_threshold[e];
  }
  report.elements_swept = zone.size();
  if (report.elements_over_threshold == 0) return result;

  // 1b. Elements at the cut's front (those the stroke's last stretch touches: the blade is in
  // them) that are longer than settings.refine_edge_m are bisected on their longest edge (one
  // level an update; an element at most once), so that the front can open within a short stroke
  // on a coarse mesh. Behind the front the snapping and splitting part what the stroke passed
  // through; refined there too, a deep stroke spent the mass budget on small parts it did not
  // need. The cut then runs on the refined model, which stands even when nothing parts.
  if (!after && settings.refine_edge_m > 0.0 && front) {
    struct Longest {
      double length_m;
      NodeIndex a, b;
    };
    std::vector<Longest> longest;
    for (std::size_t e : zone) {
      if (!over_threshold[e]) continue;
      const auto p = corners_at(model, state.position_m, e);
      Aabb box;
      for (const auto& q : p) box.grow(q);
      if (!tet_touches_sweep(p, box, *front)) continue;
      Longest best{0.0, 0, 0};
      for (const auto& edge : kEdge) {
        const NodeIndex a = model.corner[edge[0]][e], b = model.corner[edge[1]][e];
        const double length_m = (model.rest_position_m.at(a) - model.rest_position_m.at(b)).norm();
        if (length_m > best.length_m) best = {length_m, std::min(a, b), std::max(a, b)};
      }
      if (best.length_m > settings.refine_edge_m) longest.push_back(best);
    }
    std::sort(longest.begin(), longest.end(), [](const Longest& l, const Longest& r) {
      return std::tie(r.length_m, l.a, l.b) < std::tie(l.length_m, r.a, r.b);
    });
    std::vector<std::uint8_t> taken(tets, 0);
    std::vector<EdgeSplit> halves;
    for (const Longest& edge : longest) {
      bool free = true;
      for_each_element_of(model, edge.a, [&](std::size_t e) {
        if (element_has_node(model, e, edge.b) && taken[e]) free = false;
      });
      if (!free) continue;
      for_each_element_of(model, edge.a, [&](std::size_t e) {
        if (element_has_node(model, e, edge.b)) taken[e] = 1;
      });
      halves.push_back({edge.a, edge.b, 0.5});
    }
    std::sort(halves.begin(), halves.end());
    refuse_thin_parts(model, model.rest_position_m, settings.split_min_fraction, floor_m, halves);
    if (!halves.empty()) {
      const Geometry as_is = geometry_as_is(model, state);
      Refinement refined =
          split_edges(model, state, as_is, std::vector<std::uint8_t>(model.node_count, 0), halves);
      // The cut on the refined model takes the refinement's parts into its mass scaling.
      AfterSplitting refinement;
      refinement.reshaped_around = refined.reshaped_around;
      refinement.may_make_nodes = true;
      CutResult cut = cut_along(*refined.model, refined.state, surface, settings, &refinement,
                                nullptr, nullptr, recent);
      if (!cut.cut()) {
        // Nothing parted: the refined model stands, its small parts given mass here.
        SimModel& m = *refined.model;
        std::vector<NodeIndex> around;
        for (std::size_t n = 0; n < m.node_count; ++n)
          if (refined.reshaped_around[n]) around.push_back(static_cast<NodeIndex>(n));
        scale_masses_to_frequency(m, around, frequency_ceiling(model),
                                  settings.max_added_mass_fraction,
                                  &refined.state.velocity_m_per_s);
        open_energy_books(m, refined.state);
        cut.report.added_mass_kg = m.added_mass_kg;
        cut.model = refined.model;
        cut.state = std::move(refined.state);
        cut.node_origin.resize(m.node_count);
        std::iota(cut.node_origin.begin(), cut.node_origin.end(), 0);
        cut.element_origin.resize(m.tet_count);
        std::iota(cut.element_origin.begin(), cut.element_origin.end(), 0);
      }
      for (NodeIndex& n : cut.node_origin)
        if (n >= static_cast<NodeIndex>(model.node_count)) n = -1;
      for (TetIndex& e : cut.element_origin) e = refined.element_origin[e];
      cut.report.elements_refined += halves.size();
      return cut;
    }
  }

  // 2. Snap nodes onto the sweep where it crosses the edges of elements it will cut, nearest
  // crossings first.
  Geometry geometry = geometry_as_is(model, state);
  struct Crossing {
    NodeIndex node, other;
    double s;           // along the edge from node to other
    double distance_m;  // the move
  };
  // Where the edge (a, b) crosses the sweep, as the parameter from a.
  auto crossing_of = [&](NodeIndex a, NodeIndex b) {
    return surface.crossing(geometry.position_m.at(a), geometry.position_m.at(b));
  };
  std::vector<Crossing> crossings;
  std::vector<std::array<NodeIndex, 2>> edges;
  for (std::size_t e : zone)
    if (over_threshold[e])
      for (const auto& edge : kEdge) {
        NodeIndex a = model.corner[edge[0]][e], b = model.corner[edge[1]][e];
        edges.push_back({std::min(a, b), std::max(a, b)});
      }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    const auto s = crossing_of(a, b);
    if (!s) continue;
    const double length = (geometry.position_m.at(b) - geometry.position_m.at(a)).norm();
    if (*s <= settings.snap_fraction) crossings.push_back({a, b, *s, *s * length});
    if (*s >= 1.0 - settings.snap_fraction)
      crossings.push_back({b, a, 1.0 - *s, (1.0 - *s) * length});
  }
  // Shortest moves first (ties in node order, for the same cut on every run).
  std::sort(crossings.begin(), crossings.end(), [](const Crossing& l, const Crossing& r) {
    return std::tie(l.distance_m, l.node, l.other) < std::tie(r.distance_m, r.node, r.other);
  });
  std::vector<std::uint8_t> snapped(model.node_count, 0);
  for (const Crossing& crossing : crossings) {
    if (snapped[crossing.node] || model.is_fixed[crossing.node]) continue;
    // An earlier snap may have moved either end: take the crossing as it is now.
    const auto s = crossing_of(crossing.node, crossing.other);
    if (!s || *s > settings.snap_fraction) continue;
    if (try_snap(model, neighbours, geometry, crossing.node, crossing.other, *s,
                 settings.snap_min_shape_fraction, floor_m)) {
      snapped[crossing.node] = 1;
      ++report.snapped_nodes;
    }
  }

  // Elements around a snapped node now touch the sweep too.
  for (NodeIndex n = 0; n < static_cast<NodeIndex>(model.node_count); ++n) {
    if (!snapped[n]) continue;
    for_each_element_of(model, n, [&](std::size_t e) {
      if (swept[e]) return;
      swept[e] = 1;
      zone.push_back(e);
      over_threshold[e] = is_over_threshold(e);
    });
  }

  // Which side of the sweep each node is on: 0 on it, else the side of the nearest triangle's
  // plane. A node on that plane beyond the sweep's edge is on neither side either: an earlier
  // stroke in the same plane put it there (its crack's front), and counting it on one side would
  // leave the elements it holds straddling for this stroke, uncut where two strokes meet.
  std::vector<std::int8_t> node_label(model.node_count, 2);  // 2: not yet known
  auto label_of = [&](NodeIndex n) {
    if (node_label[n] == 2) {
      const Eigen::Vector3d p = geometry.position_m.at(n);
      const auto [distance_m, nearest] = surface.nearest(p);
      const double side_m = surface.side_distance_m(p, nearest);
      node_label[n] = distance_m <= surface.tolerance_m || std::abs(side_m) <= surface.tolerance_m
                          ? 0
                      : side_m >= 0.0 ? 1
                                      : -1;
    }
    return node_label[n];
  };

  // 2b. Where the sweep passes all the way through an element and still crosses an edge of it
  // away from both ends (no node could be moved there), a node is made on that edge, and the cut
  // runs on the model with those nodes: its elements then lie each on one side, none goes whole
  // to the side of its centroid (which left islands of elements joined to nothing on their side).
  if (!after || after->may_make_nodes) {
    std::vector<EdgeSplit> splits, crossed;
    for (std::size_t e : zone) {
      if (!over_threshold[e]) continue;
      crossed.clear();
      bool through = true;
      for (const auto& edge : kEdge) {
        const NodeIndex a = model.corner[edge[0]][e], b = model.corner[edge[1]][e];
        if (label_of(a) * label_of(b) >= 0) continue;
        const auto s = crossing_of(a, b);
        if (!s) {
          through = false;
          break;
        }
        crossed.push_back(a < b ? EdgeSplit{a, b, *s} : EdgeSplit{b, a, 1.0 - *s});
      }
      if (!through) continue;
      for (const EdgeSplit& split : crossed)
        if (split.s >= settings.split_min_fraction && split.s <= 1.0 - settings.split_min_fraction)
          splits.push_back(split);
    }
    std::sort(splits.begin(), splits.end());
    splits.erase(std::unique(splits.begin(), splits.end(),
                             [](const EdgeSplit& l, const EdgeSplit& r) {
                               return l.a == r.a && l.b == r.b;
                             }),
                 splits.end());
    refuse_thin_parts(model, geometry.rest_m, settings.split_min_fraction, floor_m, splits,
                      half_floor);
    if (!splits.empty()) {
      const Refinement refined = split_edges(model, state, geometry, snapped, splits);
      // The parts of elements the sweep did not touch do not touch it either (an edge it crosses
      // is in every element holding it, all touched); the nodes moved or made onto it are on it,
      // and their elements touch it.
      // (Nodes the front's refinement reshaped keep their numbers: split_edges appends.)
      AfterSplitting known;
      known.reshaped_around = refined.reshaped_around;
      if (after)
        for (std::size_t n = 0; n < model.node_count; ++n)
          known.reshaped_around[n] |= after->reshaped_around[n];
      known.may_touch.resize(refined.model->tet_count);
      for (std::size_t i = 0; i < known.may_touch.size(); ++i)
        known.may_touch[i] = swept[refined.element_origin[i]];
      // (Its elements are others: no second run of it with half the floor.)
      static const std::vector<std::uint8_t> no_half_floor;
      CutResult cut = cut_along(*refined.model, refined.state, surface, settings, &known, nullptr,
                                half_floor ? &no_half_floor : nullptr);
      cut.report.snapped_nodes += report.snapped_nodes;
      cut.report.nodes_made_on_edges = splits.size();
      if (!cut.cut()) return cut;
      // Origins in the model before the nodes were made: a node made is no old node's.
      for (NodeIndex& n : cut.node_origin)
        if (n >= static_cast<NodeIndex>(model.node_count)) n = -1;
      for (TetIndex& e : cut.element_origin) e = refined.element_origin[e];
      return cut;
    }
  }

  // 3. Sides. A node on the sweep is on neither; an element lies on the side of its nodes off
  // the sweep, or, when the sweep still passes through it, on the side of its centroid. An
  // element the sweep enters but does not pass all the way through (the blade ends inside it)
  // is not cut: the cut stops at its faces.
  std::vector<std::int8_t> element_side(tets, 0);
  std::vector<std::uint8_t> cut_through(tets, 0), left_whole(tets, 0);
  for (std::size_t e : zone) {
    bool plus = false, minus = false, through = true;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c) {
      const int label = label_of(model.corner[c][e]);
      plus |= label > 0;
      minus |= label < 0;
      centroid += 0.25 * geometry.position_m.at(model.corner[c][e]);
    }
    if (plus && minus)
      for (const auto& edge : kEdge) {
        const NodeIndex a = model.corner[edge[0]][e], b = model.corner[edge[1]][e];
        if (label_of(a) * label_of(b) < 0) through &= crossing_of(a, b).has_value();
      }
    cut_through[e] = through;
    left_whole[e] = plus && minus && through;
    element_side[e] =
        plus && minus ? (surface.side_distance_m(centroid) >= 0.0 ? 1 : -1) : (plus ? 1 : -1);
  }

  // 4. The faces to separate: between elements on opposite sides, both settled (the sweep
  // passed all the way through it, or it lies wholly on one side), one of them past the
  // threshold. An element the blade is still inside holds its faces until the stroke has passed.
  auto settled_side = [&](std::size_t e) -> int {
    if (swept[e]) return cut_through[e] ? element_side[e] : 0;
    int side = 0;
    for (int c = 0; c < 4; ++c) {
      const int label = label_of(model.corner[c][e]);
      if (side != 0 && label != side) return 0;  // straddles the plane beyond the sweep
      side = label;
    }
    return side;
  };
  std::vector<FaceKey> separated;
  for (std::size_t a : zone) {
    const int side_a = settled_side(a);
    if (side_a == 0) continue;
    for (int f = 0; f < 4; ++f) {
      const auto b = neighbours(a, f);
      if (!b || (swept[*b] && *b < a)) continue;
      const int side_b = settled_side(*b);
      if (side_b == 0 || side_b == side_a) continue;
      if (!over_threshold[a] && !(swept[*b] && over_threshold[*b])) continue;
      separated.push_back(face_key(model, a, f));
    }
  }
  std::sort(separated.begin(), separated.end());
  if (separated.empty()) return result;
  std::vector<std::uint8_t> thinner;
  CutResult cut =
      separate_faces(model, state, neighbours, std::move(geometry), snapped, std::move(separated),
                     settings, after, report, half_floor ? nullptr : &left_whole, &thinner);
  if (!thinner.empty())
    return cut_along(model, state, surface, settings, after, front, &thinner, recent);
  return cut;
}

// Steps 5 to 8 of a cut (cut_along): parts the faces `separated` (sorted) of the model, with the
// geometry its snapping left, and builds the new model and state. `left_whole` (per element: the
// sweep passed through it and left it whole), when given, may ask for the cut to run again with
// those of them a merge took and their neighbours split down to half the height floor: then
// `rerun_thinner` is set to them and what is returned is to be dropped. `keep_pinched`: a node the
// faces pinch (its copy's surface not one fan) stays so, instead of the faces around it joining
// again (part_remnants).
CutResult separate_faces(const SimModel& model, const SimState& state, FaceNeighbours& neighbours,
                         Geometry geometry, const std::vector<std::uint8_t>& snapped,
                         std::vector<FaceKey> separated, const CuttingSettings& settings,
                         const AfterSplitting* after, CutReport so_far,
                         const std::vector<std::uint8_t>* left_whole,
                         std::vector<std::uint8_t>* rerun_thinner, bool keep_pinched) {
  CutResult result;
  result.report = so_far;
  CutReport& report = result.report;
  const std::size_t tets = model.tet_count;
  auto is_separated = [&](const FaceKey& key) {
    return std::binary_search(separated.begin(), separated.end(), key);
  };

  // 5. Copies of the nodes on separated faces: the elements around a node that stay joined
  // through faces keep one copy between them. A copy whose boundary is not one fan of triangles
  // (the cut reaches it from two sides without parting its elements: a pinched vertex or edge)
  // would not be a manifold surface; the faces around it stay joined instead, until none is.
  std::array<std::vector<NodeIndex>, 4> corner;
  std::vector<NodeIndex> node_origin;
  std::vector<NodeIndex> touched, pinched;
  std::vector<std::size_t> around;
  std::vector<std::array<NodeIndex, 2>> arcs;
  std::vector<std::int32_t> component;
  std::vector<NodeIndex> copy_of;
  for (;;) {
    touched.clear();
    for (const FaceKey& key : separated) touched.insert(touched.end(), key.begin(), key.end());
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    corner = model.corner;
    node_origin.resize(model.node_count);
    std::iota(node_origin.begin(), node_origin.end(), 0);
    pinched.clear();
    for (NodeIndex n : touched) {
      around.clear();
      for_each_element_of(model, n, [&](std::size_t e) { around.push_back(e); });
      UnionFind joined(around.size());
      for (std::size_t i = 0; i < around.size(); ++i)
        for (int f = 0; f < 4; ++f) {
          const std::size_t e = around[i];
          bool has_n = false;
          for (int k = 0; k < 3; ++k) has_n |= model.corner[kTetFace[f][k]][e] == n;
          if (!has_n) continue;
          const auto other = neighbours(e, f);
          if (!other || is_separated(face_key(model, e, f))) continue;
          const auto j = std::find(around.begin(), around.end(), *other) - around.begin();
          joined.unite(static_cast<std::int32_t>(i), static_cast<std::int32_t>(j));
        }
      component.resize(around.size());
      for (std::size_t i = 0; i < around.size(); ++i)
        component[i] = joined.find(static_cast<std::int32_t>(i));
      // Component of the first element keeps n; each other component gets a copy.
      for (std::size_t i = 0; i < around.size(); ++i) {
        if (component[i] == 0) continue;
        const std::size_t first = static_cast<std::size_t>(
            std::find(component.begin(), component.end(), component[i]) - component.begin());
        NodeIndex copy = -1;
        if (first == i) {
          copy = static_cast<NodeIndex>(node_origin.size());
          node_origin.push_back(n);
        } else {
          copy = copy_in(model, corner, around[first], n);
        }
        for (int c = 0; c < 4; ++c)
          if (model.corner[c][around[i]] == n) corner[c][around[i]] = copy;
      }
    }
    // A separated face whose elements still share all three of its nodes parts nothing (the
    // cut ends at it): it stays joined.
    std::erase_if(separated, [&](const FaceKey& key) {
      std::array<std::size_t, 2> pair{};
      int found = 0;
      for_each_element_of(model, key[0], [&](std::size_t e) {
        if (found < 2 && element_has_node(model, e, key[1]) && element_has_node(model, e, key[2]))
          pair[found++] = e;
      });
      for (NodeIndex n : key)
        if (copy_in(model, corner, pair[0], n) != copy_in(model, corner, pair[1], n)) return false;
      return true;
    });
    // Each copy's boundary around it, as the arcs b → c of its boundary faces (copy, b, c).
    for (NodeIndex n : touched) {
      around.clear();
      for_each_element_of(model, n, [&](std::size_t e) { around.push_back(e); });
      // The copy of n in each element around it; each copy's arcs are gathered once, from the
      // first element that has it on.
      copy_of.resize(around.size());
      for (std::size_t i = 0; i < around.size(); ++i)
        copy_of[i] = copy_in(model, corner, around[i], n);
      bool is_pinched = false;
      for (std::size_t first = 0; first < around.size() && !is_pinched; ++first) {
        const NodeIndex copy = copy_of[first];
        if (std::find(copy_of.begin(), copy_of.begin() + first, copy) != copy_of.begin() + first)
          continue;
        arcs.clear();
        for (std::size_t i = first; i < around.size(); ++i) {
          const std::size_t e = around[i];
          if (copy_of[i] != copy) continue;
          for (int f = 0; f < 4; ++f) {
            std::array<NodeIndex, 3> face;
            for (int k = 0; k < 3; ++k) face[k] = corner[kTetFace[f][k]][e];
            const auto at = std::find(face.begin(), face.end(), copy) - face.begin();
            if (at == 3) continue;
            if (neighbours(e, f) && !is_separated(face_key(model, e, f))) continue;
            arcs.push_back({face[(at + 1) % 3], face[(at + 2) % 3]});
          }
        }
        if (arcs.empty()) continue;
        is_pinched = !arcs_form_one_cycle(arcs);
      }
      if (is_pinched) pinched.push_back(n);
    }
    if (pinched.empty() || keep_pinched) break;
    // At a pinched node, the separated faces around it fall into groups joined through edges
    // from it: keep the largest group when there are several (the others rejoin, to be cut as
    // the stroke goes on), none when one group alone pinches it (against the organ's surface).
    std::vector<FaceKey> rejoin;
    for (NodeIndex n : pinched) {
      std::vector<FaceKey> around_n;
      for (const FaceKey& key : separated)
        if (std::find(key.begin(), key.end(), n) != key.end()) around_n.push_back(key);
      UnionFind groups(around_n.size());
      for (std::size_t i = 0; i < around_n.size(); ++i)
        for (std::size_t j = 0; j < i; ++j) {
          int shared = 0;
          for (NodeIndex a : around_n[i])
            shared += std::count(around_n[j].begin(), around_n[j].end(), a);
          if (shared >= 2) groups.unite(static_cast<std::int32_t>(i), static_cast<std::int32_t>(j));
        }
      std::vector<std::size_t> size(around_n.size(), 0);
      for (std::size_t i = 0; i < around_n.size(); ++i)
        ++size[groups.find(static_cast<std::int32_t>(i))];
      const auto largest = std::max_element(size.begin(), size.end()) - size.begin();
      const bool several =
          std::count_if(size.begin(), size.end(), [](std::size_t k) { return k > 0; }) > 1;
      for (std::size_t i = 0; i < around_n.size(); ++i)
        if (!several || groups.find(static_cast<std::int32_t>(i)) != largest)
          rejoin.push_back(around_n[i]);
    }
    std::sort(rejoin.begin(), rejoin.end());
    std::erase_if(separated, [&](const FaceKey& key) {
      return std::binary_search(rejoin.begin(), rejoin.end(), key);
    });
    if (separated.empty()) return result;
  }
  if (separated.empty()) return result;
  report.separated_faces = separated.size();
  report.duplicated_nodes = node_origin.size() - model.node_count;

  // 6. Pieces: elements joined through shared nodes. Pieces holding a fixed node stay (all of
  // them: the surgeon's cut is not undone); without fixed nodes the largest stays.
  const std::size_t nodes_after_split = node_origin.size();
  Pieces pieces(corner, nodes_after_split, model.rest_volume_m3,
                [&](std::size_t n) { return model.is_fixed[node_origin[n]] != 0; });
  auto in_organ = [&](std::int32_t root) { return pieces.in_organ(root); };
  // A piece that came free stays as a body of its own unless it is a crumb.
  auto keeps = [&](std::int32_t root) {
    return in_organ(root) || pieces.volume_m3[root] >= settings.min_free_body_volume_m3;
  };
  // What was in the organ before this cut: what leaves it now is resected.
  const std::vector<std::uint8_t> was_in_organ = organ_elements(model);

  // 6b. Flaps: an element the cut leaves joined to the rest through one face or none, with a
  // corner no other element holds. That corner carries a quarter of one small element's mass, and
  // when the cut releases the stress around it, it flies off at metres per second and sets the
  // explicit step (issue 42). The flap is merged into the element across its joined face (or one
  // sharing its nodes), which takes its mass: no mass is lost, a sliver of volume is.
  std::vector<std::uint8_t> merged(tets, 0), exposed(tets, 0);  // exposed: faces bared by a merge
  std::vector<std::size_t> cut_elements;
  for (const FaceKey& key : separated)
    for (NodeIndex n : key)
      for_each_element_of(model, n, [&](std::size_t e) { cut_elements.push_back(e); });
  std::sort(cut_elements.begin(), cut_elements.end());
  cut_elements.erase(std::unique(cut_elements.begin(), cut_elements.end()), cut_elements.end());
  auto holds = [&](std::size_t e, NodeIndex copy) {
    for (int c = 0; c < 4; ++c)
      if (corner[c][e] == copy) return true;
    return false;
  };
  // Merging one flap may leave its neighbour hanging: again until none is left.
  for (bool merged_one = true; merged_one;) {
    merged_one = false;
    for (std::size_t e : cut_elements) {
      if (merged[e] || !keeps(pieces.of_element(e))) continue;
      bool lone_corner = false, holds_fixed = false;
      std::optional<std::size_t> touching, across;
      for (int c = 0; c < 4; ++c) {
        const NodeIndex copy = corner[c][e];
        holds_fixed |= model.is_fixed[node_origin[copy]] != 0;
        bool shared = false;
        for_each_element_of(model, node_origin[copy], [&](std::size_t o) {
          if (o == e || merged[o] || !holds(o, copy)) return;
          shared = true;
          if (!touching) touching = o;
        });
        lone_corner |= !shared;
      }
      if (!lone_corner || holds_fixed || !touching) continue;
      int joined_faces = 0, across_face = -1;
      for (int f = 0; f < 4; ++f) {
        const NodeIndex a = corner[kTetFace[f][0]][e], b = corner[kTetFace[f][1]][e],
                        c = corner[kTetFace[f][2]][e];
        for_each_element_of(model, node_origin[a], [&](std::size_t o) {
          if (o == e || merged[o] || !holds(o, a) || !holds(o, b) || !holds(o, c)) return;
          ++joined_faces;
          across = o;
          for (int g = 0; g < 4; ++g) {  // the face of o opposite its corner off the joined face
            const NodeIndex off = corner[g][o];
            if (off != a && off != b && off != c) across_face = g;
          }
        });
      }
      if (joined_faces > 1) continue;
      const std::size_t into = across ? *across : *touching;
      if (across) exposed[into] |= std::uint8_t(1u << across_face);
      merged[e] = 1;
      merged_one = true;
      geometry.element_mass_kg[into] += geometry.element_mass_kg[e];
      ++report.merged_elements;
      report.merged_volume_m3 += shape_of(corners_at(model, geometry.rest_m, e)).volume_m3;
    }
  }
  // A flap the stroke passed through whole (its crossings could be neither snapped nor split
  // above the height floor) would take its volume off the blade's path: in a block, a blade 15 mm
  // deep then met 4 mm less tissue. The cut runs once more with those elements split down to
  // half the floor, their thinner parts held by added mass. (Half the floor for every element
  // the stroke passes through halted a live stroke; only these few are let through.)
  if (left_whole) {
    std::vector<std::uint8_t> thinner(tets, 0);
    bool any = false;
    // (With the elements around them: an edge is split only if every element holding it may be.)
    for (std::size_t e = 0; e < tets; ++e)
      if (merged[e] && (*left_whole)[e]) {
        any = true;
        for (int c = 0; c < 4; ++c)
          for_each_element_of(model, model.corner[c][e], [&](std::size_t o) { thinner[o] = 1; });
      }
    if (any) {
      *rerun_thinner = std::move(thinner);
      return result;
    }
  }

  // A free body the merges left one element is a flap of its own: a crumb (a lone element's
  // corners carry a quarter of its mass each and would set the explicit step).
  std::vector<std::int32_t> unmerged(nodes_after_split, 0);
  for (std::size_t e = 0; e < tets; ++e)
    if (!merged[e]) ++unmerged[pieces.of_element(e)];
  auto stays = [&](std::int32_t root) {
    return in_organ(root) || (keeps(root) && unmerged[root] >= 2);
  };

  // 7. The new model: the kept elements (in their old order) and the nodes they use.
  std::vector<TetIndex> element_origin;
  element_origin.reserve(tets);
  for (std::size_t e = 0; e < tets; ++e) {
    if (merged[e]) continue;
    const std::int32_t piece = pieces.of_element(e);
    const double volume_m3 = shape_of(corners_at(model, geometry.rest_m, e)).volume_m3;
    if (was_in_organ[e] && !in_organ(piece)) report.resected_volume_m3 += volume_m3;
    if (stays(piece)) {
      element_origin.push_back(static_cast<TetIndex>(e));
      if (was_in_organ[e] && !in_organ(piece)) {
        ++report.freed_elements;
        report.freed_volume_m3 += volume_m3;
      }
    } else {
      ++report.removed_elements;
      report.removed_mass_kg += geometry.element_mass_kg[e];
    }
  }
  if (element_origin.empty())
    return result;  // the sweep would take everything away (no fixed node): leave it whole
  std::vector<NodeIndex> new_index(nodes_after_split, -1);
  std::vector<NodeIndex> kept_node_origin;
  for (TetIndex e : element_origin)
    for (int c = 0; c < 4; ++c) {
      const NodeIndex n = corner[c][e];
      if (new_index[n] < 0) new_index[n] = 0;
    }
  for (std::size_t n = 0; n < nodes_after_split; ++n)
    if (new_index[n] == 0) {
      new_index[n] = static_cast<NodeIndex>(kept_node_origin.size());
      kept_node_origin.push_back(static_cast<NodeIndex>(n));  // index after the split, for now
    }
  report.removed_nodes = nodes_after_split - kept_node_origin.size();

  auto next = std::make_shared<SimModel>(model);
  SimModel& m = *next;
  m.node_count = kept_node_origin.size();
  m.tet_count = element_origin.size();
  auto take = [&](auto& per_element) { take_from_origin(per_element, element_origin); };
  for (int c = 0; c < 4; ++c) {
    m.corner[c].resize(element_origin.size());
    for (std::size_t i = 0; i < element_origin.size(); ++i)
      m.corner[c][i] = new_index[corner[c][element_origin[i]]];
  }
  take_element_data(m, element_origin);
  if (m.cut_face_mask.empty()) m.cut_face_mask.assign(tets, 0);
  take(m.cut_face_mask);
  if (m.boundary_face_mask.empty()) {  // the first cut: the organ's surface
    m.boundary_face_mask.assign(tets, 0);
    for (std::size_t e = 0; e < tets; ++e)
      for (int f = 0; f < 4; ++f)
        if (!neighbours(e, f)) m.boundary_face_mask[e] |= std::uint8_t(1u << f);
  }
  take(m.boundary_face_mask);
  m.element_mass_kg = std::move(geometry.element_mass_kg);
  take(m.element_mass_kg);

  m.rest_position_m.resize(m.node_count);
  m.is_fixed.assign(m.node_count, 0);
  std::vector<NodeIndex> origin(m.node_count);
  for (std::size_t i = 0; i < m.node_count; ++i) {
    const NodeIndex split = kept_node_origin[i];
    origin[i] = node_origin[split];
    m.rest_position_m.set(i, geometry.rest_m.at(origin[i]));
    m.is_fixed[i] = model.is_fixed[origin[i]];
  }

  // Elements whose corners moved get their shape data again; the cut faces are marked.
  std::vector<std::uint8_t> reshaped(m.tet_count, 0), touched_by_cut(model.node_count, 0);
  for (NodeIndex n : touched) touched_by_cut[n] = 1;
  for (std::size_t i = 0; i < m.tet_count; ++i) {
    const std::size_t old = element_origin[i];
    bool moved = false;
    int corners_on_cut = 0;
    for (int c = 0; c < 4; ++c) {
      moved |= snapped[model.corner[c][old]] != 0;
      corners_on_cut += touched_by_cut[model.corner[c][old]];
    }
    if (corners_on_cut >= 3)
      for (int f = 0; f < 4; ++f)
        if (is_separated(face_key(model, old, f))) {
          m.cut_face_mask[i] |= std::uint8_t(1u << f);
          m.boundary_face_mask[i] |= std::uint8_t(1u << f);
        }
    m.cut_face_mask[i] |= exposed[old];  // inside tissue a merged flap covered
    m.boundary_face_mask[i] |= exposed[old];
    reshaped[i] = moved;
    if (!moved) continue;
    reshape_element(m, i);
  }
  // A node's added mass goes with it, shared among its copies by their masses (a copy in a piece
  // that came free takes its share away).
  if (!model.node_added_mass_kg.empty()) {
    m.node_added_mass_kg.clear();
    lump_node_masses(m);
    std::vector<double> copies_kg(model.node_count, 0.0);
    for (std::size_t i = 0; i < m.node_count; ++i) copies_kg[origin[i]] += m.lumped_mass_kg[i];
    m.node_added_mass_kg.assign(m.node_count, 0.0);
    for (std::size_t i = 0; i < m.node_count; ++i) {
      const NodeIndex n = origin[i];
      const double own_kg = model.lumped_mass_kg[n] - model.node_added_mass_kg[n];
      if (own_kg > 0.0)
        m.node_added_mass_kg[i] =
            model.node_added_mass_kg[n] * m.lumped_mass_kg[i] / std::max(own_kg, copies_kg[n]);
    }
  }
  lump_masses(m);

  // The stable step: the mesh's largest frequency is the old one or one of the modes around the
  // cut (see local_max_frequency_rad_per_s); the smallest height may only shrink.
  NodeArray position;
  position.resize(m.node_count);
  for (std::size_t n = 0; n < m.node_count; ++n) position.set(n, geometry.position_m.at(origin[n]));
  // The modes a cut raises sit on the nodes it split (less mass each) and the elements a snap
  // reshaped.
  std::vector<NodeIndex> around_cut;
  for (std::size_t n = 0; n < m.node_count; ++n)
    if (touched_by_cut[origin[n]] || (after && after->reshaped_around[origin[n]]))
      around_cut.push_back(static_cast<NodeIndex>(n));
  for (std::size_t i = 0; i < m.tet_count; ++i) {
    if (!reshaped[i]) continue;
    std::array<Eigen::Vector3d, 4> p;
    for (int c = 0; c < 4; ++c) {
      around_cut.push_back(m.corner[c][i]);
      p[c] = m.rest_position_m.at(m.corner[c][i]);
    }
    m.min_element_height_m = std::min(m.min_element_height_m, shape_of(p).min_height_m);
  }
  // And the nodes one element away: the block's estimate holds the nodes outside it still, a
  // lower bound that missed a mode reaching the light nodes beside the cut (a stroke in free
  // practice: 3059 rad/s over the whole mesh against the 2676 held, a step of 0.675 ms past its
  // limit of 0.654, and the guard halted the simulation).
  {
    std::vector<std::uint8_t> in_block(m.node_count, 0);
    for (NodeIndex n : around_cut) in_block[n] = 1;
    const std::size_t block_size = around_cut.size();
    for (std::size_t k = 0; k < block_size; ++k)
      for_each_element_of(m, around_cut[k], [&](std::size_t e) {
        for (int c = 0; c < 4; ++c) {
          const NodeIndex n = m.corner[c][e];
          if (!in_block[n]) {
            in_block[n] = 1;
            around_cut.push_back(n);
          }
        }
      });
  }
  // 8. The state carried over: positions and velocities of each node's origin, the history of
  // each element; the energy books open again on the new model.
  NodeArray velocity;
  velocity.resize(m.node_count);
  for (std::size_t n = 0; n < m.node_count; ++n)
    velocity.set(n, geometry.velocity_m_per_s.at(origin[n]));
  // Small parts would raise the frequency: they are given mass instead, so that the explicit step
  // stays.
  scale_masses_to_frequency(m, around_cut, frequency_ceiling(model),
                            settings.max_added_mass_fraction, &velocity);
  report.added_mass_kg = m.added_mass_kg;
  complete(result, std::move(next), state, std::move(position), std::move(velocity),
           std::move(origin), std::move(element_origin));
  return result;
}

}  // namespace

// The instants before the settled ones a cut looks at again (10 mm of a stroke in the loop): a
// bridge an update had to leave joined (a pinched node, a part too thin to make) may part once the
// next update has changed the mesh around it.
constexpr std::size_t kInstantsLookedAtAgain = 20;

namespace {

// Bends the stroke's instants not yet bent, with the tissue as it is now, and keeps them so.
void follow_grooves(BladeStroke& stroke, const SimModel& model, const NodeArray& position_m,
                    double guide_m) {
  if (stroke.cutting_edges_m.size() > stroke.edges_m.size())
    throw std::invalid_argument("the blade's stroke has more cutting edges than instants");
  bend_onto_grooves(model, position_m, stroke, stroke.cutting_edges_m.size(), guide_m,
                    stroke.cutting_edges_m);
}

// Whether the stroke refines the mesh around its front now (CuttingSettings::refine_over_stroke_m):
// on its first stretch, and while the cuts' added mass leaves their own thin parts half the budget.
bool refines_at(const SimModel& model, std::span<const std::array<Eigen::Vector3d, 2>> edges_m,
                const CuttingSettings& settings) {
  if (model.added_mass_kg >=
      kRefinementBudgetShare * settings.max_added_mass_fraction * tissue_mass_kg(model))
    return false;
  double travel_m = 0.0;
  for (std::size_t i = 1; i < edges_m.size(); ++i) {
    travel_m +=
        0.5 * ((edges_m[i][0] + edges_m[i][1]) - (edges_m[i - 1][0] + edges_m[i - 1][1])).norm();
    if (travel_m > settings.refine_over_stroke_m) return false;
  }
  return true;
}

}  // namespace

CutResult cut_tissue(const SimModel& model, const SimState& state, const BladeStroke& stroke,
                     const CuttingSettings& settings) {
  if (auto problem = validate(settings)) throw std::invalid_argument(*problem);
  for (const auto& edge : stroke.edges_m)
    if (!edge[0].allFinite() || !edge[1].allFinite())
      throw std::invalid_argument("the blade's stroke is not finite");
  // A blade that did not move sweeps nothing.
  if (stroke.cutting_edges_m.size() > stroke.edges_m.size())
    throw std::invalid_argument("the blade's stroke has more cutting edges than instants");
  for (const auto& edge : stroke.cutting_edges_m)
    for (const auto& point : edge)
      if (!point.allFinite()) throw std::invalid_argument("the blade's stroke is not finite");
  const std::vector<EdgePoints> edges =
      cutting_edges(model, state.position_m, stroke, settings.groove_guide_m);
  const SweepSurface surface = sweep_surface(edges, stroke.edges_m);
  if (surface.size() == 0) return {};
  std::optional<SweepSurface> recent;
  if (stroke.settled_instants > 0) {
    const std::size_t from =
        stroke.settled_instants > kInstantsLookedAtAgain + 1
            ? std::min(stroke.settled_instants - kInstantsLookedAtAgain - 1, edges.size() - 1)
            : 0;
    if (from > 0)
      recent = sweep_surface(std::vector<EdgePoints>(edges.begin() + from, edges.end()),
                             std::span(stroke.edges_m).subspan(from));
  }
  if (settings.refine_edge_m > 0.0 && edges.size() >= 2 &&
      refines_at(model, stroke.edges_m, settings)) {
    const SweepSurface front = sweep_surface(std::vector<EdgePoints>(edges.end() - 2, edges.end()),
                                             std::span(stroke.edges_m).last(2));
    if (front.size() > 0)
      return cut_along(model, state, surface, settings, nullptr, &front, nullptr,
                       recent ? &*recent : nullptr);
  }
  return cut_along(model, state, surface, settings, nullptr, nullptr, nullptr,
                   recent ? &*recent : nullptr);
}

CutResult cut_stroke_so_far(const SimModel& model, const SimState& state, BladeStroke& stroke,
                            const CuttingSettings& settings) {
  follow_grooves(stroke, model, state.position_m, settings.groove_guide_m);
  CutResult cut = cut_tissue(model, state, stroke, settings);
  stroke.settled_instants = stroke.edges_m.size();
  return cut;
}

// A maximum flow from the elements `end` marks 1 to those it marks -1 over the elements' faces, one
// through a face with a `near` element, more than kStrandFaces through any other, given up past
// kStrandFaces: the elements the last search reached (those on the first ends' side of a minimum
// cut, which parts near faces only) and the cut's size; none past kStrandFaces. (With one through
// every face, the cut nearest the first ends was taken, and held by the forceps it ran round the
// few elements they hold, away from the cut, where the lobe hung by 7 faces near it.)
struct MinimumCut {
  std::vector<std::uint8_t> reached;
  int faces = 0;
};
std::optional<MinimumCut> minimum_cut(const SimModel& model, FaceNeighbours& neighbours,
                                      const std::vector<std::int8_t>& end,
                                      const std::vector<std::uint8_t>& near) {
  const std::size_t tets = model.tet_count;
  // flow[4e + f] is what leaves element e through its face f.
  std::vector<std::int8_t> flow(4 * tets, 0);
  std::vector<std::int64_t> reached_by(tets, -1);  // 4e + f of the face it was reached through
  MinimumCut cut;
  cut.reached.assign(tets, 0);
  std::vector<std::size_t> queue;
  auto face_into = [&](std::size_t e, int f, std::size_t other) {
    const FaceKey key = face_key(model, e, f);
    for (int g = 0; g < 4; ++g)
      if (face_key(model, other, g) == key) return g;
    return -1;
  };
  for (;;) {
    std::fill(cut.reached.begin(), cut.reached.end(), 0);
    queue.clear();
    for (std::size_t e = 0; e < tets; ++e)
      if (end[e] > 0) {
        cut.reached[e] = 1;
        reached_by[e] = -1;
        queue.push_back(e);
      }
    std::optional<std::size_t> sink;
    for (std::size_t h = 0; h < queue.size() && !sink; ++h) {
      const std::size_t a = queue[h];
      for (int f = 0; f < 4; ++f) {
        const auto b = neighbours(a, f);
        if (!b || cut.reached[*b]) continue;
        if (flow[4 * a + f] >= (near[a] || near[*b] ? 1 : kStrandFaces + 1)) continue;
        cut.reached[*b] = 1;
        reached_by[*b] = static_cast<std::int64_t>(4 * a + f);
        if (end[*b] < 0) {
          sink = *b;
          break;
        }
        queue.push_back(*b);
      }
    }
    if (!sink) return cut;
    if (++cut.faces > kStrandFaces) return std::nullopt;
    for (std::size_t b = *sink; reached_by[b] >= 0;) {
      const std::size_t a = static_cast<std::size_t>(reached_by[b] / 4);
      const int f = static_cast<int>(reached_by[b] % 4);
      ++flow[4 * a + f];
      --flow[4 * b + face_into(a, f, b)];
      b = a;
    }
  }
}

// The faces a minimum cut parts (from what it reached to the rest; near the cut, as minimum_cut
// parts no other) when the piece it frees, the side that holds no fixed node, is at least
// CuttingSettings::min_free_body_volume_m3; otherwise none.
std::vector<FaceKey> strand_of_cut(const SimModel& model, FaceNeighbours& neighbours,
                                   const MinimumCut& cut, const CuttingSettings& settings) {
  if (cut.faces == 0) return {};  // apart already
  const std::size_t tets = model.tet_count;
  double reached_m3 = 0.0, rest_m3 = 0.0;
  bool reached_fixed = false, rest_fixed = false;
  for (std::size_t e = 0; e < tets; ++e) {
    bool holds_fixed = false;
    for (int c = 0; c < 4; ++c) holds_fixed |= model.is_fixed[model.corner[c][e]] != 0;
    (cut.reached[e] ? reached_m3 : rest_m3) += model.rest_volume_m3[e];
    (cut.reached[e] ? reached_fixed : rest_fixed) |= holds_fixed;
  }
  const bool frees_reached = !reached_fixed && (rest_fixed || reached_m3 <= rest_m3);
  if (!frees_reached && rest_fixed) return {};
  if ((frees_reached ? reached_m3 : rest_m3) < settings.min_free_body_volume_m3) return {};
  std::vector<FaceKey> strand;
  for (std::size_t a = 0; a < tets; ++a) {
    if (!cut.reached[a]) continue;
    for (int f = 0; f < 4; ++f) {
      const auto b = neighbours(a, f);
      if (b && !cut.reached[*b]) strand.push_back(face_key(model, a, f));
    }
  }
  return strand;
}

// The elements the stroke's sweep touches, on its two sides (by their centroids): 1 and -1.
std::vector<std::int8_t> swept_sides(const SimModel& model, const SimState& state,
                                     const BladeStroke& stroke, const CuttingSettings& settings) {
  std::vector<std::int8_t> side(model.tet_count, 0);
  if (stroke.edges_m.size() < 2) return side;
  const std::vector<EdgePoints> edges =
      cutting_edges(model, state.position_m, stroke, settings.groove_guide_m);
  const SweepSurface surface = sweep_surface(edges, stroke.edges_m);
  if (surface.size() == 0) return side;
  Aabb sweep_box;
  for (const Aabb& box : surface.box) sweep_box.grow(box);
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const auto p = corners_at(model, state.position_m, e);
    Aabb box;
    for (const auto& q : p) box.grow(q);
    if (!box.overlaps(sweep_box) || !tet_touches_sweep(p, box, surface)) continue;
    const Eigen::Vector3d centroid = 0.25 * (p[0] + p[1] + p[2] + p[3]);
    side[e] = surface.side_distance_m(centroid) >= 0.0 ? 1 : -1;
  }
  return side;
}

// A strand between the sweep's two sides: the smallest set of faces between the elements it
// touches on one side and those on the other, each reached by the sweep.
std::vector<FaceKey> strand_across_the_sweep(const SimModel& model, FaceNeighbours& neighbours,
                                             const std::vector<std::int8_t>& side,
                                             const CuttingSettings& settings) {
  if (std::find(side.begin(), side.end(), 1) == side.end() ||
      std::find(side.begin(), side.end(), -1) == side.end())
    return {};
  std::vector<std::uint8_t> swept(model.tet_count);
  for (std::size_t e = 0; e < model.tet_count; ++e) swept[e] = side[e] != 0;
  const auto cut = minimum_cut(model, neighbours, side, swept);
  if (!cut) return {};
  return strand_of_cut(model, neighbours, *cut, settings);
}

// A strand that holds what another tool holds: the smallest set of faces between the elements
// holding a held node and those holding a fixed node, each near the cut (one of its elements
// reached by the sweep or with a node on a cut face), when the held side holds no fixed node.
std::vector<FaceKey> strand_of_the_held(const SimModel& model, FaceNeighbours& neighbours,
                                        const std::vector<std::int8_t>& side,
                                        std::span<const NodeIndex> held_nodes,
                                        const CuttingSettings& settings) {
  if (held_nodes.empty() || model.cut_face_mask.empty()) return {};
  const std::size_t tets = model.tet_count;
  std::vector<std::uint8_t> held(model.node_count, 0);
  for (NodeIndex n : held_nodes)
    if (n >= 0 && static_cast<std::size_t>(n) < model.node_count) held[n] = 1;
  const std::vector<std::uint8_t> on_cut = nodes_on_cut_faces(model);
  std::vector<std::int8_t> end(tets, 0);
  std::vector<std::uint8_t> near(tets, 0);
  bool holds = false, anchored = false;
  for (std::size_t e = 0; e < tets; ++e) {
    near[e] = side[e] != 0;
    for (int c = 0; c < 4; ++c) {
      const NodeIndex n = model.corner[c][e];
      near[e] |= on_cut[n];
      if (held[n] && end[e] == 0) end[e] = 1;
      if (model.is_fixed[n]) end[e] = -1;
    }
    holds |= end[e] > 0;
    anchored |= end[e] < 0;
  }
  if (!holds || !anchored) return {};
  const auto cut = minimum_cut(model, neighbours, end, near);
  if (!cut) return {};
  return strand_of_cut(model, neighbours, *cut, settings);  // what it reached holds no fixed node
}

CutResult part_remnants(const SimModel& model, const SimState& state, const BladeStroke& stroke,
                        const CuttingSettings& settings, std::span<const NodeIndex> held_nodes) {
  if (auto problem = validate(settings)) throw std::invalid_argument(*problem);
  FaceNeighbours neighbours(model);
  const std::vector<std::int8_t> side = swept_sides(model, state, stroke, settings);
  std::vector<FaceKey> strand = strand_across_the_sweep(model, neighbours, side, settings);
  if (strand.empty()) strand = strand_of_the_held(model, neighbours, side, held_nodes, settings);
  std::sort(strand.begin(), strand.end());
  const Geometry as_is = geometry_as_is(model, state);
  add_holes_in_the_cut(model, as_is.rest_m, neighbours, settings.hole_angle_deg, strand);
  if (strand.empty()) return {};
  // Parted at a node of the organ's surface, a strand may leave the node pinched on the piece
  // (its surface and the strand's faces meet there at a point): the piece is free all the same.
  return separate_faces(model, state, neighbours, as_is,
                        std::vector<std::uint8_t>(model.node_count, 0), std::move(strand), settings,
                        nullptr, CutReport{}, nullptr, nullptr, true);
}

std::vector<std::uint8_t> organ_elements(const SimModel& model) {
  Pieces pieces(model);
  std::vector<std::uint8_t> organ(model.tet_count, 0);
  for (std::size_t e = 0; e < model.tet_count; ++e)
    organ[e] = pieces.in_organ(pieces.of_element(e)) ? 1 : 0;
  return organ;
}

std::vector<FreeBody> free_bodies(const SimModel& model) {
  Pieces pieces(model);
  std::vector<FreeBody> bodies;
  std::vector<std::int32_t> body_of_root(model.node_count, -1);
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const std::int32_t root = pieces.of_element(e);
    if (pieces.in_organ(root)) continue;
    if (body_of_root[root] < 0) {
      body_of_root[root] = static_cast<std::int32_t>(bodies.size());
      bodies.push_back({{}, pieces.volume_m3[root]});
    }
    bodies[body_of_root[root]].elements.push_back(static_cast<TetIndex>(e));
  }
  return bodies;
}

CutResult take_out_body(const SimModel& model, const SimState& state, TetIndex element) {
  if (element < 0 || static_cast<std::size_t>(element) >= model.tet_count)
    throw std::invalid_argument("take_out_body: element " + std::to_string(element) +
                                " is not in the model of " + std::to_string(model.tet_count) +
                                " elements");
  Pieces pieces(model);
  const std::int32_t body = pieces.of_element(static_cast<std::size_t>(element));
  if (pieces.in_organ(body))
    throw std::invalid_argument("take_out_body: element " + std::to_string(element) +
                                " is in the organ, not in a free body");
  CutResult result;
  std::vector<TetIndex> element_origin;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    if (pieces.of_element(e) == body) {
      ++result.report.removed_elements;
    } else {
      element_origin.push_back(static_cast<TetIndex>(e));
    }
  }
  std::vector<NodeIndex> new_index(model.node_count, -1), node_origin;
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (pieces.joined.find(static_cast<std::int32_t>(n)) != body) {
      new_index[n] = static_cast<NodeIndex>(node_origin.size());
      node_origin.push_back(static_cast<NodeIndex>(n));
    } else {  // the body's nodes are its own: their mass (added mass too) leaves with it
      result.report.removed_mass_kg += model.lumped_mass_kg[n];
    }
  result.report.removed_nodes = model.node_count - node_origin.size();

  auto next = std::make_shared<SimModel>(model);
  SimModel& m = *next;
  m.node_count = node_origin.size();
  m.tet_count = element_origin.size();
  for (int c = 0; c < 4; ++c) {
    m.corner[c].resize(m.tet_count);
    for (std::size_t i = 0; i < m.tet_count; ++i)
      m.corner[c][i] = new_index[model.corner[c][element_origin[i]]];
  }
  take_element_data(m, element_origin);
  take_from_origin(m.cut_face_mask, element_origin);
  take_from_origin(m.boundary_face_mask, element_origin);
  take_from_origin(m.element_mass_kg, element_origin);
  take_from_origin(m.is_fixed, node_origin);
  take_from_origin(m.node_added_mass_kg, node_origin);
  m.rest_position_m.resize(m.node_count);
  NodeArray position, velocity;
  position.resize(m.node_count);
  velocity.resize(m.node_count);
  for (std::size_t i = 0; i < m.node_count; ++i) {
    m.rest_position_m.set(i, model.rest_position_m.at(node_origin[i]));
    position.set(i, state.position_m.at(node_origin[i]));
    velocity.set(i, state.velocity_m_per_s.at(node_origin[i]));
  }
  m.added_mass_kg = 0.0;
  for (double kg : m.node_added_mass_kg) m.added_mass_kg += kg;
  lump_masses(m);
  complete(result, std::move(next), state, std::move(position), std::move(velocity),
           std::move(node_origin), std::move(element_origin));
  return result;
}

}  // namespace liversim
