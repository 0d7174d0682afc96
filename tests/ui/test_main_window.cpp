// MainWindow under a real X server (Xvfb in CI): a left drag on the liver grabs and pulls the
// tissue, which springs back after the release; a left drag on the background turns the camera;
// the status bar reports the frame rate and the simulation's speed; the accuracy panel changes the
// time integrator of the running simulation, and refuses invalid settings with a reason.
#include <gtest/gtest.h>

#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>
#include <QApplication>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QImage>
#include <QLabel>
#include <QMouseEvent>
#include <QPushButton>
#include <QRadioButton>
#include <QSettings>
#include <QSignalSpy>
#include <QStatusBar>
#include <QTemporaryDir>
#include <QTest>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <numbers>
#include <optional>

#include "accuracy_panel.h"
#include "liversim/engine/integrator.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "mouse_tool_control.h"
#include "render/liver_scene.h"
#include "simulation_status.h"
#include "tool_panel.h"
#include "viewport_input.h"
#include "vtk_viewport.h"
#include "wait_limits.h"

namespace liversim {
namespace {

// Smaller than the default liver, so that the simulation keeps up under Xvfb's software renderer.
constexpr int kTetCount = 3841;
// Wall-clock bounds of the waits: Xvfb with llvmpipe on a loaded machine is slow, and simulated
// time then runs slower than real time.
constexpr int kStartTimeoutMs = liversim::test::waitLimitMs(30'000);
constexpr int kSimulatedTimeTimeoutMs = liversim::test::waitLimitMs(90'000);
// The drag, in widget pixels: to the right and up.
const QPoint kDrag(80, -40);
constexpr int kDragMoves = 10;

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Pixels whose colour differs in any channel by more than `tolerance` (of 255).
int countDifferentPixels(const QImage& a, const QImage& b, int tolerance = 8) {
  if (a.size() != b.size()) return a.width() * a.height();
  const QImage ca = a.convertToFormat(QImage::Format_RGB32);
  const QImage cb = b.convertToFormat(QImage::Format_RGB32);
  int count = 0;
  for (int y = 0; y < ca.height(); ++y) {
    const auto* ra = reinterpret_cast<const QRgb*>(ca.constScanLine(y));
    const auto* rb = reinterpret_cast<const QRgb*>(cb.constScanLine(y));
    for (int x = 0; x < ca.width(); ++x) {
      const bool differs = std::abs(qRed(ra[x]) - qRed(rb[x])) > tolerance ||
                           std::abs(qGreen(ra[x]) - qGreen(rb[x])) > tolerance ||
                           std::abs(qBlue(ra[x]) - qBlue(rb[x])) > tolerance;
      count += differs ? 1 : 0;
    }
  }
  return count;
}

class MainWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QSettings().clear();  // the defaults, whatever an earlier test saved
    SceneSetup setup = default_scene(kTetCount);
    mesh_ = setup.mesh;
    window_ = std::make_unique<MainWindow>(std::move(setup));
    window_->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(window_.get()));
    // The frame timer takes in the snapshots; the first one after the start has time_s > 0.
    ASSERT_TRUE(QTest::qWaitFor([&] { return simulatedTime() > 0.0; }, kStartTimeoutMs))
        << "no simulation snapshot reached the window within " << kStartTimeoutMs << " ms";
  }

  // Leaves the pictures of a failing test where they can be inspected.
  void TearDown() override {
    if (HasFailure() && window_) {
      const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
      savePicture(window_->viewport()->grabRendering(),
                  QStringLiteral("%1_last").arg(info->name()));
      for (const auto& [suffix, picture] : pictures_) {
        savePicture(picture, QStringLiteral("%1_%2").arg(info->name(), suffix));
      }
    }
    window_.reset();
  }

  static void savePicture(const QImage& picture, const QString& name) {
    if (picture.isNull()) return;
    const QString path = QDir(LIVERSIM_TEST_OUTPUT_DIR).filePath("main_window_" + name + ".png");
    if (picture.save(path)) std::cerr << "picture saved to " << path.toStdString() << '\n';
  }

  // Only on the GUI thread, where MainWindow's frame timer swaps the snapshots in as well.
  double simulatedTime() const { return window_->simulation().snapshot().time_s; }

  // Waits (processing events) until the window has taken in a snapshot `duration_s` of simulated
  // time past the current one.
  bool waitSimulated(double duration_s) {
    const double until_s = simulatedTime() + duration_s;
    return QTest::qWaitFor([&] { return simulatedTime() >= until_s; }, kSimulatedTimeTimeoutMs);
  }

  double maxDisplacementFromRest() const {
    const NodeArray& position = window_->simulation().snapshot().position_m;
    double largest = 0.0;
    for (std::size_t i = 0; i < position.size(); ++i) {
      largest = std::max(largest, (position.at(i) - mesh_.rest_position_m.at(i)).norm());
    }
    return largest;
  }

  // Mean displacement of the grabbed nodes since the grab.
  double grabbedDisplacement(const Grab& grab) const {
    const NodeArray& position = window_->simulation().snapshot().position_m;
    double sum = 0.0;
    for (std::size_t k = 0; k < grab.nodes.size(); ++k) {
      sum += (position.at(grab.nodes[k]) - grab.node_position_at_grab_m[k]).norm();
    }
    return grab.nodes.empty() ? 0.0 : sum / static_cast<double>(grab.nodes.size());
  }

  std::array<double, 3> cameraPosition() const {
    std::array<double, 3> position{};
    window_->scene().renderer()->GetActiveCamera()->GetPosition(position.data());
    return position;
  }

  // VTK display coordinates (device pixels, origin bottom-left) ↔ viewport widget coordinates,
  // the same mapping as VtkViewport's.
  QPoint toWidget(const Eigen::Vector2d& display) const {
    return widget_point(*window_->viewport(), display);
  }
  QPoint toDisplay(QPoint widget) const { return display_point(*window_->viewport(), widget); }
  std::optional<ScenePick> pickAt(QPoint widget) const {
    const QPoint display = toDisplay(widget);
    return window_->scene().pick(display.x(), display.y());
  }

  // A point of the viewport that shows the liver: the projection of the centroid of the surface
  // nodes, or else of the anterior marked node.
  std::optional<QPoint> pointOnTheLiver() const {
    const BoundarySurface& surface = window_->scene().surface();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const NodeIndex n : surface.nodes) centroid += mesh_.rest_position_m.at(n);
    centroid /= static_cast<double>(surface.nodes.size());
    for (const QPoint candidate : {toWidget(window_->scene().world_to_display(centroid)),
                                   toWidget(window_->scene().world_to_display(
                                       mesh_.rest_position_m.at(anterior_marked_node(mesh_))))}) {
      if (window_->viewport()->rect().contains(candidate) && pickAt(candidate)) return candidate;
    }
    return std::nullopt;
  }

  void sendMouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    send_mouse(*window_->viewport(), type, pos, button, buttons);
  }

  // Presses the left button at `from` and moves to `to` in kDragMoves steps, processing events
  // (frames, snapshots) between them; `during` runs after the press and after every move.
  void pressAndMove(QPoint from, QPoint to, const std::function<void()>& during) {
    sendMouse(QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton);
    during();
    for (int step = 1; step <= kDragMoves; ++step) {
      QTest::qWait(30);
      sendMouse(QEvent::MouseMove, from + (to - from) * step / kDragMoves, Qt::NoButton,
                Qt::LeftButton);
      during();
    }
  }

  void release(QPoint at) {
    sendMouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
  }

  // Chooses an integrator, step and tolerance in the accuracy panel as a user would, presses Apply
  // and waits until the window has built the model and either applied or refused the setting.
  // Returns whether it was applied.
  std::optional<bool> applyInPanel(IntegratorKind kind, double step_ms, double tolerance_um = 1.0) {
    auto* panel = window_->findChild<AccuracyPanel*>("accuracyPanel");
    auto* choice = panel ? panel->findChild<QComboBox*>("integratorChoice") : nullptr;
    auto* step = panel ? panel->findChild<QDoubleSpinBox*>("integratorStepMs") : nullptr;
    auto* tolerance = panel ? panel->findChild<QDoubleSpinBox*>("integratorToleranceUm") : nullptr;
    auto* apply = panel ? panel->findChild<QPushButton*>("applyAccuracy") : nullptr;
    if (!choice || !step || !tolerance || !apply) {
      ADD_FAILURE() << "the accuracy panel or one of its fields is missing";
      return std::nullopt;
    }
    EXPECT_EQ(choice->count(), static_cast<int>(kAllIntegrators.size()));
    choice->setCurrentIndex(choice->findData(static_cast<int>(kind)));
    step->setValue(step_ms);
    tolerance->setValue(tolerance_um);
    EXPECT_TRUE(apply->isVisible() && apply->isEnabled());
    return clickApplyAndWait(apply);
  }

  std::optional<bool> clickApplyAndWait(QPushButton* apply) {
    QSignalSpy finished(window_.get(), &MainWindow::integratorChangeFinished);
    QTest::mouseClick(apply, Qt::LeftButton);
    return waitForIntegratorChange(finished);
  }

  static std::optional<bool> waitForIntegratorChange(QSignalSpy& finished) {
    if (finished.isEmpty() && !finished.wait(kStartTimeoutMs)) {
      ADD_FAILURE() << "the integrator change did not finish within " << kStartTimeoutMs << " ms";
      return std::nullopt;
    }
    return finished.first().first().toBool();
  }

  QString statusText() const {
    auto* status = window_->findChild<QLabel*>("simulationStatus");
    return status ? status->text() : QString();
  }

  TetMesh mesh_;
  std::unique_ptr<MainWindow> window_;
  std::vector<std::pair<QString, QImage>> pictures_;
};

TEST_F(MainWindowTest, DraggingTheLiverPullsItAndItSpringsBackAfterTheRelease) {
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start) << "neither the centre of the liver nor its anterior point is under the "
                        "viewport or hits the liver";
  const std::optional<ScenePick> hit = pickAt(*start);
  ASSERT_TRUE(hit);
  const QPoint end = *start + kDrag;
  // Where the handle ends up: the end of the drag on the camera-facing plane through the grabbed
  // point (the camera does not move during a grab).
  const QPoint endDisplay = toDisplay(end);
  const double handleTravel_m =
      (window_->scene().display_to_world(endDisplay.x(), endDisplay.y(), hit->point_m) -
       hit->point_m)
          .norm();
  ASSERT_GT(handleTravel_m, 0.005) << "the drag should move the handle by several millimetres";

  const QImage before = window_->viewport()->grabRendering();
  pictures_.emplace_back("before", before);
  const auto cameraBefore = cameraPosition();

  bool grabbedThroughout = true;
  pressAndMove(*start, end, [&] { grabbedThroughout &= window_->activeGrab() != nullptr; });
  EXPECT_TRUE(grabbedThroughout) << "the grab ended (or never began) during the drag";
  ASSERT_NE(window_->activeGrab(), nullptr);
  const Grab grab = *window_->activeGrab();  // a copy: the release ends it
  EXPECT_FALSE(grab.nodes.empty());
  EXPECT_LT((grab.grab_point_m - hit->point_m).norm(), 1e-9);

  // Hold the handle still for half a second of simulated time.
  ASSERT_TRUE(waitSimulated(0.5)) << "simulated time stalled during the hold";
  ASSERT_NE(window_->activeGrab(), nullptr);
  const double pulled_m = grabbedDisplacement(grab);
  // The springs pull the grabbed tissue most of the way (the CLI demo: 32 of 36 mm); the liver's
  // elasticity holds it back a little.
  EXPECT_GT(pulled_m, 0.3 * handleTravel_m)
      << "grabbed tissue moved " << pulled_m * 1e3 << " mm for a handle travel of "
      << handleTravel_m * 1e3 << " mm";
  EXPECT_EQ(distance(cameraBefore, cameraPosition()), 0.0) << "the grab also turned the camera";

  const QImage during = window_->viewport()->grabRendering();
  pictures_.emplace_back("during", during);
  // More than the grab marker, a sphere of 4 mm radius at the handle, must change.
  const double dragDevicePixels =
      std::hypot(kDrag.x(), kDrag.y()) * window_->viewport()->devicePixelRatioF();
  const double markerArea_px =
      std::numbers::pi * std::pow(0.004 * dragDevicePixels / handleTravel_m, 2);
  const int changed = countDifferentPixels(before, during);
  std::cout << "handle travel " << handleTravel_m * 1e3 << " mm, grabbed tissue moved "
            << pulled_m * 1e3 << " mm, " << grab.nodes.size() << " nodes grabbed; " << changed
            << " pixels changed (grab marker ~" << std::lround(markerArea_px) << ")\n";
  EXPECT_GT(changed, 3 * markerArea_px + 200)
      << "the picture barely changed: " << changed << " pixels (grab marker ~" << markerArea_px
      << " pixels)";

  // The status bar reports the frame rate and the simulation's speed, and the pull while grabbing.
  auto* status = window_->findChild<QLabel*>("simulationStatus");
  ASSERT_NE(status, nullptr);
  EXPECT_TRUE(QTest::qWaitFor([&] { return status->text().contains("pulling"); }, 5'000))
      << status->text().toStdString();
  for (const char* part : {"fps", "steps/s", "real-time factor"}) {
    EXPECT_TRUE(status->text().contains(QLatin1String(part)))
        << "'" << part << "' missing from the status: " << status->text().toStdString();
  }

  release(end);
  EXPECT_EQ(window_->activeGrab(), nullptr);
  // Mass damping α = 8/s: the free motion decays as e^(−αt/2), to e^−8 of the pull after 2 s.
  ASSERT_TRUE(waitSimulated(2.0)) << "simulated time stalled after the release";
  EXPECT_EQ(window_->activeGrab(), nullptr);
  const double residual_m = maxDisplacementFromRest();
  std::cout << "largest displacement 2 s after the release " << residual_m * 1e3 << " mm\n";
  EXPECT_LT(residual_m, 1e-3) << "the liver did not spring back: largest displacement "
                              << residual_m * 1e3 << " mm, 2 s after the release";
}

// The forceps chosen in the Tool panel (issue 7): pressing on the liver closes them on it, the
// drag pulls the tissue, the panel shows the force on them and its trace; releasing lets go. The
// rendered picture shows the tool while it is held.
TEST_F(MainWindowTest, ForcepsFromTheToolPanelHoldPullAndLetGo) {
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start);
  auto* forceps = window_->toolPanel()->findChild<QRadioButton*>("toolForceps");
  ASSERT_NE(forceps, nullptr);
  forceps->click();
  ASSERT_EQ(window_->toolPanel()->tool(), ToolKind::forceps);

  const QImage before = window_->viewport()->grabRendering();
  pictures_.emplace_back("before", before);
  bool heldThroughout = true;
  pressAndMove(*start, *start + kDrag, [&] { heldThroughout &= window_->heldTool().has_value(); });
  EXPECT_TRUE(heldThroughout);
  EXPECT_EQ(window_->activeGrab(), nullptr) << "a tool is not the hand's grab";
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return window_->simulation().snapshot().hand(Hand::right).grasping; },
                      kSimulatedTimeTimeoutMs))
      << "the forceps closed on the liver took no hold";
  ASSERT_TRUE(waitSimulated(0.3));
  const SimulationSnapshot held = window_->simulation().snapshot();
  EXPECT_GT(held.hand(Hand::right).force_n.norm(), 0.0) << "the held tissue pulls on the forceps";
  EXPECT_TRUE(window_->toolPanel()->forceText().contains("holding tissue"));
  EXPECT_GT(window_->toolPanel()->trace()->sampleCount(), 1u);
  EXPECT_GT(maxDisplacementFromRest(), 0.002) << "the pull moved the liver";
  const QImage holding = window_->viewport()->grabRendering();
  pictures_.emplace_back("holding", holding);
  EXPECT_GT(countDifferentPixels(before, holding), 100) << "neither the tool nor the pull shows";

  release(*start + kDrag);
  EXPECT_FALSE(window_->heldTool().has_value());
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return !window_->simulation().snapshot().hand(Hand::right).grasping; },
                      kSimulatedTimeTimeoutMs));
  ASSERT_TRUE(waitSimulated(0.05));
  EXPECT_EQ(window_->simulation().snapshot().hand(Hand::right).force_n.norm(), 0.0);
}

// The mouse is a device like the others (issue 8): its tool goes through the 1 kHz servo at the
// point the press put it, device millimetres being scene millimetres; its session is recorded from
// its first press, with the probe held from the press to the release, and the stored path is the
// drag's length in the scene.
TEST_F(MainWindowTest, TheMouseDrivesTheToolThroughTheServoAndItsSessionIsRecorded) {
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QString database = folder.filePath("sessions.sqlite");
  ASSERT_TRUE(window_->setSessionsDatabase(database)) << window_->sessionsProblem().toStdString();
  ASSERT_NE(window_->servo(), nullptr);
  EXPECT_FALSE(window_->recordingSession()) << "recorded before the mouse took a tool";
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start);
  window_->toolPanel()->setTool(ToolKind::probe);

  // Where the drag takes the probe: along the view plane through the picked point.
  const auto picked = pickAt(*start);
  ASSERT_TRUE(picked);
  const QPoint endDisplay = toDisplay(*start + kDrag);
  const Eigen::Vector3d dragged_m =
      window_->scene().display_to_world(endDisplay.x(), endDisplay.y(), picked->point_m) -
      picked->point_m;
  bool toolThroughTheServo = true;
  pressAndMove(*start, *start + kDrag, [&] {
    const SimulationSnapshot& seen = window_->simulation().snapshot();
    if (seen.hand(Hand::right).tool && seen.hand(Hand::right).device_sample)
      toolThroughTheServo &= (seen.hand(Hand::right).tool->pose.origin_m -
                              seen.hand(Hand::right).device_sample->position_mm * 1e-3)
                                 .norm() < 1e-12;
  });
  ASSERT_TRUE(window_->recordingSession()) << window_->sessionsProblem().toStdString();
  const std::int64_t session = *window_->recordingSession();
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        const auto& tool = window_->simulation().snapshot().hand(Hand::right).tool;
        return tool && (tool->pose.origin_m - window_->heldTool()->pose.origin_m).norm() < 1e-12;
      },
      kSimulatedTimeTimeoutMs))
      << "the probe never reached the point the drag put it";
  EXPECT_TRUE(toolThroughTheServo) << "the tool was not at the device's point";
  release(*start + kDrag);
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return !window_->simulation().snapshot().hand(Hand::right).tool; },
                      kSimulatedTimeTimeoutMs))
      << "the released probe stayed";
  // A scene change would end it too; choosing the mouse again does.
  QSignalSpy metricsStored(window_.get(), &MainWindow::sessionMetricsStored);
  ASSERT_TRUE(window_->useDevice(DeviceChoice::mouse));
  ASSERT_TRUE(metricsStored.wait(kSimulatedTimeTimeoutMs));
  EXPECT_TRUE(metricsStored.first().at(1).toBool()) << window_->sessionsProblem().toStdString();

  SqliteSessionStore store(database.toStdString(), SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].id, session);
  EXPECT_EQ(sessions[0].device, "Mouse and keyboard");
  EXPECT_EQ(sessions[0].status, SessionStatus::complete);
  ASSERT_TRUE(sessions[0].mapping);
  EXPECT_EQ(sessions[0].mapping->scale, 1.0);
  EXPECT_GT(sessions[0].frame_count, 0);
  std::vector<std::string> held;
  for (const SessionEvent& event : store.events(session))
    if (event.kind == SessionEventKind::tool_selected) held.push_back(event.detail);
  EXPECT_EQ(held, (std::vector<std::string>{"probe", "hand"}));
  // The drag moved the probe in straight steps: its path is the drag's length (to the
  // millimetre's thousandth the frames' doubles carry, and the steps' rounding to pixels).
  std::optional<double> path_mm;
  for (const MetricValue& metric : store.metrics(session))
    if (metric.name == "path_length_mm") path_mm = metric.value;
  ASSERT_TRUE(path_mm);
  EXPECT_NEAR(*path_mm, dragged_m.norm() * 1e3, 0.02 * dragged_m.norm() * 1e3)
      << "the drag was " << dragged_m.norm() * 1e3 << " mm";
}

// The scalpel drawn across the liver cuts it (issue 7): the simulation's mesh gains node copies
// along the cut, the scene shows the cut mesh's surface with its cut faces in the interior colour,
// and the liver goes on simulating.
TEST_F(MainWindowTest, TheScalpelDrawnAcrossTheLiverCutsIt) {
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start);
  auto* scalpel = window_->toolPanel()->findChild<QRadioButton*>("toolScalpel");
  ASSERT_NE(scalpel, nullptr);
  scalpel->click();
  const std::size_t nodes_before = window_->simulation().snapshot().model->node_count;
  const QImage before = window_->viewport()->grabRendering();
  pictures_.emplace_back("before", before);
  // Pressed in, the blade breaks into the tissue once the stress under it reaches the cutting
  // stress (however slowly this machine simulates); then drawn across the liver, a long stroke
  // that passes whole elements: 50 mm, whatever the viewport's size makes of it in pixels. It is
  // pressed in at the middle of the liver, where it is thickest: 30 mm to the left, on the slope
  // of the anterior face, the blade only dents the tissue (see the session note).
  const std::optional<ScenePick> centre = pickAt(*start);
  ASSERT_TRUE(centre);
  const QPoint centreDisplay = toDisplay(*start);
  const double metresPer100Px = (window_->scene().display_to_world(
                                     centreDisplay.x() + 100, centreDisplay.y(), centre->point_m) -
                                 centre->point_m)
                                    .norm();
  const QPoint across(static_cast<int>(std::lround(100.0 * 0.050 / metresPer100Px)), 0);
  sendMouse(QEvent::MouseButtonPress, *start, Qt::LeftButton, Qt::LeftButton);
  ASSERT_TRUE(QTest::qWaitFor(
      [&] { return window_->simulation().snapshot().hand(Hand::right).blade_cutting; },
      kSimulatedTimeTimeoutMs))
      << "the pressed blade did not break into the tissue";
  // Each move after some simulated time, so that a slow machine sees the same stroke.
  for (int step = 1; step <= kDragMoves; ++step) {
    ASSERT_TRUE(waitSimulated(0.02));
    sendMouse(QEvent::MouseMove, *start + across * step / kDragMoves, Qt::NoButton, Qt::LeftButton);
  }
  ASSERT_TRUE(QTest::qWaitFor([&] { return window_->simulation().snapshot().topology_version > 0; },
                              kSimulatedTimeTimeoutMs))
      << "the scalpel drawn across the liver cut nothing (contacts "
      << window_->simulation().snapshot().hand(Hand::right).contacts << ", blade in the tissue "
      << window_->simulation().snapshot().hand(Hand::right).blade_cutting << ")";
  const QImage cutting = window_->viewport()->grabRendering();
  pictures_.emplace_back("cutting", cutting);
  release(*start + across);
  ASSERT_TRUE(waitSimulated(0.1));
  const SimulationSnapshot after = window_->simulation().snapshot();
  EXPECT_GT(after.model->node_count, nodes_before) << "no node copies along the cut";
  EXPECT_EQ(after.position_m.size(), after.model->node_count);
  EXPECT_FALSE(window_->simulation().stats().halted);
  EXPECT_GT(countDifferentPixels(before, cutting), 100) << "neither the scalpel nor the cut shows";
}

// Session ▸ Remove Specimen with no piece cut free says so, and takes nothing (issue 42, item 5);
// the status line counts pieces cut free and specimens taken out, in the trainee's words.
TEST_F(MainWindowTest, RemoveSpecimenSaysWhenNoPieceIsFreeAndTheStatusLineCountsThem) {
  QAction* remove = window_->findChild<QAction*>("removeSpecimenAction");
  ASSERT_NE(remove, nullptr);
  const std::uint64_t topology = window_->simulation().snapshot().topology_version;
  remove->trigger();
  EXPECT_TRUE(window_->statusBar()->currentMessage().contains("no specimen to remove"))
      << window_->statusBar()->currentMessage().toStdString();
  ASSERT_TRUE(waitSimulated(0.05));
  EXPECT_EQ(window_->simulation().snapshot().topology_version, topology);
  EXPECT_EQ(window_->simulation().snapshot().specimens_taken_out, 0);

  SimulationStatus status;
  status.freeBodies = 2;
  status.specimensTakenOut = 1;
  status.resectedVolume_m3 = 51.5e-6;
  const QString text = simulationStatusText(status);
  // (Plural forms come from the translations the workstation installs; a test has none.)
  // What the trainee acts on comes first, before the simulation's figures: a window narrower than
  // the line cuts its end off (at 1280 px the hint to remove the specimen was not shown).
  EXPECT_TRUE(text.startsWith("2 piece") &&
              text.contains("cut free: lift out or Session ▸ Remove Specimen"))
      << text.toStdString();
  EXPECT_TRUE(text.contains("| 1 specimen")) << text.toStdString();
  EXPECT_LT(text.indexOf("resected 51.5 mL"), text.indexOf("fps")) << text.toStdString();
  EXPECT_FALSE(simulationStatusText(SimulationStatus{}).contains("cut free"));
  EXPECT_TRUE(simulationStatusText(SimulationStatus{}).startsWith("0 fps"));
}

// With the mouse the scalpel's depth is set by the wheel while the button is down (issue 42, item
// 3), and the Tool panel shows how much of its edge is in the tissue; the wheel does not zoom
// then. Put in where pressed, the 2 cm blade is about 16 mm in; six notches back draw it 6 mm out
// along its shaft, tilted 35° from the view, so its edge leaves at least 3 mm (the tissue it
// dragged may follow it some way).
TEST_F(MainWindowTest, TheWheelSetsTheHeldScalpelsDepthAndThePanelShowsIt) {
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start);
  window_->toolPanel()->findChild<QRadioButton*>("toolScalpel")->click();
  auto* blade = window_->toolPanel()->findChild<QLabel*>("toolBladeDepth");
  ASSERT_NE(blade, nullptr);
  sendMouse(QEvent::MouseButtonPress, *start, Qt::LeftButton, Qt::LeftButton);
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        return window_->simulation().snapshot().hand(Hand::right).blade_edge_in_tissue_m > 0.005;
      },
      kSimulatedTimeTimeoutMs))
      << "the blade put in where pressed is not in the tissue";
  ASSERT_TRUE(waitSimulated(0.1));
  const double inBefore_m =
      window_->simulation().snapshot().hand(Hand::right).blade_edge_in_tissue_m;
  ASSERT_TRUE(window_->simulation().snapshot().hand(Hand::right).tool);
  const Tool putOn = *window_->simulation().snapshot().hand(Hand::right).tool;
  ASSERT_TRUE(QTest::qWaitFor([&] { return blade->isVisible(); }, 5'000));
  EXPECT_TRUE(blade->text().contains(QStringLiteral("mm in the tissue")))
      << blade->text().toStdString();
  const auto camera = cameraPosition();

  send_wheel(*window_->viewport(), *start, -6, Qt::LeftButton);
  ASSERT_TRUE(waitSimulated(0.2));
  const double inAfter_m =
      window_->simulation().snapshot().hand(Hand::right).blade_edge_in_tissue_m;
  std::cout << "the blade's edge in the tissue: " << inBefore_m * 1e3
            << " mm, drawn back 6 mm: " << inAfter_m * 1e3 << " mm\n";
  EXPECT_LT(inAfter_m, inBefore_m - 0.003) << "the wheel did not draw the blade back";
  EXPECT_EQ(cameraPosition(), camera) << "the wheel zoomed while the blade was held";
  // The panel shows the depth now (to its tenth of a millimetre, a snapshot or two later).
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        return blade->text().contains(QString::number(
            window_->simulation().snapshot().hand(Hand::right).blade_edge_in_tissue_m * 1e3, 'f',
            1));
      },
      5'000))
      << blade->text().toStdString();

  // Pushed in sixteen notches, 10 mm deeper than it was put on: deeper than its blade, so its
  // handle goes into the tissue with it, and more of it is in.
  send_wheel(*window_->viewport(), *start, 16, Qt::LeftButton);
  ASSERT_TRUE(waitSimulated(0.2));
  const Tool pushed = *window_->simulation().snapshot().hand(Hand::right).tool;
  const Eigen::Vector3d shaft = putOn.pose.orientation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR((putOn.pose.origin_m - pushed.pose.origin_m).dot(shaft), 0.010, 1e-9);
  const double inDeep_m = window_->simulation().snapshot().hand(Hand::right).blade_edge_in_tissue_m;
  std::cout << "pushed 10 mm deeper than put on: " << inDeep_m * 1e3 << " mm in the tissue\n";
  EXPECT_GT(inDeep_m, inBefore_m + 0.005);
  EXPECT_FALSE(window_->simulation().stats().halted);

  release(*start);
  // Released, the wheel zooms again.
  send_wheel(*window_->viewport(), *start, 1, Qt::NoButton);
  EXPECT_NE(cameraPosition(), camera);
}

TEST_F(MainWindowTest, DraggingTheBackgroundTurnsTheCameraAndGrabsNothing) {
  const QPoint corner(20, 20);
  ASSERT_FALSE(pickAt(corner)) << "the liver covers the corner of the viewport";
  const auto before = cameraPosition();
  pictures_.emplace_back("before", window_->viewport()->grabRendering());

  bool grabbedAtAll = false;
  pressAndMove(corner, corner + kDrag, [&] { grabbedAtAll |= window_->activeGrab() != nullptr; });
  release(corner + kDrag);

  EXPECT_FALSE(grabbedAtAll);
  EXPECT_EQ(window_->activeGrab(), nullptr);
  EXPECT_GT(distance(before, cameraPosition()), 1e-3) << "the camera did not turn";
}

TEST_F(MainWindowTest, TheStatusBarReportsFrameRateAndSimulationSpeed) {
  auto* status = window_->findChild<QLabel*>("simulationStatus");
  ASSERT_NE(status, nullptr);
  ASSERT_TRUE(QTest::qWaitFor([&] { return !status->text().isEmpty(); }, 5'000));
  for (const char* part : {"fps", "steps/s", "real-time factor"}) {
    EXPECT_TRUE(status->text().contains(QLatin1String(part)))
        << "'" << part << "' missing from the status: " << status->text().toStdString();
  }
  EXPECT_FALSE(status->text().contains("pulling")) << "nothing is grabbed";
  // The accuracy part: the scenario's integrator and its error estimate.
  EXPECT_TRUE(status->text().contains(QStringLiteral("Central difference · error")))
      << status->text().toStdString();
}

TEST_F(MainWindowTest, EveryIntegratorChosenInThePanelRunsTheSimulation) {
  auto* panel = window_->accuracyPanel();
  ASSERT_NE(panel, nullptr);
  EXPECT_EQ(panel->settingsInUse().kind, IntegratorKind::central_difference);
  struct Choice {
    IntegratorKind kind;
    double step_ms;  // 0: the largest stable step of an explicit scheme
  };
  // The last one back to the default, so that a change to the same scheme works as well.
  for (const Choice choice :
       {Choice{IntegratorKind::rk4, 0.5}, Choice{IntegratorKind::dopri5, 0.0},
        Choice{IntegratorKind::backward_euler, 5.0}, Choice{IntegratorKind::bdf2, 4.0},
        Choice{IntegratorKind::central_difference, 0.0}}) {
    const std::string name(integrator_name(choice.kind));
    SCOPED_TRACE(name);
    const double timeBefore = window_->simulation().snapshot().time_s;
    const std::uint64_t stepsBefore = window_->simulation().snapshot().step_count;
    ASSERT_EQ(applyInPanel(choice.kind, choice.step_ms), true) << panel->errorText().toStdString();
    EXPECT_TRUE(panel->errorText().isEmpty()) << panel->errorText().toStdString();
    EXPECT_EQ(window_->simulation().model().integrator.kind, choice.kind);
    EXPECT_NEAR(window_->simulation().model().integrator.step_s, choice.step_ms * 1e-3, 1e-12);
    EXPECT_EQ(panel->settingsInUse().kind, choice.kind);
    // The new simulation goes on from where the old one stopped.
    EXPECT_GE(window_->simulation().snapshot().time_s, timeBefore);
    EXPECT_GE(window_->simulation().snapshot().step_count, stepsBefore);
    EXPECT_TRUE(window_->simulation().running());

    const std::uint64_t stepsAtChange = window_->simulation().snapshot().step_count;
    ASSERT_TRUE(waitSimulated(0.05)) << "simulated time stalled with " << name;
    EXPECT_GT(window_->simulation().snapshot().step_count, stepsAtChange);
    EXPECT_TRUE(QTest::qWaitFor(
        [&] {
          return statusText().contains(AccuracyPanel::integratorName(choice.kind) + " · error");
        },
        5'000))
        << statusText().toStdString();
    // At rest nothing moves whichever scheme runs.
    EXPECT_LT(maxDisplacementFromRest(), 1e-4) << name;
    std::cout << statusText().toStdString() << '\n';
  }
  // The status bar reports what the scheme costs once it has run a statistics window.
  EXPECT_TRUE(
      QTest::qWaitFor([&] { return statusText().contains("ms wall per ms simulated"); }, 5'000))
      << statusText().toStdString();
}

TEST_F(MainWindowTest, ChangingTheIntegratorDuringAPullKeepsTheTissueWhereItIs) {
  const std::optional<QPoint> start = pointOnTheLiver();
  ASSERT_TRUE(start);
  // A long pull across the liver.
  const QPoint across(160, 0);
  pressAndMove(*start - across / 2, *start + across / 2, [] {});
  ASSERT_NE(window_->activeGrab(), nullptr);
  const Grab grab = *window_->activeGrab();
  ASSERT_TRUE(waitSimulated(0.5));
  const double pulled_m = grabbedDisplacement(grab);
  ASSERT_GT(pulled_m, 0.003) << "the pull did not move the tissue";

  QSignalSpy finished(window_.get(), &MainWindow::integratorChangeFinished);
  ASSERT_TRUE(window_->applyIntegratorSettings({.kind = IntegratorKind::rk4, .step_s = 0.0}));
  // One change at a time: a second request while the model is being built is turned away.
  EXPECT_TRUE(window_->changingIntegrator());
  EXPECT_FALSE(window_->applyIntegratorSettings({.kind = IntegratorKind::dopri5}));
  ASSERT_EQ(waitForIntegratorChange(finished), true);
  EXPECT_FALSE(window_->changingIntegrator());
  ASSERT_EQ(window_->simulation().model().integrator.kind, IntegratorKind::rk4);
  // The first snapshot of the new simulation is where the old one stopped, still pulled...
  EXPECT_GT(grabbedDisplacement(grab), 0.8 * pulled_m);
  // ...and the handle still holds it there.
  ASSERT_TRUE(waitSimulated(0.5));
  EXPECT_NE(window_->activeGrab(), nullptr);
  EXPECT_GT(grabbedDisplacement(grab), 0.8 * pulled_m)
      << "pulled " << pulled_m * 1e3 << " mm before the change";
  release(*start + kDrag);
}

TEST_F(MainWindowTest, AnInvalidAccuracySettingIsExplainedAndTheRunningOneStays) {
  auto* panel = window_->accuracyPanel();
  const RealtimeSimulation* before = &window_->simulation();

  // An implicit scheme has no "largest stable step": a step of 0 is refused.
  ASSERT_EQ(applyInPanel(IntegratorKind::backward_euler, 0.0), false);
  const QString error = panel->errorText();
  EXPECT_TRUE(error.contains("step")) << error.toStdString();
  EXPECT_TRUE(panel->findChild<QLabel*>("accuracyError")->isVisible());
  EXPECT_EQ(&window_->simulation(), before) << "the simulation was replaced";
  EXPECT_EQ(window_->simulation().model().integrator.kind, IntegratorKind::central_difference);
  EXPECT_EQ(panel->settingsInUse().kind, IntegratorKind::central_difference);
  // The fields keep what the user typed, to be corrected.
  auto* choice = panel->findChild<QComboBox*>("integratorChoice");
  EXPECT_EQ(choice->currentData().toInt(), static_cast<int>(IntegratorKind::backward_euler));

  // dopri5 without an error tolerance is refused too.
  ASSERT_EQ(applyInPanel(IntegratorKind::dopri5, 0.0, 0.0), false);
  EXPECT_TRUE(panel->errorText().contains("tolerance")) << panel->errorText().toStdString();
  EXPECT_EQ(window_->simulation().model().integrator.kind, IntegratorKind::central_difference);

  // The old setting goes on running.
  EXPECT_TRUE(window_->simulation().running());
  const std::uint64_t steps = window_->simulation().snapshot().step_count;
  ASSERT_TRUE(waitSimulated(0.05));
  EXPECT_GT(window_->simulation().snapshot().step_count, steps);
  EXPECT_TRUE(QTest::qWaitFor([&] { return statusText().contains("Central difference"); }, 5'000))
      << statusText().toStdString();

  // A valid setting afterwards is applied and clears the message.
  ASSERT_EQ(applyInPanel(IntegratorKind::backward_euler, 5.0), true);
  EXPECT_TRUE(panel->errorText().isEmpty()) << panel->errorText().toStdString();
  EXPECT_EQ(window_->simulation().model().integrator.kind, IntegratorKind::backward_euler);
}

}  // namespace
}  // namespace liversim
