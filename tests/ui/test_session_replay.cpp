// A recorded session replayed in the viewport (issue 10), under a real X server. A trainee draws
// the mouse's scalpel through the lesion of a resection scenario: the session records a cut and
// a lesion breach, and its simulation input. The instructor's review opens its replay: seeking to
// the end gives the liver the workstation had to the last bit (cut included), seeking back shows
// it uncut again, play moves the cursor over the force plot and pause holds it. A session
// recorded before replays existed says why it cannot be replayed. The replay sees through the
// liver to the scenario's lesions.
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_replay.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "render/liver_scene.h"
#include "session_replay_window.h"
#include "session_review_window.h"
#include "simulated_waits.h"
#include "tool_panel.h"
#include "viewport_input.h"
#include "vtk_viewport.h"
#include "wait_limits.h"

#include <gtest/gtest.h>

#include <QCheckBox>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QSettings>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>

#include <filesystem>
#include <span>

namespace liversim {
namespace {

constexpr int kTimeoutMs = liversim::test::waitLimitMs(90'000);
const QString kSmallScenario =
    QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenario-small-resection.json";

bool samePositions(const NodeArray& a, const NodeArray& b) {
  return a.size() == b.size() && a.x == b.x && a.y == b.y && a.z == b.z;
}

int differentPixels(const QImage& a, const QImage& b) {
  if (a.size() != b.size()) return a.width() * a.height();
  const QImage ca = a.convertToFormat(QImage::Format_RGB32);
  const QImage cb = b.convertToFormat(QImage::Format_RGB32);
  int count = 0;
  for (int y = 0; y < ca.height(); ++y)
    for (int x = 0; x < ca.width(); ++x) {
      const QRgb p = ca.pixel(x, y), q = cb.pixel(x, y);
      count += std::abs(qRed(p) - qRed(q)) > 8 || std::abs(qGreen(p) - qGreen(q)) > 8 ||
               std::abs(qBlue(p) - qBlue(q)) > 8;
    }
  return count;
}

class SessionReplayWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QSettings().clear();
    ASSERT_TRUE(folder_.isValid());
    const ScenarioReading reading = read_scenario_file(kSmallScenario.toStdString());
    ASSERT_TRUE(reading.scenario);
    // The small resection at the element count of the workstation's cut test (a stroke of this
    // length passes whole elements). The stroke starts over the shipped lesion, near the lobe's
    // tip, and goes toward the thicker middle, where the blade, held at the height it was pressed
    // in at, goes deepest: about 5 to 10 mm under the surface at 70 to 110 mm. The lesion is put
    // under the middle of that stretch, 1 to 2 mm under the surface.
    scenario_ = *reading.scenario;
    strokeStart_m_ = to_metres(scenario_.lesions.front().centre_mm);
    scenario_.organ.target_tet_count = 3841;
    scenario_.lesions.front().centre_mm = {90.0, 24.0, 38.0};
    scenario_.lesions.front().radii_mm = {10.0, 10.0, 6.0};
    const std::string text = write_scenario(scenario_);
    const QString absolute = QFileInfo(kSmallScenario).absoluteFilePath();
    SceneSetup setup = build_scene(scenario_, QFileInfo(absolute).absolutePath().toStdString());
    window_ = std::make_unique<MainWindow>(std::move(setup),
                                           OpenedScenario{scenario_, absolute.toStdString(), text});
    ASSERT_TRUE(test::showRunning(*window_, window_->simulation(), kTimeoutMs));
  }
  void TearDown() override { window_.reset(); }

  const SimulationSnapshot& snapshot() const { return window_->simulation().snapshot(); }
  bool waitSimulated(double seconds) {
    return test::waitSimulated(window_->simulation(), seconds, kTimeoutMs);
  }
  bool waitArrived(SessionReplayWindow& replay) {
    return QTest::qWaitFor([&] { return !replay.seeking(); }, kTimeoutMs);
  }

  QTemporaryDir folder_;
  Scenario scenario_;
  Eigen::Vector3d strokeStart_m_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(SessionReplayWindowTest, ACutThroughTheLesionIsRecordedAndReplaysToTheSameLiver) {
  const QString database = folder_.filePath("sessions.sqlite");
  ASSERT_TRUE(window_->setSessionsDatabase(database)) << window_->sessionsProblem().toStdString();
  window_->toolPanel()->setTool(ToolKind::scalpel);
  VtkViewport& viewport = *window_->viewport();
  // Pressed on the liver near the lobe's tip and drawn toward the middle, over the lesion.
  const QPoint from = widget_point(viewport, window_->scene().world_to_display(strokeStart_m_));
  const QPoint to = from - QPoint(160, 0);
  const QPoint display = display_point(viewport, from);
  ASSERT_TRUE(window_->scene().pick(display.x(), display.y())) << "the stroke starts off the liver";
  send_mouse(viewport, QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton);
  ASSERT_TRUE(window_->recordingSession()) << window_->sessionsProblem().toStdString();
  const std::int64_t session = *window_->recordingSession();
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return snapshot().hand(Hand::right).blade_cutting; }, kTimeoutMs))
      << "the pressed blade did not break into the tissue";
  constexpr int kMoves = 14;
  for (int k = 1; k <= kMoves; ++k) {
    ASSERT_TRUE(waitSimulated(0.02));
    send_mouse(viewport, QEvent::MouseMove, from + (to - from) * k / kMoves, Qt::NoButton,
               Qt::LeftButton);
  }
  ASSERT_TRUE(waitSimulated(0.05));
  send_mouse(viewport, QEvent::MouseButtonRelease, to, Qt::LeftButton, Qt::NoButton);
  ASSERT_TRUE(waitSimulated(0.1));
  ASSERT_GT(snapshot().topology_version, 0u) << "the scalpel cut nothing";

  // The liver as the session leaves it: the simulation stopped, so every cycle it took is logged;
  // then the session ends (the mouse is chosen again) and its metrics are stored.
  window_->simulation().stop();
  const SimState live = window_->simulation().state();
  const std::size_t live_nodes = window_->simulation().model().node_count;
  QSignalSpy metricsStored(window_.get(), &MainWindow::sessionMetricsStored);
  ASSERT_TRUE(window_->useDevice(DeviceChoice::mouse));
  ASSERT_TRUE(metricsStored.wait(kTimeoutMs));

  {
    SqliteSessionStore store(database.toStdString(), SqliteSessionStore::Access::read_only);
    const std::vector<SessionEvent> events = store.events(session);
    const auto has = [&](SessionEventKind kind, const std::string& detail = {}) {
      return std::any_of(events.begin(), events.end(), [&](const SessionEvent& e) {
        return e.kind == kind && (detail.empty() || e.detail == detail);
      });
    };
    EXPECT_TRUE(has(SessionEventKind::cut)) << "no cut event";
    EXPECT_TRUE(has(SessionEventKind::lesion_breach, "peripheral tumour")) << "no breach event";
    const std::vector<MetricValue> metrics = store.metrics(session);
    const auto breached = std::find_if(metrics.begin(), metrics.end(), [](const MetricValue& m) {
      return m.name == "lesion_breached";
    });
    ASSERT_NE(breached, metrics.end());
    EXPECT_EQ(breached->value, 1.0);
    const std::optional<ReplaySetup> setup = store.replay_setup(session);
    ASSERT_TRUE(setup);
    EXPECT_FALSE(setup->built_in_liver_tets);
    EXPECT_EQ(std::filesystem::path(setup->scenario_folder),
              std::filesystem::path(QFileInfo(kSmallScenario).absolutePath().toStdString()));
  }

  // The instructor's review (after the first instructor's log-in) opens the replay.
  QString why;
  ASSERT_TRUE(window_->logInInstructor("Dr. Grey", "replay password", &why)) << why.toStdString();
  SessionReviewWindow* review = window_->openSessionReview();
  ASSERT_NE(review, nullptr);
  ASSERT_TRUE(review->openSession(session));
  SessionReplayWindow* replay = review->openReplay();
  ASSERT_NE(replay, nullptr);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(replay));
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return replay->ready() || !replay->problem().isEmpty(); }, kTimeoutMs));
  ASSERT_TRUE(replay->ready()) << replay->problem().toStdString();
  EXPECT_GT(replay->recordedForcePointCount(), 100);
  EXPECT_GT(replay->durationS(), 0.2);
  replay->seek(0.0);
  ASSERT_TRUE(waitArrived(*replay));
  const QImage at_start = replay->viewport()->grabRendering();

  // To the end: the workstation's liver, to the bit.
  replay->seek(replay->durationS());
  ASSERT_TRUE(waitArrived(*replay));
  EXPECT_DOUBLE_EQ(replay->positionS(), replay->durationS());
  RealtimeSimulation& replayed = replay->replay()->simulation();
  EXPECT_EQ(replayed.state().step_count, live.step_count);
  ASSERT_EQ(replayed.model().node_count, live_nodes);
  EXPECT_TRUE(samePositions(replayed.state().position_m, live.position_m))
      << "the replay's liver differs from the workstation's";
  const QImage at_end = replay->viewport()->grabRendering();
  EXPECT_GT(differentPixels(at_start, at_end), 100) << "the replayed cut does not show";

  // Back to the start: from rest, uncut, and the picture of the start again.
  replay->seek(0.0);
  ASSERT_TRUE(waitArrived(*replay));
  EXPECT_EQ(replay->replay()->simulation().snapshot().topology_version, 0u);
  EXPECT_LT(differentPixels(at_start, replay->viewport()->grabRendering()), 50);

  // Play runs the cursor on; pause holds it.
  replay->play();
  ASSERT_TRUE(QTest::qWaitFor([&] { return replay->positionS() > 0.1; }, kTimeoutMs));
  EXPECT_TRUE(replay->playing());
  EXPECT_GT(replay->replayedForcePointCount(), 1);
  replay->pause();
  const double held = replay->positionS();
  QTest::qWait(300);
  EXPECT_EQ(replay->positionS(), held);
  // Played from near the end, it stops at the end.
  replay->seek(replay->durationS() - 0.05);
  replay->play();
  ASSERT_TRUE(QTest::qWaitFor([&] { return !replay->playing(); }, kTimeoutMs));
  EXPECT_DOUBLE_EQ(replay->positionS(), replay->durationS());
}

TEST_F(SessionReplayWindowTest, ASessionRecordedBeforeReplaysSaysItCannotBeReplayed) {
  const QString database = folder_.filePath("old.sqlite");
  ASSERT_TRUE(QFile::copy(QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/storage/sessions-v2.sqlite",
                          database));
  QFile::setPermissions(database, QFile::ReadOwner | QFile::WriteOwner);
  { SqliteSessionStore migrated(database.toStdString()); }
  SessionReplayWindow replay(database, 1);
  replay.show();
  EXPECT_FALSE(replay.ready());
  EXPECT_TRUE(replay.problem().contains("without its simulation input"))
      << replay.problem().toStdString();
  EXPECT_EQ(replay.statusText(), replay.problem());
  // And a session that does not exist.
  SessionReplayWindow missing(database, 99);
  EXPECT_FALSE(missing.ready());
  EXPECT_FALSE(missing.problem().isEmpty());
}

// A session on the small resection (its lesion visible to the trainee), written through the
// storage API as the recorder writes one: a few cycles of simulation input, enough to replay, and
// a tissue change, where its replay stops.
TEST(SessionReplaySeeThrough, ShowsTheScenarioLesionsThroughTheLiver) {
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const ScenarioReading reading = read_scenario_file(kSmallScenario.toStdString());
  ASSERT_TRUE(reading.scenario);
  ASSERT_FALSE(visible_lesions(*reading.scenario).empty());
  const std::string text = write_scenario(*reading.scenario);
  const QString database = folder.filePath("sessions.sqlite");
  std::int64_t session = 0;
  {
    SqliteSessionStore store(database.toStdString());
    SessionStart start;
    start.trainee = "Trainee R";
    start.scenario_title = reading.scenario->title;
    start.scenario_text = text;
    start.device = "Mouse";
    start.started_unix_ms = 1'795'000'000'000;
    ReplaySetup setup;
    setup.scenario_folder = QFileInfo(kSmallScenario).absolutePath().toStdString();
    setup.integrator = reading.scenario->integrator;
    start.replay = setup;
    session = store.begin_session(start);
    std::vector<SimulationInput> cycles(3);
    for (std::size_t k = 0; k < cycles.size(); ++k) {
      cycles[k].steps = 1;
      cycles[k].servo_time_s = 0.01 * static_cast<double>(k);
    }
    store.append_inputs(session, cycles);
    // The Material panel changed the tissue at the end: the replay says it stops there.
    const SessionEvent changed{0.02, SessionEventKind::material_changed, "E 7000 Pa, nu 0.45"};
    store.append_events(session, std::span(&changed, 1));
    store.commit();
  }

  SessionReplayWindow replay(database, session);
  replay.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&replay));
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return replay.ready() || !replay.problem().isEmpty(); }, kTimeoutMs));
  ASSERT_TRUE(replay.ready()) << replay.problem().toStdString();
  EXPECT_TRUE(replay.statusText().contains("where the tissue was changed (to E 7000 Pa, nu 0.45)"))
      << replay.statusText().toStdString();
  ASSERT_NE(replay.scene(), nullptr);
  EXPECT_GT(replay.scene()->shown_lesion_triangle_count(), 0u);
  EXPECT_FALSE(replay.seeThrough());
  EXPECT_EQ(replay.scene()->opacity(), 1.0);
  const QImage solid = replay.viewport()->grabRendering();

  auto* box = replay.findChild<QCheckBox*>("replaySeeThrough");
  ASSERT_NE(box, nullptr);
  QTest::mouseClick(box, Qt::LeftButton, {}, box->rect().center());
  EXPECT_TRUE(replay.seeThrough());
  EXPECT_EQ(replay.scene()->opacity(), kSeeThroughOpacity);
  const QImage seen_through = replay.viewport()->grabRendering();
  // Seen through, every pixel of the liver changes: fitted to the view, it covers tens of
  // thousands of pixels even in the smallest viewport (480 x 360); at least 10 000 must change.
  EXPECT_GT(differentPixels(solid, seen_through), 10'000);

  QTest::mouseClick(box, Qt::LeftButton, {}, box->rect().center());
  EXPECT_FALSE(replay.seeThrough());
  EXPECT_EQ(replay.scene()->opacity(), 1.0);
}

}  // namespace
}  // namespace liversim
