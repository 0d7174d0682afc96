#pragma once
// Grabbing the liver surface at a point (mouse drag, forceps jaws): the surface nodes near the
// point are tied by springs to a handle that moves with the tool.

#include "liversim/engine/forces.h"
#include "liversim/engine/surface.h"

#include <Eigen/Core>

#include <vector>

namespace liversim {

struct Grab {
  Eigen::Vector3d grab_point_m = Eigen::Vector3d::Zero();
  std::vector<NodeIndex> nodes;
  std::vector<Eigen::Vector3d> node_position_at_grab_m;
  std::vector<double> stiffness_n_per_m;  // per node; they sum to the grab's total stiffness
  std::vector<double> damping_n_s_per_m;  // per node: critical for the node on its spring

  bool empty() const { return nodes.empty(); }
};

// How much of a grab's stiffness a node at distance_m from the grab point takes: its lumped mass
// times the smooth bump (1 − (d/r)²)² (0 at and beyond the radius).
double grab_weight(double distance_m, double radius_m, double lumped_mass_kg);

// Surface nodes within radius_m of the point, each weighted by its lumped mass times a smooth bump
// (1 − (d/r)²)², so that every grabbed node has the same spring frequency and a light corner node
// is not yanked alone; when no node is that close, the nearest surface node alone.
Grab grab_surface(const BoundarySurface& surface, const NodeArray& position,
                  const std::vector<double>& lumped_mass_kg, const Eigen::Vector3d& point_m,
                  double radius_m, double total_stiffness_n_per_m);

// Springs that pull each grabbed node toward where it was when grabbed, moved by the handle's
// displacement since the grab. Reuses `springs`' storage.
void grab_springs(const Grab& grab, const Eigen::Vector3d& handle_m,
                  std::vector<NodeSpring>& springs);

// Force the grabbed tissue exerts on the handle (the reaction of the springs), in newtons.
Eigen::Vector3d grab_reaction_force_n(const Grab& grab, const Eigen::Vector3d& handle_m,
                                      const NodeArray& position);

}  // namespace liversim
