#include "liversim/interaction/tools.h"

#include "liversim/interaction/cutting.h"
#include "liversim/interaction/grab.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

namespace liversim {

std::string_view tool_name(ToolKind kind) {
  switch (kind) {
    case ToolKind::probe:
      return "probe";
    case ToolKind::forceps:
      return "forceps";
    case ToolKind::scalpel:
      return "scalpel";
  }
  return "unknown";
}

std::optional<ToolKind> tool_kind(std::string_view name) {
  for (ToolKind kind : kToolKinds)
    if (tool_name(kind) == name) return kind;
  return std::nullopt;
}

std::string_view hand_name(Hand hand) {
  return hand == Hand::left ? "left" : "right";
}

std::optional<Hand> hand_named(std::string_view name) {
  for (Hand hand : kHands)
    if (hand_name(hand) == name) return hand;
  return std::nullopt;
}

namespace {

// Jaw j (0 or 1) of the forceps, from the hinge at the origin, in the tool frame.
Eigen::Vector3d jaw_tip_local_m(const Tool& tool, int jaw) {
  const ToolGeometry& g = tool.geometry;
  const double angle = std::clamp(tool.jaw_opening, 0.0, 1.0) * g.max_jaw_angle_rad;
  const double side = jaw == 0 ? 1.0 : -1.0;
  return g.jaw_length_m * Eigen::Vector3d(side * std::sin(angle), 0.0, -std::cos(angle));
}

// Parameters s, t in [0, 1] of the closest points of segments [p1, q1] and [p2, q2]
// (Ericson 5.1.9).
void closest_parameters_of_segments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                                    const Eigen::Vector3d& p2, const Eigen::Vector3d& q2, double& s,
                                    double& t) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  if (a <= 0.0 && e <= 0.0) {
    s = t = 0.0;
    return;
  }
  if (a <= 0.0) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(r);
  if (e <= 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denominator = a * e - b * b;
  s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

}  // namespace

// Ericson, Real-Time Collision Detection, 5.1.5: by the Voronoi regions of the corners and edges.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& p0,
                                          const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                          std::array<double, 3>& w) {
  const Eigen::Vector3d ab = p1 - p0, ac = p2 - p0, ap = p - p0;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return w = {1.0, 0.0, 0.0}, p0;
  const Eigen::Vector3d bp = p - p1;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return w = {0.0, 1.0, 0.0}, p1;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return w = {1.0 - v, v, 0.0}, p0 + v * ab;
  }
  const Eigen::Vector3d cp = p - p2;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return w = {0.0, 0.0, 1.0}, p2;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double v = d2 / (d2 - d6);
    return w = {1.0 - v, 0.0, v}, p0 + v * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return w = {0.0, 1.0 - v, v}, p1 + v * (p2 - p1);
  }
  const double denominator = 1.0 / (va + vb + vc);
  const double v = vb * denominator, u = vc * denominator;
  return w = {1.0 - v - u, v, u}, p0 + v * ab + u * ac;
}

int tool_capsules(const Tool& tool, std::array<Capsule, 3>& parts) {
  const ToolGeometry& g = tool.geometry;
  const ToolPose& pose = tool.pose;
  const Eigen::Vector3d hand_end = pose.to_scene({0.0, 0.0, g.shaft_length_m});
  switch (tool.kind) {
    case ToolKind::probe:
      // The ball at the end, on a shaft; the ball is the wider.
      parts[0] = {pose.origin_m, pose.origin_m, g.probe_tip_radius_m};
      parts[1] = {pose.origin_m, hand_end, g.shaft_radius_m};
      return 2;
    case ToolKind::forceps:
      parts[0] = {pose.origin_m, hand_end, g.shaft_radius_m};
      parts[1] = {pose.origin_m, pose.to_scene(jaw_tip_local_m(tool, 0)), g.jaw_radius_m};
      parts[2] = {pose.origin_m, pose.to_scene(jaw_tip_local_m(tool, 1)), g.jaw_radius_m};
      return 3;
    case ToolKind::scalpel:
      parts[0] = {pose.origin_m, hand_end, g.shaft_radius_m};
      parts[kScalpelBlade] = {pose.origin_m, pose.to_scene({0.0, 0.0, -g.blade_length_m}),
                              g.blade_half_thickness_m};
      return 2;
  }
  return 0;
}

Eigen::Vector3d forceps_grasp_point_m(const Tool& tool) {
  // Halfway along the jaws (which start at the hinge, the origin), midway between them.
  return tool.pose.to_scene(0.25 * (jaw_tip_local_m(tool, 0) + jaw_tip_local_m(tool, 1)));
}

Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                         const Eigen::Vector3d& p) {
  const Eigen::Vector3d ab = b - a;
  const double length_sq = ab.squaredNorm();
  if (length_sq == 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / length_sq, 0.0, 1.0) * ab;
}

SegmentTriangleClosest segment_triangle_closest(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                const Eigen::Vector3d& p0,
                                                const Eigen::Vector3d& p1,
                                                const Eigen::Vector3d& p2) {
  SegmentTriangleClosest best;
  best.distance = std::numeric_limits<double>::infinity();
  auto consider = [&](const Eigen::Vector3d& on_segment, const Eigen::Vector3d& on_triangle,
                      const std::array<double, 3>& weight) {
    const double d = (on_triangle - on_segment).norm();
    if (d < best.distance) best = {on_segment, on_triangle, weight, d};
  };
  // The segment's ends against the face.
  for (const Eigen::Vector3d* end : {&a, &b}) {
    std::array<double, 3> w;
    const Eigen::Vector3d q = closest_point_on_triangle(*end, p0, p1, p2, w);
    consider(*end, q, w);
  }
  // The segment against each edge.
  const Eigen::Vector3d* corner[3] = {&p0, &p1, &p2};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    double s = 0.0, t = 0.0;
    closest_parameters_of_segments(a, b, *corner[i], *corner[j], s, t);
    std::array<double, 3> w{0.0, 0.0, 0.0};
    w[i] = 1.0 - t;
    w[j] = t;
    consider(a + s * (b - a), *corner[i] + t * (*corner[j] - *corner[i]), w);
  }
  // The segment through the face's interior.
  const Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0);
  const double da = (a - p0).dot(normal), db = (b - p0).dot(normal);
  if ((da <= 0.0) != (db <= 0.0)) {
    const Eigen::Vector3d crossing = a + da / (da - db) * (b - a);
    std::array<double, 3> w;
    const Eigen::Vector3d q = closest_point_on_triangle(crossing, p0, p1, p2, w);
    if ((q - crossing).squaredNorm() <= 1e-24 * normal.norm()) consider(crossing, q, w);
  }
  return best;
}

std::size_t add_contact_springs(const SimModel& model, const SurfaceBvh& bvh,
                                const NodeArray& position, std::span<const Capsule> parts,
                                const ContactSettings& settings, ContactScratch& scratch,
                                std::vector<NodeSpring>& springs, std::span<PartContact> per_part,
                                std::span<const std::uint8_t> cut_triangle) {
  const double omega_sq = std::pow(2.0 * std::numbers::pi * settings.frequency_hz, 2);
  scratch.resize(model.node_count);
  for (PartContact& met : per_part) met = {};
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const Capsule& part = parts[p];
    bvh.for_each_triangle_overlapping(
        Aabb::around(part.a_m, part.b_m, part.radius_m), [&](std::size_t t) {
          const SurfaceBvh::Triangle& triangle = bvh.triangles()[t];
          const Eigen::Vector3d p0 = position.at(triangle[0]), p1 = position.at(triangle[1]),
                                p2 = position.at(triangle[2]);
          const Eigen::Vector3d outward = (p1 - p0).cross(p2 - p0);
          const double area2 = outward.norm();
          if (!(area2 > 0.0)) return;  // a collapsed face has no side to push from
          const Eigen::Vector3d normal = outward / area2;
          const SegmentTriangleClosest closest =
              segment_triangle_closest(part.a_m, part.b_m, p0, p1, p2);
          const Eigen::Vector3d axis_to_surface = closest.on_triangle - closest.on_segment;
          const double height = -axis_to_surface.dot(normal);  // of the axis above the face
          Eigen::Vector3d push;  // how far the face's point must move to clear the part
          // Behind the face's plane but beside the face (its closest point on an edge or a
          // corner), the axis has not gone through it: the face is pushed aside radially. Pushed
          // along its normal by the axis's depth, it jumped millimetres as the axis passed a
          // corner, flinging the light nodes a cut leaves at metres per second (issue 42).
          const bool beside =
              std::min({closest.weight[0], closest.weight[1], closest.weight[2]}) <= 0.0;
          if ((height > 0.0 || beside) && closest.distance > 0.0) {
            if (closest.distance >= part.radius_m) return;
            push = (part.radius_m - closest.distance) / closest.distance * axis_to_surface;
          } else {  // the axis has gone through the face: back out along the inward normal
            push = -(part.radius_m + std::max(0.0, -height)) * normal;
          }
          // A spring at the face's point, of the frequency of the mass there, shared among the
          // corners by the barycentric weights: corner i feels w_i·k·push and stiffness w_i²·k.
          double point_mass = 0.0;
          for (int i = 0; i < 3; ++i)
            point_mass +=
                closest.weight[i] * model.lumped_mass_kg[static_cast<std::size_t>(triangle[i])];
          const double stiffness = omega_sq * point_mass;
          double free_weight = 0.0;
          for (int i = 0; i < 3; ++i) {
            const auto node = static_cast<std::size_t>(triangle[i]);
            if (model.inverse_mass_per_kg[node] == 0.0 || closest.weight[i] == 0.0) continue;
            free_weight += closest.weight[i];
            scratch.add(triangle[i], closest.weight[i] * stiffness * push,
                        closest.weight[i] * closest.weight[i] * stiffness);
          }
          if (per_part.empty() || free_weight == 0.0) return;
          PartContact& met = per_part[p];
          met.force_on_part_n -= free_weight * stiffness * push;
          if (const double pushed_n = free_weight * stiffness * push.norm();
              pushed_n > met.hardest_push_n && t < bvh.triangle_tet().size()) {
            met.hardest_push_n = pushed_n;
            met.region = model.region[static_cast<std::size_t>(bvh.triangle_tet()[t])];
          }
          const Eigen::Vector3d axis = part.b_m - part.a_m;
          const double length_sq = axis.squaredNorm();
          const double s =
              length_sq > 0.0 ? (closest.on_segment - part.a_m).dot(axis) / length_sq : 0.0;
          met.touched_from = std::min(met.touched_from, s);
          met.touched_to = std::max(met.touched_to, s);
          met.pierced |= closest.distance == 0.0;
          met.touched_cut_face |= t < cut_triangle.size() && cut_triangle[t] != 0;
        });
  }
  return scratch.add_springs(model, position, springs);
}

std::size_t ContactScratch::add_springs(const SimModel& model, const NodeArray& position,
                                        std::vector<NodeSpring>& springs, double damping_ratio) {
  for (NodeIndex n : touched) {
    const auto node = static_cast<std::size_t>(n);
    const double k = stiffness_n_per_m[node];
    springs.push_back({n, position.at(n) + force_n[node] / k, k,
                       damping_ratio * critical_damping_n_s_per_m(k, model.lumped_mass_kg[node])});
    stiffness_n_per_m[node] = 0.0;
    force_n[node].setZero();
  }
  const std::size_t added = touched.size();
  touched.clear();
  return added;
}

ToolInteraction::ToolInteraction(const SimModel& model, const BoundarySurface& surface,
                                 ContactSettings contact, GraspSettings grasp)
    : model_(&model),
      bvh_(surface, model.rest_position_m),
      contact_(contact),
      grasp_settings_(grasp),
      node_mark_(model.node_count, 0) {
  contact_scratch_.resize(model.node_count);
  if (!(contact.frequency_hz > 0.0) || !std::isfinite(contact.frequency_hz))
    throw std::invalid_argument("contact frequency " + std::to_string(contact.frequency_hz) +
                                " Hz is invalid: expected a finite value > 0");
  if (!(grasp.radius_m > 0.0) || !(grasp.total_stiffness_n_per_m > 0.0) ||
      !(grasp.close_below < grasp.release_above))
    throw std::invalid_argument(
        "grasp settings are invalid: expected radius > 0, stiffness > 0 and the closing opening "
        "below the releasing one");
  const std::size_t nodes = surface.nodes.size();
  cut_triangle_ = cut_face_flags(model, surface);
  springs_.reserve(2 * nodes);  // a hold and a contact spring per node at most
  grasp_.nodes.reserve(nodes);
  grasp_.offset_in_tool_m.reserve(nodes);
  grasp_.stiffness_n_per_m.reserve(nodes);
  grasp_.damping_n_s_per_m.reserve(nodes);
  grasp_weight_.reserve(nodes);
}

void ToolInteraction::try_grasp(const Tool& tool, const NodeArray& position,
                                const SurfaceBvh& hierarchy) {
  // What the closing jaws take: the surface near them, hinge to tip. Open jaws come down on the
  // tissue and push it aside before they close, so near the grasp point alone may be nothing.
  const Eigen::Vector3d hinge = tool.pose.origin_m;
  const Eigen::Vector3d tip =
      tool.pose.to_scene(Eigen::Vector3d(0.0, 0.0, -tool.geometry.jaw_length_m));
  const double radius = grasp_settings_.radius_m;
  grasp_.clear();
  grasp_weight_.clear();
  hierarchy.for_each_triangle_overlapping(Aabb::around(hinge, tip, radius), [&](std::size_t t) {
    for (NodeIndex n : hierarchy.triangles()[t]) {
      const auto node = static_cast<std::size_t>(n);
      if (node_mark_[node] || model_->inverse_mass_per_kg[node] == 0.0) continue;
      const Eigen::Vector3d p = position.at(n);
      const double d = (p - closest_point_on_segment(hinge, tip, p)).norm();
      if (d >= radius) continue;
      node_mark_[node] = 1;
      // The grab's weighting: every held node has the same spring frequency, and the hold fades
      // out at its rim.
      grasp_.nodes.push_back(n);
      grasp_weight_.push_back(grab_weight(d, radius, model_->lumped_mass_kg[node]));
    }
  });
  for (NodeIndex n : grasp_.nodes) node_mark_[static_cast<std::size_t>(n)] = 0;
  if (grasp_.empty()) return;  // nothing between the jaws: they close on air
  double weight_sum = 0.0;
  for (double w : grasp_weight_) weight_sum += w;
  const Eigen::Quaterniond to_tool = tool.pose.orientation.conjugate();
  for (std::size_t i = 0; i < grasp_.nodes.size(); ++i) {
    const auto node = static_cast<std::size_t>(grasp_.nodes[i]);
    grasp_.offset_in_tool_m.push_back(to_tool * (position.at(node) - tool.pose.origin_m));
    const double k = grasp_settings_.total_stiffness_n_per_m * grasp_weight_[i] / weight_sum;
    grasp_.stiffness_n_per_m.push_back(k);
    grasp_.damping_n_s_per_m.push_back(critical_damping_n_s_per_m(k, model_->lumped_mass_kg[node]));
  }
}

void ToolInteraction::carry_hold(const ForcepsGrasp& held, std::span<const NodeIndex> node_origin) {
  grasp_.clear();
  if (held.empty()) return;
  // Copies of each held node in this model (a crack duplicates a node on it).
  std::unordered_map<NodeIndex, std::size_t> held_at;
  for (std::size_t i = 0; i < held.nodes.size(); ++i) held_at.emplace(held.nodes[i], i);
  std::vector<int> copies(held.nodes.size(), 0);
  std::vector<std::pair<NodeIndex, std::size_t>> carried;  // new node, index in `held`
  for (std::size_t n = 0; n < node_origin.size() && n < model_->node_count; ++n) {
    const auto found = held_at.find(node_origin[n]);
    if (found == held_at.end() || model_->inverse_mass_per_kg[n] == 0.0) continue;
    carried.emplace_back(static_cast<NodeIndex>(n), found->second);
    ++copies[found->second];
  }
  for (const auto& [node, i] : carried) {
    const double k = held.stiffness_n_per_m[i] / copies[i];
    grasp_.nodes.push_back(node);
    grasp_.offset_in_tool_m.push_back(held.offset_in_tool_m[i]);
    grasp_.stiffness_n_per_m.push_back(k);
    grasp_.damping_n_s_per_m.push_back(
        critical_damping_n_s_per_m(k, model_->lumped_mass_kg[static_cast<std::size_t>(node)]));
  }
}

std::span<const NodeSpring> ToolInteraction::update(const Tool& tool, const NodeArray& position,
                                                    bool blade_cuts, const SurfaceBvh* refitted) {
  if (!refitted) bvh_.refit(position);
  const SurfaceBvh& hierarchy = refitted ? *refitted : bvh_;
  springs_.clear();
  if (tool.kind == ToolKind::forceps) {
    if (grasping() && tool.jaw_opening > grasp_settings_.release_above) grasp_.clear();
    if (!grasping() && tool.jaw_opening < grasp_settings_.close_below)
      try_grasp(tool, position, hierarchy);
  } else {
    grasp_.clear();
  }
  std::array<Capsule, 3> parts;
  int count = tool_capsules(tool, parts);
  // A hold carries its nodes with the jaws: the jaws themselves do not push the tissue.
  if (grasping()) {
    for (std::size_t i = 0; i < grasp_.nodes.size(); ++i)
      springs_.push_back({grasp_.nodes[i], tool.pose.to_scene(grasp_.offset_in_tool_m[i]),
                          grasp_.stiffness_n_per_m[i], grasp_.damping_n_s_per_m[i]});
    count = 1;  // the shaft only (parts[0] of the forceps)
  }
  // A cutting scalpel passes: its blade and, deeper than the blade, its shaft part the tissue
  // instead (cutting_edge_m).
  if (blade_cuts && tool.kind == ToolKind::scalpel) count = 0;
  contact_count_ = add_contact_springs(
      *model_, hierarchy, position, std::span<const Capsule>(parts.data(), count), contact_,
      contact_scratch_, springs_,
      std::span<PartContact>(part_contact_.data(), part_contact_.size()), cut_triangle_);
  return springs_;
}

}  // namespace liversim
