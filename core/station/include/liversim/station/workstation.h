#pragma once
// The running workstation without a window (docs/architecture.md): the scene it runs (a scenario,
// or free practice on the built-in liver: its model and real-time simulation), live changes of the
// integrator and the tissue, the device that drives the tool through the 1 kHz servo, the
// recording of a session (its start, the recorder, the events of its display frames, the outcome
// tracking, its metrics), replays, and the training centre's link. The Qt workstation is widgets
// over it and `liversim-cli record` drives it headless: one flow, in one place.
//
// Threads. Every call is made from one thread, the owner's (the UI thread, or the CLI's loop),
// which calls frame() at display rate. Scenes and model changes are built on the station's own
// worker and a session's metrics are computed on another, each with its own connection; what they
// report reaches the owner through StationListener, always on the owner's thread (from frame(),
// or from the call that caused it), never from a worker.

#include "liversim/engine/background_job.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/haptic_device.h"
#include "liversim/haptics/haptics.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/grading.h"
#include "liversim/sessions/session_recorder.h"
#include "liversim/sessions/session_recording.h"
#include "liversim/sessions/session_store.h"
#include "liversim/simulation/realtime_simulation.h"
#include "liversim/storage/server_settings.h"
#include "liversim/storage/training_centre_sync.h"

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace liversim {

// What moves the tool. replay: the device input of a recorded session.
enum class DeviceChoice { mouse, openhaptics, scripted, replay };

// A scenario as the station runs it: its file (empty: tried from the editor, not saved) and the
// exact text it was read from, which a recorded session stores.
struct OpenedScenario {
  Scenario scenario;
  std::filesystem::path file;
  std::string text;
};

// A scenario file read for running: its exact text and the scenario, or why it cannot be run
// (each error names its field, value and what is expected; an unreadable file is one error).
std::variant<OpenedScenario, std::vector<ScenarioError>> read_scenario_to_run(
    const std::filesystem::path& file);

// The trainee a session is recorded for when none is named: $USER, else "Trainee".
std::string default_trainee_name();

// A tissue as a session event's detail (English, as the database keeps it): the parenchyma's
// parameters of the effects simulated.
std::string describe_tissue(const TissueSpec& tissue, const EffectsSpec& effects);
// Gravity as a session event's detail (English): "off", or its strength and direction.
std::string describe_gravity(const EffectsSpec& effects);

// A scene build that ended: opened, cancelled (asked for; not an error), or refused with why.
struct SceneOpening {
  enum class Result { opened, cancelled, refused };
  Result result = Result::refused;
  std::string error;  // refused: why (the builder's or the installer's message)
};

// A live change of the running model that ended: applied, or refused with why. `cut_meanwhile`:
// refused because the liver was cut while it was built (the change is to be entered again).
struct ModelChangeOutcome {
  enum class Kind { integrator, tissue, gravity };
  Kind kind = Kind::integrator;
  bool applied = false;
  bool cut_meanwhile = false;
  std::string error;
};

// A session's metrics, computed and stored after its end on a worker, or why not.
struct SessionMetricsOutcome {
  std::int64_t session = 0;
  bool stored = false;
  std::vector<MetricValue> metrics;
  RubricResult rubric;  // against the scenario's rubric (free practice: none)
  std::optional<StorageError> storage_problem;  // not stored: a storage failure
  std::string problem;                          // not stored: any other failure
};

// Why a device cannot be used (the device in use then stays): the detail is English.
struct DeviceRefusal {
  enum class Reason { omni_unavailable, no_replay_loaded, no_trajectory, servo_failed };
  Reason reason = Reason::servo_failed;
  std::string detail;
};

// What the owner hears. Each is optional; each is called on the owner's thread.
struct StationListener {
  // A surface model being meshed for a scene build: each attempt, before and after.
  std::function<void(const MeshingProgress&)> scene_build_progress;
  // The scene shown is about to be replaced by one opened: the hand and the mouse let go of it.
  std::function<void()> scene_leaving;
  std::function<void(const SceneOpening&)> scene_opened;
  std::function<void(const ModelChangeOutcome&)> model_changed;
  // The scene started again from rest, uncut (a session begins so): its picture is redrawn.
  std::function<void()> scene_restarted;
  std::function<void(const SessionMetricsOutcome&)> session_metrics_stored;
  // A session could not begin: the database refused it (the station runs on without recording).
  std::function<void(const StorageError&)> recording_refused;
  // A session that ended was not saved whole (why); what was committed stays.
  std::function<void(const std::string&)> session_not_saved;
  // The session under way is no longer being saved (a full disk, a deleted or read-only file);
  // what was committed stays. Said once per session.
  std::function<void(const StorageError&)> recording_stopped;
  // The device in use stopped (unplugged, broken): its fault is a session event, and the mouse
  // has taken over. `device`: its name.
  std::function<void(DeviceChoice choice, const std::string& device, const std::string& fault)>
      device_stopped;
  // Asked, not told: what the device holds now (none: the hand, or the mouse between presses),
  // whenever a device is attached to a simulation and for the session's tool events.
  std::function<std::optional<DeviceToolSettings>()> device_tool;
  // The same for the left hand's device (use_left_device); unset: it holds nothing.
  std::function<std::optional<DeviceToolSettings>()> left_device_tool;
  // Asked whenever a session begins: whom it is of. Unset: default_trainee_name().
  std::function<std::string()> trainee;
};

// What one display frame brought.
struct StationFrame {
  bool new_snapshot = false;  // simulation().snapshot() is newer
  bool cut = false;           // and its model is a cut newer than the last frame's
};

// The Touch Setup name of the Omni OpenHaptics opens by default (HD_DEFAULT_DEVICE).
inline constexpr const char* kDefaultOmniConfiguration = "Default Device";

class Workstation {
 public:
  // Runs `setup` (built into its model here; throws std::invalid_argument for a model that cannot
  // be built) from rest; `scenario`: what it was built from (none: free practice). The simulation
  // starts at once; no device is attached until use_device().
  Workstation(SceneSetup setup, std::optional<OpenedScenario> scenario, StationListener listener);
  // Stops the servo and the simulation, ends a session under way (its metrics are computed and
  // stored before this returns) and waits for the workers.
  ~Workstation();
  Workstation(const Workstation&) = delete;
  Workstation& operator=(const Workstation&) = delete;

  // Stops the simulation and the device (the servo's last command is a zero force) and ends a
  // session under way, as the destructor does; its metrics are then being computed
  // (finish_metrics() waits for them).
  void stop();

  // A display frame: the recorder takes the simulation's input log, the newest snapshot is
  // taken, the events it shows are recorded, a device fault is handled and what the workers
  // finished is reported. Call it at display rate.
  StationFrame frame();

  // --- The scene ---------------------------------------------------------------------------------
  RealtimeSimulation& simulation() { return *simulation_; }
  const RealtimeSimulation& simulation() const { return *simulation_; }
  const SceneSetup& setup() const { return setup_; }
  const std::optional<OpenedScenario>& scenario() const { return scenario_; }
  // The scenario running, or free practice's tissue and effects as a scenario without lesions.
  Scenario described_scenario() const;
  // The integrator in use.
  const IntegratorSettings& integrator() const { return setup_.model_options.integrator; }

  // Builds the scene of `opened` on the worker (a surface model is meshed first: seconds) while the
  // scene shown runs on; then it runs in place of it, the device staying attached (a session under
  // way ends, with the old scene's outcome, and another begins on the new one). scene_opened
  // tells how it ended. `folder`: where its organ file is named relative to. False, doing nothing,
  // while a scene or a model change is being built.
  bool open_scenario(OpenedScenario opened, const std::filesystem::path& folder);
  // Stops the scene build under way: meshing stops at its next attempt; scene_opened(cancelled).
  void cancel_scene_build();

  // Rebuilds the model with these integrator settings on the worker, then runs on from the liver's
  // state (carry_state; a cut liver keeps its cut model). model_changed tells whether it was
  // applied. False, doing nothing, while a scene or a model change is being built.
  bool change_integrator(const IntegratorSettings& settings);
  // The parenchyma's tissue (a scenario's lesions follow as its file describes), applied as an
  // integrator change is, cut or not. A tissue asked for while one is being applied is applied
  // after it (only the newest). Sessions recorded afterwards store the scenario with this tissue.
  // False while a scene or an integrator change is being built.
  bool change_tissue(const TissueSpec& tissue);
  // Switches gravity on (the scenario's direction and strength; free practice's: toward the
  // patient's back, 9.81 m/s²) with the support the organ rests on, or off, applied as a tissue
  // change is, cut or not. Sessions recorded afterwards store the scenario with it. False while a
  // scene or another change of the model is being built.
  bool change_gravity(bool on);
  bool changing_integrator() const { return changing_integrator_; }
  bool changing_tissue() const { return changing_tissue_; }
  bool changing_gravity() const { return changing_gravity_; }
  bool opening_scenario() const { return opening_scenario_; }
  bool busy_building() const;
  // Free practice's tissue or gravity was changed: its sessions cannot be replayed (nothing can
  // rebuild it).
  bool free_practice_changed() const { return free_practice_changed_; }

  // Every simulation the station runs from now on (a session's start makes a new one) pushes its
  // loop's records into `trace` (RealtimeSimulation::trace_loop), which must outlive them; null:
  // none. For the live benchmarks: what the user meets, measured in the product's own loop.
  void trace_loop(SpscRing<LoopRecord>* trace);

  // The hand's springs (a mouse grab); kept across a restart of the simulation.
  void set_hand_springs(std::vector<NodeSpring> springs);
  void clear_hand_springs();
  // The device's tool changed (listener.device_tool says what it is now); from servo time
  // `from_servo_s` on (a press puts the tool down there: earlier frames must not show it).
  void device_tool_changed(double from_servo_s = -std::numeric_limits<double>::infinity()) {
    device_tool_changed(Hand::right, from_servo_s);
  }
  // The same for the device in `hand` (listener.left_device_tool for the left).
  void device_tool_changed(Hand hand, double from_servo_s);

  // --- Devices -----------------------------------------------------------------------------------
  // Looks for the Phantom Omni in the OpenHaptics runtime `library` (libHD.so, or a path): the
  // problem, empty when found. Choosing the Omni when it is not open looks again in the same one.
  std::string open_omni(const std::string& library);
  HapticDevice* omni() const { return omni_.get(); }
  const std::string& omni_problem() const { return omni_problem_; }
  // The device that moves the tool from now on, through a new servo mapping it by `mapping` (the
  // mouse's millimetres are always the scene's; a replay maps as its session did). `script`: the
  // scripted device's trajectory and its file. A session begins at once for every device but the
  // mouse, whose begins with its first press (begin_recording). The device in use stays when the
  // new one cannot be used.
  std::optional<DeviceRefusal> use_device(DeviceChoice choice, const WorkspaceMapping& mapping,
                                          std::vector<TrajectoryPoint> script = {},
                                          const std::filesystem::path& script_file = {});
  DeviceChoice device() const { return device_; }
  // Scripted devices chosen from now on (either hand's) play on the simulation's time instead of
  // the servo's wall clock (TrajectoryDevice::play_on): a script then waits for a simulation that
  // falls behind, so what it does to the tissue does not turn on the machine's load (`record
  // --paced`). Their frames are still recorded at the servo's rate; replays keep the servo's clock.
  // A restart from rest sets the simulation's time back to 0: a paced script then holds its point
  // until the time is back where the script began (record never restarts).
  void play_scripts_on_simulated_time(bool paced) { scripts_paced_ = paced; }
  // The clock paced scripts play on: every simulation the station runs stores its time there at
  // each published cycle, so it outlives a model change's new simulation.
  const std::atomic<double>& simulated_clock_s() const { return simulated_clock_s_; }
  // A device in the left hand too (issue 43: forceps in one hand hold while the other cuts),
  // driven by the same servo as the right hand's: a scripted trajectory (its file named in
  // `script_file`), mapped by `mapping`; its tool is listener.left_device_tool's. It is taken at
  // the next use_device, which makes the servo. Refused, the left hand staying as it was, for an
  // empty or bad script or a bad mapping. Sessions record its frames and its tool's events beside
  // the right hand's. The mouse cannot be the left hand's yet.
  std::optional<DeviceRefusal> use_left_device(std::vector<TrajectoryPoint> script,
                                               const std::filesystem::path& script_file,
                                               const WorkspaceMapping& mapping);
  // The same with an Omni in the left hand: the one OpenHaptics knows by `configuration`, its
  // name in Touch Setup ("Left Device" for a second Omni; kDefaultOmniConfiguration for a single
  // Omni beside the mouse: the Omni the station opened at open_omni goes to the left hand, and
  // comes back when the left hand's device next changes). Its force is written in the tick of the
  // right hand's device. Refused, naming the runtime's answer, when it cannot be opened (absent,
  // not configured, already open: an Omni in the left hand is closed by clear_left_device and the
  // next use_device).
  std::optional<DeviceRefusal> use_left_omni(const std::string& configuration,
                                             const WorkspaceMapping& mapping);
  // Whether the left hand's device in use is an Omni.
  bool left_device_is_omni() const { return left_device_is_omni_; }
  // The left hand's device goes at the next use_device.
  void clear_left_device();
  // The left hand's device, empty without one.
  std::string left_device_name() const;
  // The right hand's device's name, as sessions record it.
  std::string right_device_name() const;
  // Both hands' devices, as the interface names them.
  std::string device_name() const;
  ServoLoop* servo() const { return servo_.get(); }
  // The mouse while it is the device (place() and set() move it), else null.
  ManualDevice* mouse() const { return mouse_; }
  // The recorded session's device input, to be played by use_device(DeviceChoice::replay): its
  // frames (read by the caller, who may show progress) and the mapping it was recorded with
  // (from the sessions database; sessions before schema 2 kept none: `fallback`).
  void load_replay(std::int64_t session, const std::vector<ServoFrame>& frames,
                   const WorkspaceMapping& fallback);
  static constexpr std::uint32_t kMouseActionButton = 1;

  // --- Sessions ----------------------------------------------------------------------------------
  // Opens (or creates) the sessions database; the problem, when it cannot (the station then runs
  // without recording). A session under way ends first; the device's begins on the new one.
  std::optional<StorageError> open_sessions(const std::filesystem::path& file);
  // A store opened by the caller (who reported its problems first), of `file`.
  void use_sessions(std::unique_ptr<SessionStore> store, const std::filesystem::path& file);
  SessionStore* sessions() const { return sessions_.get(); }
  const std::filesystem::path& sessions_file() const { return sessions_file_; }
  // Begins a session of the device in use on the scene shown, if one can be recorded (a database,
  // a device; not a replay, not the mouse holding nothing) and none is: the scene restarts from
  // rest, its input logged, so that it replays. False when the database refused it
  // (recording_refused says why).
  bool begin_recording();
  // Ends the session under way (its servo's last frames are kept); its metrics are computed on a
  // worker (session_metrics_stored). False when it was not saved whole (session_not_saved).
  bool end_recording();
  std::optional<std::int64_t> recording_session() const;
  // Frames of the session under way committed so far (0 without one).
  std::int64_t recorded_frames() const { return recorder_ ? recorder_->frames_written() : 0; }
  // The tool the device in `hand` holds now as a session event (none without a device there).
  void record_tool_choice(Hand hand = Hand::right);
  // Palpation: the rest point of the liver under the tool as the trainee's mark of the lesion (a
  // lesion_marked event). None without a session or a tool in the scene.
  std::optional<Eigen::Vector3d> mark_lesion_under_tool();
  // Session ▸ Remove Specimen: every free body (a piece a cut freed) is taken out of the field at
  // the simulation's next cycle, kept as a specimen of the session and logged as its input, so
  // that a replay takes it out at the same step. The number of free bodies in the field now (0:
  // nothing to take out, nothing asked).
  int take_out_specimens();
  // Sessions whose metrics are being computed.
  int pending_metrics() const { return pending_metrics_; }
  // Waits for the metrics being computed and reports them.
  void finish_metrics();
  // The servo's figures of the session under way.
  std::uint64_t dropped_before_recording() const { return dropped_before_recording_; }

  // --- The training centre -----------------------------------------------------------------------
  // Uploads finished sessions and pulls published scenarios in the background (docs/
  // training-centre.md). A wrong log-in is refused here, at once, with why; a server out of reach
  // is not (the link retries). Needs a sessions database.
  std::optional<std::string> connect_training_centre(const ServerSettings& server,
                                                     const std::string& password);
  void disconnect_training_centre() { training_centre_.reset(); }
  TrainingCentreSync* training_centre() const { return training_centre_.get(); }
  // Where published scenarios are pulled: beside the sessions database; empty without one.
  std::filesystem::path pulled_scenario_folder() const;

 private:
  struct ModelChangeBuilt {
    std::shared_ptr<const SimModel> model;       // to run now
    std::shared_ptr<const SimModel> rest_model;  // the scene's uncut model with the change
  };
  struct ModelChange {
    std::optional<IntegratorSettings> integrator;
    std::optional<TissueSpec> tissue;
    std::optional<bool> gravity;
  };
  void install_scene(SceneSetup setup, std::shared_ptr<const SimModel> model);
  void restart_from_rest();
  void attach_device();
  void detach_device();
  std::optional<DeviceToolSettings> device_tool(Hand hand = Hand::right) const;
  // The station's Omni, lent to the left hand by a choice not yet taken, back to omni_.
  void take_back_pending_omni();
  // A scripted device playing `script` (throws for a bad one, as TrajectoryDevice does), paced when
  // play_scripts_on_simulated_time says so.
  std::unique_ptr<TrajectoryDevice> make_scripted_device(std::vector<TrajectoryPoint> script,
                                                         const std::filesystem::path& script_file);
  // A servo for `device` in the right hand, and `left` (if any) in the left.
  std::unique_ptr<ServoLoop> make_servo(HapticDevice& device, const WorkspaceMapping& mapping,
                                        HapticDevice* left);
  void start_model_change(ModelChange change, std::function<ModelChangeBuilt()> build);
  // The running model and the scene's rest one (the same when uncut), each copied and changed.
  static ModelChangeBuilt changed_models(const std::shared_ptr<const SimModel>& running,
                                         const std::shared_ptr<const SimModel>& rest,
                                         const std::function<void(SimModel&)>& change);
  void finish_model_change(const ModelChange& change, const ModelChangeBuilt& built,
                           const std::string& error);
  void finish_scene_build();
  void apply_pending_tissue();
  void check_device();
  void record_frame_events(const SimulationSnapshot& snapshot, bool cut);
  void compute_session_metrics(std::int64_t session, std::optional<OutcomeTracking> outcome,
                               const WorkspaceMapping& mapping,
                               const std::optional<WorkspaceMapping>& left_mapping);
  void deliver_metrics();
  void restart_training_centre();

  StationListener listener_;

  SceneSetup setup_;
  std::shared_ptr<const SimModel> scene_model_;  // setup_'s model, uncut, with the integrator
  // Declared before the simulations and devices that use it, so destroyed after them.
  std::atomic<double> simulated_clock_s_{0.0};
  std::unique_ptr<RealtimeSimulation> simulation_;
  std::optional<OpenedScenario> scenario_;
  std::uint64_t shown_topology_ = 0;  // the cut of the last frame's snapshot
  std::vector<NodeSpring> hand_springs_;
  SpscRing<LoopRecord>* loop_trace_ = nullptr;

  // Builds a scene or a model change; what it built waits here for frame().
  BackgroundJob builder_;
  std::function<void()> built_;  // written by the builder before it finishes
  std::shared_ptr<std::atomic<bool>> build_cancelled_;
  std::mutex progress_mutex_;              // owner ↔ builder
  std::vector<MeshingProgress> progress_;  // reported, not yet told (each is told)
  bool changing_integrator_ = false;
  bool changing_tissue_ = false;
  bool changing_gravity_ = false;
  bool opening_scenario_ = false;
  std::optional<TissueSpec> pending_tissue_;
  bool free_practice_changed_ = false;

  DeviceChoice device_ = DeviceChoice::mouse;
  std::unique_ptr<HapticDevice> omni_;
  std::string omni_library_ = "libHD.so";
  std::string omni_problem_;
  std::unique_ptr<HapticDevice> own_device_;   // the mouse, a script or a replay (not the Omni)
  std::unique_ptr<HapticDevice> left_device_;  // the left hand's (a script), if any
  std::unique_ptr<HapticDevice> pending_left_device_;  // chosen, for the next use_device
  bool left_device_changing_ = false;  // pending_left_device_ (null: none) replaces it
  bool left_device_is_omni_ = false, pending_left_device_is_omni_ = false;
  // The left hand's device (or the one chosen for it) is omni_, lent to it (a single Omni).
  bool left_device_is_station_omni_ = false, pending_left_device_is_station_omni_ = false;
  WorkspaceMapping left_mapping_;
  ManualDevice* mouse_ = nullptr;  // own_device_, while the mouse is the device
  bool scripts_paced_ = false;     // play_scripts_on_simulated_time's
  std::unique_ptr<ServoLoop> servo_;
  std::vector<TrajectoryPoint> replay_points_;
  WorkspaceMapping replay_mapping_;
  std::string replay_name_;

  std::unique_ptr<SessionStore> sessions_;
  std::filesystem::path sessions_file_;
  std::unique_ptr<SessionRecorder> recorder_;
  std::optional<SessionEventWatch> event_watch_;
  bool recording_failure_said_ = false;
  std::uint64_t dropped_before_recording_ = 0;
  std::uint64_t left_dropped_before_recording_ = 0;
  bool left_fault_recorded_ = false;
  std::vector<SessionEvent> frame_events_;  // scratch of frame()

  BackgroundJob metrics_worker_;
  std::optional<SessionMetricsOutcome> metrics_done_;  // written by the worker before it finishes
  int pending_metrics_ = 0;

  std::unique_ptr<TrainingCentreSync> training_centre_;
};

}  // namespace liversim
