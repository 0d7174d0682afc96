#pragma once
// The seed paper's three experiments (seed §4.2–4.4) on our model: creep of a marked point under a
// rising tension, the feedback force of a forceps pull at equilibrium, and the time to simulate
// the loaded liver at the seed's mesh sizes. Runners return data; the CLI writes CSV, plots and
// tables (docs/seed-experiments.md).

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model.h"
#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <iterator>
#include <optional>
#include <vector>

namespace liversim {

// The tension of the seed's experiments is "vertical": with the patient supine that is anterior
// (+z of the built-in liver), the outward normal at the marked point of the anterior face, so the
// load pulls the surface out of the organ.
inline const Eigen::Vector3d kSeedPullDirection = Eigen::Vector3d::UnitZ();

// A load spread over the free surface nodes within a radius of a point: weights are the grab's
// (lumped mass times the bump (1 − (d/r)²)², see grab.h), they sum to 1, and fixed nodes are left
// out (their share would go straight into the support).
struct LoadPatch {
  NodeIndex marked_node = 0;
  std::vector<NodeIndex> nodes;
  std::vector<double> weight;
};
// Throws std::invalid_argument when the marked node is outside the mesh or fixed, or the radius is
// negative or not finite.
LoadPatch make_load_patch(const TetMesh& mesh, const SimModel& model, NodeIndex marked_node,
                          double radius_m);

// Writes the patch's share of `total_force_n` into `loads` (one entry per patch node, in order;
// resized only when its size differs).
void spread_load(const LoadPatch& patch, const Eigen::Vector3d& total_force_n,
                 std::vector<PointLoad>& loads);

// ---- Accuracy (seed §4.2, Fig. 5–6): creep of a marked point under a rising tension ----------

struct CreepSettings {
  double peak_force_n = 0.63;  // the seed's
  // The force rises linearly from 0 at t = 0 to the peak at ramp_time_s, then is held until
  // duration_s (the seed gives no rate).
  double ramp_time_s = 2.0;
  double duration_s = 4.0;
  double sample_interval_s = 0.01;  // one advance() per sample; the load is updated per sample
  double load_radius_m = 0.02;
  Eigen::Vector3d direction = kSeedPullDirection;  // unit vector
  std::optional<NodeIndex> marked_node;            // default: anterior_marked_node
};

// The tension at time t: linear rise, then held.
double creep_force_n(const CreepSettings& settings, double time_s);

struct CreepResult {
  LoadPatch patch;
  // Samples at t = 0 and after every sample interval.
  std::vector<double> time_s;
  std::vector<double> force_n;                     // applied total tension at that time
  std::vector<double> displacement_mm;             // |u| of the marked point
  std::vector<double> displacement_along_load_mm;  // u · direction
  // Over the ramp, per sample interval k (from sample k−1 to k): the force at its end, and the
  // ratio of displacement change to force change (incremental compliance, mm/N) and of
  // displacement to force (secant compliance, mm/N); both use |u|.
  std::vector<double> ratio_force_n;
  std::vector<double> incremental_ratio_mm_per_n;
  std::vector<double> secant_ratio_mm_per_n;
  StepReport steps;
  double wall_time_s = 0.0;
};

// Throws std::invalid_argument naming the bad setting; std::runtime_error when the motion stops
// being finite.
CreepResult run_creep_experiment(const TetMesh& mesh, const SimModel& model,
                                 const CreepSettings& settings);

// ---- Fidelity (seed §4.3, Fig. 7): feedback force of a forceps pull at equilibrium -------------

inline constexpr double kSeedPullForcesN[] = {0.93, 1.65, 2.96};

// How the pull reaches the tissue: as point loads spread over the patch, or through the forceps
// (tools.h): closed on the marked point at rest, shaft along the pull, and held by a hand that
// pulls with the given force (the tool is moved before every 1 ms interval so that its hold pulls
// with exactly that force: a massless handle under a constant force).
enum class PullAttachment { load_patch, forceps };

struct PullSettings {
  std::vector<double> forces_n{std::begin(kSeedPullForcesN), std::end(kSeedPullForcesN)};
  Eigen::Vector3d direction = kSeedPullDirection;  // unit vector
  double load_radius_m = 0.02;                     // the forceps' grabbed patch
  PullAttachment attachment = PullAttachment::load_patch;
  double forceps_stiffness_n_per_m = 2000.0;  // the forceps' hold, all nodes together
  // The force rises linearly over this time (less ringing than a step; equilibrium is the same).
  double ramp_time_s = 0.2;
  // Settled: the summed magnitude of the net nodal forces (internal + load) over all free nodes is
  // at most residual_tolerance × the applied force at every check over settle_window_s.
  double residual_tolerance = 1e-3;
  double check_interval_s = 0.01;
  double settle_window_s = 0.1;
  double max_time_s = 30.0;  // give up (settled = false) after this much simulated time
  std::optional<NodeIndex> marked_node;
  bool record_history = true;  // feedback force at every check, for the plot
};

struct PullCase {
  double applied_force_n = 0.0;
  Eigen::Vector3d applied_n = Eigen::Vector3d::Zero();
  // −Σ over the grabbed nodes of their internal (elastic) force: what the tissue pushes back on
  // the forceps with.
  Eigen::Vector3d feedback_n = Eigen::Vector3d::Zero();
  std::size_t held_nodes = 0;         // nodes the load or the forceps' hold acts on
  double relative_error = 0.0;        // |feedback − applied| / |applied|
  double residual_l1_n = 0.0;         // Σ_free |internal + load| at the end
  double bound_relative_error = 0.0;  // residual_l1_n / |applied| ≥ relative_error
  bool settled = false;
  double settle_time_s = 0.0;    // simulated time at the end
  double displacement_mm = 0.0;  // |u| of the marked point at the end
  std::vector<double> history_time_s;
  std::vector<double> history_feedback_along_load_n;  // feedback · direction at each check
  StepReport steps;
  double wall_time_s = 0.0;
};

struct PullResult {
  LoadPatch patch;
  std::vector<PullCase> cases;  // one per force, each from rest
};

// Needs an elastic model (a viscous model's internal force is not its elastic force).
// Throws std::invalid_argument naming the bad setting.
PullResult run_pull_experiment(const TetMesh& mesh, const SimModel& model,
                               const PullSettings& settings);

// ---- Real time (seed §4.4, Table 1) -------------------------------------------------------------

// The seed's Table 1 (unit not stated; read as ms). [3]: conical-spring model; [14]: FEM with
// optimised implicit Euler.
struct SeedTable1Row {
  int tets;
  double conical_spring_deform_ms, conical_spring_cut_ms;
  double implicit_fem_deform_ms, implicit_fem_cut_ms;
  double seed_deform_ms, seed_cut_ms;
};
inline constexpr SeedTable1Row kSeedTable1[] = {
    {3841, 452.9, 668.3, 349.4, 789.1, 174.5, 469.1},
    {5406, 681.6, 851.2, 425.6, 993.6, 216.9, 523.5},
    {7312, 829.8, 1032.7, 501.3, 1235.4, 323.2, 752.9},
    {9371, 997.4, 1189.3, 610.9, 1289.2, 497.8, 918.1},
    {10583, 1283.9, 1392.5, 798.3, 1569.8, 581.3, 997.6},
};

struct TimingSettings {
  double force_n = 0.75;     // the seed's
  double frame_s = 0.002;    // the seed's Δt: one advance() call per frame
  double simulated_s = 1.0;  // deformation time = wall time to simulate this much
  double load_radius_m = 0.02;
  Eigen::Vector3d direction = kSeedPullDirection;
  std::shared_ptr<WorkerPool> workers;  // threads of the force loops (null: the calling thread)
};

struct TimingCase {
  std::size_t tet_count = 0, node_count = 0;
  int frames = 0;
  double deformation_wall_s = 0.0;  // wall time of the frames' advance() calls only
  double displacement_mm = 0.0;     // |u| of the marked point at the end
  StepReport steps;                 // accumulated over the frames
  double stable_step_at_rest_s = 0.0;

  double wall_per_frame_s() const { return deformation_wall_s / frames; }
  double wall_per_substep_s() const { return deformation_wall_s / steps.substeps; }
  double substeps_per_wall_s() const { return steps.substeps / deformation_wall_s; }
  double frames_per_wall_s() const { return frames / deformation_wall_s; }
  // Simulated seconds per wall second (1 = real time).
  double real_time_factor(const TimingSettings& settings) const {
    return frames * settings.frame_s / deformation_wall_s;
  }
};

// The loaded liver from rest: the force on the patch at the marked point from t = 0, advanced in
// frames of frame_s until simulated_s. Throws std::invalid_argument naming a bad setting and
// std::runtime_error when the motion stops being finite.
TimingCase run_timing_case(const TetMesh& mesh, const SimModel& model,
                           const TimingSettings& settings);

}  // namespace liversim
