#pragma once
// Runs a simulation on its own thread in step with the wall clock, takes inputs (springs from a
// dragged point) from other threads and publishes snapshots of the node positions.
//
// Time advances in whole steps of a fixed length (the model's integrator step, or its stable
// explicit step when none is set): the wall time that passes is added to a backlog and the whole
// steps in it are taken, at most max_steps_per_cycle at a time. When the machine cannot keep up,
// the backlog beyond that cap is dropped, so simulated time runs slower than the wall clock instead
// of the loop spiralling into ever longer catch-up cycles.

#include "liversim/engine/forces.h"
#include "liversim/engine/health.h"
#include "liversim/engine/model.h"
#include "liversim/engine/state.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/haptics/spsc_ring.h"
#include "liversim/haptics/triple_buffer.h"
#include "liversim/interaction/body_contact.h"
#include "liversim/interaction/cutting.h"
#include "liversim/interaction/simulation_input.h"
#include "liversim/interaction/tools.h"
#include "liversim/simulation/tissue_outcome.h"

#include <Eigen/Geometry>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string_view>
#include <thread>
#include <vector>

namespace liversim {

// What one hand's tool did in a cycle (SimulationSnapshot::hands).
struct HandSnapshot {
  // The tool the hand held in the cycle (none: an empty hand), for drawing.
  std::optional<Tool> tool;
  // The tissue's force on the tool after the last step, whether the forceps hold tissue, and
  // how many nodes its contact pushes.
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  bool grasping = false;
  std::size_t contacts = 0;
  bool blade_cutting = false;  // the scalpel has broken into the tissue
  // Of force_n, the tissue's resistance to the cutting blade (CuttingSettings): its toughness
  // times the edge in the tissue, against the blade's motion across its edge, and the friction on
  // its sides times the same edge, against its motion.
  Eigen::Vector3d cutting_force_n = Eigen::Vector3d::Zero();
  // How much of the scalpel's edge is inside the tissue (m; with cutting enabled), cutting or not:
  // how deep the blade is, along its edge.
  double blade_edge_in_tissue_m = 0.0;
  // The newest frame of the hand's haptic device (set_haptic_servo), which its tool follows.
  std::optional<DeviceSample> device_sample;
};

struct SimulationSnapshot {
  NodeArray position_m;
  double time_s = 0.0;
  std::uint64_t step_count = 0;
  // Each hand's tool (when tools are enabled), in kHands' order.
  std::array<HandSnapshot, kHands.size()> hands;
  const HandSnapshot& hand(Hand which) const { return hands[hand_index(which)]; }
  // The model the positions belong to: a cut replaces it (and raises topology_version), so a
  // reader rebuilds what it draws from the mesh when the version changes.
  std::shared_ptr<const SimModel> model;
  std::uint64_t topology_version = 0;
  double resected_volume_m3 = 0.0;  // parted from the organ by cuts since the start
  // Free bodies (cutting.h) taken out of the field since the start, and their rest volume.
  int specimens_taken_out = 0;
  double specimens_taken_out_m3 = 0.0;
  // Free bodies in the model now (pieces a cut freed, still in the field).
  int free_bodies = 0;
};

struct RealtimeStats {
  // Measured over the last statistics window (about a quarter of a second of wall time).
  double steps_per_second = 0.0;  // integrator steps (substeps included)
  double real_time_factor = 0.0;  // simulated seconds per wall-clock second
  double step_s = 0.0;            // smallest step the integrator actually took
  bool behind = false;            // the step cap bit: simulated time runs slower than real time

  IntegratorKind integrator = IntegratorKind::central_difference;
  std::string_view integrator_name;  // integrator_name(integrator); static storage
  double requested_step_s = 0.0;     // the fixed step the loop advances by
  // Largest local error estimate of the steps taken (m, node positions); NaN when the integrator
  // gave none (e.g. right after a step change).
  double error_estimate_m = std::numeric_limits<double>::quiet_NaN();
  // Cost: wall seconds spent integrating per simulated second (below 1 keeps up with real time),
  // and internal-force evaluations of the whole mesh per simulated second.
  double wall_s_per_simulated_s = 0.0;
  double force_evaluations_per_simulated_s = 0.0;
  // An explicit scheme had to shorten the requested step to stay stable (it substepped).
  bool stability_limited = false;
  double dropped_s = 0.0;  // wall time dropped from the backlog since the start (see `behind`)

  // Guards (health.h), since the start: attempts rolled back to the last good state, inputs
  // refused as not finite, the last problem met, and whether the simulation gave up and halted
  // (the liver stays as it last was good; a new simulation is needed to go on).
  int rollbacks = 0;
  int rejected_inputs = 0;
  HealthProblem last_problem = HealthProblem::none;
  bool halted = false;
  // Energy books (energy.h), closed once per statistics window: energy created beyond the
  // guard's tolerance (a scheme going unstable shows here before any NaN), and the share of the
  // energy supplied that viscosity, plasticity and damping have taken out.
  bool energy_created = false;
  double dissipated_fraction = 0.0;
};

// One record of the real-time loop's trace (RealtimeSimulation::trace_loop): a statistics window
// (about a quarter of a second of wall time) or a cut of the scalpel. What a user meets, record by
// record: the live cutting bench writes its per-second figures from these.
struct LoopRecord {
  enum class Kind : std::uint8_t { window, cut };
  Kind kind = Kind::window;
  double wall_s = 0.0;       // since the loop started, when the record was made
  double simulated_s = 0.0;  // the state's time then
  bool blade_in_tissue = false;
  // A window: its wall time, the simulated time it advanced (their ratio is the real-time
  // factor), the wall time spent stepping, whether the step cap dropped backlog, and the steps'
  // report (StepReport: the smallest step and the limits that set it).
  double window_wall_s = 0.0;
  double window_simulated_s = 0.0;
  double integrating_s = 0.0;
  bool behind = false;
  int steps = 0;
  int force_evaluations = 0;
  int stability_limited_steps = 0;
  double smallest_step_s = 0.0;
  double smallest_stable_step_s = 0.0;
  double smallest_mesh_limit_s = std::numeric_limits<double>::infinity();
  double smallest_travel_limit_s = std::numeric_limits<double>::infinity();
  double smallest_spring_limit_s = std::numeric_limits<double>::infinity();
  // What raised the mesh's limit above its rest value (StepReport): the worst stiffening and, of
  // its causes, the smallest element volume ratio J and the largest flow stiffening met.
  double max_stiffening = 1.0;
  double least_volume_ratio = 1.0;
  double max_flow_stiffening = 1.0;
  // Steps the guard undid and retried at half the step (health.h): a step halved by a retry is
  // told apart from one a limit split.
  int guard_retries = 0;
  // A cut: the wall time of the whole update (the cut, the new model's surface and the tools on
  // it), whether it parted anything, and the model after it: its elements, its stable explicit
  // step and its smallest element height.
  double cut_update_s = 0.0;
  bool parted = false;
  std::size_t tets = 0;
  double model_stable_step_s = 0.0;
  double min_element_height_m = 0.0;
};

// The fixed-step clock of the real-time loop, without the loop: wall time is added, whole steps
// come out, at most max_steps at a time; the rest of a backlog beyond the cap is dropped.
class StepAccumulator {
 public:
  struct Due {
    int steps = 0;           // whole steps to take now (at most max_steps)
    bool capped = false;     // the cap bit and whole steps were dropped
    double dropped_s = 0.0;  // backlog dropped by this call
  };

  // step_s > 0 and max_steps >= 1, else std::invalid_argument.
  StepAccumulator(double step_s, int max_steps);

  // Adds elapsed wall time (negative or non-finite values count as 0) and takes the steps due.
  // The fraction of a step left over stays in the backlog.
  Due add(double elapsed_s);

  double step_s() const { return step_s_; }
  int max_steps() const { return max_steps_; }
  double backlog_s() const { return backlog_s_; }
  // Wall time until the next whole step is due.
  double time_to_next_step_s() const { return step_s_ - backlog_s_; }

 private:
  double step_s_;
  int max_steps_;
  double backlog_s_ = 0.0;
};

// The fixed step the real-time loop advances by: the model's integrator step, or, when that is 0,
// kLoopStepFraction of its stable explicit step. With the loop's step at the mesh's limit, a dip
// of a fraction of a per cent in the limit (a cutting scalpel's stiffening) made the integrator
// split every step in two: twice the force evaluations while the blade cut (a stroke in free
// practice: 2.70 per simulated ms, 1.49 with the step 10 % under;
// LoopStep.ACuttingScalpelTakesOneForceEvaluationPerLoopStep). A pressing probe or forceps lower
// the limit 20–40 % and still split.
inline constexpr double kLoopStepFraction = 0.9;
// The loop saves its checkpoint (the state a bad step goes back to) once per this much simulated
// time: a rollback loses at most this, and the copy is made a few hundred times a second, not at
// every step.
inline constexpr double kCheckpointIntervalS = 0.005;
// stop() lets the cycle under way end on its own for this long (wall time), then gives it up.
inline constexpr double kGiveUpCycleAfterS = 1.0;
// The outcome tracker (tissue_outcome.h) looks at the tissue once per this much simulated time,
// not per cycle: a strain past its damage limit is seen unless a hand makes and undoes it within
// 2 ms.
inline constexpr double kOutcomeIntervalS = 0.002;
double realtime_step_s(const SimModel& model);
// The loop's step before it was kept with each session (ReplaySetup::loop_step_s): the model's
// integrator step, or its stable step. Sessions recorded then replay with it.
double legacy_loop_step_s(const SimModel& model);

class RealtimeSimulation {
 public:
  struct Options {
    std::size_t spring_capacity = 1024;
    // Simulated time a cycle may cover, when max_steps_per_cycle=0: two display frames, so that
    // the loop catches up a cycle held up by a cut update instead of dropping the time. One frame
    // was not enough: a parting update of 14 ms and its cycle's steps outlast a frame (the wedge
    // resection's live bench dropped a step or two so, issue 42).
    double cycle_s = 2.0 / 60.0;
    // Steps one cycle (one published snapshot) may take at most; 0: as many as fit in cycle_s
    // (at least one).
    int max_steps_per_cycle = 0;
    // The loop's step; 0: realtime_step_s of the model (a replay passes the recorded one).
    double loop_step_s = 0.0;
  };

  RealtimeSimulation(std::shared_ptr<const SimModel> model, SimState initial_state);
  RealtimeSimulation(std::shared_ptr<const SimModel> model, SimState initial_state,
                     Options options);
  ~RealtimeSimulation();
  RealtimeSimulation(const RealtimeSimulation&) = delete;
  RealtimeSimulation& operator=(const RealtimeSimulation&) = delete;

  void start();
  void stop();
  bool running() const { return thread_.joinable(); }

  // Replaces the springs acting on the liver (at most spring_capacity; extra ones are dropped and
  // the call returns false).
  bool set_springs(std::span<const NodeSpring> springs);
  void clear_springs() { set_springs({}); }

  // Tools (tools.h) touch `surface` (the model's boundary); call while stopped. From then on the
  // tool set by set_tool acts at every step: its contact and grasp springs are recomputed from the
  // deforming surface before each step, besides the springs above.
  void enable_tools(const BoundarySurface& surface, ContactSettings contact = {},
                    GraspSettings grasp = {});
  bool tools_enabled() const { return hands_[0].tools.has_value(); }
  // From then on a scalpel cuts (cutting.h). Its blade presses on the tissue like any tool until
  // the force on it reaches the tissue's toughness times its edge in contact
  // (RegionMaterial::fracture_toughness_j_per_m2); then the blade breaks in:
  // it stops pushing and cuts with the whole tool (cutting_edge_m), whose edge at each cycle
  // extends the stroke, and
  // the tissue the stroke has passed through is separated. Taking the scalpel away or changing
  // the tool ends the stroke. A cut replaces the model and state (see SimulationSnapshot::model)
  // and drops the springs set by set_springs (their nodes may be gone). Call while stopped,
  // after enable_tools.
  void enable_cutting(CuttingSettings settings = {});
  bool cutting_enabled() const { return cutting_.has_value(); }
  // A free body (a piece a cut freed, cutting.h) leaves the simulation once its centroid is
  // farther than kFieldMarginM outside the organ's box at rest (lifted out of the field), or, from
  // any thread, at the next cycle after take_out_specimens (Session ▸ Remove Specimen: every free
  // body). Each is kept by the outcome tracker as a specimen (OutcomeTracker::specimens_taken_out).
  static constexpr double kFieldMarginM = 0.03;
  void take_out_specimens() { take_out_requested_ = true; }
  // The tool's kind, pose and jaws in `hand` from any thread (nothing: the hand holds none); the
  // newest is used from the next cycle on. Both hands' tools act in every step; a hand's forceps
  // keep their hold while the other hand's scalpel cuts. Without a hand: the right one.
  void set_tool(Hand hand, const std::optional<Tool>& tool);
  void set_tool(const std::optional<Tool>& tool) { set_tool(Hand::right, tool); }
  // Publishes the local model of the force on each hand's tool to `servo` after every cycle (none:
  // the zero model), for the hand's haptic device to render, and takes each device's newest frame
  // from it each cycle (the only reader of ServoLoop::newest_frame while it runs). Call while
  // stopped; null stops both.
  void set_haptic_servo(ServoLoop* servo);
  // From any thread: the haptic device in `hand` holds this tool (nothing: it holds none). While
  // one is set and the servo has a device in that hand, each cycle takes the device's newest
  // frame, maps it into the scene (its WorkspaceMapping) and uses device_tool() as the hand's
  // tool; set_tool for that hand is then ignored. Frames stamped before `from_servo_s` (servo
  // clock) are not taken: the mouse puts the tool down where it presses, and a frame from before
  // the press must not show it where it was. Without a hand: the right one.
  void set_device_tool(Hand hand, const std::optional<DeviceToolSettings>& settings,
                       double from_servo_s = -std::numeric_limits<double>::infinity());
  void set_device_tool(const std::optional<DeviceToolSettings>& settings,
                       double from_servo_s = -std::numeric_limits<double>::infinity()) {
    set_device_tool(Hand::right, settings, from_servo_s);
  }

  // From any thread: from the next cycle on, each published cycle is observed by an outcome
  // tracker, and cuts carry it over (a session's tissue damage, lift, resected volume). Off until
  // asked: a scene without a session pays nothing for it.
  void track_outcome(std::optional<Eigen::Vector3d> lift_point_m, DamageStrains damage = {});
  // Goes on with tracking carried from another simulation of the same model (an integrator
  // change): its elements must be this model's.
  void track_outcome(OutcomeTracking carried);
  void stop_tracking_outcome();
  // A copy of the tracking so far; none when off or not yet begun (the first cycle after
  // track_outcome begins it).
  std::optional<OutcomeTracking> outcome() const;

  // While stopped: from the next start on the loop pushes a LoopRecord into `trace` at the end of
  // each statistics window and after each cut (null: no trace). The ring is the caller's and must
  // outlive the run; a full ring drops records (SpscRing counts them), the loop never waits.
  void trace_loop(SpscRing<LoopRecord>* trace);

  // From any thread: keep (or stop keeping) every input the simulation takes from its next loop
  // on, and take those kept so far.
  void log_inputs(bool on);
  std::vector<SimulationInput> take_input_log();
  // While stopped: takes `inputs` (an input log of a simulation built from the same model and
  // state, with the same tools and cutting enabled) exactly as the loop took them, and publishes
  // a snapshot after each cycle as the loop does. `each_cycle` (optional) hears what the
  // integrator reported of each cycle, and whether the cut after it parted tissue: what a run in
  // simulated time (a test, a benchmark) looks at.
  using CycleObserver = std::function<void(const StepReport& steps, bool parted)>;
  void replay(std::span<const SimulationInput> inputs, const CycleObserver& each_cycle = {});

  // Consumer side (one thread, e.g. the UI): the newest snapshot, if one was published since.
  bool update_snapshot() { return snapshots_.update(); }
  const SimulationSnapshot& snapshot() const { return snapshots_.front(); }

  // The simulation's own state and model; only while it is stopped (e.g. to carry positions and
  // velocities over to a rebuilt model). While it runs, a cut may replace both: take the model
  // from the snapshot.
  const SimState& state() const { return state_; }

  RealtimeStats stats() const;
  // The simulated time of the last published cycle, readable from any thread without a lock: the
  // clock a scripted device paced by this simulation plays on (TrajectoryDevice::play_on).
  const std::atomic<double>& simulated_time_s() const { return simulated_time_s_; }
  // Before start(): each published cycle's time is stored in `clock_s` too, a clock that outlives
  // this simulation (the station's: the simulation that replaces this one after a model change
  // goes on storing to it, so a paced script is not left holding a dangling clock). Null: none.
  void publish_time_to(std::atomic<double>* clock_s);
  const SimModel& model() const { return *model_; }
  std::shared_ptr<const SimModel> shared_model() const { return model_; }
  double step_s() const { return step_s_; }
  int max_steps_per_cycle() const { return max_steps_per_cycle_; }

 private:
  void run();

  std::shared_ptr<const SimModel> model_;
  SimState state_;
  Options options_;
  double step_s_;
  // Simulated time the outcome tracker last looked at the tissue (−∞: not yet).
  double outcome_observed_s_ = -std::numeric_limits<double>::infinity();
  // How far the state's time is past the time the loop's steps have asked for: whole steps end
  // past it by less than one step (advance_cycle).
  double loop_lead_s_ = 0.0;
  int max_steps_per_cycle_;
  TripleBuffer<SimulationSnapshot> snapshots_;

  std::mutex springs_mutex_;  // UI ↔ simulation only; never on the haptic servo path
  std::vector<NodeSpring> pending_springs_;
  bool springs_changed_ = false;
  std::vector<NodeSpring> active_springs_;  // simulation thread's copy
  ServoLoop* haptic_servo_ = nullptr;
  // What a hand holds and does with it, and the device that moves it.
  struct HandInLoop {
    std::optional<Tool> pending_tool;                       // under springs_mutex_
    bool tool_changed = false;                              // under springs_mutex_
    std::optional<DeviceToolSettings> pending_device_tool;  // under springs_mutex_
    bool device_tool_changed = false;                       // under springs_mutex_
    double pending_device_tool_from_s = 0.0;                // under springs_mutex_
    std::optional<DeviceToolSettings> device_tool;          // simulation thread's copy
    double device_tool_from_s = 0.0;
    std::optional<DeviceSample> device_sample;  // the servo's newest frame of the hand's device
    std::optional<Tool> active_tool;            // simulation thread's copy
    std::optional<ToolInteraction> tools;       // simulation thread only once started
    BladeStroke stroke;
    bool blade_in_tissue = false;  // the scalpel broke in: its blade passes and cuts
    // Taken away in the tissue: its stroke's remnants are parted once no lock is held
    // (part_remnants_due), and then the stroke ends.
    bool remnants_due = false;
    Eigen::Vector3d cutting_force_n = Eigen::Vector3d::Zero();  // on the blade, while it cuts
    double blade_edge_in_tissue_m = 0.0;           // of the scalpel's edge, after the last cycle
    std::vector<std::uint8_t> blade_node_scratch;  // edge_in_tissue's, a byte per node
    Eigen::Vector3d blade_velocity_m_per_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d blade_middle_m = Eigen::Vector3d::Zero();
    double blade_time_s = -1.0;  // when blade_middle_m was; < 0: not yet
    bool acts() const { return tools && active_tool; }
    void end_stroke();  // the blade is out: the next cut needs a new break-in
  };
  std::array<HandInLoop, kHands.size()> hands_;
  HandInLoop& hand(Hand which) { return hands_[hand_index(which)]; }
  // A step's springs: the set ones, the tools' and the bodies' contacts'.
  std::vector<NodeSpring> step_springs_;
  ContactSettings contact_settings_;
  GraspSettings grasp_settings_;
  std::optional<CuttingSettings> cutting_;
  std::uint64_t topology_version_ = 0;
  double resected_volume_m3_ = 0.0;
  // The field: the organ's box at rest, kFieldMarginM larger; the free bodies now (refreshed when
  // the model changes) and those taken out.
  Eigen::AlignedBox3d field_m_;
  std::vector<FreeBody> free_bodies_;
  BodyContact body_contact_;  // between the organ and the free bodies (none: inactive)
  // The hands' tools hold boundary_surface(*model_), the one body_contact_ is built on (a cut's
  // swap_in builds both from it), not a surface enable_tools was given.
  bool tools_hold_model_boundary_ = false;
  int specimens_taken_out_ = 0;
  double specimens_taken_out_m3_ = 0.0;
  std::atomic<bool> take_out_requested_{false};
  // A cut's or a take-out's new model and state swapped in (tools, springs and tracking follow);
  // `body`: the free body a take-out removed (kept as a specimen).
  void swap_in(CutResult change, std::span<const TetIndex> body = {});
  // Free bodies out of the field (or all of them) taken out; true if any was.
  bool take_out_free_bodies(bool all);
  IntegratorKind integrator_kind_;  // the model's, fixed: stats() reads it from any thread
  // Extends the hand's stroke with its scalpel's edge, cuts, and swaps in the cut model and state.
  void cut_with_scalpel(HandInLoop& hand);
  // At the end of the hand's stroke: the holes and strands its cut left are parted (part_remnants).
  void part_remnants_of(HandInLoop& hand);
  // The surface hierarchy the last step refitted: the first acting hand's (tool_inputs in
  // advance_cycle); the other hand queries it. Only while a hand acts.
  const SurfaceBvh& step_hierarchy() const;
  void part_remnants_due();
  // A cut of the hand's scalpel swapped in (when it cut), and traced with the update's time.
  void swap_in_cut(const HandInLoop& hand, CutResult cut,
                   std::chrono::steady_clock::time_point update_start);
  // While the blade cuts: the tissue's resistance to it (CuttingSettings), from its edge `edge`
  // and that edge's stretch in the tissue.
  void resist_cutting(HandInLoop& hand, const std::array<Eigen::Vector3d, 2>& edge,
                      const EdgeInTissue& in);
  bool any_blade_in_tissue() const;
  // Takes the inputs set from other threads (springs, tool, device tool) for the next cycle.
  void take_inputs();
  void change_tool(Hand hand, const std::optional<Tool>& tool);
  // The loop's: logged, then change_tool.
  void take_tool(Hand hand, const std::optional<Tool>& tool);
  // A cycle's steps, guarded, and the cut of a scalpel in the tissue after them.
  GuardedReport advance_cycle(int steps, bool check_energy);
  // A cycle's publication: the snapshot, each hand's force model to the servo, the outcome's
  // observation. Outside the loop only the snapshot, so that the servo and the outcome see the
  // same cycles a replay does.
  enum class Publish { cycle, snapshot_only };
  void publish_cycle(Publish what = Publish::cycle);
  void log_input(SimulationInput input);  // simulation thread, when logging_inputs_
  std::atomic<bool> logging_inputs_{false};
  std::mutex input_log_mutex_;              // UI ↔ simulation only
  std::vector<SimulationInput> input_log_;  // under input_log_mutex_
  double haptic_servo_period_s() const;

  // Outcome tracking: asked for from any thread, begun and updated by the simulation thread.
  mutable std::mutex outcome_mutex_;  // UI ↔ simulation only
  std::optional<std::pair<std::optional<Eigen::Vector3d>, DamageStrains>> outcome_request_;
  std::optional<OutcomeTracking> outcome_;
  void observe_outcome();  // simulation thread, once per published cycle

  SpscRing<LoopRecord>* trace_ = nullptr;
  std::chrono::steady_clock::time_point loop_start_{};  // of the running loop, for the trace
  double trace_wall_s() const;

  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> give_up_cycle_{false};  // stop(): the cycle under way ends early
  std::atomic<bool> loop_ended_{false};
  // Statistics, written by the simulation thread once per window; each field on its own (a reader
  // may see fields of two neighbouring windows, which is harmless for a display).
  std::atomic<double> steps_per_second_{0.0}, real_time_factor_{0.0}, smallest_step_s_{0.0};
  std::atomic<double> error_estimate_m_{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<double> wall_s_per_simulated_s_{0.0}, force_evaluations_per_simulated_s_{0.0},
      dropped_s_{0.0};
  std::atomic<bool> behind_{false}, stability_limited_{false};
  std::atomic<double> simulated_time_s_{0.0};  // state_.time_s as of the last published cycle
  std::atomic<double>* published_clock_s_ = nullptr;  // publish_time_to's
  StateCheckpoint checkpoint_;                        // simulation thread only
  std::atomic<int> rollbacks_{0}, rejected_inputs_{0};
  std::atomic<HealthProblem> last_problem_{HealthProblem::none};
  std::atomic<bool> halted_{false};
  std::atomic<bool> energy_created_{false};
  std::atomic<double> dissipated_fraction_{0.0};
  std::thread thread_;
};

}  // namespace liversim
