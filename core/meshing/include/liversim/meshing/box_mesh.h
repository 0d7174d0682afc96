#pragma once
// Box meshes for verification, studies and the stability suite: nx × ny × nz cubes, each split
// into six tetrahedra around its main diagonal (Kuhn subdivision, conforming across cubes), with
// optional jitter of the interior nodes; and the loads and measures the box studies use.

#include "liversim/engine/forces.h"
#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <vector>

namespace liversim {

TetMesh box_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size_m,
                 double interior_jitter = 0.0, unsigned seed = 7);

// Consistent nodal loads of a uniform normal traction σ (Pa, positive pulling outward) on the
// faces of a box mesh that are perpendicular to the x axis: each boundary triangle hands a third of
// σ·area to each of its corners.
std::vector<PointLoad> end_face_tension(const TetMesh& mesh, double sigma_pa);

// Mean current coordinate `axis` of the nodes whose rest coordinate `axis` is `rest_value` (a face
// or cross-section of a box mesh).
double mean_coordinate_on_plane(const TetMesh& mesh, const NodeArray& position, int axis,
                                double rest_value);

// Nodes whose rest coordinate `axis` is `value` (to round-off).
std::vector<NodeIndex> nodes_on_plane(const TetMesh& mesh, int axis, double value);

}  // namespace liversim
