#pragma once
// The built-in organ: a liver-shaped solid (large right lobe, tapering left lobe, flattened
// visceral underside with a sharp inferior border, umbilical notch) and its ligament attachment.
// Axes: x toward the patient's left, y superior, z anterior; metres; origin near the lobes' centre.

#include "liversim/meshing/implicit_mesher.h"

namespace liversim {

class LiverShape : public ImplicitShape {
 public:
  double value(const Eigen::Vector3d& p) const override;
  Eigen::AlignedBox3d bounds() const override;
  // The bare area on the posterior-superior surface, where the coronary ligament holds the liver
  // to the diaphragm: surface nodes here are fixed.
  bool in_ligament_attachment(const Eigen::Vector3d& p) const;
};

// The seed paper's mesh sizes (§4.4); 5406 is the default.
inline constexpr int kSeedMeshSizes[] = {3841, 5406, 7312, 9371, 10583};
inline constexpr int kDefaultLiverTetCount = 5406;

// The default liver meshed at the requested element count (within 3 %), with the node set
// "ligament" (fixed nodes) filled in.
ImplicitMeshResult generate_liver_mesh(int target_tet_count = kDefaultLiverTetCount);

}  // namespace liversim
