// The shipped wedge resection with the mouse's scalpel (issue 42, item 6), under a real X server,
// on scenarios/wedge-resection-peripheral-tumour.json as shipped (the tumour where it is). The
// left hand holds the lobe tip with the forceps (a scripted device: the shipped left-hand
// trajectory until its lift). The mouse follows the scalpel passes of the shipped right-hand
// trajectory (tests/data/trajectories/wedge-resection-right-hand.txt) as a trainee with the mouse
// makes them: pressed on the liver where the passes enter, pushed in with the wheel, drawn with the
// mouse in the plane of the cut, let go at each pass's end; a mouse can put the blade in only on
// the liver's surface, so a pass the script begins below the lobe is entered there too and drawn
// down first. Once a piece is free, Session ▸ Remove Specimen takes it out, and the session's
// stored metrics say what the scenario grades: the tumour in the specimen with its margin (R0), no
// breach, task success, and the Scenario panel shows the score.
#include "device_panel.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/haptics.h"
#include "liversim/scenario/data_paths.h"
#include "liversim/scenario/scenario.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "mouse_tool_control.h"
#include "render/liver_scene.h"
#include "scenario_panel.h"
#include "simulated_waits.h"
#include "tool_panel.h"
#include "viewport_input.h"
#include "vtk_viewport.h"
#include "wait_limits.h"

#include <gtest/gtest.h>

#include <vtkCamera.h>
#include <vtkRenderer.h>

#include <QAction>
#include <QDir>
#include <QFile>
#include <QSettings>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>

namespace liversim {
namespace {

constexpr int kTimeoutMs = liversim::test::waitLimitMs(120'000);
// One mouse move (and the wheel's notches with it) per this much simulated time.
constexpr double kMoveEveryS = 0.02;
constexpr double kLongestMoveM = 0.002;

// A stretch of the trajectory with the blade armed: its points, times from its start.
struct Pass {
  std::vector<TrajectoryPoint> points;
};

std::vector<Pass> armed_passes(const std::vector<TrajectoryPoint>& points) {
  std::vector<Pass> passes;
  bool armed = false;
  for (const TrajectoryPoint& point : points) {
    const bool down = point.buttons != 0;
    if (down && !armed) passes.emplace_back();
    if (down) passes.back().points.push_back(point);
    armed = down;
  }
  return passes;
}

class MouseResectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QSettings().clear();
    ASSERT_TRUE(folder_.isValid());
    const std::filesystem::path file =
        shipped_scenarios_folder() / "wedge-resection-peripheral-tumour.json";
    auto read = read_scenario_to_run(std::filesystem::absolute(file));
    ASSERT_TRUE(std::holds_alternative<OpenedScenario>(read));
    OpenedScenario opened = std::get<OpenedScenario>(std::move(read));
    SceneSetup setup = build_scene(opened.scenario, opened.file.parent_path());
    window_ = std::make_unique<MainWindow>(std::move(setup), std::move(opened));
    window_->resize(1280, 900);
    ASSERT_TRUE(test::showRunning(*window_, window_->simulation(), kTimeoutMs));
  }
  // The session is kept with the test's output (mouse_resection_session.sqlite), so that a run
  // that freed nothing can be replayed and looked into.
  void TearDown() override {
    window_.reset();  // ends the session and closes the database
    const QString kept = QDir(LIVERSIM_TEST_OUTPUT_DIR).filePath("mouse_resection_session.sqlite");
    QFile::remove(kept);
    if (QFile::copy(folder_.filePath("sessions.sqlite"), kept))
      std::cout << "the session kept in " << kept.toStdString() << "\n";
  }

  const SimulationSnapshot& snapshot() const { return window_->simulation().snapshot(); }
  bool waitSimulated(double seconds) {
    return test::waitSimulated(window_->simulation(), seconds, kTimeoutMs);
  }

  // The mouse's tool goes to `origin_m`: the wheel pushes it along its shaft as far as the depth
  // needs (whole notches), the drag moves it the rest of the way in the view plane (whole pixels).
  void mouseToolTo(const Eigen::Vector3d& origin_m) {
    VtkViewport& viewport = *window_->viewport();
    LiverScene& scene = window_->scene();
    double direction[3];
    scene.renderer()->GetActiveCamera()->GetDirectionOfProjection(direction);
    const Eigen::Vector3d away(direction[0], direction[1], direction[2]);
    const Eigen::Vector3d step = origin_m - origin_m_;
    const double along_shaft_m = step.dot(away) / shaft_.dot(away);
    const int notches =
        static_cast<int>(std::lround(-along_shaft_m / MouseToolControl::kWheelPushM));
    if (notches != 0) {
      send_wheel(viewport, cursor_, notches, Qt::LeftButton);
      origin_m_ -= notches * MouseToolControl::kWheelPushM * shaft_;
    }
    const Eigen::Vector3d held_m = origin_m_ - MouseToolControl::kScalpelHeelAboveM * shaft_;
    const QPoint to =
        widget_point(viewport, scene.world_to_display(held_m + (origin_m - origin_m_)));
    if (to == cursor_) return;
    const QPoint display = display_point(viewport, to);
    origin_m_ += scene.display_to_world(display.x(), display.y(), held_m) - held_m;
    cursor_ = to;
    send_mouse(viewport, QEvent::MouseMove, to, Qt::NoButton, Qt::LeftButton);
  }

  // Along `from` → `to` in `duration_s` of simulated time, at that pace: each move goes where the
  // blade should be by the simulated time now, but at most kLongestMoveM beyond the last (a slow
  // frame of the window makes the stroke slower, not a jump).
  bool drawTo(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, double duration_s) {
    const double begin_s = snapshot().time_s;
    double done = 0.0;  // of the way
    const double length_m = (to_m - from_m).norm();
    while (done < 1.0) {
      if (!waitSimulated(kMoveEveryS)) return false;
      const double due = std::min(1.0, (snapshot().time_s - begin_s) / duration_s);
      done = length_m > 0.0 ? std::min(due, done + kLongestMoveM / length_m) : due;
      mouseToolTo(from_m + (to_m - from_m) * done);
    }
    return true;
  }

  QTemporaryDir folder_;
  std::unique_ptr<MainWindow> window_;
  QPoint cursor_;
  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();  // the mouse's tool's, as it moves it
  Eigen::Vector3d shaft_ = Eigen::Vector3d::UnitZ();    // outward, in the scene
};

TEST_F(MouseResectionTest, TheShippedWedgeResectionIsMadeWithTheMouseAndGradedASuccess) {
  const QString database = folder_.filePath("sessions.sqlite");
  ASSERT_TRUE(window_->setSessionsDatabase(database)) << window_->sessionsProblem().toStdString();
  window_->toolPanel()->setTool(ToolKind::scalpel);
  VtkViewport& viewport = *window_->viewport();
  const std::vector<Pass> passes =
      armed_passes(load_trajectory(std::filesystem::path(LIVERSIM_TEST_DATA_DIR) / "trajectories" /
                                   "wedge-resection-right-hand.txt"));
  ASSERT_EQ(passes.size(), 5u);
  // The script's device millimetres in the scene, as the workstation maps a device at first use.
  const WorkspaceMapping mapping = first_use_mapping(
      window_->station().setup().mesh.rest_position_m, opening_view_device_axes());
  const auto scene_m = [&](const TrajectoryPoint& point) {
    return mapping.scene_position_m(point.position_mm);
  };
  const Eigen::Vector3d entry_m = scene_m(passes.front().points.front());
  std::optional<std::int64_t> session;

  // The left hand holds the lobe tip with the forceps, as in the shipped left-hand trajectory,
  // played by a scripted device beside the mouse (the mouse is the right hand's only): its points
  // until the lift, 2 s later (so that its jaws close after the mouse's first press, which starts
  // the session from rest), then held. The specimen is taken out with Session ▸ Remove Specimen.
  std::vector<TrajectoryPoint> hold;
  for (const TrajectoryPoint& point :
       load_trajectory(std::filesystem::path(LIVERSIM_TEST_DATA_DIR) / "trajectories" /
                       "wedge-resection-left-hand.txt")) {
    if (!hold.empty() && point.position_mm.z() > hold.back().position_mm.z()) break;  // the lift
    hold.push_back(point);
    hold.back().time_s += 2.0;
  }
  ASSERT_GE(hold.size(), 3u);
  hold.insert(hold.begin(), TrajectoryPoint(0.0, hold.front().position_mm, 0));
  hold.push_back(TrajectoryPoint(600.0, hold.back().position_mm, hold.back().buttons));
  const QString left = folder_.filePath("left-hand-holds.txt");
  save_trajectory(left.toStdString(), hold);
  ASSERT_TRUE(window_->useLeftHandDevice(left))
      << window_->devicePanel()->statusText().toStdString();

  // The script's passes, then, while nothing is free, up to kMoreRunsAlong more runs of the
  // blade along the whole groove as its last pass (what a surgeon does where a transection still
  // holds; the script cannot look, the trainee does).
  constexpr std::size_t kMoreRunsAlong = 2;
  std::size_t passes_made = 0;
  for (std::size_t p = 0; p < passes.size() + kMoreRunsAlong; ++p) {
    const std::vector<TrajectoryPoint>& points = passes[std::min(p, passes.size() - 1)].points;
    ++passes_made;
    // Pressed on the liver where the passes enter: the point of the surface at the entry's device
    // x and y (the view is a perspective: the cursor over the entry, above the liver, sees a point
    // of the surface beside it), found by aiming again at the error a few times.
    const TrajectoryPoint& entry = passes.front().points.front();
    std::optional<ScenePick> hit;
    Eigen::Vector3d aim_m = entry_m;
    for (int look = 0; look < 4; ++look) {
      cursor_ = widget_point(viewport, window_->scene().world_to_display(aim_m));
      const QPoint display = display_point(viewport, cursor_);
      hit = window_->scene().pick(display.x(), display.y());
      ASSERT_TRUE(hit) << "pass " << p + 1 << " starts off the liver";
      Eigen::Vector3d off_mm = mapping.device_position_mm(hit->point_m) - entry.position_mm;
      off_mm.z() = 0.0;
      aim_m =
          hit->point_m - (mapping.scene_position_m(off_mm) - mapping.scene_position_m({0, 0, 0}));
    }
    std::cout << "pressed at device " << mapping.device_position_mm(hit->point_m).transpose()
              << "\n";
    send_mouse(viewport, QEvent::MouseButtonPress, cursor_, Qt::LeftButton, Qt::LeftButton);
    if (!session) {
      ASSERT_TRUE(window_->recordingSession()) << window_->sessionsProblem().toStdString();
      session = window_->recordingSession();
      ASSERT_TRUE(QTest::qWaitFor([&] { return snapshot().hand(Hand::left).grasping; }, kTimeoutMs))
          << "the forceps did not take hold of the lobe tip";
    }
    ASSERT_TRUE(
        QTest::qWaitFor([&] { return snapshot().hand(Hand::right).tool.has_value(); }, kTimeoutMs));
    const Tool put_on = *snapshot().hand(Hand::right).tool;
    shaft_ = put_on.pose.orientation * Eigen::Vector3d::UnitZ();
    origin_m_ = hit->point_m + MouseToolControl::kScalpelHeelAboveM * shaft_;
    // The script's blade reaches the surface on its way in from the entry; the mouse's is put on
    // there, and goes in to the pass's depth in the time the script takes. A pass the script
    // begins elsewhere (below the lobe, where a mouse cannot put the blade in) is reached from the
    // entry: straight in to its depth, then along the plane to where it begins, at the pace of its
    // first stroke.
    std::vector<std::pair<Eigen::Vector3d, double>> path;  // (to, in simulated seconds)
    std::size_t first = 1;
    if ((points.front().position_mm - entry.position_mm).norm() > 1e-9) {
      const TrajectoryPoint in(
          0.0, {entry.position_mm.x(), entry.position_mm.y(), points.front().position_mm.z()}, 1);
      const double in_s = passes.front().points[1].time_s - entry.time_s;
      const double pace_mm_per_s = (points[1].position_mm - points[0].position_mm).norm() /
                                   (points[1].time_s - points[0].time_s);
      path.emplace_back(scene_m(in), in_s);
      path.emplace_back(scene_m(points.front()),
                        (points.front().position_mm - in.position_mm).norm() / pace_mm_per_s);
    } else {
      path.emplace_back(scene_m(points[1]), points[1].time_s - points[0].time_s);
      first = 2;
    }
    for (std::size_t k = first; k < points.size(); ++k)
      path.emplace_back(scene_m(points[k]), points[k].time_s - points[k - 1].time_s);
    Eigen::Vector3d at_m = origin_m_;
    for (const auto& [to_m, duration_s] : path) {
      ASSERT_TRUE(drawTo(at_m, to_m, duration_s)) << "pass " << p + 1;
      at_m = to_m;
      std::cout << "  at " << snapshot().time_s << " s the blade's edge is "
                << snapshot().hand(Hand::right).blade_edge_in_tissue_m * 1e3 << " mm in, cutting "
                << snapshot().hand(Hand::right).blade_cutting << ", off its mark by "
                << (snapshot().hand(Hand::right).tool->pose.origin_m - to_m).norm() * 1e3
                << " mm, the mouse's by " << (origin_m_ - to_m).norm() * 1e3 << " mm\n";
    }
    ASSERT_FALSE(window_->simulation().stats().halted) << "pass " << p + 1;
    send_mouse(viewport, QEvent::MouseButtonRelease, cursor_, Qt::LeftButton, Qt::NoButton);
    ASSERT_TRUE(waitSimulated(0.5));
    std::cout << "pass " << p + 1 << ": " << snapshot().free_bodies << " piece(s) free at "
              << snapshot().time_s << " s, topology " << snapshot().topology_version << "\n";
    // Once the status line says a piece is free, the trainee takes it out; cutting on would cut
    // the specimen the forceps hold.
    if (snapshot().free_bodies > 0) break;
  }
  ASSERT_TRUE(session);
  std::cout << "freed after " << passes_made << " passes (the script makes " << passes.size()
            << ")\n";
  ASSERT_GT(snapshot().free_bodies, 0) << "the passes freed nothing";

  // What the trainee sees then, kept with the test's output.
  const QString picture = QDir(LIVERSIM_TEST_OUTPUT_DIR).filePath("mouse_resection_freed.png");
  if (window_->grab().save(picture))
    std::cout << "the window saved to " << picture.toStdString() << "\n";

  QAction* remove = window_->findChild<QAction*>("removeSpecimenAction");
  ASSERT_NE(remove, nullptr);
  remove->trigger();
  ASSERT_TRUE(QTest::qWaitFor([&] { return snapshot().specimens_taken_out > 0; }, kTimeoutMs));
  ASSERT_TRUE(waitSimulated(0.1));

  // The mouse chosen again ends the session; its result reaches the Scenario panel.
  QSignalSpy metricsStored(window_.get(), &MainWindow::sessionMetricsStored);
  ASSERT_TRUE(window_->useDevice(DeviceChoice::mouse));
  ASSERT_TRUE(metricsStored.wait(kTimeoutMs));
  EXPECT_TRUE(metricsStored.first().at(1).toBool()) << window_->sessionsProblem().toStdString();
  EXPECT_TRUE(window_->scenarioPanel()->resultText().contains("score 100 %"))
      << window_->scenarioPanel()->resultText().toStdString();

  SqliteSessionStore store(database.toStdString(), SqliteSessionStore::Access::read_only);
  const std::vector<SessionEvent> events = store.events(*session);
  const auto count = [&](SessionEventKind kind) {
    return std::count_if(events.begin(), events.end(),
                         [&](const SessionEvent& e) { return e.kind == kind; });
  };
  EXPECT_GT(count(SessionEventKind::cut), 0);
  EXPECT_EQ(count(SessionEventKind::lesion_breach), 0) << "the blade went into the tumour";
  EXPECT_EQ(count(SessionEventKind::specimen_removed), 1);
  std::map<std::string, double> metric;
  for (const MetricValue& m : store.metrics(*session)) metric[m.name] = m.value;
  for (const auto& [name, value] : metric) std::cout << name << " " << value << "\n";
  EXPECT_EQ(metric["specimen_contains_lesion"], 1.0);
  EXPECT_EQ(metric["specimen_r0"], 1.0);
  EXPECT_GE(metric["specimen_margin_mm"], 10.0);
  EXPECT_EQ(metric["lesion_breached"], 0.0);
  EXPECT_LE(metric["plane_deviation_mm"], 5.0);
  EXPECT_EQ(metric["task_success"], 1.0);
}

}  // namespace
}  // namespace liversim
