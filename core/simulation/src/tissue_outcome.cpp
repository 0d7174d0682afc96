#include "liversim/simulation/tissue_outcome.h"

#include "liversim/engine/forces.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <limits>

namespace liversim {

bool strained_beyond(const Eigen::Matrix3d& deformation_gradient, double tension_strain,
                     double compression_strain) {
  const Eigen::Matrix3d c = deformation_gradient.transpose() * deformation_gradient;
  const double largest = (1.0 + tension_strain) * (1.0 + tension_strain);
  const double smallest = (1.0 - compression_strain) * (1.0 - compression_strain);
  // |λ_k(C) − 1| ≤ ‖C − I‖_F: below both margins every principal stretch is inside the range
  // (the cheap test that clears nearly every element without an eigen-decomposition).
  if ((c - Eigen::Matrix3d::Identity()).norm() < std::min(largest - 1.0, 1.0 - smallest))
    return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(c, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d squared_stretch = solver.eigenvalues();  // ascending
  return squared_stretch[2] > largest || squared_stretch[0] < smallest;
}

OutcomeTracker::OutcomeTracker(const SimModel& model, std::optional<Eigen::Vector3d> lift_point_m,
                               DamageStrains damage)
    : damage_(damage), damaged_(model.tet_count, 0) {
  if (lift_point_m && model.node_count > 0) {
    NodeIndex nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < model.node_count; ++i) {
      const double d = (model.rest_position_m.at(i) - *lift_point_m).squaredNorm();
      if (d < best) best = d, nearest = static_cast<NodeIndex>(i);
    }
    lift_node_ = nearest;
  }
}

void OutcomeTracker::observe(const SimModel& model, const NodeArray& position_m) {
  for (std::size_t e = 0; e < model.tet_count; ++e)
    if (!damaged_[e] && strained_beyond(deformation_gradient(model, position_m, e),
                                        damage_.tension_strain, damage_.compression_strain))
      damaged_[e] = 1;
  if (lift_node_) {
    const auto i = static_cast<std::size_t>(*lift_node_);
    largest_lift_m_ =
        std::max(largest_lift_m_, (position_m.at(i) - model.rest_position_m.at(i)).norm());
  }
}

void OutcomeTracker::carry_over(const CutResult& cut) {
  if (!cut.cut()) return;
  std::vector<std::uint8_t> damaged(cut.element_origin.size(), 0);
  for (std::size_t e = 0; e < damaged.size(); ++e)
    damaged[e] = damaged_[static_cast<std::size_t>(cut.element_origin[e])];
  damaged_ = std::move(damaged);
  resected_volume_m3_ += cut.report.resected_volume_m3;
  if (lift_node_) {
    std::optional<NodeIndex> copy;
    for (std::size_t i = 0; i < cut.node_origin.size() && !copy; ++i)
      if (cut.node_origin[i] == *lift_node_) copy = static_cast<NodeIndex>(i);
    lift_node_ = copy;  // none: the point went with a piece that was taken out
  }
}

Specimen specimen_of(const SimModel& model, std::span<const TetIndex> elements) {
  Specimen specimen;
  specimen.rest_corners_m.reserve(elements.size());
  for (const TetIndex e : elements) {
    std::array<Eigen::Vector3d, 4> corners;
    for (int c = 0; c < 4; ++c) corners[c] = model.rest_position_m.at(model.corner[c][e]);
    specimen.rest_corners_m.push_back(corners);
    specimen.region.push_back(model.region[e]);
    specimen.cut_face_mask.push_back(model.cut_face_mask.empty() ? 0 : model.cut_face_mask[e]);
    specimen.rest_volume_m3 += model.rest_volume_m3[e];
  }
  return specimen;
}

void OutcomeTracker::take_out(const SimModel& model, std::span<const TetIndex> body,
                              const CutResult& removal) {
  specimens_.push_back(specimen_of(model, body));
  carry_over(removal);
}

double OutcomeTracker::damaged_volume_m3(const SimModel& model) const {
  const std::vector<std::uint8_t> organ = organ_elements(model);  // not in specimens
  double volume = 0.0;
  for (std::size_t e = 0; e < model.tet_count && e < damaged_.size(); ++e)
    if (damaged_[e] && organ[e]) volume += model.rest_volume_m3[e];
  return volume;
}

}  // namespace liversim
