#include "liversim/interaction/body_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace liversim {

BodyContact::BodyContact(const SimModel& model, const BoundarySurface& surface,
                         std::span<const FreeBody> bodies) {
  if (bodies.empty() || surface.triangles.empty()) return;
  std::vector<std::int32_t> body_of_element(model.tet_count, 0);
  for (std::size_t b = 0; b < bodies.size(); ++b)
    for (const TetIndex e : bodies[b].elements)
      body_of_element[static_cast<std::size_t>(e)] = static_cast<std::int32_t>(b + 1);
  hierarchy_ = SurfaceBvh(surface, model.rest_position_m);
  body_of_triangle_.resize(surface.triangles.size());
  std::vector<std::int32_t> body_of_node(model.node_count, -1);
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const std::int32_t body = body_of_element[static_cast<std::size_t>(surface.triangle_tet[t])];
    body_of_triangle_[t] = body;
    for (const std::int32_t corner : surface.triangles[t])
      body_of_node[static_cast<std::size_t>(surface.nodes[static_cast<std::size_t>(corner)])] =
          body;
  }
  surface_nodes_ = surface.nodes;
  body_box_.resize(bodies.size() + 1);
  body_of_surface_node_.reserve(surface_nodes_.size());
  for (const NodeIndex n : surface_nodes_)
    body_of_surface_node_.push_back(body_of_node[static_cast<std::size_t>(n)]);
  // One stiffness for every contact, so that the penalty is the gradient of ½·k·d²: a k that
  // followed the face's corners or weights changed as the node slid, and its work kept the
  // underside of a resting specimen chattering. No spring of one contact is faster than ω_c.
  double lightest_kg = std::numeric_limits<double>::infinity();
  for (const NodeIndex n : surface_nodes_)
    lightest_kg = std::min(lightest_kg, model.lumped_mass_kg[static_cast<std::size_t>(n)]);
  const double omega = model.support_frequency_fraction * model.max_frequency_rad_per_s;
  stiffness_n_per_m_ = omega * omega * lightest_kg;
  scratch_.resize(model.node_count);
}

void BodyContact::add_springs(const SimModel& model, const NodeArray& position,
                              std::vector<NodeSpring>& springs, const SurfaceBvh* refitted) {
  contacts_ = 0;
  if (!active()) return;
  if (!refitted) hierarchy_.refit(position);
  const SurfaceBvh& hierarchy = refitted ? *refitted : hierarchy_;
  const auto& triangles = hierarchy.triangles();
  // Each body's box, so that only a node within another body's box (and its reach) is looked
  // up: the organ's thousands of surface nodes far from a specimen cost one test each.
  for (Aabb& box : body_box_) box = Aabb{};
  for (std::size_t s = 0; s < surface_nodes_.size(); ++s)
    body_box_[static_cast<std::size_t>(body_of_surface_node_[s])].grow(
        position.at(surface_nodes_[s]));
  for (std::size_t s = 0; s < surface_nodes_.size(); ++s) {
    const NodeIndex node = surface_nodes_[s];
    const std::int32_t body = body_of_surface_node_[s];
    const Eigen::Vector3d x = position.at(node);
    const Aabb reach = Aabb::around(x, x, kBodyContactReachM);
    bool near_another = false;
    for (std::size_t b = 0; b < body_box_.size() && !near_another; ++b)
      near_another = static_cast<std::int32_t>(b) != body && body_box_[b].overlaps(reach);
    if (!near_another) continue;
    // The nearest face of another body the node is behind, its projection on the face inside it.
    double depth_m = kBodyContactReachM;
    std::int32_t face = -1;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(), weights = Eigen::Vector3d::Zero();
    hierarchy.for_each_triangle_overlapping(reach, [&](std::int32_t t) {
      if (body_of_triangle_[static_cast<std::size_t>(t)] == body) return;
      const auto& corner = triangles[static_cast<std::size_t>(t)];
      const Eigen::Vector3d a = position.at(corner[0]), b = position.at(corner[1]),
                            c = position.at(corner[2]);
      const Eigen::Vector3d area_normal = (b - a).cross(c - a);
      const double twice_area = area_normal.norm();
      if (!(twice_area > 0.0)) return;
      const Eigen::Vector3d unit = area_normal / twice_area;
      const double behind_m = (a - x).dot(unit);  // > 0: behind the outward face
      if (!(behind_m > 0.0 && behind_m < depth_m)) return;
      const Eigen::Vector3d p = x + behind_m * unit;
      const double wa = (c - b).cross(p - b).dot(unit) / twice_area;
      const double wb = (a - c).cross(p - c).dot(unit) / twice_area;
      const double wc = 1.0 - wa - wb;
      if (wa < 0.0 || wb < 0.0 || wc < 0.0) return;
      depth_m = behind_m;
      face = t;
      normal = unit;
      weights = {wa, wb, wc};
    });
    if (face < 0) continue;
    ++contacts_;
    const auto& corner = triangles[static_cast<std::size_t>(face)];
    const Eigen::Vector3d push_n = stiffness_n_per_m_ * depth_m * normal;
    scratch_.add(node, push_n, stiffness_n_per_m_);
    for (int i = 0; i < 3; ++i)
      if (weights[i] > 0.0)
        scratch_.add(corner[i], -weights[i] * push_n, weights[i] * weights[i] * stiffness_n_per_m_);
  }
  scratch_.add_springs(model, position, springs, model.support_damping_ratio);
}

}  // namespace liversim
