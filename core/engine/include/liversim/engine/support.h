#pragma once
// What the organ rests on when gravity pulls it: a rigid support beneath it along gravity's
// direction. Over the organ's footprint it is the organ's own underside at rest (its bed: the
// organs and the wall it lies on, as a mould of it); around it, a flat tray at the organ's lowest
// point, where a piece that comes free lands. A height field on a grid across gravity, bilinear
// between grid points: a point deeper (farther along gravity) than the support is pushed back by a
// penalty spring along the support's normal, k times its distance past it along the normal
// (p/√(1 + slope²), p its depth past it along gravity), k = m·ω², so that every node meets the
// same contact frequency ω, on a slope as on the flat, and a light node pushes no harder than a
// heavy one. On a slope the push has a sideways part: the bed holds the organ as a bowl would.
//
// The bed also holds the organ where it lay: a node touching it is pulled back across gravity
// toward its rest place by the same k, up to μ times the push (static friction anchored at the
// rest position: the organ's attachments to its bed), fading to nothing once it is
// kSupportHoldReleaseM from it, so that a freed piece set down elsewhere lies free. Without it the
// liver slid on its frictionless bed for as long as the scene ran, and its stress never settled
// (issue 42). And a node touching the bed is damped, a fraction ζ of critical (2·ζ·ω per second,
// integrated implicitly by the leapfrog): light surface nodes held by one or two elements rang
// against the bed's creases at ~1 m/s without it.

#include "liversim/engine/surface.h"
#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <vector>

namespace liversim {

struct SupportSurface {
  Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();   // unit, gravity's direction
  Eigen::Vector3d axis_u = Eigen::Vector3d::UnitX();  // unit, across `down`
  Eigen::Vector3d axis_v = Eigen::Vector3d::UnitY();  // unit, across `down` and axis_u
  double origin_u_m = 0.0, origin_v_m = 0.0;          // the grid's first point
  double cell_m = 0.002;
  int cells_u = 0, cells_v = 0;  // (cells_u + 1) × (cells_v + 1) points, u fastest
  // How far along `down` a point may go at each grid point (the support's surface).
  std::vector<double> depth_m;
  double floor_depth_m = 0.0;  // the tray, and everywhere beyond the grid

  struct Depth {
    double depth_m = 0.0;
    double slope_u = 0.0, slope_v = 0.0;  // ∂depth/∂u, ∂depth/∂v
    double past_m = 0.0;  // how far the point is deeper than the support (≤ 0: clear of it)
  };
  // The support's depth and slope under the point `point_m` (its u, v), bilinear in the grid, and
  // how far the point has gone past it.
  Depth depth_under(const Eigen::Vector3d& point_m) const;
};

// The steepest the support may rise, as rise over run (3: 72°). The organ's underside rises to its
// rim within a cell or two; a penalty pushes along the support's gradient, so such a wall pushed a
// node at the rim sideways dozens of times harder than up, and the sagging liver's rim chattered
// against it at metres per second, setting the explicit step (issue 42). Limited to 1 (45°), the
// bed fell away under the rim and the left lobe's tip drooped more than 2 cm into the gap; with the
// bed's hold and damping, 3 keeps the rim quiet and the tip within 1 cm (docs/tissue-model.md).
inline constexpr double kSupportMaxSlope = 3.0;

// How far across gravity from its rest place the bed's hold on a node reaches (m).
inline constexpr double kSupportHoldReleaseM = 0.01;

// The support's force on one node and the energy it holds: the push out of the bed and the hold
// toward the rest place (above), for a node of stiffness k = m·ω² (N/m).
struct SupportContact {
  bool touching = false;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  double energy_j = 0.0;  // ½·k·d² of the push (d its distance past the support along the normal)
                          // and the hold's potential
};
SupportContact support_contact(const SupportSurface& support, const Eigen::Vector3d& position_m,
                               const Eigen::Vector3d& rest_position_m, double stiffness_n_per_m,
                               double friction_coefficient);

// Deepens the support wherever it rises more steeply than `max_slope` toward a deeper neighbour:
// afterwards depth(p) >= depth(q) - max_slope·|p - q| for all neighbouring grid points p, q.
void limit_support_slope(SupportSurface& support, double max_slope);

// The support under an organ at rest: the organ's underside over its footprint (each grid point
// the deepest point of the boundary over the cells around it, so that no node lies below the
// bilinear surface between grid points: under a slope the bed is up to a cell's rise deeper),
// the tray (its deepest node) elsewhere, both `clearance_m` deeper so that the organ at rest
// touches nothing; the grid reaches `margin_m`
// beyond the footprint on every side. `down` need not be of unit length (not zero).
// The support is then deepened where it would rise more steeply than `max_slope`
// (limit_support_slope; infinity: as moulded).
SupportSurface support_under(const NodeArray& rest_position_m, const BoundarySurface& surface,
                             const Eigen::Vector3d& down, double cell_m = 0.002,
                             double margin_m = 0.05, double clearance_m = 1e-4,
                             double max_slope = kSupportMaxSlope);
// The same under a mesh at rest (its boundary extracted), with the defaults: what a scene with
// gravity gets.
SupportSurface support_under(const TetMesh& mesh, const Eigen::Vector3d& down);

}  // namespace liversim
