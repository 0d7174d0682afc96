#include "liversim/meshing/implicit_mesher.h"

#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/surface.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace liversim {

Eigen::Vector3d ImplicitShape::gradient(const Eigen::Vector3d& p) const {
  constexpr double h = 1e-5;
  Eigen::Vector3d g;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[k] = h;
    g[k] = (value(p + step) - value(p - step)) / (2.0 * h);
  }
  return g;
}

Eigen::Vector3d ImplicitShape::closest_surface_point(Eigen::Vector3d p) const {
  for (int it = 0; it < 6; ++it) {
    const Eigen::Vector3d g = gradient(p);
    const double g2 = g.squaredNorm();
    if (g2 < 1e-24) break;
    p -= value(p) * g / g2;
  }
  return p;
}

namespace {

struct Lattice {
  Eigen::Vector3d origin;
  double spacing;
  int nx, ny, nz;  // cells per axis

  int corner_id(int i, int j, int k) const { return i + (nx + 1) * (j + (ny + 1) * k); }
  int center_id(int i, int j, int k) const {
    return (nx + 1) * (ny + 1) * (nz + 1) + i + nx * (j + ny * k);
  }
  int node_count() const { return (nx + 1) * (ny + 1) * (nz + 1) + nx * ny * nz; }
  Eigen::Vector3d position(int id) const {
    const int corners = (nx + 1) * (ny + 1) * (nz + 1);
    if (id < corners) {
      const int i = id % (nx + 1), j = (id / (nx + 1)) % (ny + 1), k = id / ((nx + 1) * (ny + 1));
      return origin + spacing * Eigen::Vector3d(i, j, k);
    }
    id -= corners;
    const int i = id % nx, j = (id / nx) % ny, k = id / (nx * ny);
    return origin + spacing * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
};

Lattice make_lattice(const Eigen::AlignedBox3d& bounds, double spacing) {
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(2.0 * spacing);
  const Eigen::Vector3d lo = bounds.min() - pad, extent = bounds.max() + pad - lo;
  return {lo, spacing, static_cast<int>(std::ceil(extent.x() / spacing)),
          static_cast<int>(std::ceil(extent.y() / spacing)),
          static_cast<int>(std::ceil(extent.z() / spacing))};
}

// Each pair of neighbouring cell centres and the square face they share make four tetrahedra.
std::vector<std::array<int, 4>> lattice_tets_inside(const ImplicitShape& shape,
                                                    const Lattice& lattice) {
  std::vector<std::array<int, 4>> tets;
  auto emit = [&](int c1, int c2, const std::array<int, 4>& square) {
    for (int m = 0; m < 4; ++m) {
      std::array<int, 4> t{c1, c2, square[m], square[(m + 1) % 4]};
      const Eigen::Vector3d centroid = 0.25 * (lattice.position(t[0]) + lattice.position(t[1]) +
                                               lattice.position(t[2]) + lattice.position(t[3]));
      if (shape.value(centroid) >= 0.0) continue;
      const double volume = signed_tet_volume(lattice.position(t[0]), lattice.position(t[1]),
                                              lattice.position(t[2]), lattice.position(t[3]));
      if (volume < 0) std::swap(t[2], t[3]);
      tets.push_back(t);
    }
  };
  const Lattice& l = lattice;
  for (int k = 0; k < l.nz; ++k)
    for (int j = 0; j < l.ny; ++j)
      for (int i = 0; i < l.nx; ++i) {
        const int c = l.center_id(i, j, k);
        if (i + 1 < l.nx)
          emit(c, l.center_id(i + 1, j, k),
               {l.corner_id(i + 1, j, k), l.corner_id(i + 1, j + 1, k),
                l.corner_id(i + 1, j + 1, k + 1), l.corner_id(i + 1, j, k + 1)});
        if (j + 1 < l.ny)
          emit(c, l.center_id(i, j + 1, k),
               {l.corner_id(i, j + 1, k), l.corner_id(i + 1, j + 1, k),
                l.corner_id(i + 1, j + 1, k + 1), l.corner_id(i, j + 1, k + 1)});
        if (k + 1 < l.nz)
          emit(c, l.center_id(i, j, k + 1),
               {l.corner_id(i, j, k + 1), l.corner_id(i + 1, j, k + 1),
                l.corner_id(i + 1, j + 1, k + 1), l.corner_id(i, j + 1, k + 1)});
      }
  return tets;
}

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Keeps the largest set of elements connected through shared faces.
std::vector<std::array<int, 4>> largest_face_connected_part(std::vector<std::array<int, 4>> tets) {
  struct Face {
    std::array<int, 3> nodes;
    int tet;
  };
  std::vector<Face> faces;
  faces.reserve(4 * tets.size());
  for (int t = 0; t < static_cast<int>(tets.size()); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      for (int c = 0, m = 0; c < 4; ++c)
        if (c != skip) f[m++] = tets[t][c];
      std::sort(f.begin(), f.end());
      faces.push_back({f, t});
    }
  std::sort(faces.begin(), faces.end(),
            [](const Face& a, const Face& b) { return a.nodes < b.nodes; });
  std::vector<int> parent(tets.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t f = 0; f + 1 < faces.size(); ++f)
    if (faces[f].nodes == faces[f + 1].nodes)
      parent[find_root(parent, faces[f].tet)] = find_root(parent, faces[f + 1].tet);
  std::vector<int> size(tets.size(), 0);
  for (int t = 0; t < static_cast<int>(tets.size()); ++t) ++size[find_root(parent, t)];
  const int biggest = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<std::array<int, 4>> kept;
  for (int t = 0; t < static_cast<int>(tets.size()); ++t)
    if (find_root(parent, t) == biggest) kept.push_back(tets[t]);
  return kept;
}

std::vector<std::array<int, 4>> clipped_lattice(const ImplicitShape& shape, double spacing) {
  auto tets = lattice_tets_inside(shape, make_lattice(shape.bounds(), spacing));
  return tets.empty() ? tets : largest_face_connected_part(std::move(tets));
}

// Mesh with compact node numbering from lattice tetrahedra.
TetMesh compact_mesh(const Lattice& lattice, const std::vector<std::array<int, 4>>& tets) {
  TetMesh mesh;
  std::vector<int> new_id(lattice.node_count(), -1);
  for (const auto& t : tets) {
    std::array<NodeIndex, 4> nodes;
    for (int c = 0; c < 4; ++c) {
      int& id = new_id[t[c]];
      if (id < 0) {
        id = static_cast<int>(mesh.node_count());
        mesh.rest_position_m.push_back(lattice.position(t[c]));
      }
      nodes[c] = id;
    }
    mesh.add_tet(nodes);
  }
  return mesh;
}

// Moves vertices under a quality guard: a move is accepted only if every incident element stays
// positively oriented, with all dihedral angles and heights at or above the guards.
class GuardedMover {
 public:
  GuardedMover(TetMesh& mesh, double guard_deg, double min_height_m)
      : mesh_(mesh), guard_deg_(guard_deg), min_height_m_(min_height_m) {
    incident_.resize(mesh.node_count());
    for (std::size_t e = 0; e < mesh.tet_count(); ++e)
      for (auto n : mesh.tet(e)) incident_[n].push_back(static_cast<TetIndex>(e));
  }

  double worst_angle_with(NodeIndex node, const Eigen::Vector3d& p) const {
    double worst = 180.0;
    for (auto e : incident_[node]) {
      std::array<Eigen::Vector3d, 4> x;
      const auto tet = mesh_.tet(e);
      for (int c = 0; c < 4; ++c) x[c] = tet[c] == node ? p : mesh_.rest_position_m.at(tet[c]);
      const TetShape s = tet_shape(x[0], x[1], x[2], x[3]);
      if (s.volume_m3 <= 0.0 || s.min_height_m < min_height_m_) return -1.0;
      worst = std::min(worst, s.min_dihedral_deg);
    }
    return worst;
  }

  // Tries the full move toward `target`, then a half and a quarter of it.
  bool move_toward(NodeIndex node, const Eigen::Vector3d& target) {
    const Eigen::Vector3d start = mesh_.rest_position_m.at(node);
    for (double fraction : {1.0, 0.5, 0.25}) {
      const Eigen::Vector3d p = start + fraction * (target - start);
      if (worst_angle_with(node, p) >= guard_deg_) {
        mesh_.rest_position_m.set(node, p);
        return true;
      }
    }
    return false;
  }

  // Smart Laplacian: accept only when the worst incident angle does not get worse.
  void smooth(NodeIndex node, const Eigen::Vector3d& target) {
    const double before = worst_angle_with(node, mesh_.rest_position_m.at(node));
    if (worst_angle_with(node, target) >= std::max(before, guard_deg_))
      mesh_.rest_position_m.set(node, target);
  }

 private:
  TetMesh& mesh_;
  double guard_deg_;
  double min_height_m_;
  std::vector<std::vector<TetIndex>> incident_;
};

std::vector<std::uint8_t> boundary_flags(const TetMesh& mesh) {
  std::vector<std::uint8_t> on_boundary(mesh.node_count(), 0);
  for (NodeIndex n : extract_surface(mesh).nodes) on_boundary[n] = 1;
  return on_boundary;
}

}  // namespace

ImplicitMeshResult mesh_implicit_shape(const ImplicitShape& shape,
                                       const ImplicitMeshOptions& options) {
  if (options.target_tet_count < 100 || options.target_tet_count > 2'000'000)
    throw std::invalid_argument("target element count " + std::to_string(options.target_tet_count) +
                                " is outside the supported range 100 … 2000000");
  const double target = options.target_tet_count;
  const Eigen::AlignedBox3d box = shape.bounds();
  // A BCC cell of volume h³ holds 12 tetrahedra: start from the bounding box volume and refine.
  double spacing = std::cbrt(12.0 * box.volume() / target);
  double best_spacing = spacing, best_error = std::numeric_limits<double>::infinity();
  int iterations = 0;
  for (; iterations < options.max_search_iterations; ++iterations) {
    const auto count = static_cast<double>(clipped_lattice(shape, spacing).size());
    const double error = count > 0 ? std::abs(count - target) / target : 1.0;
    if (error < best_error) {
      best_error = error;
      best_spacing = spacing;
    }
    if (error <= options.count_tolerance) break;
    // Counts scale like h⁻³; damp the update slightly so the step function cannot cycle.
    const double ratio = count > 0 ? count / target : 0.125;
    spacing *= std::pow(ratio, (iterations < 10 ? 1.0 : 0.5) / 3.0);
  }
  if (best_error > 0.03)
    throw std::runtime_error("could not mesh the shape within 3 % of " +
                             std::to_string(options.target_tet_count) + " elements");

  const Lattice lattice = make_lattice(box, best_spacing);
  ImplicitMeshResult result;
  result.mesh = compact_mesh(lattice, clipped_lattice(shape, best_spacing));
  result.lattice_spacing_m = best_spacing;
  result.search_iterations = iterations + 1;

  TetMesh& mesh = result.mesh;
  const auto on_boundary = boundary_flags(mesh);
  GuardedMover mover(mesh, options.min_dihedral_guard_deg,
                     options.min_height_guard * result.lattice_spacing_m);
  // Edge neighbours: interior vertices smooth over all of them, boundary vertices over the
  // boundary ones only (a tangential average, projected back onto the surface).
  std::vector<std::vector<NodeIndex>> neighbours(mesh.node_count());
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto t = mesh.tet(e);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b && (!on_boundary[t[a]] || on_boundary[t[b]])) neighbours[t[a]].push_back(t[b]);
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  auto neighbour_mean = [&](std::size_t n) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (auto m : neighbours[n]) mean += mesh.rest_position_m.at(m);
    return Eigen::Vector3d(mean / static_cast<double>(neighbours[n].size()));
  };
  // Alternate: pull the boundary onto the surface, then relax the interior so that vertices the
  // guards held back get room on the next pass.
  for (int pass = 0; pass < options.projection_passes; ++pass) {
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      if (on_boundary[n])
        mover.move_toward(static_cast<NodeIndex>(n),
                          shape.closest_surface_point(mesh.rest_position_m.at(n)));
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      if (on_boundary[n])
        mover.move_toward(static_cast<NodeIndex>(n),
                          shape.closest_surface_point(neighbour_mean(n)));
    for (int smooth = 0; smooth < options.smoothing_passes; ++smooth)
      for (std::size_t n = 0; n < mesh.node_count(); ++n)
        if (!on_boundary[n]) mover.smooth(static_cast<NodeIndex>(n), neighbour_mean(n));
  }

  int boundary_count = 0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (on_boundary[n]) {
      const double distance = std::abs(shape.value(mesh.rest_position_m.at(n)));
      result.max_surface_distance_m = std::max(result.max_surface_distance_m, distance);
      result.mean_surface_distance_m += distance;
      ++boundary_count;
    }
  result.mean_surface_distance_m /= std::max(boundary_count, 1);
  return result;
}

}  // namespace liversim
