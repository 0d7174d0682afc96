#include "liversim/simulation/realtime_simulation.h"

#include "liversim/engine/integrator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace liversim {
namespace {

SimulationSnapshot snapshot_of(const SimState& state, std::shared_ptr<const SimModel> model) {
  SimulationSnapshot snapshot;
  snapshot.position_m = state.position_m;
  snapshot.time_s = state.time_s;
  snapshot.step_count = state.step_count;
  snapshot.model = std::move(model);
  return snapshot;
}

// Whole steps that fit in `cycle_s`, at least one: a step longer than a cycle is still taken.
int steps_per_cycle(double cycle_s, double step_s) {
  if (!(cycle_s > 0.0) || !std::isfinite(cycle_s)) return 1;
  return static_cast<int>(std::clamp(std::ceil(cycle_s / step_s - 1e-9), 1.0, 1e6));
}

}  // namespace

StepAccumulator::StepAccumulator(double step_s, int max_steps)
    : step_s_(step_s), max_steps_(max_steps) {
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("real-time step must be a finite value > 0 s, not " +
                                std::to_string(step_s));
  if (max_steps < 1)
    throw std::invalid_argument("real-time step cap must be at least 1 step per cycle, not " +
                                std::to_string(max_steps));
}

StepAccumulator::Due StepAccumulator::add(double elapsed_s) {
  if (std::isfinite(elapsed_s) && elapsed_s > 0.0) backlog_s_ += elapsed_s;
  // A relative slack of 1e-9 step keeps wall times that sum to a whole step in floating point
  // (10 × 0.1 ms) from coming out one step short.
  const double whole = std::floor(backlog_s_ / step_s_ + 1e-9);
  Due due;
  if (whole > static_cast<double>(max_steps_)) {
    due.steps = max_steps_;
    due.capped = true;
    due.dropped_s = (whole - max_steps_) * step_s_;
  } else {
    due.steps = static_cast<int>(whole);
  }
  backlog_s_ = std::max(0.0, backlog_s_ - whole * step_s_);
  return due;
}

// Elements longer than this around a cutting blade are bisected (CuttingSettings::refine_edge_m).
constexpr double kBladeRefineEdgeM = 0.008;
// The stroke gains an instant (and the tissue a cut update) each time the edge has moved this far:
// a quarter of the thinnest part a cut may make (CuttingSettings::min_part_height_m), so the
// crack's front still moves in steps finer than any element, at a fifth of the updates a tenth of
// a millimetre made (each update is a pass over the elements on the simulation's thread).
constexpr double kStrokeInstantM = 0.0005;

double realtime_step_s(const SimModel& model) {
  return model.integrator.step_s > 0.0 ? model.integrator.step_s
                                       : kLoopStepFraction * model.stable_time_step_s;
}

double legacy_loop_step_s(const SimModel& model) {
  return model.integrator.step_s > 0.0 ? model.integrator.step_s : model.stable_time_step_s;
}

RealtimeSimulation::RealtimeSimulation(std::shared_ptr<const SimModel> model,
                                       SimState initial_state)
    : RealtimeSimulation(std::move(model), std::move(initial_state), Options{}) {}

RealtimeSimulation::RealtimeSimulation(std::shared_ptr<const SimModel> model,
                                       SimState initial_state, Options options)
    : model_(std::move(model)),
      state_(std::move(initial_state)),
      options_(options),
      step_s_(options.loop_step_s > 0.0 ? options.loop_step_s : realtime_step_s(*model_)),
      max_steps_per_cycle_(options.max_steps_per_cycle > 0
                               ? options.max_steps_per_cycle
                               : steps_per_cycle(options.cycle_s, step_s_)),
      snapshots_(snapshot_of(state_, model_)),
      integrator_kind_(model_->integrator.kind) {
  simulated_time_s_.store(state_.time_s, std::memory_order_relaxed);
  if (!(step_s_ > 0.0) || !std::isfinite(step_s_))
    throw std::invalid_argument("the model has no usable time step (" + std::to_string(step_s_) +
                                " s)");
  pending_springs_.reserve(options_.spring_capacity);
  active_springs_.reserve(options_.spring_capacity);
  checkpoint_ = make_checkpoint(*model_);
  for (std::size_t n = 0; n < model_->node_count; ++n)
    field_m_.extend(model_->rest_position_m.at(n));
  field_m_.min().array() -= kFieldMarginM;
  field_m_.max().array() += kFieldMarginM;
  free_bodies_ = free_bodies(*model_);
  if (!free_bodies_.empty())
    body_contact_ = BodyContact(*model_, boundary_surface(*model_), free_bodies_);
  step_springs_.reserve(options_.spring_capacity + body_contact_.max_springs());
}

RealtimeSimulation::~RealtimeSimulation() {
  stop();
}

void RealtimeSimulation::start() {
  if (thread_.joinable()) return;
  stop_requested_ = false;
  give_up_cycle_ = false;
  loop_ended_ = false;
  thread_ = std::thread([this] {
    run();
    loop_ended_ = true;
  });
}

void RealtimeSimulation::stop() {
  stop_requested_ = true;
  if (!thread_.joinable()) return;
  // A cycle ends within milliseconds and is kept whole (a session's replay takes whole cycles).
  // One that has not ended after kGiveUpCycleAfterS (steps fallen to microseconds: a crawl that
  // held `record` past SIGTERM for minutes) is given up where its step under way ends; a replay
  // then takes that last cycle further than the live loop did.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(kGiveUpCycleAfterS);
  while (!loop_ended_.load() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  give_up_cycle_ = true;
  thread_.join();
}

void RealtimeSimulation::enable_tools(const BoundarySurface& surface, ContactSettings contact,
                                      GraspSettings grasp) {
  if (running()) throw std::logic_error("enable_tools: stop the simulation first");
  for (HandInLoop& hand : hands_) hand.tools.emplace(*model_, surface, contact, grasp);
  tools_hold_model_boundary_ = false;  // the caller's surface (the scene's drawn one)
  contact_settings_ = contact;
  grasp_settings_ = grasp;
  // The set springs and at most two per surface node from each hand's tool (hold and contact):
  // no reallocation in a step.
  step_springs_.reserve(options_.spring_capacity + 2 * hands_.size() * surface.nodes.size() +
                        body_contact_.max_springs());
}

void RealtimeSimulation::enable_cutting(CuttingSettings settings) {
  if (running()) throw std::logic_error("enable_cutting: stop the simulation first");
  if (!tools_enabled()) throw std::logic_error("enable_cutting: enable the tools first");
  if (auto problem = validate(settings)) throw std::invalid_argument(*problem);
  cutting_ = settings;
}

void RealtimeSimulation::cut_with_scalpel(HandInLoop& hand) {
  const Tool& scalpel = *hand.active_tool;
  // Out, the blade; in, the whole tool cuts (cutting_edge_m).
  const auto edge = hand.blade_in_tissue ? cutting_edge_m(scalpel) : blade_edge_m(scalpel);
  // How deep the blade is, shown to the trainee (with the mouse it sets the depth); while it cuts,
  // what holds it back, and whether it is still in: within a few millimetres of tissue (in its own
  // cut the edge may touch no element). Clear of the surface's box (refitted in this cycle's
  // steps), the edge meets nothing: no walk over the elements.
  constexpr double kBladeReachM = 0.003;
  const EdgeInTissue in =
      step_hierarchy().bounds().overlaps(Aabb::around(edge[0], edge[1], kBladeReachM))
          ? edge_in_tissue(*model_, state_.position_m, edge, kBladeReachM, kEdgeInTissueMarginM,
                           &hand.blade_node_scratch)
          : EdgeInTissue{};
  hand.blade_edge_in_tissue_m = in.length_m;
  if (!hand.blade_in_tissue) {
    if (!scalpel.blade_armed) return;
    // Breaks in once the force on the blade reaches the toughness of the tissue it presses on
    // times the length of its edge in contact: the tissue would give way at that load
    // (CuttingSettings). An element's average stress under a thin blade depends on the element's
    // size, not the blade's load. An edge already through the surface (put in deep, or pressed
    // through faster than the tissue gave way) has made its way in: it is in.
    const PartContact& blade = hand.tools->part_contact(kScalpelBlade);
    if (!blade.touched()) return;
    const RegionMaterial& pressed =
        model_->regions[static_cast<std::size_t>(std::max(0, blade.region))];
    // Put into a cut it made (touching a cut face), it is in its groove: it cuts on at once.
    if (!blade.pierced && !blade.touched_cut_face &&
        blade.force_on_part_n.norm() <
            pressed.fracture_toughness_j_per_m2 * blade_edge_in_contact_m(blade, scalpel.geometry))
      return;
    hand.blade_in_tissue = true;
    hand.stroke.restart(cutting_edge_m(scalpel));
    return;
  }
  resist_cutting(hand, edge, in);
  // A new instant of the stroke once the edge has moved kStrokeInstantM (a broken-in blade's
  // stroke starts where it broke in).
  const auto& last = hand.stroke.edges_m.back();
  if ((edge[0] - last[0]).norm() < kStrokeInstantM && (edge[1] - last[1]).norm() < kStrokeInstantM)
    return;
  // Drawn out of the tissue, the blade has to break in again; the holes and strands the stroke's
  // cut left are parted (part_remnants).
  if (!in.within_reach) {
    part_remnants_of(hand);
    return hand.end_stroke();
  }
  // Disarmed, the blade passes on without cutting; armed again, the stroke goes on from here.
  if (!scalpel.blade_armed) {
    part_remnants_of(hand);
    hand.stroke.restart(edge);
    return;
  }
  hand.stroke.add(edge);
  if (hand.stroke.edges_m.size() < 2) return;
  const auto update_start = std::chrono::steady_clock::now();
  // Once in, the edge cuts whatever it is drawn through: the stress at a sharp edge in the tissue
  // (a crack front) is unbounded, which no element's average resolves, so the threshold decides
  // only where the blade breaks in. Otherwise the tissue, relaxed around a still blade, would let
  // the blade pass uncut.
  CuttingSettings propagating = *cutting_;
  propagating.cutting_stress_pa = 0.0;
  // And the mesh is refined around the blade as it goes, so that a short stroke parts tissue on
  // the shipped meshes (elements 10–14 mm across).
  propagating.refine_edge_m = kBladeRefineEdgeM;
  // Each instant follows the groove it is in as the tissue is now (CuttingSettings).
  swap_in_cut(hand, cut_stroke_so_far(*model_, state_, hand.stroke, propagating), update_start);
}

const SurfaceBvh& RealtimeSimulation::step_hierarchy() const {
  // enable_tools and swap_in give every hand the same surface.
  for (const HandInLoop& hand : hands_)
    if (hand.acts()) return hand.tools->bvh();
  throw std::logic_error("step_hierarchy: no hand acts");
}

void RealtimeSimulation::part_remnants_of(HandInLoop& hand) {
  if (hand.stroke.edges_m.size() < 2) return;
  const auto update_start = std::chrono::steady_clock::now();
  // What the other hand's forceps hold is the specimen's side (part_remnants).
  std::vector<NodeIndex> held_nodes;
  for (const HandInLoop& other : hands_)
    if (&other != &hand && other.tools)
      if (const ForcepsGrasp* grasp = other.tools->grasp())
        held_nodes.insert(held_nodes.end(), grasp->nodes.begin(), grasp->nodes.end());
  swap_in_cut(hand, part_remnants(*model_, state_, hand.stroke, *cutting_, held_nodes),
              update_start);
}

void RealtimeSimulation::swap_in_cut(const HandInLoop& hand, CutResult cut,
                                     std::chrono::steady_clock::time_point update_start) {
  const auto trace_cut = [&](bool parted) {
    if (!trace_) return;
    LoopRecord record;
    record.kind = LoopRecord::Kind::cut;
    record.wall_s = trace_wall_s();
    record.simulated_s = state_.time_s;
    record.blade_in_tissue = hand.blade_in_tissue;
    record.cut_update_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - update_start).count();
    record.parted = parted;
    record.tets = model_->tet_count;
    record.model_stable_step_s = model_->stable_time_step_s;
    record.min_element_height_m = model_->min_element_height_m;
    trace_->push(record);
  };
  if (!cut.cut()) return trace_cut(false);
  const bool parted = cut.report.separated_faces > 0;
  resected_volume_m3_ += cut.report.resected_volume_m3;
  swap_in(std::move(cut));
  trace_cut(parted);
}

void RealtimeSimulation::swap_in(CutResult change, std::span<const TetIndex> body) {
  {
    std::lock_guard lock(outcome_mutex_);
    if (outcome_) {
      if (body.empty())
        outcome_->tracker.carry_over(change);
      else
        outcome_->tracker.take_out(*model_, body, change);
      outcome_->model = change.model;
    }
  }
  model_ = std::move(change.model);
  state_ = std::move(change.state);
  checkpoint_ = make_checkpoint(*model_);
  const BoundarySurface surface = boundary_surface(*model_);
  for (HandInLoop& hand : hands_) {
    // A hold of one hand's forceps goes on through the other hand's cut.
    ForcepsGrasp held;
    if (hand.tools && hand.tools->grasp()) held = *hand.tools->grasp();
    hand.tools.emplace(*model_, surface, contact_settings_, grasp_settings_);
    hand.tools->carry_hold(held, change.node_origin);
  }
  tools_hold_model_boundary_ = true;
  free_bodies_ = free_bodies(*model_);
  body_contact_ = BodyContact(*model_, surface, free_bodies_);
  step_springs_.reserve(options_.spring_capacity + 2 * hands_.size() * surface.nodes.size() +
                        body_contact_.max_springs());
  {
    std::lock_guard lock(springs_mutex_);
    pending_springs_.clear();
    springs_changed_ = false;
  }
  active_springs_.clear();
  ++topology_version_;
}

bool RealtimeSimulation::take_out_free_bodies(bool all) {
  bool any = false;
  for (bool again = true; again;) {
    again = false;
    for (const FreeBody& body : free_bodies_) {
      if (!all) {  // the centroid of its elements' centroids, by volume
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        double volume = 0.0;
        for (const TetIndex e : body.elements) {
          Eigen::Vector3d middle = Eigen::Vector3d::Zero();
          for (int c = 0; c < 4; ++c) middle += state_.position_m.at(model_->corner[c][e]);
          centroid += 0.25 * model_->rest_volume_m3[e] * middle;
          volume += model_->rest_volume_m3[e];
        }
        if (field_m_.contains(centroid / volume)) continue;
      }
      const std::vector<TetIndex> elements = body.elements;  // swap_in refreshes the list
      ++specimens_taken_out_;
      specimens_taken_out_m3_ += body.rest_volume_m3;
      swap_in(take_out_body(*model_, state_, elements.front()), elements);
      any = again = true;
      break;
    }
  }
  return any;
}

void RealtimeSimulation::trace_loop(SpscRing<LoopRecord>* trace) {
  if (running()) throw std::logic_error("trace_loop: stop the simulation first");
  trace_ = trace;
}

double RealtimeSimulation::trace_wall_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start_).count();
}

void RealtimeSimulation::track_outcome(std::optional<Eigen::Vector3d> lift_point_m,
                                       DamageStrains damage) {
  std::lock_guard lock(outcome_mutex_);
  outcome_.reset();
  outcome_request_.emplace(lift_point_m, damage);
}

void RealtimeSimulation::track_outcome(OutcomeTracking carried) {
  std::lock_guard lock(outcome_mutex_);
  outcome_request_.reset();
  outcome_ = std::move(carried);
}

void RealtimeSimulation::stop_tracking_outcome() {
  std::lock_guard lock(outcome_mutex_);
  outcome_request_.reset();
  outcome_.reset();
}

std::optional<OutcomeTracking> RealtimeSimulation::outcome() const {
  std::lock_guard lock(outcome_mutex_);
  return outcome_;
}

void RealtimeSimulation::observe_outcome() {
  std::lock_guard lock(outcome_mutex_);
  if (outcome_request_) {  // allocates once, when tracking begins
    outcome_.emplace(
        OutcomeTracking{OutcomeTracker(*model_, outcome_request_->first, outcome_request_->second),
                        model_, model_});
    outcome_request_.reset();
    outcome_observed_s_ = -std::numeric_limits<double>::infinity();
  }
  if (!outcome_) return;
  outcome_->model = model_;
  // A pass over every element: once per kOutcomeIntervalS of simulated time, not per cycle (at
  // one 0.43 ms step a cycle, it was 8 % of a cutting stroke's time).
  if (state_.time_s >= outcome_observed_s_ &&
      state_.time_s < outcome_observed_s_ + kOutcomeIntervalS)
    return;
  outcome_observed_s_ = state_.time_s;
  outcome_->tracker.observe(*model_, state_.position_m);
}

void RealtimeSimulation::resist_cutting(HandInLoop& hand,
                                        const std::array<Eigen::Vector3d, 2>& edge,
                                        const EdgeInTissue& in) {
  // The edge's velocity across itself, from its midpoint cycle to cycle in simulated time,
  // smoothed over 10 ms (a device's frames come at the servo's rate, cycles at the loop's).
  constexpr double kSmoothingS = 0.01;
  const Eigen::Vector3d middle = 0.5 * (edge[0] + edge[1]);
  const double dt = state_.time_s - hand.blade_time_s;
  if (hand.blade_time_s >= 0.0 && dt > 0.0)
    hand.blade_velocity_m_per_s +=
        dt / (kSmoothingS + dt) *
        ((middle - hand.blade_middle_m) / dt - hand.blade_velocity_m_per_s);
  hand.blade_middle_m = middle;
  hand.blade_time_s = state_.time_s;
  const Eigen::Vector3d axis = (edge[1] - edge[0]).normalized();
  const Eigen::Vector3d& velocity = hand.blade_velocity_m_per_s;
  const Eigen::Vector3d across = velocity - velocity.dot(axis) * axis;
  const double full_speed = cutting_->full_resistance_speed_m_per_s;
  // Each force against a motion, growing with its speed up to full_speed, then constant.
  const auto against = [full_speed](const Eigen::Vector3d& motion, double force_n) {
    const double speed = motion.norm();
    return speed > 0.0
               ? Eigen::Vector3d(-force_n * std::min(1.0, speed / full_speed) / speed * motion)
               : Eigen::Vector3d::Zero();
  };
  hand.cutting_force_n = against(across, in.resistance_n) + against(velocity, in.friction_n);
}

void RealtimeSimulation::HandInLoop::end_stroke() {
  stroke.edges_m.clear();
  blade_in_tissue = false;
  remnants_due = false;
  cutting_force_n.setZero();
  blade_velocity_m_per_s.setZero();
  blade_time_s = -1.0;
}

bool RealtimeSimulation::any_blade_in_tissue() const {
  return std::any_of(hands_.begin(), hands_.end(),
                     [](const HandInLoop& hand) { return hand.blade_in_tissue; });
}

double RealtimeSimulation::haptic_servo_period_s() const {
  // Without a servo the model's damping is not used: any period will do.
  return haptic_servo_ ? 1.0 / haptic_servo_->safety().nominal_rate_hz : 1e-3;
}

void RealtimeSimulation::set_haptic_servo(ServoLoop* servo) {
  if (running()) throw std::logic_error("set_haptic_servo: stop the simulation first");
  haptic_servo_ = servo;
  for (HandInLoop& hand : hands_) hand.device_sample.reset();
  // The display's next snapshot holds no sample of the device gone (a replay's first frame
  // showed the mouse's when the old loop's last snapshot was still the newest).
  publish_cycle(Publish::snapshot_only);
}

void RealtimeSimulation::set_device_tool(Hand which,
                                         const std::optional<DeviceToolSettings>& settings,
                                         double from_servo_s) {
  std::lock_guard lock(springs_mutex_);
  HandInLoop& held = hand(which);
  held.pending_device_tool = settings;
  held.pending_device_tool_from_s = from_servo_s;
  held.device_tool_changed = true;
  // The hand's tool held so far goes with the change; a set_tool after this call counts.
  held.pending_tool.reset();
  held.tool_changed = false;
}

void RealtimeSimulation::take_tool(Hand which, const std::optional<Tool>& tool) {
  if (logging_inputs_.load(std::memory_order_relaxed)) {
    SimulationInput input{SimulationInput::Kind::tool, tool, {}, 0, false};
    input.hand = which;
    log_input(std::move(input));
  }
  change_tool(which, tool);
}

void RealtimeSimulation::change_tool(Hand which, const std::optional<Tool>& tool) {
  HandInLoop& held = hand(which);
  const bool kind_changed = !tool || !held.active_tool || tool->kind != held.active_tool->kind;
  const bool stroke_ends = kind_changed || tool->kind != ToolKind::scalpel;
  held.active_tool = tool;
  if (!held.active_tool && held.tools) held.tools->release();
  if (!stroke_ends) return;
  // A blade taken away in the tissue (the mouse let go) ends its stroke as drawing it out does,
  // what the stroke left parted first; not here, where take_inputs may hold the springs' lock,
  // which a cut's swap takes.
  if (held.blade_in_tissue && cutting_)
    held.remnants_due = true;
  else
    held.end_stroke();
}

void RealtimeSimulation::part_remnants_due() {
  for (HandInLoop& held : hands_)
    if (held.remnants_due) {
      part_remnants_of(held);
      held.end_stroke();
    }
}

void RealtimeSimulation::take_inputs() {
  {
    std::lock_guard lock(springs_mutex_);
    if (springs_changed_) {
      active_springs_.assign(pending_springs_.begin(), pending_springs_.end());  // no realloc
      springs_changed_ = false;
      if (logging_inputs_.load(std::memory_order_relaxed))  // a copy: only when logging
        log_input({SimulationInput::Kind::springs, std::nullopt, active_springs_, 0, false});
    }
    for (Hand which : kHands) {
      HandInLoop& held = hand(which);
      if (held.device_tool_changed) {
        // The tool held so far goes: the device's appears with its first frame, or without a
        // device, set_tool's next one.
        held.device_tool_changed = false;
        held.device_tool = held.pending_device_tool;
        held.device_tool_from_s = held.pending_device_tool_from_s;
        take_tool(which, std::nullopt);
      }
      if (held.tool_changed) {
        held.tool_changed = false;
        if (!held.device_tool) take_tool(which, held.pending_tool);
      }
    }
  }
  part_remnants_due();
  if (take_out_requested_.exchange(false)) {
    if (logging_inputs_.load(std::memory_order_relaxed))
      log_input({SimulationInput::Kind::take_out_specimens, std::nullopt, {}, 0, false});
    take_out_free_bodies(true);
  }
  if (!haptic_servo_) return;
  for (Hand which : kHands) {
    HandInLoop& held = hand(which);
    ServoFrame frame;
    if (!haptic_servo_->newest_frame(which, frame)) continue;
    held.device_sample = frame.sample;
    if (!held.device_tool || frame.time_s < held.device_tool_from_s) continue;
    const WorkspaceMapping& mapping = haptic_servo_->mapping(which);
    std::optional<Eigen::Quaterniond> stylus;
    if (frame.sample.orientation) stylus = mapping.scene_orientation(*frame.sample.orientation);
    take_tool(which,
              device_tool(*held.device_tool, mapping.scene_position_m(frame.sample.position_mm),
                          frame.sample.buttons, stylus));
  }
}

void RealtimeSimulation::set_tool(Hand which, const std::optional<Tool>& tool) {
  std::lock_guard lock(springs_mutex_);
  hand(which).pending_tool = tool;
  hand(which).tool_changed = true;
}

bool RealtimeSimulation::set_springs(std::span<const NodeSpring> springs) {
  const std::size_t count = std::min(springs.size(), options_.spring_capacity);
  std::lock_guard lock(springs_mutex_);
  pending_springs_.assign(springs.begin(), springs.begin() + static_cast<std::ptrdiff_t>(count));
  springs_changed_ = true;
  return count == springs.size();
}

RealtimeStats RealtimeSimulation::stats() const {
  RealtimeStats stats;
  stats.steps_per_second = steps_per_second_.load();
  stats.real_time_factor = real_time_factor_.load();
  stats.step_s = smallest_step_s_.load();
  stats.behind = behind_.load();
  stats.integrator = integrator_kind_;
  stats.integrator_name = integrator_name(integrator_kind_);
  stats.requested_step_s = step_s_;
  stats.error_estimate_m = error_estimate_m_.load();
  stats.wall_s_per_simulated_s = wall_s_per_simulated_s_.load();
  stats.force_evaluations_per_simulated_s = force_evaluations_per_simulated_s_.load();
  stats.stability_limited = stability_limited_.load();
  stats.dropped_s = dropped_s_.load();
  stats.rollbacks = rollbacks_.load();
  stats.rejected_inputs = rejected_inputs_.load();
  stats.last_problem = last_problem_.load();
  stats.halted = halted_.load();
  stats.energy_created = energy_created_.load();
  stats.dissipated_fraction = dissipated_fraction_.load();
  return stats;
}

namespace {

// The reports of consecutive guarded advances as one.
void merge_guarded(GuardedReport& total, const GuardedReport& one) {
  accumulate(total.steps, one.steps);
  total.rollbacks += one.rollbacks;
  if (one.problem != HealthProblem::none) total.problem = one.problem;
  total.step_scale = one.step_scale;
  total.gave_up = total.gave_up || one.gave_up;
  total.inputs_rejected = total.inputs_rejected || one.inputs_rejected;
  if (one.energy) {
    total.energy = one.energy;
    total.energy_created = one.energy_created;
  }
}

}  // namespace

GuardedReport RealtimeSimulation::advance_cycle(int steps, bool check_energy) {
  const SimModel& model = *model_;  // a cut may replace it between cycles
  // Tools and bodies in contact push with springs that follow the surface: made before every
  // step.
  const bool springs_follow_surface =
      body_contact_.active() ||
      std::any_of(hands_.begin(), hands_.end(), [](const HandInLoop& h) { return h.acts(); });
  // Guarded: a bad step goes back to the last good state and is retried with shorter steps; a
  // bad input (a NaN from a device) is refused.
  GuardOptions guard;
  guard.check_energy = check_energy;
  // The hands hold the same surface: the first that acts refits its hierarchy, the other queries
  // it (step_hierarchy).
  auto step_inputs = [&] {
    step_springs_.assign(active_springs_.begin(), active_springs_.end());
    const SurfaceBvh* refitted = nullptr;
    for (HandInLoop& hand : hands_) {
      if (!hand.acts()) continue;
      const auto tool_springs =
          hand.tools->update(*hand.active_tool, state_.position_m, hand.blade_in_tissue, refitted);
      if (!refitted) refitted = &hand.tools->bvh();
      step_springs_.insert(step_springs_.end(), tool_springs.begin(), tool_springs.end());
    }
    // On the same surface as the hands' (after a cut, swap_in), their hierarchy refitted this
    // step serves.
    body_contact_.add_springs(model, state_.position_m, step_springs_,
                              tools_hold_model_boundary_ ? refitted : nullptr);
    return StepInputs{{}, step_springs_};
  };
  // Whole steps as long as the limits allow, up to the loop's step: the state may end a little
  // past the time the loop asked for (lead_s_), and the next step asks for that much less.
  guard.whole_step_s = step_s_;
  // Given up (stop(), a cycle that would not end), the cycle ends where its step under way ends,
  // what it did kept: in a crawl one cycle's steps took minutes, and `record` ignored SIGTERM.
  guard.give_up = &give_up_cycle_;
  // The checkpoint (a copy of the whole state, its viscous history 1 MB at 5450 elements) once per
  // kCheckpointIntervalS of simulated time: saved every cycle, it was 7 % of a stroke's time.
  const bool checkpoint_due = !checkpoint_.valid ||
                              !(state_.time_s - checkpoint_.time_s < kCheckpointIntervalS) ||
                              state_.time_s < checkpoint_.time_s;
  guard.checkpoint_on_entry = checkpoint_due;
  guard.checkpoint_after_advance = false;
  // Less than this left to cover: the loop's time is reached (round-off of the lead).
  const double reached_s = 1e-9 * step_s_;
  // Advances by what is left of `interval_s` (nothing when it is reached: the guard still runs)
  // and keeps the lead past it.
  auto advance_by = [&](double interval_s, const StepInputs& inputs, const GuardOptions& options) {
    const double before_s = state_.time_s;
    const GuardedReport one = guarded_advance(
        model, state_, inputs, interval_s > reached_s ? interval_s : 0.0, checkpoint_, options);
    loop_lead_s_ = one.gave_up ? 0.0 : std::max(0.0, (state_.time_s - before_s) - interval_s);
    return one;
  };
  GuardedReport guarded;
  if (springs_follow_surface) {
    bool first = true;
    for (int s = 0; s < steps && !give_up_cycle_.load(std::memory_order_relaxed); ++s) {
      const double interval_s = step_s_ - loop_lead_s_;
      // Already there: the last step's lead covers it. The cycle's last loop step still goes
      // through the guard, taking no step: its tools are updated (and, when due, the checkpoint
      // saved), as when every loop step was stepped.
      if (interval_s <= reached_s && s < steps - 1) {
        loop_lead_s_ = std::max(0.0, -interval_s);
        continue;
      }
      GuardOptions step_guard = guard;
      step_guard.check_energy = guard.check_energy && first;
      step_guard.checkpoint_on_entry = checkpoint_due && first;
      first = false;
      const GuardedReport one = advance_by(interval_s, step_inputs(), step_guard);
      merge_guarded(guarded, one);
      if (one.gave_up) break;
    }
  } else {
    guarded = advance_by(steps * step_s_ - loop_lead_s_, StepInputs{{}, active_springs_}, guard);
  }
  if (guarded.energy) {
    energy_created_ = guarded.energy_created;
    const double supplied = guarded.energy->supplied_j();
    dissipated_fraction_ = supplied > 0.0 ? guarded.energy->dissipated_j() / supplied : 0.0;
  }
  if (guarded.problem != HealthProblem::none) last_problem_ = guarded.problem;
  rollbacks_ += guarded.rollbacks;
  if (guarded.inputs_rejected) ++rejected_inputs_;
  if (guarded.gave_up) halted_ = true;
  if (cutting_ && !guarded.gave_up)
    for (HandInLoop& hand : hands_)
      if (hand.acts() && hand.active_tool->kind == ToolKind::scalpel) cut_with_scalpel(hand);
  if (!free_bodies_.empty() && !guarded.gave_up) take_out_free_bodies(false);
  return guarded;
}

namespace {
// Room for the loop's log between two takes (a display frame holds a few cycles), so that the
// simulation thread appends without allocating: the caller of take_input_log allocates it.
constexpr std::size_t kInputLogReserve = 256;
}  // namespace

void RealtimeSimulation::log_inputs(bool on) {
  if (on) {
    std::lock_guard lock(input_log_mutex_);
    input_log_.reserve(kInputLogReserve);
  }
  logging_inputs_.store(on);
}

std::vector<SimulationInput> RealtimeSimulation::take_input_log() {
  std::vector<SimulationInput> fresh;
  fresh.reserve(kInputLogReserve);
  std::lock_guard lock(input_log_mutex_);
  std::swap(fresh, input_log_);
  return fresh;
}

void RealtimeSimulation::log_input(SimulationInput input) {
  std::lock_guard lock(input_log_mutex_);
  // A device moves the tool at every loop, many times between cycles: a tool of the same kind
  // in the same hand replacing one that no cycle used has the same effect as both (change_tool),
  // so it replaces it. The other hand's tools taken since do not act on this hand's.
  if (input.kind == SimulationInput::Kind::tool && input.tool)
    for (auto last = input_log_.rbegin();
         last != input_log_.rend() && last->kind == SimulationInput::Kind::tool; ++last) {
      if (last->hand != input.hand) continue;
      if (!last->tool || last->tool->kind != input.tool->kind) break;
      last->tool = input.tool;
      return;
    }
  input_log_.push_back(std::move(input));
}

void RealtimeSimulation::replay(std::span<const SimulationInput> inputs,
                                const CycleObserver& each_cycle) {
  if (running()) throw std::logic_error("replay needs the simulation stopped");
  // The loop parts what a blade taken away left after the tools it takes at once, before anything
  // else: before the next input that is not a tool, or at the end.
  for (const SimulationInput& input : inputs) switch (input.kind) {
      case SimulationInput::Kind::tool:
        change_tool(input.hand, input.tool);
        break;
      case SimulationInput::Kind::springs:
        part_remnants_due();
        // A log from another model (or a damaged one) must not index past this one's nodes.
        for (const NodeSpring& spring : input.springs)
          if (spring.node < 0 || static_cast<std::size_t>(spring.node) >= model_->node_count)
            throw std::invalid_argument("replay: a spring holds node " +
                                        std::to_string(spring.node) + " of a model of " +
                                        std::to_string(model_->node_count) + " nodes");
        active_springs_.assign(input.springs.begin(), input.springs.end());
        break;
      case SimulationInput::Kind::take_out_specimens:
        part_remnants_due();
        take_out_free_bodies(true);
        break;
      case SimulationInput::Kind::cycle: {
        part_remnants_due();
        if (halted_.load()) break;
        const std::uint64_t topology_before = topology_version_;
        const GuardedReport guarded = advance_cycle(input.steps, input.check_energy);
        publish_cycle();  // as the live loop does: the snapshot shows the replayed cycle
        if (each_cycle) each_cycle(guarded.steps, topology_version_ != topology_before);
        break;
      }
    }
  part_remnants_due();
}

void RealtimeSimulation::publish_time_to(std::atomic<double>* clock_s) {
  published_clock_s_ = clock_s;
  if (published_clock_s_) published_clock_s_->store(state_.time_s, std::memory_order_relaxed);
}

void RealtimeSimulation::publish_cycle(Publish what) {
  SimulationSnapshot& out = snapshots_.back();
  // Same size: copies without allocating (a cut's new size allocates once).
  out.position_m.x = state_.position_m.x;
  out.position_m.y = state_.position_m.y;
  out.position_m.z = state_.position_m.z;
  out.time_s = state_.time_s;
  out.step_count = state_.step_count;
  simulated_time_s_.store(state_.time_s, std::memory_order_relaxed);
  if (published_clock_s_) published_clock_s_->store(state_.time_s, std::memory_order_relaxed);
  for (Hand which : kHands) {
    const HandInLoop& held = hand(which);
    HandSnapshot& seen = out.hands[hand_index(which)];
    seen.device_sample = held.device_sample;
    if (!held.acts()) {
      seen.tool.reset();
      seen.force_n.setZero();
      seen.cutting_force_n.setZero();
      seen.grasping = seen.blade_cutting = false;
      seen.contacts = 0;
      seen.blade_edge_in_tissue_m = 0.0;
      if (haptic_servo_ && what == Publish::cycle) haptic_servo_->publish(which, LocalForceModel{});
      continue;
    }
    // The local model of the force on the tool: its F0 is the snapshot's tool force.
    LocalForceModel force_model =
        tool_force_model(held.tools->springs(), state_.position_m, held.active_tool->pose.origin_m,
                         haptic_servo_period_s());
    if (held.blade_in_tissue) force_model.force_n += held.cutting_force_n;  // the cut's pull
    seen.force_n = force_model.force_n;
    seen.cutting_force_n = held.blade_in_tissue ? held.cutting_force_n : Eigen::Vector3d::Zero();
    seen.grasping = held.tools->grasping();
    seen.contacts = held.tools->contact_count();
    seen.blade_cutting = held.blade_in_tissue;
    seen.blade_edge_in_tissue_m =
        cutting_ && held.active_tool->kind == ToolKind::scalpel ? held.blade_edge_in_tissue_m : 0.0;
    seen.tool = held.active_tool;
    if (haptic_servo_ && what == Publish::cycle) haptic_servo_->publish(which, force_model);
  }
  if (what == Publish::cycle) observe_outcome();
  out.model = model_;
  out.topology_version = topology_version_;
  out.resected_volume_m3 = resected_volume_m3_;
  out.specimens_taken_out = specimens_taken_out_;
  out.specimens_taken_out_m3 = specimens_taken_out_m3_;
  out.free_bodies = static_cast<int>(free_bodies_.size());
  snapshots_.publish();
}

void RealtimeSimulation::run() {
  using Clock = std::chrono::steady_clock;
  using Seconds = std::chrono::duration<double>;
  StepAccumulator clock(step_s_, max_steps_per_cycle_);
  auto last_cycle = Clock::now();
  loop_start_ = last_cycle;

  // The statistics window: what the integrator reported, the wall time it took and whether the
  // cap bit, since the window began.
  constexpr double kWindowS = 0.25;
  const auto empty_window = [] {
    StepReport report;
    report.error_estimate_m = std::numeric_limits<double>::quiet_NaN();  // none yet
    return report;
  };
  auto window_start = last_cycle;
  double window_sim_start_s = state_.time_s;
  std::uint64_t window_start_steps = state_.step_count;
  StepReport window_report = empty_window();
  double window_integrating_s = 0.0;
  int window_retries = 0;  // the guard's rollbacks in the window (each retries at half the step)
  bool window_capped = false;
  bool close_books = false;  // close the energy books with the next advance
  double dropped_s = 0.0;

  while (!stop_requested_.load(std::memory_order_relaxed)) {
    take_inputs();
    const auto cycle_start = Clock::now();
    const StepAccumulator::Due due = clock.add(Seconds(cycle_start - last_cycle).count());
    last_cycle = cycle_start;
    if (due.capped) {
      window_capped = true;
      dropped_s += due.dropped_s;
    }
    if (due.steps > 0 && !halted_.load(std::memory_order_relaxed)) {
      const bool check_energy = close_books;  // one pass over the elements, once per window
      close_books = false;
      if (logging_inputs_.load(std::memory_order_relaxed))
        log_input(
            {SimulationInput::Kind::cycle,
             std::nullopt,
             {},
             due.steps,
             check_energy,
             haptic_servo_ ? haptic_servo_->now_s() : std::numeric_limits<double>::quiet_NaN()});
      const GuardedReport guarded = advance_cycle(due.steps, check_energy);
      window_integrating_s += Seconds(Clock::now() - cycle_start).count();
      window_retries += guarded.rollbacks;
      accumulate(window_report, guarded.steps);
      publish_cycle();
    } else {
      // Sleep towards the next step, but wake often enough to stop and to pick up springs.
      const double sleep_s = std::clamp(clock.time_to_next_step_s(), 0.5e-3, 2e-3);
      std::this_thread::sleep_for(Seconds(sleep_s));
    }

    const auto now = Clock::now();
    const double window_s = Seconds(now - window_start).count();
    if (window_s >= kWindowS) {
      close_books = true;
      const double simulated_s = state_.time_s - window_sim_start_s;
      steps_per_second_ = static_cast<double>(state_.step_count - window_start_steps) / window_s;
      real_time_factor_ = simulated_s / window_s;
      if (window_report.substeps > 0) {
        smallest_step_s_ = window_report.smallest_substep_s;
        error_estimate_m_ = window_report.error_estimate_m;
        stability_limited_ = window_report.stability_limited_steps > 0;
      }
      if (simulated_s > 0.0) {
        wall_s_per_simulated_s_ = window_integrating_s / simulated_s;
        force_evaluations_per_simulated_s_ = window_report.force_evaluations / simulated_s;
      }
      behind_ = window_capped;
      dropped_s_ = dropped_s;
      if (trace_) {
        LoopRecord record;
        record.kind = LoopRecord::Kind::window;
        record.wall_s = Seconds(now - loop_start_).count();
        record.simulated_s = state_.time_s;
        record.blade_in_tissue = any_blade_in_tissue();
        record.window_wall_s = window_s;
        record.window_simulated_s = simulated_s;
        record.integrating_s = window_integrating_s;
        record.behind = window_capped;
        record.steps = window_report.substeps;
        record.force_evaluations = window_report.force_evaluations;
        record.stability_limited_steps = window_report.stability_limited_steps;
        record.smallest_step_s =
            window_report.substeps > 0 ? window_report.smallest_substep_s : 0.0;
        record.smallest_stable_step_s = window_report.smallest_stable_step_s;
        record.smallest_mesh_limit_s = window_report.smallest_mesh_limit_s;
        record.smallest_travel_limit_s = window_report.smallest_travel_limit_s;
        record.smallest_spring_limit_s = window_report.smallest_spring_limit_s;
        record.max_stiffening = window_report.max_stiffening;
        record.least_volume_ratio = window_report.least_volume_ratio;
        record.max_flow_stiffening = window_report.max_flow_stiffening;
        record.guard_retries = window_retries;
        trace_->push(record);
      }
      window_start = now;
      window_sim_start_s = state_.time_s;
      window_start_steps = state_.step_count;
      window_report = empty_window();
      window_integrating_s = 0.0;
      window_retries = 0;
      window_capped = false;
    }
  }
}

}  // namespace liversim
