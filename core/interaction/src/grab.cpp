#include "liversim/interaction/grab.h"

#include <cmath>
#include <limits>

namespace liversim {

double grab_weight(double distance_m, double radius_m, double lumped_mass_kg) {
  if (!(distance_m < radius_m)) return 0.0;
  const double s = 1.0 - (distance_m / radius_m) * (distance_m / radius_m);
  return s * s * lumped_mass_kg;
}

Grab grab_surface(const BoundarySurface& surface, const NodeArray& position,
                  const std::vector<double>& lumped_mass_kg, const Eigen::Vector3d& point_m,
                  double radius_m, double total_stiffness_n_per_m) {
  Grab grab;
  grab.grab_point_m = point_m;
  std::vector<double> weight;
  NodeIndex nearest = -1;
  double nearest_distance = std::numeric_limits<double>::infinity();
  for (NodeIndex n : surface.nodes) {
    const double d = (position.at(n) - point_m).norm();
    if (d < nearest_distance) {
      nearest_distance = d;
      nearest = n;
    }
    if (d < radius_m) {
      grab.nodes.push_back(n);
      weight.push_back(grab_weight(d, radius_m, lumped_mass_kg[n]));
    }
  }
  if (grab.nodes.empty() && nearest >= 0) {
    grab.nodes.push_back(nearest);
    weight.push_back(1.0);
  }
  double weight_sum = 0.0;
  for (double w : weight) weight_sum += w;
  for (std::size_t i = 0; i < grab.nodes.size(); ++i) {
    grab.node_position_at_grab_m.push_back(position.at(grab.nodes[i]));
    const double k = total_stiffness_n_per_m * weight[i] / weight_sum;
    grab.stiffness_n_per_m.push_back(k);
    grab.damping_n_s_per_m.push_back(critical_damping_n_s_per_m(k, lumped_mass_kg[grab.nodes[i]]));
  }
  return grab;
}

void grab_springs(const Grab& grab, const Eigen::Vector3d& handle_m,
                  std::vector<NodeSpring>& springs) {
  const Eigen::Vector3d shift = handle_m - grab.grab_point_m;
  springs.clear();
  for (std::size_t i = 0; i < grab.nodes.size(); ++i)
    springs.push_back({grab.nodes[i], grab.node_position_at_grab_m[i] + shift,
                       grab.stiffness_n_per_m[i], grab.damping_n_s_per_m[i]});
}

Eigen::Vector3d grab_reaction_force_n(const Grab& grab, const Eigen::Vector3d& handle_m,
                                      const NodeArray& position) {
  const Eigen::Vector3d shift = handle_m - grab.grab_point_m;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < grab.nodes.size(); ++i) {
    const Eigen::Vector3d anchor = grab.node_position_at_grab_m[i] + shift;
    force -= grab.stiffness_n_per_m[i] * (anchor - position.at(grab.nodes[i]));
  }
  return force;
}

}  // namespace liversim
