#include "record_command.h"

#include "cli_commands.h"
#include "liversim/engine/model_building.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/haptics.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_recorder.h"
#include "liversim/sessions/session_recording.h"
#include "liversim/sessions/session_replay.h"
#include "liversim/simulation/realtime_simulation.h"
#include "liversim/storage/sqlite_session_store.h"

#include <CLI/CLI.hpp>

#include <signal.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace liversim::cli {
namespace {

namespace fs = std::filesystem;

struct RecordOptions {
  std::optional<fs::path> scenario;  // none: free practice on the built-in liver
  int tet_count = kDefaultLiverTetCount;
  fs::path trajectory;
  fs::path database;
  std::optional<std::string> trainee;  // none: $USER, as the workstation's default
  std::optional<double> duration_s;    // none: the trajectory's length
  std::optional<double> progress_s;
  std::string tool = "hand";  // the workstation's Tool panel starts on the hand
};

// The workstation's display frame: how often the recorder takes the simulation's input log and
// the display's events are looked for.
constexpr double kFramePeriodS = 0.016;

// A storage failure: said with the file and the cause (StorageError names both), and what was
// committed before stays. Exit code 1 (bad input is 2).
int storage_failure(const std::string& what) {
  std::cerr << "liversim-cli: error: " << what
            << "\nliversim-cli: the session was not saved whole; what was committed before is "
               "kept.\n";
  return 1;
}

// The process's resident memory now and at its peak (VmRSS, VmHWM of /proc/self/status), MiB.
struct ResidentMemory {
  double now_mib = NAN;
  double peak_mib = NAN;
};
ResidentMemory resident_memory() {
  ResidentMemory memory;
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    std::istringstream fields(line);
    std::string name;
    double kib = NAN;
    fields >> name >> kib;
    if (name == "VmRSS:") memory.now_mib = kib / 1024.0;
    if (name == "VmHWM:") memory.peak_mib = kib / 1024.0;
  }
  return memory;
}

// SIGINT and SIGTERM end the session normally: blocked in every thread (the threads started
// later inherit the mask) and taken by the main loop's wait, so no handler runs in a thread
// that holds a lock.
sigset_t block_stop_signals() {
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);
  return stop;
}

// Waits up to `seconds`; the signal that came, or 0.
int wait_for_stop_signal(const sigset_t& stop, double seconds) {
  seconds = std::max(seconds, 0.0);
  timespec timeout{};
  timeout.tv_sec = static_cast<time_t>(seconds);
  timeout.tv_nsec = static_cast<long>((seconds - static_cast<double>(timeout.tv_sec)) * 1e9);
  const int signal = sigtimedwait(&stop, nullptr, &timeout);
  return signal > 0 ? signal : 0;
}

// The scene a session runs: a scenario's (its exact text is stored with the session) or free
// practice on the built-in liver.
struct RecordedScene {
  std::optional<Scenario> scenario;
  std::string scenario_text;
  fs::path scenario_folder;
  SceneSetup setup;
};

// Reads the scenario (its errors are thrown, each naming its field); the scene is built later.
RecordedScene read_recorded_scenario(const RecordOptions& options) {
  RecordedScene scene;
  if (!options.scenario) return scene;
  const fs::path& file = *options.scenario;
  ScenarioReading reading = read_scenario_file(file);
  if (!reading.scenario) {
    std::string message = "cannot open the scenario " + file.string() + ":";
    for (const ScenarioError& error : reading.errors) message += "\n  " + error.text();
    throw std::runtime_error(message);
  }
  scene.scenario = std::move(reading.scenario);
  std::ifstream in(file, std::ios::binary);
  scene.scenario_text.assign(std::istreambuf_iterator<char>(in), {});
  scene.scenario_folder = fs::absolute(file).parent_path();
  return scene;
}

// The tool the device holds (none: the hand), checked against the tools the scenario allows.
std::optional<ToolKind> held_tool(const RecordOptions& options, const RecordedScene& scene) {
  if (options.tool == "hand") return std::nullopt;
  const std::optional<ToolKind> kind = tool_kind(options.tool);
  if (!kind)
    throw std::invalid_argument("--tool " + options.tool +
                                " is unknown: expected hand, probe, forceps or scalpel");
  if (scene.scenario && std::find(scene.scenario->tools.begin(), scene.scenario->tools.end(),
                                  *kind) == scene.scenario->tools.end()) {
    std::string allowed;
    for (const ToolKind tool : scene.scenario->tools)
      allowed += (allowed.empty() ? "" : ", ") + std::string(tool_name(tool));
    throw std::invalid_argument("--tool " + options.tool + " is not a tool the scenario " +
                                options.scenario->string() + " allows (it allows: hand" +
                                (allowed.empty() ? "" : ", " + allowed) + ")");
  }
  return kind;
}

std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

SessionStart session_start(const RecordOptions& options, const RecordedScene& scene,
                           const HapticDevice& device, const WorkspaceMapping& mapping) {
  SessionStart start;
  if (options.trainee) {
    start.trainee = *options.trainee;
  } else {
    const char* user = std::getenv("USER");
    start.trainee = user != nullptr && *user != '\0' ? user : "Trainee";
  }
  ReplaySetup replay;
  replay.integrator = scene.setup.model_options.integrator;
  if (scene.scenario) {
    start.scenario_title = scene.scenario->title;
    start.scenario_text = scene.scenario_text;
    replay.scenario_folder = scene.scenario_folder.string();
  } else {
    start.scenario_title = "Free practice";
    start.scenario_text = free_practice_text(scene.setup.mesh.tet_count());
    replay.built_in_liver_tets = scene.setup.built_in_liver_tets;
  }
  start.replay = replay;
  start.device = device.name();
  start.started_unix_ms = unix_ms_now();
  start.mapping = mapping;
  return start;
}

int record(const RecordOptions& options) {
  const sigset_t stop_signals = block_stop_signals();  // before any thread starts

  // Input first (a bad file is said before anything slow), then the database, then the scene.
  std::unique_ptr<TrajectoryDevice> device;
  RecordedScene scene;
  std::optional<ToolKind> tool;
  try {
    // Its errors name the file and the line.
    std::vector<TrajectoryPoint> points = load_trajectory(options.trajectory);
    try {
      // Named as the workstation names a scripted device.
      device = std::make_unique<TrajectoryDevice>(
          "Scripted: " + options.trajectory.filename().string(), std::move(points));
    } catch (const std::exception& e) {
      throw std::invalid_argument("cannot play the trajectory " + options.trajectory.string() +
                                  ": " + e.what());
    }
    scene = read_recorded_scenario(options);
    tool = held_tool(options, scene);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  const double duration_s = options.duration_s.value_or(device->duration_s());
  if (!(duration_s > 0.0))
    return fail("the trajectory " + options.trajectory.string() +
                " lasts 0 s: give the session's length with --duration");

  std::unique_ptr<SqliteSessionStore> store;
  try {
    // Opened for writing, it marks sessions left recording by a killed writer incomplete.
    store = std::make_unique<SqliteSessionStore>(options.database);
  } catch (const StorageError& e) {
    std::cerr << "liversim-cli: error: " << e.what() << '\n';
    return 1;
  }

  std::shared_ptr<const SimModel> model;
  try {
    scene.setup = scene.scenario ? build_scene(*scene.scenario, scene.scenario_folder)
                                 : default_scene(options.tet_count);
    model =
        std::make_shared<const SimModel>(build_model(scene.setup.mesh, scene.setup.model_options));
  } catch (const std::exception& e) {
    return fail("cannot build the scene" +
                (options.scenario ? " of " + options.scenario->string() : std::string()) + ": " +
                e.what());
  }
  const Scenario* scenario = scene.scenario ? &*scene.scenario : nullptr;

  // A device not calibrated: the workstation's first-use mapping in its opening view.
  const Eigen::Quaterniond view_axes = opening_view_device_axes();
  ServoLoop::Options servo_options;
  servo_options.mapping = first_use_mapping(scene.setup.mesh.rest_position_m, view_axes);
  ServoLoop servo(*device, servo_options);
  // The session starts from rest with its simulation's input logged, so that it can be replayed.
  std::unique_ptr<RealtimeSimulation> simulation =
      make_scene_simulation(model, scene.setup.visual.surface);
  simulation->set_haptic_servo(&servo);
  if (tool) {
    DeviceToolSettings held;
    held.kind = *tool;
    held.orientation = tool_orientation_from_view(view_axes);
    simulation->set_device_tool(held);
  }
  simulation->log_inputs(true);

  const SessionStart start = session_start(options, scene, *device, servo.mapping());
  const std::uint64_t dropped_before = skip_earlier_servo_frames(servo);
  std::unique_ptr<SessionRecorder> recorder;
  try {
    recorder = std::make_unique<SessionRecorder>(
        *store, start, [&servo](ServoFrame& frame) { return servo.next_logged_frame(frame); });
  } catch (const StorageError& e) {
    std::cerr << "liversim-cli: error: " << e.what() << '\n';
    return 1;
  }
  recorder->record_event({servo.now_s(), SessionEventKind::tool_selected,
                          tool ? std::string(tool_name(*tool)) : "hand"});
  track_session_outcome(*simulation, scenario);
  SessionEventWatch watch(scenario);

  std::cout << "recording session " << recorder->session() << " to " << options.database.string()
            << ": " << start.scenario_title << " (" << scene.setup.mesh.tet_count()
            << " tetrahedra), " << device->name() << ", tool " << options.tool << ", "
            << number(duration_s) << " s" << std::endl;
  simulation->start();
  servo.start();
  const double begin_s = servo.now_s();
  double next_progress_s = begin_s + options.progress_s.value_or(INFINITY);
  std::uint64_t shown_topology = 0;
  std::vector<SessionEvent> events;
  int stop_signal = 0;
  std::optional<StorageError> failure;
  while (true) {
    const double now_s = servo.now_s();
    if (now_s - begin_s >= duration_s) break;
    stop_signal =
        wait_for_stop_signal(stop_signals, std::min(kFramePeriodS, duration_s - (now_s - begin_s)));
    if (stop_signal != 0) break;
    recorder->record_inputs(simulation->take_input_log());
    if ((failure = recorder->failure())) break;
    if (simulation->update_snapshot()) {
      const SimulationSnapshot& snapshot = simulation->snapshot();
      const bool cut = snapshot.topology_version != shown_topology && snapshot.model;
      if (cut) shown_topology = snapshot.topology_version;
      events.clear();
      watch.observe(servo.now_s(), snapshot, simulation->stats(), cut, events);
      for (SessionEvent& event : events) recorder->record_event(std::move(event));
    }
    if (const std::string fault = servo.device_fault(); !fault.empty()) {
      // As the workstation: the session ends with what it recorded.
      recorder->record_event({servo.now_s(), SessionEventKind::device_fault, fault});
      std::cerr << "liversim-cli: the device stopped: " << fault << '\n';
      break;
    }
    if (servo.now_s() >= next_progress_s) {
      const ResidentMemory memory = resident_memory();
      std::cout << std::fixed << std::setprecision(2) << "elapsed " << servo.now_s() - begin_s
                << " s: " << recorder->frames_written() << " frames committed, VmRSS "
                << std::setprecision(1) << memory.now_mib << " MiB, VmHWM " << memory.peak_mib
                << " MiB" << std::endl;
      std::cout.unsetf(std::ios::floatfield);
      next_progress_s += *options.progress_s;
    }
  }

  // The servo first: its last command is a zero force, and its last frames are kept.
  servo.stop();
  simulation->stop();
  simulation->log_inputs(false);
  recorder->record_inputs(simulation->take_input_log());
  const std::optional<OutcomeTracking> outcome = simulation->outcome();
  simulation->stop_tracking_outcome();
  if (failure) return storage_failure(failure->what());
  const SessionServoFigures figures =
      servo_figures(servo.stats(), servo.dropped_log_frames() - dropped_before);
  if (!recorder->finish(unix_ms_now(), figures)) return storage_failure(recorder->error());
  const std::int64_t session = recorder->session();
  const std::int64_t frames = recorder->frames_written();
  recorder.reset();
  std::vector<MetricValue> metrics;
  try {
    metrics = store_session_metrics(*store, session, outcome, scenario, servo.mapping());
  } catch (const StorageError& e) {
    return storage_failure(e.what());
  }
  std::cout << "recorded session " << session << " (complete"
            << (stop_signal == SIGINT    ? ", ended by SIGINT"
                : stop_signal == SIGTERM ? ", ended by SIGTERM"
                                         : "")
            << "): " << frames << " frames, servo " << number(figures.rate_hz) << " Hz, "
            << metrics.size() << " metrics stored in " << options.database.string() << std::endl;
  return 0;
}

}  // namespace

std::function<std::optional<int>()> add_record_command(CLI::App& app) {
  auto options = std::make_shared<RecordOptions>();
  auto* command = app.add_subcommand(
      "record",
      "Record a session headless, as the workstation does: a scripted trajectory drives the tool "
      "through the 1 kHz servo on a scenario's scene (or free practice on the built-in liver); "
      "frames, events, input log, servo figures and metrics go to a sessions database. SIGINT or "
      "SIGTERM end the session normally (exit 0); a storage failure exits with 1, a bad input "
      "with 2");
  command->add_option("--scenario", options->scenario,
                      "Scenario file (scenarios/*.json); default: free practice on the built-in "
                      "liver, as the workstation starts");
  auto* tets = command
                   ->add_option("--tets", options->tet_count,
                                "Element count of the built-in liver (free practice only)")
                   ->check(CLI::Range(100, 2'000'000))
                   ->capture_default_str();
  command
      ->add_option("--trajectory", options->trajectory,
                   "Trajectory the scripted device plays, in device millimetres (a line per "
                   "point: time_s x_mm y_mm z_mm buttons); it holds its last point after the end")
      ->required();
  command
      ->add_option("--database", options->database, "Sessions database (.sqlite), created if new")
      ->required();
  command->add_option("--trainee", options->trainee, "Trainee the session is of (default: $USER)");
  command
      ->add_option("--duration", options->duration_s,
                   "Wall time to record, in seconds (default: the trajectory's length)")
      ->check(CLI::PositiveNumber);
  command
      ->add_option("--progress", options->progress_s,
                   "Print a line every this many seconds: elapsed time, frames committed, VmRSS "
                   "and VmHWM in MiB")
      ->check(CLI::PositiveNumber);
  command
      ->add_option("--tool", options->tool,
                   "Tool the device holds: hand (none, the workstation's default), probe, "
                   "forceps or scalpel; its first button closes the forceps or arms the scalpel")
      ->capture_default_str();
  return [options, command, tets]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    if (options->scenario && tets->count() > 0)
      return fail(
          "--tets and --scenario cannot go together: the scenario sets the element count "
          "(organ.target_tet_count)");
    return record(*options);
  };
}

}  // namespace liversim::cli
