#include "liversim/engine/surface_bvh.h"

#include <algorithm>
#include <numeric>

namespace liversim {
namespace {

Aabb triangle_box(const SurfaceBvh::Triangle& triangle, const NodeArray& position) {
  Aabb box;
  for (NodeIndex n : triangle) box.grow(position.at(n));
  return box;
}

}  // namespace

SurfaceBvh::SurfaceBvh(const BoundarySurface& surface, const NodeArray& position) {
  triangles_.reserve(surface.triangles.size());
  for (const auto& t : surface.triangles)
    triangles_.push_back({surface.nodes[static_cast<std::size_t>(t[0])],
                          surface.nodes[static_cast<std::size_t>(t[1])],
                          surface.nodes[static_cast<std::size_t>(t[2])]});
  if (surface.triangle_tet.size() == surface.triangles.size()) triangle_tet_ = surface.triangle_tet;
  if (triangles_.empty()) return;
  std::vector<Eigen::Vector3d> centroid(triangles_.size());
  for (std::size_t i = 0; i < triangles_.size(); ++i)
    centroid[i] = (position.at(triangles_[i][0]) + position.at(triangles_[i][1]) +
                   position.at(triangles_[i][2])) /
                  3.0;
  triangle_box_.resize(triangles_.size());
  order_.resize(triangles_.size());
  std::iota(order_.begin(), order_.end(), 0);

  // Breadth-first: a node's two children are appended together, after it.
  struct Range {
    std::size_t node;
    std::int32_t first, count;
  };
  nodes_.reserve(2 * triangles_.size() / kLeafTriangles + 2);
  nodes_.push_back({});
  std::vector<Range> pending{{0, 0, static_cast<std::int32_t>(triangles_.size())}};
  for (std::size_t p = 0; p < pending.size(); ++p) {
    const Range range = pending[p];
    if (range.count <= kLeafTriangles) {
      nodes_[range.node].first = range.first;
      nodes_[range.node].count = range.count;
      continue;
    }
    Aabb centroids;
    for (std::int32_t i = range.first; i < range.first + range.count; ++i)
      centroids.grow(centroid[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])]);
    int axis = 0;
    (centroids.max_m - centroids.min_m).maxCoeff(&axis);
    const auto begin = order_.begin() + range.first, end = begin + range.count;
    const auto middle = begin + range.count / 2;
    std::nth_element(begin, middle, end, [&](std::int32_t a, std::int32_t b) {
      return centroid[static_cast<std::size_t>(a)][axis] <
             centroid[static_cast<std::size_t>(b)][axis];
    });
    const auto children = static_cast<std::int32_t>(nodes_.size());
    nodes_[range.node].first = children;
    nodes_[range.node].count = 0;
    nodes_.push_back({});
    nodes_.push_back({});
    const std::int32_t half = range.count / 2;
    pending.push_back({static_cast<std::size_t>(children), range.first, half});
    pending.push_back(
        {static_cast<std::size_t>(children) + 1, range.first + half, range.count - half});
  }
  refit(position);
}

void SurfaceBvh::refit(const NodeArray& position) {
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    triangle_box_[t] = triangle_box(triangles_[t], position);
  for (std::size_t k = nodes_.size(); k-- > 0;) {
    TreeNode& node = nodes_[k];
    if (node.count > 0) {
      node.box = Aabb{};
      for (std::int32_t i = node.first; i < node.first + node.count; ++i)
        node.box.grow(triangle_box_[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])]);
    } else {
      node.box = nodes_[static_cast<std::size_t>(node.first)].box;
      node.box.grow(nodes_[static_cast<std::size_t>(node.first) + 1].box);
    }
  }
}

}  // namespace liversim
