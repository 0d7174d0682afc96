#include "liversim/engine/surface.h"
#include "liversim/meshing/default_scene.h"

#include <gtest/gtest.h>

namespace liversim {
namespace {

TEST(VisualSurface, SitsOnTheSmoothLiverAndReproducesItAtRest) {
  const SceneSetup setup = default_scene(3841);
  const VisualSurface& visual = setup.visual;
  ASSERT_EQ(visual.vertex_count(), visual.surface.nodes.size());
  std::vector<double> xyz;
  map_visual_positions(visual, setup.mesh.rest_position_m, xyz);
  const LiverShape shape;
  double worst = 0.0;
  for (std::size_t v = 0; v < visual.vertex_count(); ++v) {
    const Eigen::Vector3d p(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    worst = std::max(worst, std::abs(shape.value(p)));
    double weight_sum = 0.0;
    for (double w : visual.weights[v]) weight_sum += w;
    EXPECT_NEAR(weight_sum, 1.0, 1e-12);
  }
  // Newton projection converges quadratically; 1 µm is far below the 12 mm lattice spacing.
  EXPECT_LT(worst, 1e-6);
}

TEST(VisualSurface, FollowsAnAffineDeformationExactly) {
  // Barycentric weights reproduce affine fields, so the mapped surface moves with the elements.
  const SceneSetup setup = default_scene(3841);
  Eigen::Matrix3d A;
  A << 1.2, 0.1, 0.0, -0.05, 0.9, 0.02, 0.0, 0.03, 1.1;
  const Eigen::Vector3d b(0.01, -0.02, 0.03);
  NodeArray moved = setup.mesh.rest_position_m;
  for (std::size_t n = 0; n < moved.size(); ++n)
    moved.set(n, A * setup.mesh.rest_position_m.at(n) + b);
  std::vector<double> rest_xyz, moved_xyz;
  map_visual_positions(setup.visual, setup.mesh.rest_position_m, rest_xyz);
  map_visual_positions(setup.visual, moved, moved_xyz);
  for (std::size_t v = 0; v < setup.visual.vertex_count(); ++v) {
    const Eigen::Vector3d rest(rest_xyz[3 * v], rest_xyz[3 * v + 1], rest_xyz[3 * v + 2]);
    const Eigen::Vector3d now(moved_xyz[3 * v], moved_xyz[3 * v + 1], moved_xyz[3 * v + 2]);
    EXPECT_LT((now - (A * rest + b)).norm(), 1e-12);
  }
}

TEST(VisualSurface, OnNodesIsThePhysicsSurface) {
  const SceneSetup setup = default_scene(3841);
  const VisualSurface visual = visual_surface_on_nodes(setup.mesh);
  std::vector<double> xyz;
  map_visual_positions(visual, setup.mesh.rest_position_m, xyz);
  for (std::size_t v = 0; v < visual.vertex_count(); ++v)
    EXPECT_EQ(xyz[3 * v], setup.mesh.rest_position_m.x[visual.surface.nodes[v]]);
}

TEST(VisualSurface, NormalsPointOutOfTheLiver) {
  const SceneSetup setup = default_scene(3841);
  std::vector<double> xyz;
  std::vector<float> normals;
  map_visual_positions(setup.visual, setup.mesh.rest_position_m, xyz);
  compute_vertex_normals(setup.visual.surface.triangles, xyz, normals);
  const LiverShape shape;
  int outward = 0;
  const int count = static_cast<int>(setup.visual.vertex_count());
  for (int v = 0; v < count; ++v) {
    const Eigen::Vector3d p(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    const Eigen::Vector3d n(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
    EXPECT_NEAR(n.norm(), 1.0, 1e-6);
    outward += shape.gradient(p).dot(n) > 0.0;
  }
  EXPECT_EQ(outward, count);
}

}  // namespace
}  // namespace liversim
