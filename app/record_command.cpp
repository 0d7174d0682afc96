#include "record_command.h"

#include "cli_commands.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/haptics.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "liversim/station/scripted_tools.h"
#include "liversim/station/workstation.h"
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
  // A device in the left hand too: its trajectory (in the same device frame as the right's) and
  // the tool it holds until its tool column says otherwise.
  std::optional<fs::path> left_trajectory;
  std::string left_tool = "hand";
  // The scripts play on the simulation's time, not the wall clock (--paced).
  bool paced = false;
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

// A session recorded headless by the workstation's own station (core/station): the display frames
// are this loop's, at the workstation's rate.
int record(const RecordOptions& options) {
  const sigset_t stop_signals = block_stop_signals();  // before any thread starts

  // Input first (a bad file is said before anything slow), then the database, then the scene.
  std::vector<TrajectoryPoint> script, left_script;
  std::optional<OpenedScenario> scenario;
  std::optional<ScriptedTools> tools;       // --tool, then the trajectory's tool column
  std::optional<ScriptedTools> left_tools;  // --left-tool, then the left trajectory's
  try {
    TrajectoryFile file = read_trajectory_file(options.trajectory);  // errors name file and line
    script = std::move(file.points);
    std::optional<TrajectoryFile> left_file;
    if (options.left_trajectory) left_file = read_trajectory_file(*options.left_trajectory);
    scenario = open_scenario_to_run(options.scenario);
    std::optional<AllowedTools> allowed;
    if (scenario) allowed = AllowedTools{scenario->scenario.tools, options.scenario->string()};
    tools.emplace(tool_for_the_hand(options.tool, allowed, "--tool"), file.tool_changes, allowed);
    if (left_file) {
      left_script = std::move(left_file->points);
      left_tools.emplace(tool_for_the_hand(options.left_tool, allowed, "--left-tool"),
                         left_file->tool_changes, allowed, Hand::left);
    }
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  double scripts_end_s = script.empty() ? 0.0 : script.back().time_s;
  if (!left_script.empty()) scripts_end_s = std::max(scripts_end_s, left_script.back().time_s);
  const double duration_s = options.duration_s.value_or(scripts_end_s);
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

  // What the station reports, on this thread.
  const Eigen::Quaterniond view_axes = opening_view_device_axes();
  std::optional<StorageError> failure;
  std::string not_saved;
  std::string device_fault;
  std::optional<SessionMetricsOutcome> metrics;
  StationListener listener;
  listener.device_tool = [&] { return scripted_tool_held(tools, view_axes); };
  listener.left_device_tool = [&] { return scripted_tool_held(left_tools, view_axes); };
  listener.trainee = [&] { return options.trainee.value_or(default_trainee_name()); };
  listener.recording_refused = [&](const StorageError& e) { failure = e; };
  listener.recording_stopped = [&](const StorageError& e) { failure = e; };
  listener.session_not_saved = [&](const std::string& error) { not_saved = error; };
  listener.device_stopped = [&](DeviceChoice, const std::string&, const std::string& fault) {
    device_fault = fault;
  };
  listener.session_metrics_stored = [&](const SessionMetricsOutcome& outcome) {
    metrics = outcome;
  };

  std::unique_ptr<Workstation> station;
  try {
    const fs::path folder = scenario ? scenario->file.parent_path() : fs::path();
    SceneSetup setup =
        scenario ? build_scene(scenario->scenario, folder) : default_scene(options.tet_count);
    station = std::make_unique<Workstation>(std::move(setup), std::move(scenario), listener);
  } catch (const std::exception& e) {
    return fail("cannot build the scene" +
                (options.scenario ? " of " + options.scenario->string() : std::string()) + ": " +
                e.what());
  }
  station->use_sessions(std::move(store), options.database);
  station->play_scripts_on_simulated_time(options.paced);
  // A device not calibrated: the workstation's first-use mapping in its opening view.
  const WorkspaceMapping mapping =
      first_use_mapping(station->setup().mesh.rest_position_m, view_axes);
  if (!left_script.empty())
    if (const std::optional<DeviceRefusal> refusal =
            station->use_left_device(std::move(left_script), *options.left_trajectory, mapping))
      return fail("cannot play the left hand's trajectory " + options.left_trajectory->string() +
                  ": " + refusal->detail);
  if (const std::optional<DeviceRefusal> refusal = station->use_device(
          DeviceChoice::scripted, mapping, std::move(script), options.trajectory))
    return fail("cannot play the trajectory " + options.trajectory.string() + ": " +
                refusal->detail);
  if (failure) {
    std::cerr << "liversim-cli: error: " << failure->what() << '\n';
    return 1;
  }
  const std::int64_t session = *station->recording_session();

  std::cout << "recording session " << session << " to " << options.database.string() << ": "
            << (station->scenario() ? station->scenario()->scenario.title : "Free practice") << " ("
            << station->setup().mesh.tet_count() << " tetrahedra), " << station->device_name()
            << ", tool " << (tools->held() ? tool_name(*tools->held()) : "hand")
            << (left_tools
                    ? std::string(", left hand's tool ") +
                          std::string(left_tools->held() ? tool_name(*left_tools->held()) : "hand")
                    : std::string())
            << ", " << number(duration_s) << (options.paced ? " s of simulated time" : " s")
            << std::endl;
  ServoLoop& servo = *station->servo();
  const double begin_s = servo.now_s();
  // Paced, the scripts' time (their tool columns' too) is the simulation's since this moment.
  const std::atomic<double>& simulated_s = station->simulated_clock_s();
  const double simulated_begin_s = simulated_s.load(std::memory_order_relaxed);
  const auto script_time_s = [&] {
    return options.paced ? simulated_s.load(std::memory_order_relaxed) - simulated_begin_s
                         : servo.now_s() - begin_s;
  };
  double next_progress_s = begin_s + options.progress_s.value_or(INFINITY);
  int stop_signal = 0;
  bool halted = false;
  while (true) {
    const double played_s = script_time_s();
    if (played_s >= duration_s) break;
    stop_signal =
        wait_for_stop_signal(stop_signals, std::min(kFramePeriodS, duration_s - played_s));
    if (stop_signal != 0) break;
    tools->advance(script_time_s(), servo.now_s(), *station);  // the script's tools
    if (left_tools) left_tools->advance(script_time_s(), servo.now_s(), *station);
    station->frame();
    if (failure) break;
    // Paced, a halted simulation's time stands still: the session ends with what it recorded.
    if (options.paced && station->simulation().stats().halted) {
      halted = true;
      break;
    }
    if (!device_fault.empty()) {
      // As the workstation: the session ended with what it recorded; the mouse took over.
      std::cerr << "liversim-cli: the device stopped: " << device_fault << '\n';
      break;
    }
    if (servo.now_s() >= next_progress_s) {
      const ResidentMemory memory = resident_memory();
      std::cout << std::fixed << std::setprecision(2) << "elapsed " << servo.now_s() - begin_s
                << " s" << (options.paced ? " (" + number(script_time_s()) + " s simulated)" : "")
                << ": " << station->recorded_frames() << " frames committed, VmRSS "
                << std::setprecision(1) << memory.now_mib << " MiB, VmHWM " << memory.peak_mib
                << " MiB" << std::endl;
      std::cout.unsetf(std::ios::floatfield);
      next_progress_s += *options.progress_s;
    }
  }
  if (halted)
    std::cerr << "liversim-cli: the simulation halted at " << number(script_time_s())
              << " s of the script: "
              << health_problem_text(station->simulation().stats().last_problem)
              << "; the session ends with what it recorded\n";
  // The servo's last command is a zero force, and its last frames are kept.
  station->stop();
  if (failure) return storage_failure(failure->what());
  if (!not_saved.empty()) return storage_failure(not_saved);
  station->finish_metrics();
  if (!metrics || !metrics->stored)
    return storage_failure(metrics && metrics->storage_problem ? metrics->storage_problem->what()
                           : metrics                           ? metrics->problem
                                                               : "no metrics were stored");
  const SessionSummary summary = [&] {
    for (const SessionSummary& s : station->sessions()->sessions())
      if (s.id == session) return s;
    return SessionSummary{};
  }();
  const double rate_hz = summary.servo ? summary.servo->rate_hz : 0.0;
  std::cout << "recorded session " << session << " (complete"
            << (stop_signal == SIGINT    ? ", ended by SIGINT"
                : stop_signal == SIGTERM ? ", ended by SIGTERM"
                                         : "")
            << "): " << summary.frame_count << " frames"
            << (summary.left_hand
                    ? " (and " + std::to_string(summary.left_frame_count) + " of the left hand)"
                    : "")
            << ", servo " << number(rate_hz) << " Hz, " << metrics->metrics.size()
            << " metrics stored in " << options.database.string() << std::endl;
  return 0;
}

}  // namespace

std::optional<DeviceToolSettings> scripted_tool_held(const std::optional<ScriptedTools>& hand,
                                                     const Eigen::Quaterniond& view_axes) {
  std::optional<DeviceToolSettings> held;
  if (!hand || !hand->held()) return held;
  held.emplace();
  held->kind = *hand->held();
  held->orientation = tool_orientation_from_view(view_axes);
  return held;
}

std::optional<OpenedScenario> open_scenario_to_run(const std::optional<fs::path>& file) {
  if (!file) return std::nullopt;
  auto read = read_scenario_to_run(*file);
  if (auto* errors = std::get_if<std::vector<ScenarioError>>(&read)) {
    std::string message = "cannot open the scenario " + file->string() + ":";
    for (const ScenarioError& error : *errors) message += "\n  " + error.text();
    throw std::runtime_error(message);
  }
  return std::get<OpenedScenario>(std::move(read));
}

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
                   "point: time_s x_mm y_mm z_mm buttons [tool]; a tool, hand, probe, forceps or "
                   "scalpel, is what the hand holds from that point on); it holds its last point "
                   "after the end")
      ->required();
  command
      ->add_option("--database", options->database, "Sessions database (.sqlite), created if new")
      ->required();
  command->add_option("--trainee", options->trainee, "Trainee the session is of (default: $USER)");
  command
      ->add_option("--duration", options->duration_s,
                   "Time to record, in seconds: wall time, or simulated time with --paced "
                   "(default: the trajectory's length)")
      ->check(CLI::PositiveNumber);
  command->add_flag(
      "--paced", options->paced,
      "Play the trajectories on the simulation's time instead of the wall clock: they "
      "wait for a simulation that falls behind, so what they do to the tissue does not "
      "turn on the machine's load (the session then takes as long as the simulation "
      "needs)");
  command
      ->add_option("--progress", options->progress_s,
                   "Print a line every this many seconds: elapsed time, frames committed, VmRSS "
                   "and VmHWM in MiB")
      ->check(CLI::PositiveNumber);
  command
      ->add_option(
          "--tool", options->tool,
          "Tool the device holds: hand (none, the workstation's default), probe, "
          "forceps or scalpel, until the trajectory's tool column says otherwise; its first "
          "button closes the forceps or arms the scalpel")
      ->capture_default_str();
  command->add_option(
      "--left-trajectory", options->left_trajectory,
      "A second scripted device, in the left hand (forceps holding while the right "
      "hand cuts): its trajectory, as --trajectory's, in the same device frame; the "
      "session records its frames, events and metrics as the right hand's, tagged left");
  auto* left_tool =
      command
          ->add_option("--left-tool", options->left_tool,
                       "Tool the left hand's device holds, as --tool (with --left-trajectory)")
          ->capture_default_str();
  return [options, command, tets, left_tool]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    if (options->scenario && tets->count() > 0)
      return fail(
          "--tets and --scenario cannot go together: the scenario sets the element count "
          "(organ.target_tet_count)");
    if (left_tool->count() > 0 && !options->left_trajectory)
      return fail("--left-tool needs --left-trajectory: the left hand's device plays it");
    return record(*options);
  };
}

}  // namespace liversim::cli
