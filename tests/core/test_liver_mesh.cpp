#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/liver_geometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace liversim {
namespace {

class LiverMeshAtSeedSize : public ::testing::TestWithParam<int> {};

TEST_P(LiverMeshAtSeedSize, HitsTheElementCountWithGoodElements) {
  const int target = GetParam();
  const ImplicitMeshResult result = generate_liver_mesh(target);
  const TetMesh& mesh = result.mesh;
  const MeshQualityReport quality = assess_quality(mesh);
  RecordProperty("tets", static_cast<int>(mesh.tet_count()));
  RecordProperty("nodes", static_cast<int>(mesh.node_count()));
  RecordProperty("min_dihedral_deg", std::to_string(quality.min_dihedral_deg));

  EXPECT_LE(std::abs(static_cast<double>(mesh.tet_count()) - target), 0.03 * target);
  EXPECT_EQ(quality.inverted_count, 0u);
  EXPECT_EQ(quality.degenerate_count, 0u);
  // The guards of the mesher, checked independently on the result.
  ImplicitMeshOptions defaults;
  EXPECT_GE(quality.min_dihedral_deg, defaults.min_dihedral_guard_deg);
  EXPECT_GE(quality.min_height_m, defaults.min_height_guard * result.lattice_spacing_m * 0.999);
  // An adult liver holds 1.2–1.9 L; the built-in shape is designed near 1.65 L.
  EXPECT_GT(quality.volume_m3, 1.2e-3);
  EXPECT_LT(quality.volume_m3, 1.9e-3);
}

INSTANTIATE_TEST_SUITE_P(SeedSizes, LiverMeshAtSeedSize, ::testing::ValuesIn(kSeedMeshSizes));

TEST(LiverMesh, SurfaceIsClosedAndOutwardOriented) {
  const TetMesh mesh = generate_liver_mesh(3841).mesh;
  const BoundarySurface surface = extract_surface(mesh);
  // Closed 2-manifold: every edge is shared by exactly two triangles, in opposite directions.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  // Divergence theorem: the outward surface encloses the mesh volume.
  double enclosed = 0.0;
  for (const auto& t : surface.triangles) {
    enclosed += mesh.rest_position_m.at(surface.nodes[t[0]])
                    .dot(mesh.rest_position_m.at(surface.nodes[t[1]])
                             .cross(mesh.rest_position_m.at(surface.nodes[t[2]]))) /
                6.0;
  }
  EXPECT_NEAR(enclosed, assess_quality(mesh).volume_m3, 1e-12);
}

TEST(LiverMesh, LooksLikeALiverNotABlob) {
  const LiverShape liver;
  // Right lobe much thicker (anterior-posterior) than the left lobe, and the right lobe is the
  // larger: sample thickness along z through each lobe's centre.
  auto thickness_at = [&](double x, double y) {
    int inside = 0;
    for (double z = -0.1; z <= 0.1; z += 0.0005) inside += liver.value({x, y, z}) < 0;
    return inside * 0.0005;
  };
  const double right = thickness_at(-0.05, 0.0), left = thickness_at(0.09, 0.02);
  EXPECT_GT(right, 0.09);
  EXPECT_LT(left, 0.6 * right);
  EXPECT_GT(left, 0.02);
  // Wider (left-right) than tall or deep.
  const TetMesh mesh = generate_liver_mesh(3841).mesh;
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) box.extend(mesh.rest_position_m.at(n));
  const Eigen::Vector3d size = box.sizes();
  EXPECT_GT(size.x(), 1.3 * size.y());
  EXPECT_GT(size.x(), 1.3 * size.z());
  EXPECT_GT(size.x(), 0.20);  // adult liver: about 21–23 cm across
  EXPECT_LT(size.x(), 0.28);
}

TEST(LiverMesh, LigamentAttachmentHoldsSurfaceNodes) {
  TetMesh mesh = generate_liver_mesh(5406).mesh;
  const auto& ligament = mesh.node_sets.at("ligament");
  const BoundarySurface surface = extract_surface(mesh);
  EXPECT_GE(ligament.size(), 20u);
  for (NodeIndex n : ligament)
    EXPECT_TRUE(std::binary_search(surface.nodes.begin(), surface.nodes.end(), n));
}

TEST(LiverMesh, IsReproducible) {
  const TetMesh a = generate_liver_mesh(3841).mesh, b = generate_liver_mesh(3841).mesh;
  ASSERT_EQ(a.tet_count(), b.tet_count());
  EXPECT_EQ(a.rest_position_m.x, b.rest_position_m.x);
  EXPECT_EQ(a.corner, b.corner);
}

TEST(LiverMesh, RejectsAnUnreasonableElementCount) {
  EXPECT_THROW(generate_liver_mesh(10), std::invalid_argument);
  EXPECT_THROW(generate_liver_mesh(-5), std::invalid_argument);
}

}  // namespace
}  // namespace liversim
