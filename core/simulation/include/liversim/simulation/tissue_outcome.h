#pragma once
// What a session's simulation does to the tissue, followed while it runs (on the simulation
// thread, once per published cycle, allocating nothing): which elements were ever strained past
// the damage strains, how far a retraction point was lifted, what cuts took out. Grading these
// (sessions/outcome_metrics.h) happens after the session, off the simulation thread.

#include "liversim/engine/model.h"
#include "liversim/engine/tet_mesh.h"
#include "liversim/interaction/cutting.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace liversim {

// An element is damaged once a principal stretch exceeds 1 + tension strain (tissue tears in
// tension: the parenchyma's failure strain is of this order) or falls below 1 − compression strain
// (it crushes only at larger strains). Assumed values, not fitted to data; a scenario's task may
// set its own.
struct DamageStrains {
  double tension_strain = 0.3;
  double compression_strain = 0.5;
};

// Whether a principal stretch of the deformation gradient leaves [1 − compression, 1 + tension].
bool strained_beyond(const Eigen::Matrix3d& deformation_gradient, double tension_strain,
                     double compression_strain);

// A free body as a specimen: its elements at rest (corners), their regions and faces made by cuts
// (bit c: the face opposite corner c), what the specimen's measure needs
// (sessions/outcome_metrics.h) once the body is gone from the model.
struct Specimen {
  std::vector<std::array<Eigen::Vector3d, 4>> rest_corners_m;
  std::vector<std::int32_t> region;
  std::vector<std::uint8_t> cut_face_mask;
  double rest_volume_m3 = 0.0;
};
Specimen specimen_of(const SimModel& model, std::span<const TetIndex> elements);

// Follows a session's simulation for what its end alone cannot tell: which tissue was ever
// strained past the damage strain, how far the retraction point was lifted, what cuts took out.
// Observed once per published simulation cycle (not per step); observe() allocates nothing.
class OutcomeTracker {
 public:
  // `lift_point_m`: the retraction task's grasp point (rest), followed through the node nearest to
  // it; none for other tasks.
  OutcomeTracker(const SimModel& model, std::optional<Eigen::Vector3d> lift_point_m,
                 DamageStrains damage = {});

  void observe(const SimModel& model, const NodeArray& position_m);
  // After a cut replaced the model: damage follows each element's origin; the node followed for
  // the lift, its first copy; the resected volume adds up.
  void carry_over(const CutResult& cut);
  // A free body of `model` taken out of the field (`removal`: take_out_body's result): kept as a
  // specimen, then carried over as a cut.
  void take_out(const SimModel& model, std::span<const TetIndex> body, const CutResult& removal);

  // Rest volume of the organ's elements that were ever damaged (pieces cut free, taken out or
  // not, no longer count).
  double damaged_volume_m3(const SimModel& model) const;
  double resected_volume_m3() const { return resected_volume_m3_; }
  double largest_lift_m() const { return largest_lift_m_; }
  // The free bodies taken out so far, in order.
  const std::vector<Specimen>& specimens_taken_out() const { return specimens_; }
  const DamageStrains& damage() const { return damage_; }
  // Per element of the current model: ever damaged.
  std::span<const std::uint8_t> damaged() const { return damaged_; }

 private:
  DamageStrains damage_;
  std::vector<std::uint8_t> damaged_;
  double resected_volume_m3_ = 0.0;
  std::optional<NodeIndex> lift_node_;
  double largest_lift_m_ = 0.0;
  std::vector<Specimen> specimens_;
};

// A session's outcome tracking as it stands: the tracker, the model its elements belong to (the
// newest it observed), and the model when tracking began.
struct OutcomeTracking {
  OutcomeTracker tracker;
  std::shared_ptr<const SimModel> initial_model;
  std::shared_ptr<const SimModel> model;
};

}  // namespace liversim
