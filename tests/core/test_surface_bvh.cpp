// The surface hierarchy against brute force: after refitting to a deformed configuration, a query
// visits exactly the triangles whose boxes overlap the query box, each once.
#include "block_mesh.h"

#include "liversim/engine/surface.h"
#include "liversim/engine/surface_bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace liversim {
namespace {

TEST(SurfaceBvh, RefittedQueriesVisitExactlyTheOverlappingTriangles) {
  const TetMesh mesh = testing::block_mesh(6, 5, 4, {0.06, 0.05, 0.04}, 0.2);
  const BoundarySurface surface = extract_surface(mesh);
  SurfaceBvh bvh(surface, mesh.rest_position_m);
  ASSERT_EQ(bvh.triangles().size(), surface.triangles.size());

  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  NodeArray position = mesh.rest_position_m;
  for (int configuration = 0; configuration < 3; ++configuration) {
    // A bend and a twist, large against the element size (1 cm), plus noise.
    for (std::size_t n = 0; n < position.x.size(); ++n) {
      const Eigen::Vector3d rest = mesh.rest_position_m.at(n);
      const double angle = 4.0 * configuration * rest.x();
      const Eigen::Vector3d moved(rest.x(), std::cos(angle) * rest.y() - std::sin(angle) * rest.z(),
                                  std::sin(angle) * rest.y() + std::cos(angle) * rest.z() +
                                      0.02 * configuration * rest.x() * rest.x() / 0.06);
      position.set(n, moved + 1e-3 * Eigen::Vector3d(u(random), u(random), u(random)));
    }
    bvh.refit(position);
    std::vector<Aabb> triangle_boxes;
    for (const auto& t : bvh.triangles()) {
      Aabb box;
      for (NodeIndex n : t) box.grow(position.at(n));
      triangle_boxes.push_back(box);
    }
    for (int query = 0; query < 200; ++query) {
      const Eigen::Vector3d centre(0.03 + 0.04 * u(random), 0.06 * u(random), 0.06 * u(random));
      const double half = 0.002 + 0.01 * (1.0 + u(random));
      Aabb box;
      box.grow(centre - Eigen::Vector3d::Constant(half));
      box.grow(centre + Eigen::Vector3d::Constant(half));
      std::vector<int> visits(bvh.triangles().size(), 0);
      bvh.for_each_triangle_overlapping(box, [&](std::size_t t) { ++visits[t]; });
      for (std::size_t t = 0; t < visits.size(); ++t)
        ASSERT_EQ(visits[t], triangle_boxes[t].overlaps(box) ? 1 : 0)
            << "configuration " << configuration << ", query " << query << ", triangle " << t;
    }
    // The root holds every node of the surface.
    for (NodeIndex n : surface.nodes) {
      Aabb point;
      point.grow(position.at(n));
      EXPECT_TRUE(bvh.bounds().overlaps(point));
    }
  }
}

TEST(SurfaceBvh, EmptySurfaceVisitsNothing) {
  const SurfaceBvh bvh(BoundarySurface{}, NodeArray{});
  Aabb everything;
  everything.grow(Eigen::Vector3d::Constant(-1e9));
  everything.grow(Eigen::Vector3d::Constant(1e9));
  int visits = 0;
  bvh.for_each_triangle_overlapping(everything, [&](std::size_t) { ++visits; });
  EXPECT_EQ(visits, 0);
  EXPECT_TRUE(bvh.empty());
}

}  // namespace
}  // namespace liversim
