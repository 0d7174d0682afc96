#include "liversim/engine/support.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace liversim {

SupportSurface::Depth SupportSurface::depth_under(const Eigen::Vector3d& point_m) const {
  const double u = (point_m.dot(axis_u) - origin_u_m) / cell_m;
  const double v = (point_m.dot(axis_v) - origin_v_m) / cell_m;
  if (!(u >= 0.0 && v >= 0.0 && u <= cells_u && v <= cells_v))
    return {floor_depth_m, 0.0, 0.0, point_m.dot(down) - floor_depth_m};
  const int i = std::min(static_cast<int>(u), cells_u - 1);
  const int j = std::min(static_cast<int>(v), cells_v - 1);
  const double a = u - i, b = v - j;
  const std::size_t row = static_cast<std::size_t>(cells_u) + 1;
  const std::size_t k = static_cast<std::size_t>(j) * row + static_cast<std::size_t>(i);
  const double d00 = depth_m[k], d10 = depth_m[k + 1], d01 = depth_m[k + row],
               d11 = depth_m[k + row + 1];
  Depth out;
  out.depth_m = (1 - a) * (1 - b) * d00 + a * (1 - b) * d10 + (1 - a) * b * d01 + a * b * d11;
  out.slope_u = ((1 - b) * (d10 - d00) + b * (d11 - d01)) / cell_m;
  out.slope_v = ((1 - a) * (d01 - d00) + a * (d11 - d10)) / cell_m;
  out.past_m = point_m.dot(down) - out.depth_m;
  return out;
}

void limit_support_slope(SupportSurface& support, double max_slope) {
  // Max-plus relaxation over the 8 neighbours, sweeping forward then backward until nothing
  // moves: depth(p) >= depth(q) - max_slope * |p - q|. Only deepens, so nothing the support
  // cleared at rest touches it.
  const int nu = support.cells_u + 1, nv = support.cells_v + 1;
  const double straight = max_slope * support.cell_m, diagonal = straight * std::sqrt(2.0);
  auto at = [&](int i, int j) -> double& {
    return support.depth_m[static_cast<std::size_t>(j) * static_cast<std::size_t>(nu) +
                           static_cast<std::size_t>(i)];
  };
  auto relax = [&](int i, int j) {
    bool moved = false;
    double& here = at(i, j);
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if ((di == 0 && dj == 0) || i + di < 0 || j + dj < 0 || i + di >= nu || j + dj >= nv)
          continue;
        const double bound = at(i + di, j + dj) - (di != 0 && dj != 0 ? diagonal : straight);
        if (bound > here) {
          here = bound;
          moved = true;
        }
      }
    return moved;
  };
  for (bool moved = true; moved;) {
    moved = false;
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) moved |= relax(i, j);
    for (int j = nv - 1; j >= 0; --j)
      for (int i = nu - 1; i >= 0; --i) moved |= relax(i, j);
  }
}

SupportSurface support_under(const NodeArray& rest_position_m, const BoundarySurface& surface,
                             const Eigen::Vector3d& down, double cell_m, double margin_m,
                             double clearance_m, double max_slope) {
  if (!down.allFinite() || down.norm() == 0.0)
    throw std::invalid_argument("the support needs a direction of gravity, not zero");
  if (!(cell_m > 0.0) || !(margin_m >= 0.0) || !(clearance_m >= 0.0) || !(max_slope > 0.0))
    throw std::invalid_argument(
        "the support's cell and its steepest slope must be > 0 and its margin and clearance >= 0");
  if (surface.triangles.empty())
    throw std::invalid_argument("the support needs the organ's surface, which has no triangles");
  SupportSurface support;
  support.down = down.normalized();
  // Any unit vector across `down`, then the third by the cross product.
  const Eigen::Vector3d helper =
      std::abs(support.down.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  support.axis_u = (helper - helper.dot(support.down) * support.down).normalized();
  support.axis_v = support.down.cross(support.axis_u);

  double min_u = std::numeric_limits<double>::infinity(), max_u = -min_u;
  double min_v = min_u, max_v = -min_u, deepest = -min_u;
  for (NodeIndex n : surface.nodes) {
    const Eigen::Vector3d p = rest_position_m.at(n);
    min_u = std::min(min_u, p.dot(support.axis_u));
    max_u = std::max(max_u, p.dot(support.axis_u));
    min_v = std::min(min_v, p.dot(support.axis_v));
    max_v = std::max(max_v, p.dot(support.axis_v));
    deepest = std::max(deepest, p.dot(support.down));
  }
  support.floor_depth_m = deepest + clearance_m;
  support.cell_m = cell_m;
  support.origin_u_m = min_u - margin_m;
  support.origin_v_m = min_v - margin_m;
  support.cells_u =
      std::max(1, static_cast<int>(std::ceil((max_u - min_u + 2 * margin_m) / cell_m)));
  support.cells_v =
      std::max(1, static_cast<int>(std::ceil((max_v - min_v + 2 * margin_m) / cell_m)));
  // The deepest point of the surface over each cell (its clipped triangles' deepest corners);
  // none: NaN. A grid point takes the deepest of the cells around it, so that between grid points
  // the bilinear support lies at least as deep as everything above the cell: no node of the organ
  // at rest is inside it, however steep the underside (a bed sampled at grid points cut through
  // the liver's steep sides by up to 18 mm).
  const std::size_t cells_row = static_cast<std::size_t>(support.cells_u);
  std::vector<double> cell_deepest(cells_row * static_cast<std::size_t>(support.cells_v),
                                   std::numeric_limits<double>::quiet_NaN());
  std::vector<Eigen::Vector3d> polygon, clipped;
  for (const auto& triangle : surface.triangles) {
    Eigen::Vector3d q[3];  // u, v (in cells), depth of each corner
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d p = rest_position_m.at(surface.nodes[triangle[c]]);
      q[c] = {(p.dot(support.axis_u) - support.origin_u_m) / cell_m,
              (p.dot(support.axis_v) - support.origin_v_m) / cell_m, p.dot(support.down)};
    }
    const int i0 =
        std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int i1 = std::min(support.cells_u - 1,
                            static_cast<int>(std::floor(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int j0 =
        std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int j1 = std::min(support.cells_v - 1,
                            static_cast<int>(std::floor(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        // The triangle clipped to the cell (Sutherland–Hodgman against its four sides, depth
        // carried linearly): a linear depth is deepest at a corner of what is left.
        polygon.assign(q, q + 3);
        struct Side {
          int axis;
          double limit, sign;  // kept: sign · (coordinate − limit) >= 0
        };
        const std::array<Side, 4> sides{{{0, static_cast<double>(i), 1.0},
                                         {0, i + 1.0, -1.0},
                                         {1, static_cast<double>(j), 1.0},
                                         {1, j + 1.0, -1.0}}};
        for (const Side& side : sides) {
          clipped.clear();
          for (std::size_t k = 0; k < polygon.size(); ++k) {
            const Eigen::Vector3d& a = polygon[k];
            const Eigen::Vector3d& b = polygon[(k + 1) % polygon.size()];
            const double da = side.sign * (a[side.axis] - side.limit);
            const double db = side.sign * (b[side.axis] - side.limit);
            if (da >= 0.0) clipped.push_back(a);
            if ((da >= 0.0) != (db >= 0.0)) clipped.push_back(a + (b - a) * (da / (da - db)));
          }
          polygon.swap(clipped);
          if (polygon.empty()) break;
        }
        if (polygon.empty()) continue;
        double& deepest_here = cell_deepest[static_cast<std::size_t>(j) * cells_row + i];
        for (const Eigen::Vector3d& p : polygon)
          if (!(p.z() <= deepest_here)) deepest_here = p.z();  // NaN: the first
      }
  }
  const std::size_t row = static_cast<std::size_t>(support.cells_u) + 1;
  support.depth_m.assign(row * (static_cast<std::size_t>(support.cells_v) + 1),
                         support.floor_depth_m);
  for (int j = 0; j <= support.cells_v; ++j)
    for (int i = 0; i <= support.cells_u; ++i) {
      double deepest_around = std::numeric_limits<double>::quiet_NaN();
      for (int cj = j - 1; cj <= j; ++cj)
        for (int ci = i - 1; ci <= i; ++ci) {
          if (ci < 0 || cj < 0 || ci >= support.cells_u || cj >= support.cells_v) continue;
          const double d = cell_deepest[static_cast<std::size_t>(cj) * cells_row + ci];
          if (!std::isnan(d) && !(d <= deepest_around)) deepest_around = d;
        }
      if (!std::isnan(deepest_around))
        support.depth_m[static_cast<std::size_t>(j) * row + i] = deepest_around + clearance_m;
    }
  if (std::isfinite(max_slope)) limit_support_slope(support, max_slope);
  return support;
}

SupportSurface support_under(const TetMesh& mesh, const Eigen::Vector3d& down) {
  return support_under(mesh.rest_position_m, extract_surface(mesh), down);
}

SupportContact support_contact(const SupportSurface& support, const Eigen::Vector3d& position_m,
                               const Eigen::Vector3d& rest_position_m, double stiffness_n_per_m,
                               double friction_coefficient) {
  SupportContact contact;
  const SupportSurface::Depth under = support.depth_under(position_m);
  const double past = under.past_m;
  if (!(past > 0.0)) return contact;
  contact.touching = true;
  const double k = stiffness_n_per_m;
  // ½·k·(p/|∇|)² with ∇ = ∇(x·down − depth(u, v)): the penalty of the distance along the bed's
  // normal, so a node pressed along it meets k on a slope as on the flat (the depth along gravity
  // alone was (1 + slope²) times as stiff across the rim's walls). The slope's change within a
  // cell is left out of the force, as the bilinear bed's creases are.
  const Eigen::Vector3d gradient =
      support.down - under.slope_u * support.axis_u - under.slope_v * support.axis_v;
  const double steepness = gradient.squaredNorm();  // 1 + |∇depth|²
  const Eigen::Vector3d push = -k * past / steepness * gradient;
  contact.force_n = push;
  contact.energy_j = 0.5 * k * past * past / steepness;
  // The hold: the force −min(k·d, μ·P·(1 − d/R)) along the offset d across gravity, the gradient
  // of its potential for the push P as it is now.
  Eigen::Vector3d offset = position_m - rest_position_m;
  offset -= offset.dot(support.down) * support.down;
  const double d = offset.norm();
  const double limit_n = friction_coefficient * push.norm();
  const double reach = kSupportHoldReleaseM;
  if (!(d > 0.0) || !(limit_n > 0.0)) return contact;
  // Where the spring meets the fading limit: k·s = μ·P·(1 − s/R).
  const double held = limit_n / (k + limit_n / reach);
  if (d <= held) {
    contact.force_n -= k * offset;
    contact.energy_j += 0.5 * k * d * d;
    return contact;
  }
  const double beyond = std::min(d, reach);
  contact.energy_j += 0.5 * k * held * held +
                      limit_n * ((beyond - held) - (beyond * beyond - held * held) / (2.0 * reach));
  if (d < reach) contact.force_n -= limit_n * (1.0 - d / reach) / d * offset;
  return contact;
}

}  // namespace liversim
