#pragma once
// Element and mesh quality measures for linear tetrahedra.

#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <cstddef>
#include <iosfwd>

namespace liversim {

struct TetShape {
  double volume_m3 = 0.0;         // signed
  double min_dihedral_deg = 0.0;  // over the six edges
  double max_dihedral_deg = 0.0;
  double min_height_m = 0.0;  // smallest distance from a vertex to the opposite face
  double longest_edge_m = 0.0;
  // Radius ratio R / (3 r): 1 for the regular tetrahedron, growing without bound as it degenerates.
  double aspect_ratio = 0.0;
};

TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d);

// Degenerate: |V| ≤ 1e-9 · (longest edge)³ (a regular tet has V ≈ 0.118 · edge³).
bool is_degenerate(const TetShape& shape);

struct MeshQualityReport {
  std::size_t node_count = 0;
  std::size_t tet_count = 0;
  double volume_m3 = 0.0;
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  double max_aspect_ratio = 0.0;
  double mean_aspect_ratio = 0.0;
  double min_height_m = 0.0;
  double median_height_m = 0.0;
  std::size_t inverted_count = 0;    // signed volume < 0 (and not degenerate)
  std::size_t degenerate_count = 0;  // see is_degenerate
};

MeshQualityReport assess_quality(const TetMesh& mesh, const NodeArray& position);
inline MeshQualityReport assess_quality(const TetMesh& mesh) {
  return assess_quality(mesh, mesh.rest_position_m);
}

std::ostream& operator<<(std::ostream& out, const MeshQualityReport& report);

}  // namespace liversim
