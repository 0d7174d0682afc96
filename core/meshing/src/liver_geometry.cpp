#include "liversim/meshing/liver_geometry.h"

#include "liversim/engine/surface.h"

#include <algorithm>
#include <cmath>

namespace liversim {
namespace {

// Approximate signed distance to an axis-aligned ellipsoid (exact on the axes).
double ellipsoid(const Eigen::Vector3d& p, const Eigen::Vector3d& centre,
                 const Eigen::Vector3d& radii) {
  const double scaled = ((p - centre).array() / radii.array()).matrix().norm();
  return (scaled - 1.0) * radii.minCoeff();
}

// Polynomial smooth minimum / maximum (blend width k in metres).
double smooth_union(double a, double b, double k) {
  const double h = std::clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
  return b + (a - b) * h - k * h * (1.0 - h);
}
double smooth_intersection(double a, double b, double k) {
  return -smooth_union(-a, -b, k);
}

}  // namespace

double LiverShape::value(const Eigen::Vector3d& p) const {
  // Right lobe: the bulk, domed under the diaphragm. Left lobe: thinner, reaching across the
  // midline toward the patient's left (+x) and slightly up.
  const double right_lobe = ellipsoid(p, {-0.040, 0.000, 0.000}, {0.085, 0.075, 0.068});
  const double left_lobe = ellipsoid(p, {0.055, 0.018, 0.012}, {0.080, 0.042, 0.036});
  double liver = smooth_union(right_lobe, left_lobe, 0.035);
  // Visceral (inferior) surface: a plane rising toward the left lobe, tilted back, so the front
  // lower edge is the liver's sharp inferior border.
  const Eigen::Vector3d visceral_normal = Eigen::Vector3d(0.22, -1.0, 0.35).normalized();
  const double visceral = visceral_normal.dot(p - Eigen::Vector3d(0.0, -0.030, 0.0));
  liver = smooth_intersection(liver, visceral, 0.012);
  // Flattened posterior surface against the spine and vena cava.
  liver = smooth_intersection(liver, -(p.z() + 0.042), 0.020);
  // Umbilical notch on the inferior border between the lobes (ligamentum teres).
  const double notch = ellipsoid(p, {0.022, -0.030, 0.045}, {0.014, 0.030, 0.030});
  return smooth_intersection(liver, -notch, 0.006);
}

Eigen::AlignedBox3d LiverShape::bounds() const {
  return Eigen::AlignedBox3d(Eigen::Vector3d(-0.130, -0.080, -0.070),
                             Eigen::Vector3d(0.140, 0.080, 0.075));
}

bool LiverShape::in_ligament_attachment(const Eigen::Vector3d& p) const {
  // Posterior-superior bare area of the right lobe.
  return p.z() < -0.015 && p.y() > 0.015 && p.x() > -0.090 && p.x() < 0.010;
}

ImplicitMeshResult generate_liver_mesh(int target_tet_count) {
  const LiverShape shape;
  ImplicitMeshOptions options;
  options.target_tet_count = target_tet_count;
  ImplicitMeshResult result = mesh_implicit_shape(shape, options);
  TetMesh& mesh = result.mesh;
  auto& ligament = mesh.node_sets["ligament"];
  for (NodeIndex n : extract_surface(mesh).nodes)
    if (shape.in_ligament_attachment(mesh.rest_position_m.at(n))) ligament.push_back(n);
  return result;
}

}  // namespace liversim
