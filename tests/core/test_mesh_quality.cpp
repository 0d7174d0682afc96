#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace liversim {
namespace {

TetMesh single_tet(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d) {
  TetMesh mesh;
  for (const auto& p : {a, b, c, d}) mesh.rest_position_m.push_back(p);
  mesh.add_tet({0, 1, 2, 3});
  return mesh;
}

TEST(MeshQuality, RegularTetrahedronHasTheTextbookValues) {
  // Regular tetrahedron with edge √8 (alternate corners of a cube of side 2).
  const TetShape s = tet_shape({1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1});
  const double edge = std::sqrt(8.0);
  const double dihedral = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;  // 70.53°
  EXPECT_NEAR(std::abs(s.volume_m3), edge * edge * edge / (6.0 * std::sqrt(2.0)), 1e-12);
  EXPECT_NEAR(s.min_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(s.max_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(s.aspect_ratio, 1.0, 1e-12);
  EXPECT_NEAR(s.min_height_m, edge * std::sqrt(2.0 / 3.0), 1e-12);
}

TEST(MeshQuality, CornerTetrahedronHasRightAngles) {
  const TetShape s = tet_shape({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  EXPECT_NEAR(s.volume_m3, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(s.max_dihedral_deg, 90.0, 1e-9);
  // The three edges at the slanted face meet it at acos(1/√3) = 54.74°.
  EXPECT_NEAR(s.min_dihedral_deg, std::acos(1.0 / std::sqrt(3.0)) * 180.0 / std::numbers::pi, 1e-9);
  EXPECT_NEAR(s.min_height_m, 1.0 / std::sqrt(3.0), 1e-12);  // origin to the plane x+y+z=1
}

TEST(MeshQuality, ReportCountsInvertedAndDegenerateElements) {
  TetMesh mesh = single_tet({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  mesh.add_tet({0, 2, 1, 3});  // the same element, reversed: inverted
  mesh.rest_position_m.push_back({0.5, 0.5, 0.0});
  mesh.add_tet({0, 1, 2, 4});  // flat: all four points in z = 0
  const MeshQualityReport report = assess_quality(mesh);
  EXPECT_EQ(report.tet_count, 3u);
  EXPECT_EQ(report.inverted_count, 1u);
  EXPECT_EQ(report.degenerate_count, 1u);
  EXPECT_NEAR(report.min_dihedral_deg, 0.0, 1e-9);
}

TEST(Surface, TwoTetsShareOneInteriorFace) {
  TetMesh mesh = single_tet({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  mesh.rest_position_m.push_back({1, 1, 1});
  mesh.add_tet({1, 2, 3, 4});
  ASSERT_GT(mesh.rest_volume_m3(1), 0.0);
  const BoundarySurface surface = extract_surface(mesh);
  EXPECT_EQ(surface.triangles.size(), 6u);  // 8 faces, the shared one is interior
  EXPECT_EQ(surface.nodes.size(), 5u);
  // Outward orientation: the divergence theorem gives the enclosed volume from the triangles.
  double volume = 0.0;
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d a = mesh.rest_position_m.at(surface.nodes[t[0]]);
    const Eigen::Vector3d b = mesh.rest_position_m.at(surface.nodes[t[1]]);
    const Eigen::Vector3d c = mesh.rest_position_m.at(surface.nodes[t[2]]);
    volume += a.dot(b.cross(c)) / 6.0;
  }
  EXPECT_NEAR(volume, mesh.rest_volume_m3(0) + mesh.rest_volume_m3(1), 1e-14);
}

}  // namespace
}  // namespace liversim
