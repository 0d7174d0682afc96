#include "liversim/engine/surface.h"

#include <Eigen/Geometry>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace liversim {
namespace {

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
    for (const auto& f : kTetFace) {
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

void compute_vertex_normals(const std::vector<std::array<std::int32_t, 3>>& triangles,
                            const std::vector<double>& vertex_xyz, std::vector<float>& normals) {
  normals.assign(vertex_xyz.size(), 0.0f);
  auto at = [&](std::int32_t v) {
    return Eigen::Vector3d(vertex_xyz[3 * v], vertex_xyz[3 * v + 1], vertex_xyz[3 * v + 2]);
  };
  for (const auto& t : triangles) {
    const Eigen::Vector3d p0 = at(t[0]);
    const Eigen::Vector3d n = (at(t[1]) - p0).cross(at(t[2]) - p0);  // length = 2 · area
    for (auto v : t)
      for (int k = 0; k < 3; ++k) normals[3 * v + k] += static_cast<float>(n[k]);
  }
  for (std::size_t v = 0; v < normals.size() / 3; ++v) {
    float* n = &normals[3 * v];
    const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length > 0.0f)
      for (int k = 0; k < 3; ++k) n[k] /= length;
  }
}

VisualSurface visual_surface_on_nodes(const TetMesh& mesh) {
  VisualSurface visual;
  visual.surface = extract_surface(mesh);
  for (NodeIndex n : visual.surface.nodes) {
    visual.host_nodes.push_back({n, n, n, n});
    visual.weights.push_back({1.0, 0.0, 0.0, 0.0});
  }
  return visual;
}

namespace {

// Barycentric weights of rest point p in element e (negative outside it).
std::array<double, 4> barycentric_weights(const TetMesh& mesh, std::size_t e,
                                          const Eigen::Vector3d& p) {
  const auto t = mesh.tet(e);
  const Eigen::Vector3d x0 = mesh.rest_position_m.at(t[0]);
  Eigen::Matrix3d edges;
  for (int c = 1; c < 4; ++c) edges.col(c - 1) = mesh.rest_position_m.at(t[c]) - x0;
  const Eigen::Vector3d local = edges.inverse() * (p - x0);
  return {1.0 - local.sum(), local[0], local[1], local[2]};
}

}  // namespace

VisualSurface embed_visual_surface(const TetMesh& mesh, const BoundarySurface& surface,
                                   const std::vector<Eigen::Vector3d>& vertex_rest_m) {
  if (vertex_rest_m.size() != surface.nodes.size())
    throw std::invalid_argument("embed_visual_surface: one rest position per surface node needed");
  std::vector<std::vector<TetIndex>> incident(mesh.node_count());
  for (std::size_t e = 0; e < mesh.tet_count(); ++e)
    for (auto n : mesh.tet(e)) incident[n].push_back(static_cast<TetIndex>(e));

  VisualSurface visual;
  visual.surface = surface;
  for (std::size_t v = 0; v < surface.nodes.size(); ++v) {
    const Eigen::Vector3d& p = vertex_rest_m[v];
    double best_min_weight = -std::numeric_limits<double>::infinity();
    std::array<NodeIndex, 4> best_nodes{};
    std::array<double, 4> best_weights{};
    for (TetIndex e : incident[surface.nodes[v]]) {
      const std::array<double, 4> w = barycentric_weights(mesh, e, p);
      const double min_weight = *std::min_element(w.begin(), w.end());
      if (min_weight > best_min_weight) {
        best_min_weight = min_weight;
        best_nodes = mesh.tet(e);
        best_weights = w;
      }
    }
    visual.host_nodes.push_back(best_nodes);
    visual.weights.push_back(best_weights);
  }
  return visual;
}

void map_visual_positions(const VisualSurface& visual, const NodeArray& position,
                          std::vector<double>& vertex_xyz) {
  map_embedded_positions(visual.host_nodes, visual.weights, position, vertex_xyz);
}

EmbeddedPoints embed_points(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& points_m) {
  // Each element's rest bounding box, grown by the reach, so that only the few elements whose
  // box holds a point are solved for its weights.
  const std::size_t elements = mesh.tet_count();
  std::vector<Eigen::AlignedBox3d> box(elements);
  for (std::size_t e = 0; e < elements; ++e) {
    for (auto n : mesh.tet(e)) box[e].extend(mesh.rest_position_m.at(n));
    const Eigen::Vector3d margin = -kEmbeddingReach * (box[e].max() - box[e].min());
    box[e].extend(box[e].min() - margin);
    box[e].extend(box[e].max() + margin);
  }
  EmbeddedPoints embedded;
  embedded.host_nodes.resize(points_m.size(), {0, 0, 0, 0});
  embedded.weights.resize(points_m.size(), {0.0, 0.0, 0.0, 0.0});
  embedded.held.resize(points_m.size(), 0);
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    double best_min_weight = kEmbeddingReach;
    for (std::size_t e = 0; e < elements; ++e) {
      if (!box[e].contains(points_m[i])) continue;
      const std::array<double, 4> w = barycentric_weights(mesh, e, points_m[i]);
      const double min_weight = *std::min_element(w.begin(), w.end());
      if (min_weight < best_min_weight) continue;
      best_min_weight = min_weight;
      embedded.host_nodes[i] = mesh.tet(e);
      embedded.weights[i] = w;
      embedded.held[i] = 1;
      if (min_weight >= 0.0) break;  // inside: no element holds it better
    }
  }
  return embedded;
}

void map_embedded_positions(const std::vector<std::array<NodeIndex, 4>>& host_nodes,
                            const std::vector<std::array<double, 4>>& weights,
                            const NodeArray& position, std::vector<double>& xyz) {
  xyz.resize(3 * host_nodes.size());
  for (std::size_t v = 0; v < host_nodes.size(); ++v) {
    double x = 0.0, y = 0.0, z = 0.0;
    for (int c = 0; c < 4; ++c) {
      const auto n = host_nodes[v][c];
      const double w = weights[v][c];
      x += w * position.x[n];
      y += w * position.y[n];
      z += w * position.z[n];
    }
    xyz[3 * v] = x;
    xyz[3 * v + 1] = y;
    xyz[3 * v + 2] = z;
  }
}

}  // namespace liversim
