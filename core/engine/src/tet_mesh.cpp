#include "liversim/engine/tet_mesh.h"

#include <Eigen/Geometry>

namespace liversim {

double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double TetMesh::rest_volume_m3(std::size_t e) const {
  const auto n = tet(e);
  return signed_tet_volume(rest_position_m.at(n[0]), rest_position_m.at(n[1]),
                           rest_position_m.at(n[2]), rest_position_m.at(n[3]));
}

}  // namespace liversim
