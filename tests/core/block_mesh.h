#pragma once
// Test meshes: the box meshes of core (box_mesh.h) under the names the tests use.

#include "liversim/meshing/box_mesh.h"

namespace liversim::testing {

inline TetMesh block_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size_m,
                          double interior_jitter = 0.0, unsigned seed = 7) {
  return box_mesh(nx, ny, nz, size_m, interior_jitter, seed);
}
// One element: the corner tetrahedron of a cube `edge_m` on a side, its right angle at the origin.
inline TetMesh corner_tet_mesh(double edge_m) {
  TetMesh mesh;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(edge_m, 0, 0),
                                   Eigen::Vector3d(0, edge_m, 0), Eigen::Vector3d(0, 0, edge_m)})
    mesh.rest_position_m.push_back(p);
  mesh.add_tet({0, 1, 2, 3});
  return mesh;
}
using liversim::end_face_tension;
using liversim::mean_coordinate_on_plane;

}  // namespace liversim::testing
