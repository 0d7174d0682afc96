#pragma once
// A bounding-volume hierarchy of axis-aligned boxes over the boundary triangles of the deforming
// liver: built once from the surface's topology, refitted to the current node positions every
// step (the tree's shape is kept; only its boxes move), and queried for the triangles near a
// tool. Refitting and querying allocate nothing.

#include "liversim/engine/surface.h"
#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace liversim {

struct Aabb {
  Eigen::Vector3d min_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max_m = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

  void grow(const Eigen::Vector3d& point_m) {
    min_m = min_m.cwiseMin(point_m);
    max_m = max_m.cwiseMax(point_m);
  }
  void grow(const Aabb& box) {
    min_m = min_m.cwiseMin(box.min_m);
    max_m = max_m.cwiseMax(box.max_m);
  }
  // The box around segment [a, b] swept by a sphere of `radius_m` (a point: a = b).
  static Aabb around(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m, double radius_m) {
    Aabb box;
    box.min_m = a_m.cwiseMin(b_m).array() - radius_m;
    box.max_m = a_m.cwiseMax(b_m).array() + radius_m;
    return box;
  }
  bool overlaps(const Aabb& other) const {
    return (min_m.array() <= other.max_m.array()).all() &&
           (other.min_m.array() <= max_m.array()).all();
  }
};

class SurfaceBvh {
 public:
  // Triangles as mesh node indices (counter-clockwise seen from outside), in surface order.
  using Triangle = std::array<NodeIndex, 3>;

  SurfaceBvh() = default;
  // Over the triangles of `surface` at `position`: top-down, split at the median centroid along
  // the longest axis of the centroids' box, up to kLeafTriangles per leaf.
  SurfaceBvh(const BoundarySurface& surface, const NodeArray& position);

  // The boxes around the triangles at `position` (the same nodes as at construction).
  void refit(const NodeArray& position);

  // Calls visit(triangle index) for every triangle whose box overlaps `box`. The index is into
  // triangles() (the surface's order). Depth-first with a fixed stack: allocates nothing.
  template <typename Visit>
  void for_each_triangle_overlapping(const Aabb& box, Visit&& visit) const;

  const std::vector<Triangle>& triangles() const { return triangles_; }
  // The element each triangle bounds; empty when the surface did not say.
  const std::vector<TetIndex>& triangle_tet() const { return triangle_tet_; }
  // The box around the whole surface (empty for an empty surface).
  Aabb bounds() const { return nodes_.empty() ? Aabb{} : nodes_.front().box; }
  bool empty() const { return triangles_.empty(); }

  static constexpr int kLeafTriangles = 4;

 private:
  struct TreeNode {
    Aabb box;
    // Leaf: triangles order_[first, first + count). Inner: children at `first` and `first + 1`
    // in nodes_, count = 0. Children always come after their parent, so refitting walks nodes_
    // backwards.
    std::int32_t first = 0;
    std::int32_t count = 0;
  };
  static constexpr int kMaxDepth = 64;

  std::vector<Triangle> triangles_;
  std::vector<TetIndex> triangle_tet_;
  std::vector<Aabb> triangle_box_;   // per triangle, at the last refit
  std::vector<std::int32_t> order_;  // triangle indices, grouped by leaf
  std::vector<TreeNode> nodes_;
};

template <typename Visit>
void SurfaceBvh::for_each_triangle_overlapping(const Aabb& box, Visit&& visit) const {
  if (nodes_.empty()) return;
  std::int32_t stack[kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const TreeNode& node = nodes_[static_cast<std::size_t>(stack[--top])];
    if (!node.box.overlaps(box)) continue;
    if (node.count > 0) {
      for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
        const auto triangle = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        if (triangle_box_[triangle].overlaps(box)) visit(triangle);
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
}

}  // namespace liversim
