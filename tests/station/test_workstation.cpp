// The running station without a window (core/station): recording a session of a device that drives
// the tool through the 1 kHz servo, the events of its display frames, its metrics, a database that
// vanishes mid-session, replays, live changes of the integrator and the tissue that carry the liver
// on, and a scenario opened while a session is recorded. The owner's display frames are this
// test's own loop; each wait ends on an event, with a limit that only catches a hang.
#include <gtest/gtest.h>

#include "liversim/engine/model_building.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/sessions/trace_metrics.h"
#include "liversim/station/workstation.h"
#include "liversim/storage/sqlite_session_store.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <thread>
#include <vector>

#include "../openhaptics/fake_hd_hooks.h"
#include "../ui/wait_limits.h"

namespace liversim {
namespace {

namespace fs = std::filesystem;

constexpr int kTetCount = 1500;
constexpr double kHangS = liversim::test::waitLimitMs(90'000) / 1000.0;

class StationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("liversim-station-" + std::to_string(::getpid()) + "-" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override {
    station_.reset();
    fs::remove_all(folder_);
  }

  // The built-in liver in free practice; the device holds `tool` (none: the hand).
  void open(std::optional<ToolKind> tool = std::nullopt) {
    SceneSetup setup = default_scene(kTetCount);
    mesh_ = setup.mesh;
    tool_ = tool;
    StationListener listener;
    listener.device_tool = [this]() -> std::optional<DeviceToolSettings> {
      if (!tool_) return std::nullopt;
      DeviceToolSettings held;
      held.kind = *tool_;
      held.orientation = tool_orientation_from_view(opening_view_device_axes());
      return held;
    };
    listener.left_device_tool = [this]() -> std::optional<DeviceToolSettings> {
      if (!left_tool_) return std::nullopt;
      DeviceToolSettings held;
      held.kind = *left_tool_;
      return held;
    };
    listener.trainee = [] { return std::string("Trainee One"); };
    listener.session_metrics_stored = [this](const SessionMetricsOutcome& outcome) {
      metrics_.push_back(outcome);
    };
    listener.recording_stopped = [this](const StorageError& e) { stopped_.push_back(e); };
    listener.model_changed = [this](const ModelChangeOutcome& outcome) {
      changes_.push_back(outcome);
    };
    listener.scene_opened = [this](const SceneOpening& opening) { openings_.push_back(opening); };
    listener.device_stopped = [this](DeviceChoice, const std::string&, const std::string& fault) {
      faults_.push_back(fault);
    };
    station_ = std::make_unique<Workstation>(std::move(setup), std::nullopt, std::move(listener));
  }

  // The station's display frames until `done`; false when it never came (a hang).
  template <typename Done>
  bool frameUntil(Done done) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(kHangS);
    while (!done()) {
      if (std::chrono::steady_clock::now() > give_up) return false;
      station_->frame();
      std::this_thread::sleep_for(std::chrono::milliseconds(4));
    }
    return true;
  }
  bool servoTicks(std::uint64_t ticks) {
    return frameUntil(
        [&] { return station_->servo() && station_->servo()->stats().ticks > ticks; });
  }
  const SimulationSnapshot& snapshot() const { return station_->simulation().snapshot(); }

  // A scripted device playing `points`, mapped mm for mm onto the scene.
  void play(const std::vector<TrajectoryPoint>& points) {
    const fs::path file = folder_ / "trajectory.txt";
    save_trajectory(file, points);
    ASSERT_FALSE(station_->use_device(DeviceChoice::scripted, WorkspaceMapping{},
                                      load_trajectory(file), file));
  }

  // The highest rest point of the liver within 8 mm (in x–y) of its centre, in mm.
  Eigen::Vector3d topOfTheMiddle_mm() const {
    Eigen::AlignedBox3d box;
    for (std::size_t n = 0; n < mesh_.rest_position_m.size(); ++n)
      box.extend(mesh_.rest_position_m.at(n));
    Eigen::Vector3d top(box.center().x(), box.center().y(),
                        -std::numeric_limits<double>::infinity());
    for (std::size_t n = 0; n < mesh_.rest_position_m.size(); ++n) {
      const Eigen::Vector3d p = mesh_.rest_position_m.at(n);
      if ((p.head<2>() - box.center().head<2>()).norm() < 0.008) top.z() = std::max(top.z(), p.z());
    }
    return top * 1e3;
  }

  fs::path folder_;
  TetMesh mesh_;
  std::optional<ToolKind> tool_;
  std::optional<ToolKind> left_tool_;  // what the left hand's device holds
  std::unique_ptr<Workstation> station_;
  std::vector<SessionMetricsOutcome> metrics_;
  std::vector<StorageError> stopped_;
  std::vector<ModelChangeOutcome> changes_;
  std::vector<SceneOpening> openings_;
  std::vector<std::string> faults_;  // device_stopped
};

// A device session from choosing the device to choosing the mouse again: its servo frames (the
// scripted trajectory's positions), the tool chosen, the servo's figures and its metrics, computed
// after its end; the mouse's session begins only with its first press.
TEST_F(StationTest, ADeviceSessionIsRecordedWithItsFramesToolFiguresAndMetrics) {
  open(ToolKind::forceps);
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  EXPECT_FALSE(station_->recording_session()) << "no device yet";
  const Eigen::Vector3d start_mm(5.0, 6.0, 40.0), end_mm(15.0, 6.0, 40.0);
  play({{0.0, start_mm, 0}, {0.4, end_mm, 1}, {600.0, end_mm, 1}});
  ASSERT_TRUE(station_->recording_session());
  const std::int64_t session = *station_->recording_session();
  ASSERT_TRUE(servoTicks(600));
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  EXPECT_FALSE(station_->recording_session())
      << "the mouse's session begins with its first press on the liver";
  ASSERT_TRUE(frameUntil([&] { return !metrics_.empty(); }));
  EXPECT_EQ(metrics_[0].session, session);
  ASSERT_TRUE(metrics_[0].stored) << metrics_[0].problem;
  EXPECT_EQ(station_->pending_metrics(), 0);

  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::complete);
  EXPECT_EQ(sessions[0].trainee, "Trainee One");
  EXPECT_EQ(sessions[0].scenario_title, "Free practice");
  EXPECT_EQ(sessions[0].device, "Scripted: trajectory.txt");
  ASSERT_TRUE(sessions[0].mapping);
  ASSERT_TRUE(sessions[0].servo);
  const std::vector<ServoFrame> frames = store.frames(session);
  // Every tick is a frame; the figures are those the servo published last, up to 50 ms before
  // it stopped.
  EXPECT_GE(frames.size(), sessions[0].servo->ticks);
  EXPECT_LE(frames.size(), sessions[0].servo->ticks + 100);
  EXPECT_EQ(sessions[0].servo->dropped_frames, 0u);
  EXPECT_LT((frames.back().sample.position_mm - end_mm).norm(), 1e-9);
  EXPECT_EQ(frames.back().sample.buttons, 1u);
  for (const ServoFrame& frame : frames) {
    const double along =
        (frame.sample.position_mm - start_mm).dot((end_mm - start_mm).normalized());
    ASSERT_GE(along, -1e-9);
    ASSERT_LE(along, 10.0 + 1e-9);
  }
  const std::vector<SessionEvent> events = store.events(session);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events[0].kind, SessionEventKind::tool_selected);
  EXPECT_EQ(events[0].detail, "forceps");
  // The path went straight, one way: its length is the distance from the first frame to the last.
  const std::vector<MetricValue> metrics = store.metrics(session);
  const auto path = std::find_if(metrics.begin(), metrics.end(),
                                 [](const MetricValue& m) { return m.name == "path_length_mm"; });
  ASSERT_NE(path, metrics.end());
  const double straight_mm =
      (frames.back().sample.position_mm - frames.front().sample.position_mm).norm();
  EXPECT_NEAR(path->value, straight_mm, 1e-9 * straight_mm);
  // Free practice: the trace's metrics, damage and resected volume; what was reported was stored.
  // (economy of motion too: the tool moved)
  EXPECT_EQ(metrics.size(), trace_metric_values(TraceMetrics{}).size() + 3);
  EXPECT_EQ(metrics_[0].metrics.size(), metrics.size());
  EXPECT_FALSE(metrics_[0].rubric.score_percent) << "free practice has no rubric";

  // The mouse: no session until it takes a tool to the liver, then one from rest.
  ASSERT_NE(station_->mouse(), nullptr);
  station_->mouse()->place(topOfTheMiddle_mm() + Eigen::Vector3d(0, 0, 30), 1);
  ASSERT_TRUE(station_->begin_recording());
  ASSERT_TRUE(station_->recording_session());
  EXPECT_NE(*station_->recording_session(), session);
}

// A file that cannot be a database is refused with its name; the device runs without recording.
TEST_F(StationTest, AFileThatIsNoDatabaseIsRefusedAndTheDeviceRunsWithoutRecording) {
  open();
  const fs::path not_a_database = folder_ / "notes.txt";
  std::ofstream(not_a_database) << "not a database\n";
  const std::optional<StorageError> problem = station_->open_sessions(not_a_database);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->problem(), StorageProblem::not_a_database);
  EXPECT_NE(std::string(problem->what()).find("notes.txt"), std::string::npos) << problem->what();
  EXPECT_EQ(station_->sessions(), nullptr);
  play({{0.0, Eigen::Vector3d(5.0, 6.0, 40.0), 0}, {600.0, Eigen::Vector3d(5.0, 6.0, 40.0), 0}});
  EXPECT_FALSE(station_->recording_session());
  ASSERT_TRUE(servoTicks(100)) << "the device runs without recording";
}

// The sessions database deleted while a device session is recorded: said once, at once; the
// simulation goes on, and the database opened again at its path records a new session whole.
TEST_F(StationTest, ADatabaseDeletedMidSessionIsSaidOnceAndTheNextSessionRecords) {
  open();
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  const std::vector<TrajectoryPoint> line{{0.0, Eigen::Vector3d(5.0, 6.0, 40.0), 0},
                                          {600.0, Eigen::Vector3d(15.0, 6.0, 40.0), 0}};
  play(line);
  ASSERT_TRUE(station_->recording_session());
  ASSERT_TRUE(servoTicks(300));
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(database.string() + suffix);
  ASSERT_TRUE(frameUntil([&] { return !stopped_.empty(); }));
  EXPECT_EQ(stopped_[0].problem(), StorageProblem::deleted) << stopped_[0].what();
  const double time_s = snapshot().time_s;
  ASSERT_TRUE(frameUntil([&] { return snapshot().time_s > time_s + 0.05; }))
      << "the simulation stopped with the recording";
  EXPECT_EQ(stopped_.size(), 1u) << "said once";

  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  ASSERT_FALSE(station_->open_sessions(database));
  play(line);
  ASSERT_TRUE(station_->recording_session());
  ASSERT_TRUE(servoTicks(300));
  metrics_.clear();
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  ASSERT_TRUE(frameUntil([&] { return !metrics_.empty(); }));
  EXPECT_TRUE(metrics_[0].stored) << metrics_[0].problem;
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  ASSERT_EQ(store.sessions().size(), 1u);
  EXPECT_EQ(store.sessions()[0].status, SessionStatus::complete);
  EXPECT_GT(store.sessions()[0].frame_count, 0);
}

// The simulation's events reach the session: scripted forceps closing on the top of the liver
// (the device's button), holding and opening again record a grasp, then a release.
TEST_F(StationTest, AGraspAndReleaseByTheDeviceAreSessionEvents) {
  open(ToolKind::forceps);
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  // First where the view holds the forceps: the grasp point's offset from the device's point.
  const Eigen::Vector3d above_mm = topOfTheMiddle_mm() + Eigen::Vector3d(0, 0, 40);
  play({{0.0, above_mm, 0}, {600.0, above_mm, 0}});
  ASSERT_TRUE(frameUntil([&] { return snapshot().hand(Hand::right).tool.has_value(); }));
  Tool closed = *snapshot().hand(Hand::right).tool;
  closed.jaw_opening = 0.0;
  const Eigen::Vector3d grasp_offset_m = forceps_grasp_point_m(closed) - closed.pose.origin_m;
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  // Then the grasp point on the top, jaws closed from 0.3 s to 1.5 s.
  const Eigen::Vector3d at_mm = topOfTheMiddle_mm() - grasp_offset_m * 1e3;
  play({{0.0, at_mm, 0}, {0.3, at_mm, 1}, {1.5, at_mm, 0}, {600.0, at_mm, 0}});
  ASSERT_TRUE(station_->recording_session());
  const std::int64_t session = *station_->recording_session();
  ASSERT_TRUE(frameUntil([&] { return snapshot().hand(Hand::right).grasping; }))
      << "the forceps took no hold";
  ASSERT_TRUE(frameUntil([&] { return !snapshot().hand(Hand::right).grasping; }))
      << "they did not let go";
  station_->frame();  // the display frame that sees the release
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  station_->finish_metrics();
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  std::vector<SessionEventKind> kinds;
  for (const SessionEvent& e : store.events(session))
    if (e.kind == SessionEventKind::grasp || e.kind == SessionEventKind::release)
      kinds.push_back(e.kind);
  const std::vector<SessionEventKind> expected{SessionEventKind::grasp, SessionEventKind::release};
  EXPECT_EQ(kinds, expected);
}

// A recorded session's device input plays back through the servo along the recorded line to its
// end, mapped as it was recorded; the replay is not recorded again.
TEST_F(StationTest, ARecordedSessionReplaysItsDeviceInputAndIsNotRecordedAgain) {
  open();
  const fs::path database = folder_ / "replay.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  const Eigen::Vector3d start_mm(-5.0, 0.0, 35.0), end_mm(-5.0, 12.0, 35.0);
  play({{0.0, start_mm, 0}, {0.3, end_mm, 1}, {600.0, end_mm, 1}});
  const std::int64_t session = *station_->recording_session();
  ASSERT_TRUE(servoTicks(500));
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  // The display has seen the mouse (at the origin), whose loop publishes until the next change:
  // none of its snapshots may be shown once the replay is chosen.
  ASSERT_TRUE(frameUntil([&] {
    const auto sample = snapshot().hand(Hand::right).device_sample;
    return sample && sample->position_mm.norm() == 0.0;
  }));
  const std::optional<DeviceRefusal> none =
      station_->use_device(DeviceChoice::replay, WorkspaceMapping{});
  ASSERT_TRUE(none);
  EXPECT_EQ(none->reason, DeviceRefusal::Reason::no_replay_loaded);
  EXPECT_EQ(station_->device(), DeviceChoice::mouse) << "the device in use stays";

  const std::vector<ServoFrame> frames = station_->sessions()->frames(session);
  WorkspaceMapping wrong;
  wrong.scale = 3.0;  // the session's own mapping is used, not this fallback
  station_->load_replay(session, frames, wrong);
  ASSERT_FALSE(station_->use_device(DeviceChoice::replay, WorkspaceMapping{}));
  EXPECT_EQ(station_->device(), DeviceChoice::replay);
  EXPECT_EQ(station_->device_name(), "Replay of session " + std::to_string(session));
  EXPECT_EQ(station_->servo()->mapping().scale, 1.0);
  EXPECT_FALSE(station_->recording_session()) << "a replay was recorded";
  const Eigen::Vector3d along = (end_mm - start_mm).normalized();
  station_->frame();  // the display's first frame since the choice
  ASSERT_TRUE(frameUntil([&] {
    const auto sample = snapshot().hand(Hand::right).device_sample;
    if (!sample) return false;
    const Eigen::Vector3d off = sample->position_mm - start_mm;
    EXPECT_LT((off - off.dot(along) * along).norm(), 1e-9) << "off the recorded line";
    return (sample->position_mm - end_mm).norm() < 1e-9;
  }));
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  EXPECT_EQ(station_->sessions()->sessions().size(), 1u);
}

// A device in each hand (issue 43): the left hand's scripted device holds the forceps over one
// end of the liver while the right hand's holds the probe over the other, through one servo; each
// tool is where its own device puts it. The session's input log keeps the left hand's tools, so
// that it replays whole. A left script that is empty is refused and the left hand stays empty.
TEST_F(StationTest, ADeviceInTheLeftHandMovesItsOwnToolBesideTheRightHandsDevice) {
  open(ToolKind::probe);
  left_tool_ = ToolKind::forceps;
  const fs::path database = folder_ / "two-hands.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  const std::optional<DeviceRefusal> empty =
      station_->use_left_device({}, folder_ / "none.txt", WorkspaceMapping{});
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->reason, DeviceRefusal::Reason::no_trajectory);
  WorkspaceMapping left_mapping;
  left_mapping.offset_m = {-0.03, 0.0, 0.0};  // the left hand's device 3 cm to the left
  const Eigen::Vector3d above_mm = topOfTheMiddle_mm() + Eigen::Vector3d(0.0, 0.0, 20.0);
  const fs::path left_file = folder_ / "left.txt";
  save_trajectory(left_file, {{0.0, above_mm, 0}, {600.0, above_mm, 0}});
  ASSERT_FALSE(station_->use_left_device(load_trajectory(left_file), left_file, left_mapping));
  EXPECT_EQ(station_->left_device_name(), "") << "taken before the next device change";
  play({{0.0, above_mm, 0}, {600.0, above_mm, 0}});
  EXPECT_EQ(station_->left_device_name(), "Scripted: left.txt");
  EXPECT_NE(station_->device_name().find("left hand: Scripted: left.txt"), std::string::npos)
      << station_->device_name();
  ASSERT_TRUE(station_->servo()->has_device(Hand::left));
  const std::int64_t session = *station_->recording_session();
  ASSERT_TRUE(frameUntil([&] {
    return snapshot().hand(Hand::left).tool && snapshot().hand(Hand::right).tool;
  })) << "the two hands' tools never came";
  const HandSnapshot& left = snapshot().hand(Hand::left);
  const HandSnapshot& right = snapshot().hand(Hand::right);
  EXPECT_EQ(left.tool->kind, ToolKind::forceps);
  EXPECT_EQ(right.tool->kind, ToolKind::probe);
  EXPECT_LT((left.tool->pose.origin_m - left_mapping.scene_position_m(above_mm)).norm(), 1e-12);
  EXPECT_LT((right.tool->pose.origin_m - above_mm * 1e-3).norm(), 1e-12);
  // The left hand's tool changed by its device's holder (as the Device panel does): from the
  // change on, it holds nothing.
  left_tool_.reset();
  station_->device_tool_changed(Hand::left, station_->servo()->now_s());
  station_->record_tool_choice(Hand::left);
  ASSERT_TRUE(frameUntil([&] { return !snapshot().hand(Hand::left).tool; }));
  EXPECT_TRUE(snapshot().hand(Hand::right).tool) << "the right hand's tool went too";
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  EXPECT_TRUE(station_->servo()->has_device(Hand::left))
      << "the left hand's device went with the right hand's change to the mouse";
  int left_tools = 0;
  for (const SimulationInput& input : station_->sessions()->inputs(session))
    left_tools += input.kind == SimulationInput::Kind::tool && input.hand == Hand::left;
  EXPECT_GE(left_tools, 2) << "the left hand's forceps and their putting down are not in the log";

  // The session recorded both devices (issue 43, item 3): each hand's frames, the left hand's
  // device and mapping, and each tool choice under its hand.
  std::optional<SessionSummary> recorded;
  for (const SessionSummary& s : station_->sessions()->sessions())
    if (s.id == session) recorded = s;
  ASSERT_TRUE(recorded);
  EXPECT_EQ(recorded->status, SessionStatus::complete);
  EXPECT_EQ(recorded->device, "Scripted: trajectory.txt");
  ASSERT_TRUE(recorded->left_hand);
  EXPECT_EQ(recorded->left_hand->device, "Scripted: left.txt");
  EXPECT_EQ(recorded->left_hand->mapping.offset_m, left_mapping.offset_m);
  EXPECT_GT(recorded->left_frame_count, 0);
  EXPECT_EQ(static_cast<std::int64_t>(station_->sessions()->frames(session, Hand::left).size()),
            recorded->left_frame_count);
  ASSERT_TRUE(recorded->left_servo);
  EXPECT_GT(recorded->left_servo->ticks, 0u);
  std::vector<std::pair<Hand, std::string>> tool_choices;
  for (const SessionEvent& e : station_->sessions()->events(session))
    if (e.kind == SessionEventKind::tool_selected) tool_choices.emplace_back(e.hand, e.detail);
  EXPECT_EQ(tool_choices,
            (std::vector<std::pair<Hand, std::string>>{
                {Hand::right, "probe"}, {Hand::left, "forceps"}, {Hand::left, "hand"}}));
}

// A live integrator change carries the liver on where it is (carry_state), mid-press, and is a
// session event; the same mesh keeps the session's outcome tracking. A tissue change does the same
// and is stored with free practice's text, which then cannot be replayed; so does gravity switched
// on.
TEST_F(StationTest, LiveModelChangesCarryTheLiverOnAndAreSessionEvents) {
  open(ToolKind::probe);
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  const double ball_mm = Tool{}.geometry.probe_tip_radius_m * 1e3;
  const Eigen::Vector3d pressed = topOfTheMiddle_mm() + Eigen::Vector3d(0, 0, ball_mm - 6);
  play({{0.0, pressed + Eigen::Vector3d(0, 0, 20), 0}, {0.5, pressed, 0}, {600.0, pressed, 0}});
  const std::int64_t session = *station_->recording_session();
  ASSERT_TRUE(frameUntil([&] { return snapshot().hand(Hand::right).force_n.norm() > 0.05; }));

  IntegratorSettings settings = station_->integrator();
  ASSERT_EQ(settings.kind, IntegratorKind::central_difference);
  settings.kind = IntegratorKind::rk4;
  ASSERT_TRUE(station_->change_integrator(settings));
  EXPECT_TRUE(station_->busy_building());
  EXPECT_FALSE(station_->change_integrator(settings)) << "one change at a time";
  const std::uint64_t steps_before = snapshot().step_count;
  ASSERT_TRUE(frameUntil([&] { return !changes_.empty(); }));
  ASSERT_TRUE(changes_[0].applied) << changes_[0].error;
  EXPECT_EQ(changes_[0].kind, ModelChangeOutcome::Kind::integrator);
  EXPECT_EQ(station_->integrator().kind, IntegratorKind::rk4);
  EXPECT_EQ(station_->simulation().stats().integrator, IntegratorKind::rk4);
  ASSERT_TRUE(
      frameUntil([&] { return snapshot().model && snapshot().model->integrator == settings; }));
  // Carried on, not restarted: the step count and time go on, and the probe still presses.
  EXPECT_GE(snapshot().step_count, steps_before);
  ASSERT_TRUE(frameUntil([&] { return snapshot().hand(Hand::right).force_n.norm() > 0.05; }));
  EXPECT_EQ(station_->recording_session(), session) << "the session goes on";

  // A bad setting is refused, naming it; the integrator in use stays.
  IntegratorSettings bad = settings;
  bad.step_s = -1.0;
  ASSERT_TRUE(station_->change_integrator(bad));
  ASSERT_TRUE(frameUntil([&] { return changes_.size() == 2; }));
  EXPECT_FALSE(changes_[1].applied);
  EXPECT_NE(changes_[1].error.find("step"), std::string::npos) << changes_[1].error;
  EXPECT_EQ(station_->integrator().kind, IntegratorKind::rk4);

  TissueSpec stiffer = station_->described_scenario().parenchyma;
  stiffer.elastic.youngs_modulus_pa *= 2.0;
  if (stiffer.viscoelastic) stiffer.viscoelastic->e1_pa *= 2.0;
  ASSERT_TRUE(station_->change_tissue(stiffer));
  ASSERT_TRUE(frameUntil([&] { return changes_.size() == 3; }));
  ASSERT_TRUE(changes_[2].applied) << changes_[2].error;
  EXPECT_EQ(station_->described_scenario().parenchyma.elastic.youngs_modulus_pa,
            stiffer.elastic.youngs_modulus_pa);
  EXPECT_TRUE(station_->free_practice_changed());

  // Gravity switched on: the scene's support comes with it, and the session says so.
  ASSERT_TRUE(station_->change_gravity(true));
  EXPECT_FALSE(station_->change_tissue(stiffer)) << "one change of the model at a time";
  ASSERT_TRUE(frameUntil([&] { return changes_.size() == 4; }));
  ASSERT_TRUE(changes_[3].applied) << changes_[3].error;
  EXPECT_EQ(changes_[3].kind, ModelChangeOutcome::Kind::gravity);
  ASSERT_TRUE(frameUntil([&] { return snapshot().model && snapshot().model->effects.gravity; }));
  EXPECT_NE(snapshot().model->support, nullptr);
  EXPECT_TRUE(station_->described_scenario().effects.gravity);

  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  station_->finish_metrics();
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  std::vector<SessionEventKind> changes;
  for (const SessionEvent& e : store.events(session))
    if (e.kind == SessionEventKind::integrator_changed ||
        e.kind == SessionEventKind::material_changed || e.kind == SessionEventKind::gravity_changed)
      changes.push_back(e.kind);
  const std::vector<SessionEventKind> expected{SessionEventKind::integrator_changed,
                                               SessionEventKind::material_changed,
                                               SessionEventKind::gravity_changed};
  EXPECT_EQ(changes, expected);
  // The next session stores the changed tissue with free practice's text, and no replay set-up.
  play({{0.0, pressed + Eigen::Vector3d(0, 0, 20), 0},
        {600.0, pressed + Eigen::Vector3d(0, 0, 20), 0}});
  const std::int64_t next = *station_->recording_session();
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  station_->finish_metrics();
  SqliteSessionStore after(database, SqliteSessionStore::Access::read_only);
  const std::string next_text = after.scenario_text(next);
  EXPECT_NE(next_text.find("changed: tissue E "), std::string::npos) << next_text;
  EXPECT_NE(next_text.find("gravity 9.81 m/s2 toward (0, 0, -1)"), std::string::npos) << next_text;
  EXPECT_FALSE(after.replay_setup(next)) << "a changed free practice cannot be built again";
}

// A scenario opened while a device session is recorded: the session of the old scene ends whole,
// and one begins on the new scene, storing the scenario's exact text; a cancelled build changes
// nothing.
// Paced scripts play on the simulation's time (record --paced): while the simulation stands
// still the script waits, so the device is where the script puts it at the simulation's time, not
// the wall clock's, also after a model change has replaced the simulation.
TEST_F(StationTest, APacedScriptWaitsForTheSimulationAlsoAfterAModelChange) {
  open(ToolKind::probe);
  station_->play_scripts_on_simulated_time(true);
  // Held 20 mm above the liver for 1 s, then moving sideways at 10 mm/s (touching nothing).
  const Eigen::Vector3d start = topOfTheMiddle_mm() + Eigen::Vector3d(-40, 0, 20);
  constexpr double kSpeedMmPerS = 10.0;
  const double begin_s = station_->simulated_clock_s().load();
  play({{0.0, start, 0}, {1.0, start, 0}, {61.0, start + Eigen::Vector3d(600, 0, 0), 0}});
  // Where the script puts the device at a simulated time (its clock's origin is the simulated
  // time of the servo's first read: a few milliseconds after begin_s, kOriginS leaves room for a
  // loaded machine).
  constexpr double kOriginS = 0.25;
  auto expected_x_mm = [&](double simulated_s) {
    return start.x() + kSpeedMmPerS * std::max(0.0, simulated_s - begin_s - 1.0);
  };
  // The device's reading a snapshot shows is the servo's last before the cycle: it lags the
  // snapshot's time by at most a cycle (2/60 s of simulated time), so it lies between where the
  // script puts it kOriginS + 35 ms before and at the snapshot's time.
  auto on_the_script = [&] {
    const SimulationSnapshot& seen = snapshot();
    if (!seen.hand(Hand::right).device_sample) return ::testing::AssertionFailure() << "no sample";
    const double x = seen.hand(Hand::right).device_sample->position_mm.x();
    const double lo = expected_x_mm(seen.time_s - kOriginS - 0.035),
                 hi = expected_x_mm(seen.time_s);
    if (x >= lo - 1e-9 && x <= hi + 1e-9) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "the device at x = " << x << " mm, the script between " << lo << " and " << hi
           << " mm at " << seen.time_s << " s simulated";
  };
  const double moving_s = begin_s + 1.5;
  ASSERT_TRUE(frameUntil([&] { return snapshot().time_s > moving_s; }));
  EXPECT_TRUE(on_the_script());
  // The simulation stopped for a second of wall time: a script on the wall clock would be 10 mm
  // ahead when it goes on.
  station_->simulation().stop();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double stopped_at_s = station_->simulation().snapshot().time_s;
  station_->simulation().start();
  ASSERT_TRUE(frameUntil([&] { return snapshot().time_s > stopped_at_s + 0.05; }));
  EXPECT_TRUE(on_the_script());
  // A model change replaces the simulation: the new one's time is the script's clock.
  IntegratorSettings settings = station_->integrator();
  settings.kind = IntegratorKind::rk4;
  ASSERT_TRUE(station_->change_integrator(settings));
  ASSERT_TRUE(frameUntil([&] { return !changes_.empty(); }));
  ASSERT_TRUE(changes_[0].applied) << changes_[0].error;
  const double changed_at_s = snapshot().time_s;
  ASSERT_TRUE(frameUntil([&] { return snapshot().time_s > changed_at_s + 0.2; }));
  EXPECT_TRUE(on_the_script());
  EXPECT_NEAR(station_->simulated_clock_s().load(),
              station_->simulation().simulated_time_s().load(), 0.05);
}

TEST_F(StationTest, OpeningAScenarioEndsTheSessionAndBeginsOneOnTheNewScene) {
  open();
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  play({{0.0, Eigen::Vector3d(5.0, 6.0, 60.0), 0}, {600.0, Eigen::Vector3d(5.0, 6.0, 60.0), 0}});
  const std::int64_t first = *station_->recording_session();
  ASSERT_TRUE(servoTicks(200));

  const fs::path file =
      fs::path(LIVERSIM_TEST_DATA_DIR) / ".." / ".." / "scenarios" / "palpation-hidden-lesion.json";
  auto read = read_scenario_to_run(file);
  ASSERT_TRUE(std::holds_alternative<OpenedScenario>(read));
  OpenedScenario opened = std::get<OpenedScenario>(read);
  const std::string text = opened.text;
  const std::string title = opened.scenario.title;
  ASSERT_TRUE(station_->open_scenario(opened, file.parent_path()));
  station_->cancel_scene_build();
  ASSERT_TRUE(frameUntil([&] { return !openings_.empty(); }));
  EXPECT_EQ(openings_[0].result, SceneOpening::Result::cancelled);
  EXPECT_FALSE(station_->scenario()) << "the running scene goes on";
  EXPECT_EQ(station_->recording_session(), first);

  ASSERT_TRUE(station_->open_scenario(std::move(opened), file.parent_path()));
  ASSERT_TRUE(frameUntil([&] { return openings_.size() == 2; }));
  ASSERT_EQ(openings_[1].result, SceneOpening::Result::opened) << openings_[1].error;
  ASSERT_TRUE(station_->scenario());
  EXPECT_EQ(station_->scenario()->scenario.title, title);
  ASSERT_TRUE(station_->recording_session());
  const std::int64_t second = *station_->recording_session();
  EXPECT_NE(second, first);
  ASSERT_TRUE(servoTicks(station_->servo()->stats().ticks + 100));
  ASSERT_FALSE(station_->use_device(DeviceChoice::mouse, WorkspaceMapping{}));
  station_->finish_metrics();
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 2u);
  for (const SessionSummary& s : sessions) EXPECT_EQ(s.status, SessionStatus::complete);
  const auto on_scenario = std::find_if(sessions.begin(), sessions.end(),
                                        [&](const SessionSummary& s) { return s.id == second; });
  ASSERT_NE(on_scenario, sessions.end());
  EXPECT_EQ(on_scenario->scenario_title, title);
  EXPECT_EQ(store.scenario_text(second), text) << "the exact text is stored";
  const std::optional<ReplaySetup> replay = store.replay_setup(second);
  ASSERT_TRUE(replay);
  EXPECT_EQ(fs::path(replay->scenario_folder), fs::absolute(file).parent_path());

  // A bad file is refused before any build, each error naming its field.
  const fs::path bad = folder_ / "bad.json";
  std::ofstream(bad) << R"({"format_version": 1, "title": ""})";
  auto refused = read_scenario_to_run(bad);
  ASSERT_TRUE(std::holds_alternative<std::vector<ScenarioError>>(refused));
  EXPECT_FALSE(std::get<std::vector<ScenarioError>>(refused).empty());
}

#ifdef LIVERSIM_FAKE_HD_LIBRARY
using test::fakeHook;

// The Phantom Omni unplugged mid-session (a fatal HD_COMM_ERROR): its force is off, the fault is a
// session event, the session ends whole with what it recorded, the mouse takes over and the owner
// is told; choosing the Omni again opens it anew.
TEST_F(StationTest, AFatalDeviceFaultEndsTheSessionAndTheMouseTakesOver) {
  open(ToolKind::probe);
  ASSERT_EQ(station_->open_omni(LIVERSIM_FAKE_HD_LIBRARY), "");
  const fs::path database = folder_ / "sessions.sqlite";
  ASSERT_FALSE(station_->open_sessions(database));
  ASSERT_FALSE(station_->use_device(DeviceChoice::openhaptics, WorkspaceMapping{}));
  ASSERT_TRUE(station_->recording_session());
  ASSERT_TRUE(servoTicks(200));
  ASSERT_TRUE(frameUntil([&] { return snapshot().hand(Hand::right).tool.has_value(); }));
  auto inject = fakeHook<void (*)(unsigned, int)>("fake_hd_inject_error");
  auto last_force = fakeHook<void (*)(double*)>("fake_hd_last_force");
  ASSERT_TRUE(inject && last_force);
  inject(0x0302, 0);  // HD_COMM_ERROR
  ASSERT_TRUE(frameUntil([&] { return station_->device() == DeviceChoice::mouse; }))
      << "the station did not notice the fault";
  ASSERT_EQ(faults_.size(), 1u) << "the owner is told once";
  EXPECT_EQ(faults_[0], station_->omni_problem());
  EXPECT_FALSE(station_->omni()) << "a faulty Omni is opened anew when chosen again";
  EXPECT_FALSE(station_->omni_problem().empty());
  double force_n[3];
  last_force(force_n);
  EXPECT_EQ(Eigen::Vector3d(force_n[0], force_n[1], force_n[2]), Eigen::Vector3d::Zero());
  station_->finish_metrics();
  {
    SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
    const std::vector<SessionSummary> sessions = store.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, SessionStatus::complete);
    EXPECT_GT(sessions[0].frame_count, 200);
    const std::vector<SessionEvent> events = store.events(sessions[0].id);
    EXPECT_TRUE(std::any_of(events.begin(), events.end(), [](const SessionEvent& e) {
      return e.kind == SessionEventKind::device_fault && !e.detail.empty();
    })) << "the fault is not among the session's events";
  }
  ASSERT_EQ(station_->open_omni(LIVERSIM_FAKE_HD_LIBRARY), "");
  ASSERT_FALSE(station_->use_device(DeviceChoice::openhaptics, WorkspaceMapping{}));
  ASSERT_TRUE(servoTicks(200));
  EXPECT_TRUE(station_->servo()->device_fault().empty());
}
#endif

// carry_state: another model of the same mesh goes on from the liver's motion, time and books,
// with its own scheme's history; a model of another mesh is refused.
TEST(CarryState, KeepsTheLiversMotionTimeAndBooksOnAnotherModelOfTheSameMesh) {
  SceneSetup setup = default_scene(kTetCount);
  const SimModel model = build_model(setup.mesh, setup.model_options);
  SimState old = make_rest_state(model);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    old.position_m.x[n] += 1e-4 * static_cast<double>(n % 7);
    old.velocity_m_per_s.y[n] = 1e-3 * static_cast<double>(n % 5);
  }
  old.time_s = 1.25;
  old.step_count = 4321;
  old.energy.tool_work_j = 0.5;
  old.max_speed_m_per_s = 0.004;
  ModelOptions options = setup.model_options;
  options.integrator.kind = IntegratorKind::rk4;
  const SimModel other = build_model(setup.mesh, options);
  const SimState carried = carry_state(old, other);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    ASSERT_EQ(carried.position_m.at(n), old.position_m.at(n));
    ASSERT_EQ(carried.velocity_m_per_s.at(n), old.velocity_m_per_s.at(n));
  }
  EXPECT_EQ(carried.time_s, 1.25);
  EXPECT_EQ(carried.step_count, 4321u);
  EXPECT_EQ(carried.energy.tool_work_j, 0.5);
  EXPECT_EQ(carried.max_speed_m_per_s, 0.004);
  EXPECT_EQ(carried.last_step_s, 0.0) << "the new scheme starts its own history";
  EXPECT_EQ(carried.integrator.start_position_m.size(), model.node_count) << "sized for RK4";

  const SceneSetup smaller = default_scene(600);
  const SimModel small = build_model(smaller.mesh, smaller.model_options);
  EXPECT_THROW(carry_state(old, small), std::invalid_argument);
}

}  // namespace
}  // namespace liversim
