#include "liversim/engine/mesh_quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <ostream>
#include <vector>

namespace liversim {

TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d) {
  const std::array<Eigen::Vector3d, 4> p{a, b, c, d};
  // Face i is opposite vertex i; its outward normal (area-weighted) is n[i].
  TetShape shape;
  shape.volume_m3 = (b - a).dot((c - a).cross(d - a)) / 6.0;
  std::array<Eigen::Vector3d, 4> normal;
  double area_sum = 0.0, max_area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const auto& f = kTetFace[i];
    normal[i] = 0.5 * (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]);
    const double area = normal[i].norm();
    area_sum += area;
    max_area = std::max(max_area, area);
  }
  const double abs_volume = std::abs(shape.volume_m3);
  shape.min_height_m = max_area > 0 ? 3.0 * abs_volume / max_area : 0.0;

  // Dihedral angle at the edge shared by faces i and j: π − angle between outward normals.
  shape.min_dihedral_deg = 180.0;
  shape.max_dihedral_deg = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const double ni = normal[i].norm(), nj = normal[j].norm();
      double angle = 0.0;
      if (ni > 0 && nj > 0) {
        const double cosine = std::clamp(normal[i].dot(normal[j]) / (ni * nj), -1.0, 1.0);
        angle = 180.0 - std::acos(cosine) * 180.0 / std::numbers::pi;
      }
      shape.min_dihedral_deg = std::min(shape.min_dihedral_deg, angle);
      shape.max_dihedral_deg = std::max(shape.max_dihedral_deg, angle);
    }
  }

  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      shape.longest_edge_m = std::max(shape.longest_edge_m, (p[i] - p[j]).norm());

  // Inradius r = 3V / total area. Circumradius from the standard formula
  // R = |a²(b×c) + b²(c×a) + c²(a×b)| / (12 V) with edges from vertex a.
  const Eigen::Vector3d e1 = b - a, e2 = c - a, e3 = d - a;
  const Eigen::Vector3d numerator = e1.squaredNorm() * e2.cross(e3) +
                                    e2.squaredNorm() * e3.cross(e1) +
                                    e3.squaredNorm() * e1.cross(e2);
  if (abs_volume > 0) {
    const double inradius = 3.0 * abs_volume / area_sum;
    const double circumradius = numerator.norm() / (12.0 * abs_volume);
    shape.aspect_ratio = circumradius / (3.0 * inradius);
  } else {
    shape.aspect_ratio = std::numeric_limits<double>::infinity();
  }
  return shape;
}

bool is_degenerate(const TetShape& shape) {
  const double edge = shape.longest_edge_m;
  return !(std::abs(shape.volume_m3) > 1e-9 * edge * edge * edge);
}

MeshQualityReport assess_quality(const TetMesh& mesh, const NodeArray& position) {
  MeshQualityReport report;
  report.node_count = mesh.node_count();
  report.tet_count = mesh.tet_count();
  if (report.tet_count == 0) return report;
  report.min_dihedral_deg = 180.0;
  report.min_height_m = std::numeric_limits<double>::infinity();
  std::vector<double> heights;
  heights.reserve(report.tet_count);
  double aspect_sum = 0.0;
  for (std::size_t e = 0; e < report.tet_count; ++e) {
    const auto n = mesh.tet(e);
    const TetShape s =
        tet_shape(position.at(n[0]), position.at(n[1]), position.at(n[2]), position.at(n[3]));
    report.volume_m3 += s.volume_m3;
    if (is_degenerate(s)) {
      ++report.degenerate_count;
    } else if (s.volume_m3 < 0) {
      ++report.inverted_count;
    }
    report.min_dihedral_deg = std::min(report.min_dihedral_deg, s.min_dihedral_deg);
    report.max_dihedral_deg = std::max(report.max_dihedral_deg, s.max_dihedral_deg);
    report.max_aspect_ratio = std::max(report.max_aspect_ratio, s.aspect_ratio);
    aspect_sum += s.aspect_ratio;
    report.min_height_m = std::min(report.min_height_m, s.min_height_m);
    heights.push_back(s.min_height_m);
  }
  report.mean_aspect_ratio = aspect_sum / static_cast<double>(report.tet_count);
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  report.median_height_m = heights[heights.size() / 2];
  return report;
}

std::ostream& operator<<(std::ostream& out, const MeshQualityReport& r) {
  const auto flags = out.flags();
  out << std::fixed << std::setprecision(2) << "nodes " << r.node_count << ", tetrahedra "
      << r.tet_count << ", volume " << std::setprecision(4) << r.volume_m3 * 1e3 << " L\n"
      << std::setprecision(2) << "dihedral angle min " << r.min_dihedral_deg << " deg, max "
      << r.max_dihedral_deg << " deg\n"
      << "aspect ratio (R/3r) max " << r.max_aspect_ratio << ", mean " << r.mean_aspect_ratio
      << "\n"
      << "element height min " << r.min_height_m * 1e3 << " mm, median " << r.median_height_m * 1e3
      << " mm\n"
      << "inverted " << r.inverted_count << ", degenerate " << r.degenerate_count << "\n";
  out.flags(flags);
  return out;
}

}  // namespace liversim
