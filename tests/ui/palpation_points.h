#pragma once
// Where the palpation tests hold the probe: 10 mm outside the surface node nearest a lesion's
// centre, so that the probe's ball (3 mm) is clear of the curved surface around it.

#include "liversim/engine/model.h"
#include "liversim/interaction/cutting.h"

#include <Eigen/Core>

namespace liversim {

inline Eigen::Vector3d hover_over_lesion_mm(const SimModel& model,
                                            const Eigen::Vector3d& centre_m) {
  const BoundarySurface surface = boundary_surface(model);
  Eigen::Vector3d nearest = model.rest_position_m.at(surface.nodes.front());
  for (NodeIndex n : surface.nodes)
    if ((model.rest_position_m.at(n) - centre_m).norm() < (nearest - centre_m).norm())
      nearest = model.rest_position_m.at(n);
  return (nearest + 0.010 * (nearest - centre_m).normalized()) * 1e3;
}

}  // namespace liversim
