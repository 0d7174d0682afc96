// The trainee's walkthrough, through the window as a user drives it: start the workstation on its
// defaults, open a shipped scenario from File ▸ Open, run it for a few seconds with a scripted
// device chosen in the Device panel, mark the lesion with its shortcut, stop by going back to the
// mouse, and read the result in the Scenario panel.
#include <gtest/gtest.h>

#include <QAbstractItemView>
#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QSettings>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>

#include <memory>

#include "device_panel.h"
#include "haptic_preferences.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/data_paths.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "palpation_points.h"
#include "scenario_panel.h"
#include "tool_panel.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kTimeoutMs = liversim::test::waitLimitMs(90'000);

// Answers the next file dialog with `file` (Qt's own dialog: the test asks for no native one).
void answerNextFileDialogWith(const QString& file) {
  auto* poll = new QTimer;
  QObject::connect(poll, &QTimer::timeout, [poll, file] {
    auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
    if (dialog == nullptr) return;
    poll->stop();
    poll->deleteLater();
    dialog->selectFile(file);
    QMetaObject::invokeMethod(dialog, "accept", Qt::QueuedConnection);  // its slot, as OK is
  });
  poll->start(20);
}

// Picks the entry of `combo` whose data is `value` as a user does: opens its list and clicks it.
void pickFromList(QComboBox* combo, int value) {
  const int index = combo->findData(value);
  ASSERT_GE(index, 0);
  combo->showPopup();
  QAbstractItemView* list = combo->view();
  ASSERT_TRUE(QTest::qWaitFor([&] { return list->isVisible(); }, 5000));
  const QRect row = list->visualRect(combo->model()->index(index, 0));
  QTest::mouseClick(list->viewport(), Qt::LeftButton, {}, row.center());
}

TEST(Walkthrough, OpenAShippedScenarioRunItWithAScriptedDeviceStopAndSeeTheResult) {
  QApplication::setAttribute(Qt::AA_DontUseNativeDialogs);
  QSettings().clear();
  {
    // The device's millimetres are the scene's (a calibration's result).
    HapticPreferences preferences;
    preferences.mapping_set = true;
    QSettings settings;
    save_haptic_preferences(settings, preferences);
  }
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());

  // Start: the default scene, a sessions database.
  MainWindow window(default_scene());
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  const QString database = folder.filePath("sessions.sqlite");
  ASSERT_TRUE(window.setSessionsDatabase(database)) << window.sessionsProblem().toStdString();

  // Open the shipped palpation scenario from File ▸ Open.
  const QString scenarioFile = QString::fromStdString(
      (shipped_data_folder() / "scenarios" / "palpation-hidden-lesion.json").string());
  QSignalSpy opened(&window, &MainWindow::scenarioOpenFinished);
  answerNextFileDialogWith(scenarioFile);
  window.findChild<QAction*>("openScenarioAction")->trigger();
  ASSERT_TRUE(opened.wait(kTimeoutMs));
  ASSERT_TRUE(opened.first().first().toBool())
      << window.scenarioPanel()->problemText().toStdString();
  ASSERT_TRUE(
      window.windowTitle().contains(QString::fromStdString(window.scenario()->scenario.title)));
  EXPECT_FALSE(window.scenarioPanel()->taskText().isEmpty());

  // A trajectory that holds the probe 10 mm off the surface nearest the hidden lesion.
  const Scenario& scenario = window.scenario()->scenario;
  const Eigen::Vector3d centre_m = to_metres(scenario.lesions.at(0).centre_mm);
  const Eigen::Vector3d hover_mm =
      hover_over_lesion_mm(*window.simulation().snapshot().model, centre_m);
  const QString trajectory = folder.filePath("hover.txt");
  save_trajectory(trajectory.toStdString(), {{0.0, hover_mm, 0}, {600.0, hover_mm, 0}});

  // The probe from the Tool panel, then the scripted device from the Device panel's list.
  window.toolPanel()->setTool(ToolKind::probe);
  answerNextFileDialogWith(trajectory);
  pickFromList(window.findChild<QComboBox*>("deviceChoice"),
               static_cast<int>(DeviceChoice::scripted));
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return window.device() == DeviceChoice::scripted; }, kTimeoutMs));
  ASSERT_TRUE(window.recordingSession().has_value()) << window.sessionsProblem().toStdString();
  const std::int64_t session = *window.recordingSession();

  // A few seconds of the scenario, the probe at its place; the lesion marked with M.
  const double start_s = window.simulation().snapshot().time_s;
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        const SimulationSnapshot& s = window.simulation().snapshot();
        return s.time_s > start_s + 2.0 && s.hand(Hand::right).tool &&
               (s.hand(Hand::right).tool->pose.origin_m - hover_mm * 1e-3).norm() < 1e-9;
      },
      kTimeoutMs));
  window.activateWindow();  // its shortcuts work while it is the active window
  ASSERT_TRUE(QTest::qWaitForWindowActive(&window));
  QTest::keyClick(&window, Qt::Key_M);

  // Stop: back to the mouse, which ends the session; its result reaches the Scenario panel.
  QSignalSpy metricsStored(&window, &MainWindow::sessionMetricsStored);
  pickFromList(window.findChild<QComboBox*>("deviceChoice"), static_cast<int>(DeviceChoice::mouse));
  ASSERT_TRUE(metricsStored.wait(kTimeoutMs));
  EXPECT_EQ(metricsStored.first().at(0).toLongLong(), session);
  EXPECT_TRUE(metricsStored.first().at(1).toBool()) << window.sessionsProblem().toStdString();
  EXPECT_FALSE(window.recordingSession().has_value());
  EXPECT_TRUE(window.scenarioPanel()->resultText().contains("score 100 %"))
      << window.scenarioPanel()->resultText().toStdString();

  // What the panel says is what the database keeps.
  SqliteSessionStore store(database.toStdString(), SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].scenario_title, scenario.title);
  EXPECT_EQ(lesion_marks(store.events(session)).size(), 1u);
}

}  // namespace
}  // namespace liversim
