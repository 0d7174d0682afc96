#pragma once
// Tetrahedral meshing of a smooth implicit volume at a requested element count: a body-centred
// cubic (BCC) lattice of well-shaped tetrahedra clipped to the shape, boundary vertices projected
// onto the surface under a quality guard, then guarded smoothing.

#include "liversim/engine/tet_mesh.h"

#include <Eigen/Geometry>

namespace liversim {

// A solid given by a function that is negative inside, zero on the surface, and positive outside,
// roughly a signed distance in metres near the surface.
class ImplicitShape {
 public:
  virtual ~ImplicitShape() = default;
  virtual double value(const Eigen::Vector3d& p) const = 0;
  virtual Eigen::AlignedBox3d bounds() const = 0;            // contains the whole solid
  Eigen::Vector3d gradient(const Eigen::Vector3d& p) const;  // central differences
  // The surface point nearest to p, by Newton steps along the gradient.
  Eigen::Vector3d closest_surface_point(Eigen::Vector3d p) const;
};

struct ImplicitMeshOptions {
  int target_tet_count = 5406;
  double count_tolerance = 0.01;  // relative; the search stops once within it
  int max_search_iterations = 40;
  // No move may make an element's dihedral angle smaller than this, or its smallest height smaller
  // than min_height_guard × lattice spacing (thin elements set the explicit stable step).
  double min_dihedral_guard_deg = 15.0;
  double min_height_guard = 0.3;
  int projection_passes = 6;
  int smoothing_passes = 4;
};

struct ImplicitMeshResult {
  TetMesh mesh;
  double lattice_spacing_m = 0.0;
  int search_iterations = 0;
  double max_surface_distance_m = 0.0;   // largest |value| left at a boundary vertex
  double mean_surface_distance_m = 0.0;  // mean |value| over boundary vertices
};

// Throws std::runtime_error when no lattice spacing gives a count within 3 % of the target.
ImplicitMeshResult mesh_implicit_shape(const ImplicitShape& shape,
                                       const ImplicitMeshOptions& options);

}  // namespace liversim
