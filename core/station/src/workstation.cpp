#include "liversim/station/workstation.h"

#include "liversim/engine/model_building.h"
#include "liversim/engine/worker_pool.h"
#include "liversim/haptics/openhaptics_device.h"
#include "liversim/sessions/outcome_metrics.h"
#include "liversim/sessions/session_replay.h"
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace liversim {
namespace {

std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Device millimetres are the scene's for the mouse.
const WorkspaceMapping kMouseMapping{};

}  // namespace

std::variant<OpenedScenario, std::vector<ScenarioError>> read_scenario_to_run(
    const std::filesystem::path& file) {
  // The exact text is what a recorded session refers to, so it is read once, here.
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    ScenarioReading reading = read_scenario_file(file);  // names why it cannot be read
    if (reading.scenario)  // readable after all (a race with the file's creation)
      return read_scenario_to_run(file);
    return std::move(reading.errors);
  }
  std::string text(std::istreambuf_iterator<char>(in), {});
  ScenarioReading reading = read_scenario(text);
  if (!reading.scenario) {
    // The file's own errors name no file: the text came from it.
    return std::move(reading.errors);
  }
  return OpenedScenario{std::move(*reading.scenario), std::filesystem::absolute(file),
                        std::move(text)};
}

std::string default_trainee_name() {
  const char* user = std::getenv("USER");
  return user != nullptr && *user != '\0' ? user : "Trainee";
}

std::string describe_tissue(const TissueSpec& tissue, const EffectsSpec& effects) {
  std::ostringstream text;
  text << "E " << tissue.elastic.youngs_modulus_pa << " Pa, nu " << tissue.elastic.poisson_ratio
       << ", density " << tissue.elastic.density_kg_per_m3 << " kg/m3, fracture toughness "
       << tissue.fracture_toughness_j_per_m2 << " J/m2, blade friction "
       << tissue.blade_friction_n_per_m << " N/m";
  if (effects.viscoelastic && tissue.viscoelastic)
    text << ", E1 " << tissue.viscoelastic->e1_pa << " Pa, eta1 " << tissue.viscoelastic->eta1_pa_s
         << " Pa s";
  if (effects.viscoplastic && tissue.viscoplastic)
    text << ", yield limit " << tissue.viscoplastic->yield_limit_pa << " Pa, eta2 "
         << tissue.viscoplastic->eta2_pa_s_pow_n << " Pa s^n, n "
         << tissue.viscoplastic->creep_index_n;
  if (effects.fibres && tissue.fibres)
    text << ", k1 " << tissue.fibres->k1_pa << " Pa, k2 " << tissue.fibres->k2;
  return text.str();
}

std::string describe_gravity(const EffectsSpec& effects) {
  if (!effects.gravity) return "off";
  const auto& d = effects.gravity_direction;
  std::ostringstream text;
  text << effects.gravity_m_per_s2 << " m/s2 toward (" << d[0] << ", " << d[1] << ", " << d[2]
       << ")";
  return text.str();
}

Workstation::Workstation(SceneSetup setup, std::optional<OpenedScenario> scenario,
                         StationListener listener)
    : listener_(std::move(listener)), scenario_(std::move(scenario)) {
  auto model = std::make_shared<const SimModel>(build_model(setup.mesh, setup.model_options));
  install_scene(std::move(setup), std::move(model));
  simulation_->start();
}

Workstation::~Workstation() {
  builder_.wait();
  stop();
  finish_metrics();
}

void Workstation::stop() {
  simulation_->stop();
  detach_device();  // the servo's last command is a zero force; a session ends (its metrics start)
}

// --- The scene ---------------------------------------------------------------------------------

void Workstation::install_scene(SceneSetup setup, std::shared_ptr<const SimModel> model) {
  // The visual surface's triangles are the physics boundary's (its vertex i is node nodes[i]).
  auto simulation = make_scene_simulation(model, setup.visual.surface);
  if (simulation_) {
    // The hand lets go of the old liver; a device stays attached.
    hand_springs_.clear();
    simulation_->stop();
  }
  simulation_ = std::move(simulation);
  simulation_->publish_time_to(&simulated_clock_s_);
  setup_ = std::move(setup);
  scene_model_ = std::move(model);
  shown_topology_ = 0;
  free_practice_changed_ = false;
}

void Workstation::restart_from_rest() {
  simulation_->stop();
  // An integrator changed on a cut liver: the scene's model with it, built now.
  if (scene_model_->integrator != setup_.model_options.integrator)
    scene_model_ = std::make_shared<const SimModel>(build_model(setup_.mesh, setup_.model_options));
  simulation_ = make_scene_simulation(scene_model_, setup_.visual.surface);
  simulation_->publish_time_to(&simulated_clock_s_);
  if (!hand_springs_.empty()) simulation_->set_springs(hand_springs_);
  attach_device();
  shown_topology_ = 0;
  if (listener_.scene_restarted) listener_.scene_restarted();
  simulation_->log_inputs(true);
  simulation_->start();
}

Scenario Workstation::described_scenario() const {
  if (scenario_) return scenario_->scenario;
  // Free practice: the built-in liver's parenchyma (region 0), the effects its model has.
  const ModelOptions& options = setup_.model_options;
  const RegionMaterial& parenchyma = options.regions.at(0);
  Scenario s;
  s.lesions.clear();
  s.parenchyma.elastic = parenchyma.tissue;
  s.parenchyma.viscoelastic = parenchyma.viscoelastic;
  s.parenchyma.viscoplastic = parenchyma.viscoplastic;
  s.parenchyma.fracture_toughness_j_per_m2 = parenchyma.fracture_toughness_j_per_m2;
  s.parenchyma.blade_friction_n_per_m = parenchyma.blade_friction_n_per_m;
  if (parenchyma.fibres && !options.fibre_field.first_family.empty()) {
    const Eigen::Vector3d& d = options.fibre_field.first_family.front();
    s.parenchyma.fibres =
        FibreSpec{parenchyma.fibres->k1_pa, parenchyma.fibres->k2, {d.x(), d.y(), d.z()}};
  }
  s.effects = {options.average_nodal_pressure, parenchyma.viscoelastic.has_value(),
               parenchyma.viscoplastic.has_value(), s.parenchyma.fibres.has_value()};
  if (const Eigen::Vector3d& g = options.gravity_m_per_s2; !g.isZero(0.0)) {
    s.effects.gravity = true;
    const Eigen::Vector3d down = g.normalized();
    s.effects.gravity_m_per_s2 = g.norm();
    s.effects.gravity_direction = {down.x(), down.y(), down.z()};
  }
  s.organ.target_tet_count = setup_.built_in_liver_tets.value_or(s.organ.target_tet_count);
  s.integrator = options.integrator;
  return s;
}

bool Workstation::busy_building() const {
  return changing_integrator_ || changing_tissue_ || changing_gravity_ || opening_scenario_;
}

bool Workstation::open_scenario(OpenedScenario opened, const std::filesystem::path& folder) {
  if (busy_building()) return false;
  builder_.wait();  // the last one has reported back
  opening_scenario_ = true;
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  build_cancelled_ = cancelled;
  builder_.start([this, opened = std::move(opened), folder, cancelled]() mutable {
    std::shared_ptr<SceneSetup> setup;
    std::shared_ptr<const SimModel> model;
    std::string error;
    try {
      // A surface model is meshed first: each attempt is reported.
      const auto progress = [this, cancelled](const MeshingProgress& p) {
        std::lock_guard lock(progress_mutex_);
        progress_.push_back(p);
        return !*cancelled;
      };
      setup = std::make_shared<SceneSetup>(build_scene(opened.scenario, folder, progress));
      model = std::make_shared<const SimModel>(build_model(setup->mesh, setup->model_options));
    } catch (const std::exception& e) {
      error = e.what();
    }
    built_ = [this, opened = std::move(opened), setup, model, error] {
      opening_scenario_ = false;
      const bool cancelled = build_cancelled_ && *build_cancelled_;
      build_cancelled_.reset();
      SceneOpening opening;
      const auto report = [&] {
        if (listener_.scene_opened) listener_.scene_opened(opening);
      };
      if (cancelled) {  // asked for: not an error, and whatever was built is dropped
        opening.result = SceneOpening::Result::cancelled;
        return report();
      }
      if (!model) {
        opening.error = error;
        return report();
      }
      // The device stays; its session was of the old scene: it ends (with the old scene's
      // outcome) and another begins on the new one.
      const bool recording = recorder_ != nullptr;
      end_recording();
      if (listener_.scene_leaving) listener_.scene_leaving();
      try {
        install_scene(std::move(*setup), model);
      } catch (const std::exception& e) {
        simulation_->start();  // nothing was replaced: the old scene goes on
        if (recording) begin_recording();
        opening.error = e.what();
        return report();
      }
      scenario_ = opened;
      attach_device();
      simulation_->start();
      opening.result = SceneOpening::Result::opened;
      report();
      if (recording) begin_recording();
    };
  });
  return true;
}

void Workstation::cancel_scene_build() {
  if (build_cancelled_) *build_cancelled_ = true;
}

bool Workstation::change_integrator(const IntegratorSettings& settings) {
  if (busy_building()) return false;
  changing_integrator_ = true;
  ModelOptions options = setup_.model_options;
  options.integrator = settings;
  // A cut liver is not the scene's mesh any more: its model is taken as it is.
  std::shared_ptr<const SimModel> cut =
      shown_topology_ > 0 ? simulation_->snapshot().model : nullptr;
  // Reads setup_.mesh on the worker: it changes only when no model is being built.
  start_model_change(
      {settings, std::nullopt, std::nullopt}, [this, options = std::move(options), settings, cut] {
        ModelChangeBuilt built;
        if (cut) {
          validate_integrator(settings);
          auto changed = std::make_shared<SimModel>(*cut);
          changed->integrator = settings;
          changed->stable_time_step_s = stable_time_step_s(*changed, StepInputs{});
          built.model = std::move(changed);
        } else {
          // build_model checks the settings first, so a bad entry is refused at once.
          built.model = std::make_shared<const SimModel>(build_model(setup_.mesh, options));
          built.rest_model = built.model;
        }
        return built;
      });
  return true;
}

bool Workstation::change_tissue(const TissueSpec& tissue) {
  if (changing_tissue_) {  // the newest entry is applied after the one being applied
    pending_tissue_ = tissue;
    return true;
  }
  if (busy_building()) return false;
  Scenario described = described_scenario();
  described.parenchyma = tissue;
  std::vector<RegionMaterial> regions = region_materials(described);
  changing_tissue_ = true;
  // The model running (cut or not) and the scene's uncut one, which a restart from rest runs.
  std::shared_ptr<const SimModel> running = simulation_->snapshot().model;
  std::shared_ptr<const SimModel> rest = scene_model_;
  start_model_change(
      {std::nullopt, tissue, std::nullopt}, [regions = std::move(regions), running, rest] {
        return changed_models(running, rest,
                              [&](SimModel& model) { set_region_materials(model, regions); });
      });
  return true;
}

Workstation::ModelChangeBuilt Workstation::changed_models(
    const std::shared_ptr<const SimModel>& running, const std::shared_ptr<const SimModel>& rest,
    const std::function<void(SimModel&)>& change) {
  const auto changed = [&](const SimModel& model) {
    auto copy = std::make_shared<SimModel>(model);
    change(*copy);
    return copy;
  };
  ModelChangeBuilt built;
  built.model = changed(*running);
  built.rest_model = running == rest ? built.model : changed(*rest);
  return built;
}

bool Workstation::change_gravity(bool on) {
  if (busy_building()) return false;
  EffectsSpec effects = described_scenario().effects;
  effects.gravity = on;
  const Eigen::Vector3d gravity_m_per_s2 = gravity_acceleration_m_per_s2(effects);
  changing_gravity_ = true;
  std::shared_ptr<const SimModel> running = simulation_->snapshot().model;
  std::shared_ptr<const SimModel> rest = scene_model_;
  // Reads setup_.mesh on the worker: it changes only when no model is being built.
  start_model_change({std::nullopt, std::nullopt, on}, [this, gravity_m_per_s2, running, rest] {
    // The support is the scene's organ at rest: the same under a cut liver.
    std::shared_ptr<const SupportSurface> support;
    if (!gravity_m_per_s2.isZero(0.0))
      support =
          std::make_shared<const SupportSurface>(support_under(setup_.mesh, gravity_m_per_s2));
    return changed_models(running, rest,
                          [&](SimModel& model) { set_gravity(model, gravity_m_per_s2, support); });
  });
  return true;
}

void Workstation::start_model_change(ModelChange change, std::function<ModelChangeBuilt()> build) {
  builder_.wait();  // the last one has reported back
  builder_.start([this, change = std::move(change), build = std::move(build)] {
    ModelChangeBuilt built;
    std::string error;
    try {
      built = build();
    } catch (const std::exception& e) {
      error = e.what();
    }
    built_ = [this, change, built, error] { finish_model_change(change, built, error); };
  });
}

void Workstation::finish_model_change(const ModelChange& change, const ModelChangeBuilt& built,
                                      const std::string& error) {
  ModelChangeOutcome outcome;
  outcome.kind = change.integrator ? ModelChangeOutcome::Kind::integrator
                 : change.gravity  ? ModelChangeOutcome::Kind::gravity
                                   : ModelChangeOutcome::Kind::tissue;
  const auto report = [&] {
    if (change.integrator)
      changing_integrator_ = false;
    else if (change.gravity)
      changing_gravity_ = false;
    else
      changing_tissue_ = false;
    if (listener_.model_changed) listener_.model_changed(outcome);
    if (change.tissue) apply_pending_tissue();
  };
  if (!built.model) {
    outcome.error = error;
    return report();
  }
  // Carry the liver's motion over: the same mesh, so the same node order.
  simulation_->stop();
  const SimState& old = simulation_->state();
  if (old.position_m.size() != built.model->node_count) {  // a cut came in while it was built
    simulation_->start();
    outcome.cut_meanwhile = true;
    return report();
  }
  // A recorded session's input log ends here: a replay does not follow a change of the model.
  if (recorder_) {
    simulation_->log_inputs(false);
    recorder_->record_inputs(simulation_->take_input_log());
  }
  const std::shared_ptr<const SimModel>& model = built.model;
  // The same mesh: a session's damage and lift tracking go on in the new simulation.
  std::optional<OutcomeTracking> tracking = simulation_->outcome();
  try {
    auto replacement = std::make_unique<RealtimeSimulation>(
        model, carry_state(old, *model, realtime_worker_pool()));
    simulation_ = std::move(replacement);
    simulation_->publish_time_to(&simulated_clock_s_);
    if (tracking) simulation_->track_outcome(std::move(*tracking));
  } catch (const std::exception& e) {
    if (recorder_) simulation_->log_inputs(true);  // the old one's log goes on
    simulation_->start();                          // the old one goes on where it stopped
    outcome.error = e.what();
    return report();
  }
  if (!hand_springs_.empty()) simulation_->set_springs(hand_springs_);
  simulation_->enable_tools(setup_.visual.surface);
  simulation_->enable_cutting();
  attach_device();
  simulation_->start();
  // Built from the scene's mesh (not a cut one): a restart from rest can use it.
  if (built.rest_model &&
      (built.rest_model != built.model ||
       (shown_topology_ == 0 && built.model->node_count == setup_.mesh.node_count())))
    scene_model_ = built.rest_model;
  const double now_s = servo_ ? servo_->now_s() : 0.0;
  if (change.integrator) {
    const IntegratorSettings& settings = *change.integrator;
    if (recorder_)
      recorder_->record_event({now_s, SessionEventKind::integrator_changed,
                               std::string(integrator_name(settings.kind))});
    setup_.model_options.integrator = settings;
  } else if (change.gravity) {
    setup_.model_options.gravity_m_per_s2 = model->gravity_m_per_s2;
    setup_.model_options.support = model->support;
    if (scenario_) {
      // Sessions recorded from now on store the scenario as it runs, so that they replay with it.
      scenario_->scenario.effects.gravity = *change.gravity;
      scenario_->text = write_scenario(scenario_->scenario);
    } else {
      free_practice_changed_ = true;
    }
    if (recorder_)
      recorder_->record_event({now_s, SessionEventKind::gravity_changed,
                               describe_gravity(described_scenario().effects)});
  } else {
    const TissueSpec& tissue = *change.tissue;
    const EffectsSpec effects = described_scenario().effects;  // a tissue change keeps them
    if (recorder_)
      recorder_->record_event(
          {now_s, SessionEventKind::material_changed, describe_tissue(tissue, effects)});
    setup_.model_options.regions = model->regions;
    if (scenario_) {
      // Sessions recorded from now on store the scenario as it runs, so that they replay with it.
      scenario_->scenario.parenchyma = tissue;
      scenario_->text = write_scenario(scenario_->scenario);
    } else {
      free_practice_changed_ = true;
    }
  }
  outcome.applied = true;
  report();
}

void Workstation::apply_pending_tissue() {
  if (!pending_tissue_) return;
  const TissueSpec next = *pending_tissue_;
  pending_tissue_.reset();
  change_tissue(next);
}

void Workstation::set_hand_springs(std::vector<NodeSpring> springs) {
  hand_springs_ = std::move(springs);
  simulation_->set_springs(hand_springs_);
}

void Workstation::clear_hand_springs() {
  hand_springs_.clear();
  simulation_->clear_springs();
}

std::optional<DeviceToolSettings> Workstation::device_tool(Hand hand) const {
  const auto& asked = hand == Hand::left ? listener_.left_device_tool : listener_.device_tool;
  return asked ? asked() : std::nullopt;
}

void Workstation::device_tool_changed(Hand hand, double from_servo_s) {
  if (servo_ && servo_->has_device(hand))
    simulation_->set_device_tool(hand, device_tool(hand), from_servo_s);
}

// --- A display frame ---------------------------------------------------------------------------

StationFrame Workstation::frame() {
  StationFrame frame;
  if (recorder_) {
    recorder_->record_inputs(simulation_->take_input_log());
    // Said when it happens, not at the session's end.
    if (!recording_failure_said_)
      if (const std::optional<StorageError> failure = recorder_->failure()) {
        recording_failure_said_ = true;
        if (listener_.recording_stopped) listener_.recording_stopped(*failure);
      }
  }
  if (simulation_->update_snapshot()) {
    const SimulationSnapshot& snapshot = simulation_->snapshot();
    frame.new_snapshot = true;
    frame.cut = snapshot.topology_version != shown_topology_ && snapshot.model;
    if (frame.cut) shown_topology_ = snapshot.topology_version;
    record_frame_events(snapshot, frame.cut);
  }
  check_device();
  {
    std::vector<MeshingProgress> progress;
    {
      std::lock_guard lock(progress_mutex_);
      progress.swap(progress_);
    }
    if (listener_.scene_build_progress && !(build_cancelled_ && *build_cancelled_))
      for (const MeshingProgress& report : progress) listener_.scene_build_progress(report);
  }
  if (builder_.done()) {
    builder_.wait();
    auto built = std::move(built_);
    built_ = nullptr;
    if (built) built();
  }
  if (metrics_worker_.done()) deliver_metrics();
  return frame;
}

void Workstation::record_frame_events(const SimulationSnapshot& snapshot, bool cut) {
  if (!recorder_ || !servo_ || !event_watch_) return;
  frame_events_.clear();
  event_watch_->observe(servo_->now_s(), snapshot, simulation_->stats(), cut, frame_events_);
  for (SessionEvent& event : frame_events_) recorder_->record_event(std::move(event));
}

// --- Devices -----------------------------------------------------------------------------------

std::string Workstation::open_omni(const std::string& library) {
  omni_library_ = library;
  OpenHapticsOpening omni = open_openhaptics_device(library);
  omni_ = std::move(omni.device);
  omni_problem_ = omni.problem;
  return omni_problem_;
}

std::string Workstation::right_device_name() const {
  if (own_device_) return own_device_->name();
  if (device_ == DeviceChoice::openhaptics && omni_) return omni_->name();
  return "haptic device";
}

std::string Workstation::device_name() const {
  return right_device_name() + (left_device_ ? "; left hand: " + left_device_->name() : "");
}

void Workstation::clear_left_device() {
  take_back_pending_omni();
  pending_left_device_.reset();
  pending_left_device_is_omni_ = false;
  left_device_changing_ = true;
}

void Workstation::take_back_pending_omni() {
  if (pending_left_device_is_station_omni_) omni_ = std::move(pending_left_device_);
  pending_left_device_is_station_omni_ = false;
}

std::optional<DeviceRefusal> Workstation::use_left_omni(const std::string& configuration,
                                                        const WorkspaceMapping& mapping) {
  using Reason = DeviceRefusal::Reason;
  if (auto problem = validate(mapping)) return DeviceRefusal{Reason::servo_failed, *problem};
  take_back_pending_omni();
  // A single Omni beside the mouse: the one the station holds open, while the right hand does
  // not use it, goes to the left hand (opened again, the runtime says it is open already).
  const bool lend =
      configuration == kDefaultOmniConfiguration && omni_ && device_ != DeviceChoice::openhaptics;
  if (lend) {
    pending_left_device_ = std::move(omni_);
  } else {
    OpenHapticsOpening omni = open_openhaptics_device(omni_library_, configuration.c_str());
    if (!omni.device) return DeviceRefusal{Reason::omni_unavailable, omni.problem};
    pending_left_device_ = std::move(omni.device);
  }
  pending_left_device_is_station_omni_ = lend;
  pending_left_device_is_omni_ = true;
  left_device_changing_ = true;
  left_mapping_ = mapping;
  return std::nullopt;
}

std::string Workstation::left_device_name() const {
  return left_device_ ? left_device_->name() : std::string();
}

std::unique_ptr<TrajectoryDevice> Workstation::make_scripted_device(
    std::vector<TrajectoryPoint> script, const std::filesystem::path& script_file) {
  auto device = std::make_unique<TrajectoryDevice>("Scripted: " + script_file.filename().string(),
                                                   std::move(script));
  if (scripts_paced_) device->play_on(&simulated_clock_s_);
  return device;
}

std::unique_ptr<ServoLoop> Workstation::make_servo(HapticDevice& device,
                                                   const WorkspaceMapping& mapping,
                                                   HapticDevice* left) {
  ServoLoop::Options options;
  options.mapping = mapping;
  options.left_mapping = left_mapping_;
  return left ? std::make_unique<ServoLoop>(device, *left, options)
              : std::make_unique<ServoLoop>(device, options);
}

std::optional<DeviceRefusal> Workstation::use_left_device(std::vector<TrajectoryPoint> script,
                                                          const std::filesystem::path& script_file,
                                                          const WorkspaceMapping& mapping) {
  using Reason = DeviceRefusal::Reason;
  if (script.empty()) return DeviceRefusal{Reason::no_trajectory, {}};
  if (auto problem = validate(mapping)) return DeviceRefusal{Reason::servo_failed, *problem};
  std::unique_ptr<HapticDevice> device;
  try {
    device = make_scripted_device(std::move(script), script_file);
  } catch (const std::exception& e) {
    return DeviceRefusal{Reason::no_trajectory, e.what()};
  }
  // The servo in use holds the old one (if any): the next use_device replaces both.
  take_back_pending_omni();
  pending_left_device_ = std::move(device);
  pending_left_device_is_omni_ = false;
  left_device_changing_ = true;
  left_mapping_ = mapping;
  return std::nullopt;
}

std::optional<DeviceRefusal> Workstation::use_device(DeviceChoice choice,
                                                     const WorkspaceMapping& mapping,
                                                     std::vector<TrajectoryPoint> script,
                                                     const std::filesystem::path& script_file) {
  using Reason = DeviceRefusal::Reason;
  HapticDevice* device = nullptr;
  std::unique_ptr<HapticDevice> owned;  // the devices the station makes: all but the Omni
  switch (choice) {
    case DeviceChoice::mouse:
      owned = std::make_unique<ManualDevice>();
      device = owned.get();
      break;
    case DeviceChoice::openhaptics:
      if (left_device_is_station_omni_ || pending_left_device_is_station_omni_)
        return DeviceRefusal{Reason::omni_unavailable,
                             "the Omni is in the left hand: put the left hand's device down "
                             "first"};
      if (!omni_) open_omni(omni_library_);
      if (!omni_) return DeviceRefusal{Reason::omni_unavailable, omni_problem_};
      device = omni_.get();
      break;
    case DeviceChoice::replay:
      if (replay_points_.empty()) return DeviceRefusal{Reason::no_replay_loaded, {}};
      owned = std::make_unique<TrajectoryDevice>(replay_name_, replay_points_);
      device = owned.get();
      break;
    case DeviceChoice::scripted:
      if (script.empty()) return DeviceRefusal{Reason::no_trajectory, {}};
      try {
        owned = make_scripted_device(std::move(script), script_file);
      } catch (const std::exception& e) {
        return DeviceRefusal{Reason::no_trajectory, e.what()};
      }
      device = owned.get();
      break;
  }
  const bool mouse = choice == DeviceChoice::mouse;
  std::unique_ptr<ServoLoop> servo;
  // The left hand's device: one chosen since the last device change, else the one in use.
  HapticDevice* left = left_device_changing_ ? pending_left_device_.get() : left_device_.get();
  try {
    servo = make_servo(*device,
                       mouse                            ? kMouseMapping
                       : choice == DeviceChoice::replay ? replay_mapping_
                                                        : mapping,
                       left);
  } catch (const std::exception& e) {
    return DeviceRefusal{Reason::servo_failed, e.what()};
  }
  simulation_->stop();
  detach_device();  // the old servo, which may hold the old left device, goes
  if (left_device_changing_) {
    if (left_device_is_station_omni_) omni_ = std::move(left_device_);  // lent back
    left_device_ = std::move(pending_left_device_);
    left_device_is_omni_ = pending_left_device_is_omni_;
    left_device_is_station_omni_ = pending_left_device_is_station_omni_;
    pending_left_device_is_station_omni_ = false;
    left_device_changing_ = false;
  }
  servo_ = std::move(servo);
  own_device_ = std::move(owned);
  mouse_ = mouse ? static_cast<ManualDevice*>(own_device_.get()) : nullptr;
  device_ = choice;
  attach_device();
  simulation_->start();
  servo_->start();
  if (!mouse) begin_recording();  // the mouse's begins with its first press
  return std::nullopt;
}

void Workstation::attach_device() {
  simulation_->trace_loop(loop_trace_);  // every simulation the station makes is traced alike
  if (!servo_) return;
  simulation_->set_haptic_servo(servo_.get());
  for (Hand hand : kHands)
    if (servo_->has_device(hand)) simulation_->set_device_tool(hand, device_tool(hand));
}

void Workstation::trace_loop(SpscRing<LoopRecord>* trace) {
  loop_trace_ = trace;
  const bool running = simulation_->running();
  simulation_->stop();
  simulation_->trace_loop(trace);
  if (running) simulation_->start();
}

void Workstation::detach_device() {
  if (!simulation_->running()) {
    simulation_->set_haptic_servo(nullptr);
    for (Hand hand : kHands) simulation_->set_device_tool(hand, std::nullopt);
  }
  if (servo_) servo_->stop();  // the last command is a zero force; its last frames are logged
  end_recording();
  servo_.reset();
  mouse_ = nullptr;
  own_device_.reset();
}

void Workstation::check_device() {
  if (!servo_) return;
  // The left hand's device stops its own force only; its fault is recorded once.
  if (recorder_ && !left_fault_recorded_ && servo_->has_device(Hand::left))
    if (const std::string left_fault = servo_->device_fault(Hand::left); !left_fault.empty()) {
      left_fault_recorded_ = true;
      recorder_->record_event(
          {servo_->now_s(), SessionEventKind::device_fault, left_fault, Hand::left});
    }
  const std::string fault = servo_->device_fault();
  if (fault.empty()) return;
  if (recorder_) recorder_->record_event({servo_->now_s(), SessionEventKind::device_fault, fault});
  // A vanished or broken device: its force is off already; the mouse takes over.
  const DeviceChoice stopped = device_;
  const std::string name = device_name();
  use_device(DeviceChoice::mouse, kMouseMapping);
  if (stopped == DeviceChoice::openhaptics) {
    // Its fault sticks: choosing it again opens it anew.
    omni_.reset();
    omni_problem_ = fault;
  }
  if (listener_.device_stopped) listener_.device_stopped(stopped, name, fault);
}

void Workstation::load_replay(std::int64_t session, const std::vector<ServoFrame>& frames,
                              const WorkspaceMapping& fallback) {
  // Mapped as it was recorded (sessions before schema 2 kept no mapping: the fallback).
  replay_mapping_ = fallback;
  if (sessions_)
    for (const SessionSummary& summary : sessions_->sessions())
      if (summary.id == session && summary.mapping) replay_mapping_ = *summary.mapping;
  replay_points_ = trajectory_of_frames(frames);
  replay_name_ = "Replay of session " + std::to_string(session);
}

// --- Sessions ----------------------------------------------------------------------------------

std::optional<StorageError> Workstation::open_sessions(const std::filesystem::path& file) {
  end_recording();
  sessions_.reset();
  std::unique_ptr<SessionStore> store;
  try {
    store = std::make_unique<SqliteSessionStore>(file);
  } catch (const StorageError& e) {
    sessions_file_.clear();
    training_centre_.reset();
    return e;
  }
  use_sessions(std::move(store), file);
  return std::nullopt;
}

void Workstation::use_sessions(std::unique_ptr<SessionStore> store,
                               const std::filesystem::path& file) {
  end_recording();
  sessions_ = std::move(store);
  sessions_file_ = file;
  if (servo_) begin_recording();
  restart_training_centre();
}

bool Workstation::begin_recording() {
  // A replay is not a new session: its input is already recorded. The mouse's session begins
  // with its first press.
  if (!sessions_ || !servo_ || recorder_ || device_ == DeviceChoice::replay) return true;
  if (mouse_ && !device_tool()) return true;
  SessionStart start;
  start.trainee = listener_.trainee ? listener_.trainee() : default_trainee_name();
  ReplaySetup replay;
  replay.integrator = setup_.model_options.integrator;
  replay.loop_step_s = simulation_->step_s();
  if (scenario_) {
    start.scenario_title = scenario_->scenario.title;
    start.scenario_text = scenario_->text;
    // An unsaved scenario's organ file is named from the working folder, as it was opened.
    replay.scenario_folder =
        (scenario_->file.empty() ? std::filesystem::current_path()
                                 : std::filesystem::absolute(scenario_->file).parent_path())
            .string();
  } else {
    // Free practice has no file: the text names the scene it ran.
    start.scenario_title = "Free practice";
    start.scenario_text = free_practice_text(setup_.mesh.tet_count());
    if (free_practice_changed_) {
      const Scenario described = described_scenario();
      start.scenario_text += ", changed: tissue " +
                             describe_tissue(described.parenchyma, described.effects) +
                             ", gravity " + describe_gravity(described.effects);
    }
    replay.built_in_liver_tets = setup_.built_in_liver_tets;
  }
  // Free practice stores only its element count: a tissue or gravity changed in it cannot be
  // built again.
  if (scenario_ || (setup_.built_in_liver_tets && !free_practice_changed_)) start.replay = replay;
  start.device = right_device_name();
  start.started_unix_ms = unix_ms_now();
  start.mapping = servo_->mapping();
  ServoLoop* servo = servo_.get();
  const bool two_hands = servo->has_device(Hand::left);
  if (two_hands) start.left_hand = LeftHandDevice{left_device_name(), servo->mapping(Hand::left)};
  dropped_before_recording_ = skip_earlier_servo_frames(*servo);
  left_dropped_before_recording_ = two_hands ? skip_earlier_servo_frames(*servo, Hand::left) : 0;
  recording_failure_said_ = false;
  left_fault_recorded_ = false;
  try {
    SessionRecorder::FrameSource left;
    if (two_hands)
      left = [servo](ServoFrame& frame) { return servo->next_logged_frame(Hand::left, frame); };
    recorder_ = std::make_unique<SessionRecorder>(
        *sessions_, start,
        [servo](ServoFrame& frame) { return servo->next_logged_frame(Hand::right, frame); },
        std::move(left), SessionRecorder::Options{});
  } catch (const StorageError& e) {
    if (listener_.recording_refused) listener_.recording_refused(e);
    return false;
  }
  for (const Hand hand : kHands) record_tool_choice(hand);
  // The session starts from rest, its simulation's input logged, so that it can be replayed.
  restart_from_rest();
  // Damage, lift and resection need the simulation: tracked while the session runs.
  const Scenario* running = scenario_ ? &scenario_->scenario : nullptr;
  track_session_outcome(*simulation_, running);
  event_watch_.emplace(running);
  return true;
}

bool Workstation::end_recording() {
  if (!recorder_) return true;
  simulation_->log_inputs(false);
  recorder_->record_inputs(simulation_->take_input_log());
  const ServoStats stats = servo_ ? servo_->stats() : ServoStats{};
  const std::uint64_t dropped =
      servo_ ? servo_->dropped_log_frames() - dropped_before_recording_ : 0;
  std::optional<SessionServoFigures> left_figures;
  if (servo_ && servo_->has_device(Hand::left))
    left_figures = servo_figures(servo_->stats(Hand::left), servo_->dropped_log_frames(Hand::left) -
                                                                left_dropped_before_recording_);
  const std::int64_t session = recorder_->session();
  event_watch_.reset();
  std::optional<OutcomeTracking> outcome = simulation_->outcome();
  simulation_->stop_tracking_outcome();
  if (!recorder_->finish(unix_ms_now(), servo_figures(stats, dropped), left_figures)) {
    const std::string error = recorder_->error();
    recorder_.reset();
    if (listener_.session_not_saved) listener_.session_not_saved(error);
    return false;
  }
  recorder_.reset();
  std::optional<WorkspaceMapping> left_mapping;
  if (servo_ && servo_->has_device(Hand::left)) left_mapping = servo_->mapping(Hand::left);
  compute_session_metrics(session, std::move(outcome),
                          servo_ ? servo_->mapping() : WorkspaceMapping{}, left_mapping);
  return true;
}

std::optional<std::int64_t> Workstation::recording_session() const {
  if (!recorder_) return std::nullopt;
  return recorder_->session();
}

void Workstation::record_tool_choice(Hand hand) {
  if (!recorder_ || !servo_ || !servo_->has_device(hand)) return;
  const std::optional<DeviceToolSettings> tool = device_tool(hand);
  // The hand holds no tool (tool_intervals reads any other name as none).
  recorder_->record_event({servo_->now_s(), SessionEventKind::tool_selected,
                           tool ? std::string(tool_name(tool->kind)) : "hand", hand});
}

std::optional<Eigen::Vector3d> Workstation::mark_lesion_under_tool() {
  if (!recorder_ || !servo_) return std::nullopt;
  const SimulationSnapshot& snapshot = simulation_->snapshot();
  const std::optional<Tool>& tool = snapshot.hand(Hand::right).tool;
  if (!tool || !snapshot.model) return std::nullopt;
  const Eigen::Vector3d rest_m =
      rest_point_nearest(*snapshot.model, snapshot.position_m, tool->pose.origin_m);
  recorder_->record_event({servo_->now_s(), SessionEventKind::lesion_marked, mark_detail(rest_m)});
  return rest_m;
}

int Workstation::take_out_specimens() {
  const int bodies = simulation_->snapshot().free_bodies;
  if (bodies > 0) simulation_->take_out_specimens();
  return bodies;
}

void Workstation::compute_session_metrics(std::int64_t session,
                                          std::optional<OutcomeTracking> outcome,
                                          const WorkspaceMapping& mapping,
                                          const std::optional<WorkspaceMapping>& left_mapping) {
  // The metrics of its trace, from what was stored, and of its simulation
  // (docs/session-metrics.md): a long session is hundreds of megabytes of frames, so they are
  // read and computed on a worker with its own connection, off the owner's thread.
  if (metrics_worker_.started()) deliver_metrics();  // one at a time
  ++pending_metrics_;
  std::optional<Scenario> scenario;
  if (scenario_) scenario = scenario_->scenario;
  metrics_worker_.start([this, file = sessions_file_, session, outcome = std::move(outcome),
                         scenario = std::move(scenario), mapping, left_mapping] {
    SessionMetricsOutcome result;
    result.session = session;
    try {
      SqliteSessionStore store{file};
      result.metrics = store_session_metrics(
          store, session, outcome, scenario ? &*scenario : nullptr, mapping, left_mapping);
      result.stored = true;
      if (scenario) result.rubric = grade_against_rubric(scenario->rubric, result.metrics);
    } catch (const StorageError& e) {
      result.storage_problem = e;
    } catch (const std::exception& e) {
      result.problem = e.what();
    }
    metrics_done_ = std::move(result);
  });
}

void Workstation::deliver_metrics() {
  metrics_worker_.wait();
  if (!metrics_done_) return;
  SessionMetricsOutcome result = std::move(*metrics_done_);
  metrics_done_.reset();
  --pending_metrics_;
  // A session's upload waits for its metrics: the link is asked to run once they are stored.
  if (result.stored && training_centre_) training_centre_->run_soon();
  if (listener_.session_metrics_stored) listener_.session_metrics_stored(result);
}

void Workstation::finish_metrics() {
  if (metrics_worker_.started()) deliver_metrics();
}

// --- The training centre -----------------------------------------------------------------------

std::filesystem::path Workstation::pulled_scenario_folder() const {
  if (sessions_file_.empty()) return {};
  return std::filesystem::absolute(sessions_file_).parent_path() / "training-centre-scenarios";
}

std::optional<std::string> Workstation::connect_training_centre(const ServerSettings& server,
                                                                const std::string& password) {
  if (!sessions_) return "There is no sessions database to upload from.";
  // A wrong log-in is said here, at once; a server out of reach is not: the link retries.
  try {
    PostgresSessionStore{server, password};
  } catch (const StorageError& e) {
    if (e.problem() == StorageProblem::refused || e.problem() == StorageProblem::not_a_database ||
        e.problem() == StorageProblem::newer_version)
      return std::string(e.what());
  }
  TrainingCentreLink link;
  link.server = server;
  link.password = password;
  link.sessions_database = sessions_file_;
  link.scenario_folder = pulled_scenario_folder();
  training_centre_.reset();  // the old link's run ends first
  training_centre_ = std::make_unique<TrainingCentreSync>(std::move(link));
  return std::nullopt;
}

void Workstation::restart_training_centre() {
  if (!training_centre_) return;
  // The same server and log-in, from the new file.
  TrainingCentreLink link = training_centre_->link();
  training_centre_.reset();
  link.sessions_database = sessions_file_;
  link.scenario_folder = pulled_scenario_folder();
  training_centre_ = std::make_unique<TrainingCentreSync>(std::move(link));
}

}  // namespace liversim
