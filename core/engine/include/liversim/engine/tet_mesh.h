#pragma once
// Linear tetrahedral mesh, laid out as structure of arrays. Coordinates are in metres.

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products of node positions are everywhere

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace liversim {

using NodeIndex = std::int32_t;
using TetIndex = std::int32_t;

// Three coordinate arrays (x, y, z): the layout the element loops read.
struct NodeArray {
  std::vector<double> x, y, z;

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n, double value = 0.0) {
    x.assign(n, value);
    y.assign(n, value);
    z.assign(n, value);
  }
  void push_back(const Eigen::Vector3d& p) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  }
  Eigen::Vector3d at(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void set(std::size_t i, const Eigen::Vector3d& p) {
    x[i] = p.x();
    y[i] = p.y();
    z[i] = p.z();
  }
};

// Corners of the face opposite corner i, ordered so that its normal points out of a positively
// oriented element.
inline constexpr int kTetFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct TetMesh {
  NodeArray rest_position_m;                     // reference (material) coordinates
  std::array<std::vector<NodeIndex>, 4> corner;  // corner[c][e]: node of corner c of element e
  std::vector<std::int32_t> region;              // region id per element (0 when not given)
  std::map<std::string, std::vector<NodeIndex>> node_sets;    // named node sets, 0-based
  std::map<std::string, std::vector<TetIndex>> element_sets;  // named element sets, 0-based

  std::size_t node_count() const { return rest_position_m.size(); }
  std::size_t tet_count() const { return corner[0].size(); }
  std::array<NodeIndex, 4> tet(std::size_t e) const {
    return {corner[0][e], corner[1][e], corner[2][e], corner[3][e]};
  }
  void add_tet(const std::array<NodeIndex, 4>& nodes, std::int32_t region_id = 0) {
    for (int c = 0; c < 4; ++c) corner[c].push_back(nodes[c]);
    region.push_back(region_id);
  }
  // Signed volume of element e in the rest configuration (positive when correctly oriented).
  double rest_volume_m3(std::size_t e) const;
};

// Signed volume of the tetrahedron (a, b, c, d): positive when (b-a, c-a, d-a) is right-handed.
double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, const Eigen::Vector3d& d);

}  // namespace liversim
