#include "liversim/studies/seed_experiments.h"

#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/interaction/grab.h"
#include "liversim/interaction/tools.h"
#include "liversim/meshing/default_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace liversim {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void require_positive(double value, const char* what) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(what) + " = " + std::to_string(value) +
                                " is invalid: expected a finite value > 0");
}

Eigen::Vector3d unit_direction(const Eigen::Vector3d& direction) {
  const double length = direction.norm();
  if (!std::isfinite(length) || length == 0.0)
    throw std::invalid_argument("the load direction must be a finite, non-zero vector");
  return direction / length;
}

NodeIndex marked_node_or_default(const TetMesh& mesh, const std::optional<NodeIndex>& node) {
  return node ? *node : anterior_marked_node(mesh);
}

// Number of equal intervals of length `interval_s` in `total_s`; the tolerance keeps round-off
// (4 / 0.01 = 399.99…) from adding an interval.
int interval_count(double total_s, double interval_s) {
  return std::max(1, static_cast<int>(std::ceil(total_s / interval_s * (1.0 - 1e-12))));
}

void require_finite(const SimState& state, NodeIndex node) {
  if (!state.position_m.at(node).allFinite())
    throw std::runtime_error("the simulation diverged at t = " + std::to_string(state.time_s) +
                             " s (non-finite position)");
}

// The forceps of the pull experiment: shaft along the pull, jaws closed on `point`.
Tool pull_forceps(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) {
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 0.0;
  forceps.pose.orientation =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction);
  forceps.pose.origin_m = point - (forceps_grasp_point_m(forceps) - forceps.pose.origin_m);
  return forceps;
}

// Moves the tool so that the springs of its hold pull the tissue with `pull_n` at `position`:
// a translation δ changes their pull by (Σk)·δ.
void hold_with_force(const ForcepsGrasp& grasp, const Eigen::Vector3d& pull_n,
                     const NodeArray& position, Tool& forceps) {
  Eigen::Vector3d current = Eigen::Vector3d::Zero();
  double total_stiffness = 0.0;
  for (std::size_t i = 0; i < grasp.nodes.size(); ++i) {
    const Eigen::Vector3d anchor = forceps.pose.to_scene(grasp.offset_in_tool_m[i]);
    current += grasp.stiffness_n_per_m[i] * (anchor - position.at(grasp.nodes[i]));
    total_stiffness += grasp.stiffness_n_per_m[i];
  }
  forceps.pose.origin_m += (pull_n - current) / total_stiffness;
}

// Net force (internal + load) on the free nodes, summed in magnitude, and the feedback force:
// minus the internal force summed over the patch. `internal_n` and `scratch` are sized for the
// model; nothing is allocated.
struct Balance {
  double residual_l1_n = 0.0;
  Eigen::Vector3d feedback_n = Eigen::Vector3d::Zero();
};
Balance force_balance(const SimModel& model, const NodeArray& position, const StepInputs& pull,
                      ForceScratch& scratch, NodeArray& internal_n) {
  compute_elastic_forces(model, position, scratch, internal_n);
  Balance balance;
  for (const PointLoad& load : pull.point_loads) balance.feedback_n -= internal_n.at(load.node);
  for (const NodeSpring& spring : pull.springs) balance.feedback_n -= internal_n.at(spring.node);
  add_external_forces(pull, position, internal_n);
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (!model.is_fixed[n]) balance.residual_l1_n += internal_n.at(n).norm();
  return balance;
}

}  // namespace

LoadPatch make_load_patch(const TetMesh& mesh, const SimModel& model, NodeIndex marked_node,
                          double radius_m) {
  if (marked_node < 0 || static_cast<std::size_t>(marked_node) >= model.node_count)
    throw std::invalid_argument("node " + std::to_string(marked_node) + " is outside the mesh (" +
                                std::to_string(model.node_count) + " nodes, numbered from 0)");
  if (model.is_fixed[marked_node])
    throw std::invalid_argument("node " + std::to_string(marked_node) + " is a fixed node");
  if (!std::isfinite(radius_m) || radius_m < 0.0)
    throw std::invalid_argument("load radius " + std::to_string(radius_m) +
                                " m is invalid: expected a finite value >= 0");
  const Grab grab = grab_surface(extract_surface(mesh), mesh.rest_position_m, model.lumped_mass_kg,
                                 mesh.rest_position_m.at(marked_node), radius_m, 1.0);
  LoadPatch patch;
  patch.marked_node = marked_node;
  double weight_sum = 0.0;
  for (std::size_t i = 0; i < grab.nodes.size(); ++i) {
    if (model.is_fixed[grab.nodes[i]]) continue;
    patch.nodes.push_back(grab.nodes[i]);
    patch.weight.push_back(grab.stiffness_n_per_m[i]);
    weight_sum += grab.stiffness_n_per_m[i];
  }
  if (patch.nodes.empty()) {  // a radius below the node spacing: the marked node alone
    patch.nodes.push_back(marked_node);
    patch.weight.push_back(1.0);
    weight_sum = 1.0;
  }
  for (double& w : patch.weight) w /= weight_sum;
  return patch;
}

void spread_load(const LoadPatch& patch, const Eigen::Vector3d& total_force_n,
                 std::vector<PointLoad>& loads) {
  if (loads.size() != patch.nodes.size()) loads.resize(patch.nodes.size());
  for (std::size_t i = 0; i < patch.nodes.size(); ++i)
    loads[i] = {patch.nodes[i], patch.weight[i] * total_force_n};
}

double creep_force_n(const CreepSettings& settings, double time_s) {
  if (time_s <= 0.0) return 0.0;
  return settings.peak_force_n * std::min(1.0, time_s / settings.ramp_time_s);
}

CreepResult run_creep_experiment(const TetMesh& mesh, const SimModel& model,
                                 const CreepSettings& settings) {
  if (!std::isfinite(settings.peak_force_n) || settings.peak_force_n <= 0.0)
    throw std::invalid_argument("peak force " + std::to_string(settings.peak_force_n) +
                                " N is invalid: expected a finite value > 0");
  require_positive(settings.ramp_time_s, "ramp time (s)");
  require_positive(settings.sample_interval_s, "sample interval (s)");
  if (!std::isfinite(settings.duration_s) || settings.duration_s < settings.sample_interval_s)
    throw std::invalid_argument("duration " + std::to_string(settings.duration_s) +
                                " s is invalid: expected at least the sample interval");
  const Eigen::Vector3d direction = unit_direction(settings.direction);

  CreepResult result;
  result.patch = make_load_patch(mesh, model, marked_node_or_default(mesh, settings.marked_node),
                                 settings.load_radius_m);
  const NodeIndex node = result.patch.marked_node;
  const Eigen::Vector3d rest = model.rest_position_m.at(node);
  const int samples = interval_count(settings.duration_s, settings.sample_interval_s);
  for (auto* series : {&result.time_s, &result.force_n, &result.displacement_mm,
                       &result.displacement_along_load_mm, &result.ratio_force_n,
                       &result.incremental_ratio_mm_per_n, &result.secant_ratio_mm_per_n})
    series->reserve(samples + 1);

  SimState state = make_rest_state(model);
  std::vector<PointLoad> loads;
  spread_load(result.patch, Eigen::Vector3d::Zero(), loads);
  auto record = [&](double force_n) {
    const Eigen::Vector3d u_mm = 1e3 * (state.position_m.at(node) - rest);
    result.time_s.push_back(state.time_s);
    result.force_n.push_back(force_n);
    result.displacement_mm.push_back(u_mm.norm());
    result.displacement_along_load_mm.push_back(u_mm.dot(direction));
  };
  record(0.0);
  const auto wall_start = Clock::now();
  for (int k = 1; k <= samples; ++k) {
    const double t0_s = state.time_s;
    const double t1_s = std::min(settings.duration_s, k * settings.sample_interval_s);
    // The force at the interval's midpoint: the same impulse as the linear ramp over it.
    spread_load(result.patch, creep_force_n(settings, 0.5 * (t0_s + t1_s)) * direction, loads);
    accumulate(result.steps, advance(model, state, StepInputs{loads, {}}, t1_s - t0_s));
    require_finite(state, node);
    const double force_n = creep_force_n(settings, t1_s);
    record(force_n);
    if (t1_s <= settings.ramp_time_s * (1.0 + 1e-12)) {
      const std::size_t i = result.time_s.size() - 1;
      const double force_change_n = force_n - result.force_n[i - 1];
      result.ratio_force_n.push_back(force_n);
      result.incremental_ratio_mm_per_n.push_back(
          (result.displacement_mm[i] - result.displacement_mm[i - 1]) / force_change_n);
      result.secant_ratio_mm_per_n.push_back(result.displacement_mm[i] / force_n);
    }
  }
  result.wall_time_s = seconds_since(wall_start);
  return result;
}

PullResult run_pull_experiment(const TetMesh& mesh, const SimModel& model,
                               const PullSettings& settings) {
  if (model.effects.viscous)
    throw std::invalid_argument(
        "the pull experiment needs an elastic model: a viscous model's internal force is not its "
        "elastic force");
  if (settings.forces_n.empty()) throw std::invalid_argument("no pull force given");
  for (double f : settings.forces_n) require_positive(f, "pull force (N)");
  require_positive(settings.ramp_time_s, "ramp time (s)");
  require_positive(settings.residual_tolerance, "residual tolerance");
  require_positive(settings.check_interval_s, "check interval (s)");
  if (!std::isfinite(settings.settle_window_s) || settings.settle_window_s < 0.0)
    throw std::invalid_argument("settle window must be a finite value >= 0");
  require_positive(settings.max_time_s, "maximum simulated time (s)");
  const Eigen::Vector3d direction = unit_direction(settings.direction);

  PullResult result;
  result.patch = make_load_patch(mesh, model, marked_node_or_default(mesh, settings.marked_node),
                                 settings.load_radius_m);
  const NodeIndex node = result.patch.marked_node;
  const Eigen::Vector3d rest = model.rest_position_m.at(node);
  const int max_checks = interval_count(settings.max_time_s, settings.check_interval_s);

  ForceScratch scratch = make_force_scratch(model);
  NodeArray internal_n;
  internal_n.resize(model.node_count);
  require_positive(settings.forceps_stiffness_n_per_m, "forceps stiffness (N/m)");
  const bool forceps = settings.attachment == PullAttachment::forceps;
  const BoundarySurface surface = forceps ? extract_surface(mesh) : BoundarySurface{};
  GraspSettings hold;
  hold.radius_m = settings.load_radius_m;
  hold.total_stiffness_n_per_m = settings.forceps_stiffness_n_per_m;
  std::vector<PointLoad> loads;
  for (double force_n : settings.forces_n) {
    PullCase pull;
    pull.applied_force_n = force_n;
    pull.applied_n = force_n * direction;
    if (settings.record_history) {
      pull.history_time_s.reserve(max_checks + 1);
      pull.history_feedback_along_load_n.reserve(max_checks + 1);
      pull.history_time_s.push_back(0.0);
      pull.history_feedback_along_load_n.push_back(0.0);
    }
    auto load_at = [&](double t_s) { return std::min(1.0, t_s / settings.ramp_time_s); };
    SimState state = make_rest_state(model);
    std::optional<ToolInteraction> hand;
    Tool tool;
    if (forceps) {
      hand.emplace(model, surface, ContactSettings{}, hold);
      tool = pull_forceps(rest, direction);
      hand->update(tool, state.position_m);
      if (!hand->grasping())
        throw std::runtime_error("the forceps closed on no tissue at node " + std::to_string(node));
      pull.held_nodes = hand->grasp()->nodes.size();
    } else {
      pull.held_nodes = result.patch.nodes.size();
    }
    // The pull at time t, as the step's inputs (the forceps moved to pull with it).
    auto inputs_at = [&](double t_s) -> StepInputs {
      const Eigen::Vector3d pull_n = load_at(t_s) * pull.applied_n;
      if (!forceps) {
        spread_load(result.patch, pull_n, loads);
        return {loads, {}};
      }
      hold_with_force(*hand->grasp(), pull_n, state.position_m, tool);
      return {{}, hand->update(tool, state.position_m)};
    };
    double window_start_s = -1.0;  // first check of the current run of passing checks
    Balance balance;
    const auto wall_start = Clock::now();
    for (int k = 1; k <= max_checks; ++k) {
      const double t0_s = state.time_s;
      const double t1_s = k * settings.check_interval_s;
      if (forceps) {  // the hand follows the tissue every millisecond
        const int substeps = interval_count(t1_s - t0_s, 1e-3);
        for (int s = 0; s < substeps; ++s) {
          const double a_s = t0_s + (t1_s - t0_s) * s / substeps;
          const double b_s = t0_s + (t1_s - t0_s) * (s + 1) / substeps;
          accumulate(pull.steps, advance(model, state, inputs_at(0.5 * (a_s + b_s)), b_s - a_s));
        }
      } else {
        accumulate(pull.steps, advance(model, state, inputs_at(0.5 * (t0_s + t1_s)), t1_s - t0_s));
      }
      require_finite(state, node);
      balance = force_balance(model, state.position_m, inputs_at(t1_s), scratch, internal_n);
      if (settings.record_history) {
        pull.history_time_s.push_back(t1_s);
        pull.history_feedback_along_load_n.push_back(balance.feedback_n.dot(direction));
      }
      const bool passes = t1_s >= settings.ramp_time_s &&
                          balance.residual_l1_n <= settings.residual_tolerance * force_n;
      if (!passes) {
        window_start_s = -1.0;
        continue;
      }
      if (window_start_s < 0.0) window_start_s = t1_s;
      // Small slack: the window is a whole number of check intervals summed in floating point.
      if (t1_s - window_start_s >= settings.settle_window_s - 1e-9) {
        pull.settled = true;
        break;
      }
    }
    pull.wall_time_s = seconds_since(wall_start);
    pull.settle_time_s = state.time_s;
    pull.feedback_n = balance.feedback_n;
    pull.residual_l1_n = balance.residual_l1_n;
    pull.relative_error = (pull.feedback_n - pull.applied_n).norm() / force_n;
    pull.bound_relative_error = pull.residual_l1_n / force_n;
    pull.displacement_mm = 1e3 * (state.position_m.at(node) - rest).norm();
    result.cases.push_back(std::move(pull));
  }
  return result;
}

TimingCase run_timing_case(const TetMesh& mesh, const SimModel& model,
                           const TimingSettings& settings) {
  require_positive(settings.force_n, "force (N)");
  require_positive(settings.frame_s, "frame time (s)");
  if (!std::isfinite(settings.simulated_s) || settings.simulated_s < settings.frame_s)
    throw std::invalid_argument("simulated time must be at least one frame");
  const Eigen::Vector3d direction = unit_direction(settings.direction);

  const LoadPatch patch =
      make_load_patch(mesh, model, anterior_marked_node(mesh), settings.load_radius_m);
  std::vector<PointLoad> loads;
  spread_load(patch, settings.force_n * direction, loads);
  const StepInputs inputs{loads, {}};

  TimingCase timing;
  timing.tet_count = model.tet_count;
  timing.node_count = model.node_count;
  timing.stable_step_at_rest_s = model.stable_time_step_s;
  timing.frames = interval_count(settings.simulated_s, settings.frame_s);
  SimState state = make_rest_state(model, settings.workers);
  const auto wall_start = Clock::now();
  for (int frame = 0; frame < timing.frames; ++frame)
    accumulate(timing.steps, advance(model, state, inputs, settings.frame_s));
  timing.deformation_wall_s = seconds_since(wall_start);
  require_finite(state, patch.marked_node);
  timing.displacement_mm =
      1e3 *
      (state.position_m.at(patch.marked_node) - model.rest_position_m.at(patch.marked_node)).norm();
  return timing;
}

}  // namespace liversim
