#include "liversim/meshing/box_mesh.h"

#include "liversim/engine/surface.h"

#include <cmath>
#include <random>

namespace liversim {
namespace {

bool on_box_boundary(int i, int j, int k, int nx, int ny, int nz) {
  return i == 0 || j == 0 || k == 0 || i == nx || j == ny || k == nz;
}

}  // namespace

TetMesh box_mesh(int nx, int ny, int nz, const Eigen::Vector3d& size_m, double interior_jitter,
                 unsigned seed) {
  TetMesh mesh;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> jitter(-interior_jitter, interior_jitter);
  const Eigen::Vector3d h(size_m.x() / nx, size_m.y() / ny, size_m.z() / nz);
  auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        Eigen::Vector3d p(i * h.x(), j * h.y(), k * h.z());
        if (!on_box_boundary(i, j, k, nx, ny, nz))
          p += Eigen::Vector3d(jitter(random), jitter(random), jitter(random)).cwiseProduct(h);
        mesh.rest_position_m.push_back(p);
      }
  // Kuhn subdivision: the six paths from corner 000 to 111 along the axes.
  static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& path : kPaths) {
          int c[3] = {i, j, k};
          std::array<NodeIndex, 4> tet;
          tet[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[path[s]];
            tet[s + 1] = id(c[0], c[1], c[2]);
          }
          if (signed_tet_volume(mesh.rest_position_m.at(tet[0]), mesh.rest_position_m.at(tet[1]),
                                mesh.rest_position_m.at(tet[2]),
                                mesh.rest_position_m.at(tet[3])) < 0)
            std::swap(tet[2], tet[3]);
          mesh.add_tet(tet);
        }
  return mesh;
}

// Consistent nodal loads of a uniform normal traction σ (Pa, positive pulling outward) on the
// faces of a box mesh that are perpendicular to the x axis: each boundary triangle hands a third of
// σ·area to each of its corners.
std::vector<PointLoad> end_face_tension(const TetMesh& mesh, double sigma_pa) {
  std::vector<PointLoad> loads;
  const BoundarySurface surface = extract_surface(mesh);
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d a = mesh.rest_position_m.at(surface.nodes[t[0]]);
    const Eigen::Vector3d b = mesh.rest_position_m.at(surface.nodes[t[1]]);
    const Eigen::Vector3d c = mesh.rest_position_m.at(surface.nodes[t[2]]);
    const Eigen::Vector3d area_normal = 0.5 * (b - a).cross(c - a);
    if (std::abs(std::abs(area_normal.normalized().x()) - 1.0) > 1e-12) continue;  // not an end
    for (auto v : t) loads.push_back({surface.nodes[v], sigma_pa * area_normal / 3.0});
  }
  return loads;
}

// Mean current coordinate `axis` of the nodes whose rest coordinate `axis` is `rest_value` (a face
// or cross-section of a box mesh): how the block tests measure elongation and thinning.
double mean_coordinate_on_plane(const TetMesh& mesh, const NodeArray& position, int axis,
                                double rest_value) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (std::abs(mesh.rest_position_m.at(n)[axis] - rest_value) < 1e-12) {
      sum += position.at(n)[axis];
      ++count;
    }
  return sum / count;
}

std::vector<NodeIndex> nodes_on_plane(const TetMesh& mesh, int axis, double value) {
  std::vector<NodeIndex> nodes;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (std::abs(mesh.rest_position_m.at(n)[axis] - value) < 1e-12) nodes.push_back(NodeIndex(n));
  return nodes;
}

}  // namespace liversim
