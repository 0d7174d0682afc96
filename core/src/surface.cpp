#include "liversim/core/surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace liversim {
namespace {

// Face opposite vertex i, ordered so that its normal points out of a positively oriented element.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct FaceKey {
  NodeIndex a, b, c;  // sorted
  bool operator==(const FaceKey&) const = default;
};

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = static_cast<std::size_t>(k.a) * 73856093u;
    h ^= static_cast<std::size_t>(k.b) * 19349663u + (h << 6) + (h >> 2);
    h ^= static_cast<std::size_t>(k.c) * 83492791u + (h << 6) + (h >> 2);
    return h;
  }
};

struct FaceUse {
  int count = 0;
  std::array<NodeIndex, 3> oriented{};
  TetIndex tet = 0;
};

}  // namespace

BoundarySurface extract_surface(const TetMesh& mesh) {
  std::unordered_map<FaceKey, FaceUse, FaceKeyHash> faces;
  faces.reserve(mesh.tet_count() * 2 + 16);
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto tet = mesh.tet(e);
    for (const auto& f : kFace) {
      std::array<NodeIndex, 3> oriented{tet[f[0]], tet[f[1]], tet[f[2]]};
      auto sorted = oriented;
      std::sort(sorted.begin(), sorted.end());
      auto& use = faces[FaceKey{sorted[0], sorted[1], sorted[2]}];
      ++use.count;
      use.oriented = oriented;
      use.tet = static_cast<TetIndex>(e);
    }
  }

  // Collect in a deterministic order (by sorted key) so surfaces are reproducible.
  std::vector<std::pair<FaceKey, const FaceUse*>> boundary;
  for (const auto& [key, use] : faces)
    if (use.count != 2) boundary.emplace_back(key, &use);
  std::sort(boundary.begin(), boundary.end(), [](const auto& l, const auto& r) {
    return std::tie(l.first.a, l.first.b, l.first.c) < std::tie(r.first.a, r.first.b, r.first.c);
  });

  BoundarySurface surface;
  std::vector<std::int32_t> local(mesh.node_count(), -1);
  for (const auto& [key, use] : boundary)
    for (auto n : use->oriented) local[n] = 0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    if (local[n] == 0) {
      local[n] = static_cast<std::int32_t>(surface.nodes.size());
      surface.nodes.push_back(static_cast<NodeIndex>(n));
    }
  }
  surface.triangles.reserve(boundary.size());
  surface.triangle_tet.reserve(boundary.size());
  for (const auto& [key, use] : boundary) {
    surface.triangles.push_back(
        {local[use->oriented[0]], local[use->oriented[1]], local[use->oriented[2]]});
    surface.triangle_tet.push_back(use->tet);
  }
  return surface;
}

void compute_vertex_normals(const BoundarySurface& surface, const NodeArray& position,
                            std::vector<float>& normals) {
  normals.assign(3 * surface.nodes.size(), 0.0f);
  auto at = [&](std::int32_t local) { return position.at(surface.nodes[local]); };
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d p0 = at(t[0]);
    const Eigen::Vector3d n = (at(t[1]) - p0).cross(at(t[2]) - p0);  // length = 2 · area
    for (auto v : t)
      for (int k = 0; k < 3; ++k) normals[3 * v + k] += static_cast<float>(n[k]);
  }
  for (std::size_t v = 0; v < surface.nodes.size(); ++v) {
    float* n = &normals[3 * v];
    const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length > 0.0f)
      for (int k = 0; k < 3; ++k) n[k] /= length;
  }
}

}  // namespace liversim
