#pragma once
// Test meshes: the box meshes of core (box_mesh.h) under the names the tests use.

#include "liversim/meshing/box_mesh.h"

namespace liversim::testing {

inline TetMesh block_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size_m,
                          double interior_jitter = 0.0, unsigned seed = 7) {
  return box_mesh(nx, ny, nz, size_m, interior_jitter, seed);
}
using liversim::end_face_tension;
using liversim::mean_coordinate_on_plane;

}  // namespace liversim::testing
