// Long work in the workstation, each with progress and Cancel: the accuracy study (run from the
// Accuracy panel, cancelled mid-run, its best trade-offs marked, a run's setting put to use, the
// result saved as CSV) and reading a ten-minute session for review.
#include <gtest/gtest.h>

#include <QApplication>
#include <QCheckBox>
#include <QDir>
#include <QFile>
#include <QProgressBar>
#include <QProgressDialog>
#include <QPushButton>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>

#include <algorithm>
#include <cmath>
#include <memory>

#include "accuracy_panel.h"
#include "accuracy_study_dialog.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "session_review_window.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kTetCount = 3841;  // the running scene, as the other window tests
constexpr int kTimeoutMs = liversim::test::waitLimitMs(120'000);
constexpr int kBestColumn = 7;

std::unique_ptr<MainWindow> openWindow() {
  auto window = std::make_unique<MainWindow>(default_scene(kTetCount));
  window->show();
  EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
  return window;
}

AccuracyStudyDialog* openStudy(MainWindow& window) {
  auto* button = window.accuracyPanel()->findChild<QPushButton*>("openAccuracyStudy");
  EXPECT_NE(button, nullptr);
  if (button == nullptr) return nullptr;
  QTest::mouseClick(button, Qt::LeftButton);
  auto* dialog = window.findChild<AccuracyStudyDialog*>("accuracyStudyDialog");
  EXPECT_NE(dialog, nullptr);
  if (dialog != nullptr) {
    EXPECT_TRUE(QTest::qWaitForWindowExposed(dialog));
  }
  return dialog;
}

void chooseStudy(AccuracyStudyDialog& dialog, int tets, int durationMs,
                 std::initializer_list<IntegratorKind> kinds) {
  dialog.findChild<QSpinBox*>("studyTetCount")->setValue(tets);
  dialog.findChild<QSpinBox*>("studyDurationMs")->setValue(durationMs);
  for (IntegratorKind kind : kAllIntegrators)
    dialog.findChild<QCheckBox*>(QStringLiteral("studyIntegrator_%1").arg(static_cast<int>(kind)))
        ->setChecked(std::find(kinds.begin(), kinds.end(), kind) != kinds.end());
}

TEST(AccuracyStudyWindow, ComparesIntegratorsMarksTheBestTradeOffsAndPutsOneToUse) {
  QSettings().clear();
  auto window = openWindow();
  AccuracyStudyDialog* dialog = openStudy(*window);
  ASSERT_NE(dialog, nullptr);
  // A small liver and 2 ms keep the reference (RK4 at 0.25 ms / 64) short.
  chooseStudy(*dialog, 1000, 2, {IntegratorKind::central_difference, IntegratorKind::rk4});
  QSignalSpy finished(dialog, &AccuracyStudyDialog::finished);
  QTest::mouseClick(dialog->findChild<QPushButton*>("runStudy"), Qt::LeftButton);
  EXPECT_FALSE(dialog->findChild<QPushButton*>("runStudy")->isEnabled());
  ASSERT_TRUE(finished.wait(kTimeoutMs)) << dialog->statusText().toStdString();
  ASSERT_TRUE(dialog->result().has_value());
  EXPECT_EQ(dialog->findChild<QProgressBar*>("studyProgress")->value(),
            dialog->findChild<QProgressBar*>("studyProgress")->maximum());

  // 2 integrators × 3 steps, each row shown with its error and cost.
  const auto& rows = dialog->result()->rows;
  auto* table = dialog->findChild<QTableWidget*>("studyResults");
  ASSERT_EQ(rows.size(), 6u);
  ASSERT_EQ(table->rowCount(), 6);
  std::size_t most_accurate = 0, cheapest = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    EXPECT_TRUE(std::isfinite(rows[r].max_node_error_m));
    if (rows[r].max_node_error_m < rows[most_accurate].max_node_error_m) most_accurate = r;
    if (rows[r].wall_s < rows[cheapest].wall_s) cheapest = r;
  }
  // Nothing beats the most accurate run in error, nor the cheapest in cost: both are best
  // trade-offs whatever the figures; a run beaten in both is not.
  auto marked = [&](std::size_t r) {
    return !table->item(static_cast<int>(r), kBestColumn)->text().isEmpty();
  };
  EXPECT_TRUE(marked(most_accurate));
  EXPECT_TRUE(marked(cheapest));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t other = 0; other < rows.size(); ++other)
      if (rows[other].max_node_error_m < rows[r].max_node_error_m &&
          rows[other].wall_s < rows[r].wall_s) {
        EXPECT_FALSE(marked(r)) << "row " << r << " is beaten by row " << other;
      }

  // Runge–Kutta 4 at 0.5 ms, put to use on the running liver.
  int chosen = -1;
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (rows[r].integrator == IntegratorKind::rk4 && rows[r].step_s == 5e-4)
      chosen = static_cast<int>(r);
  ASSERT_GE(chosen, 0);
  table->selectRow(chosen);
  QSignalSpy applied(window.get(), &MainWindow::integratorChangeFinished);
  QTest::mouseClick(dialog->findChild<QPushButton*>("useStudySetting"), Qt::LeftButton);
  ASSERT_TRUE(applied.wait(kTimeoutMs));
  EXPECT_TRUE(applied.at(0).at(0).toBool());
  EXPECT_EQ(window->accuracyPanel()->settingsInUse().kind, IntegratorKind::rk4);
  EXPECT_DOUBLE_EQ(window->accuracyPanel()->settingsInUse().step_s, 5e-4);

  // Saved as the CLI's CSV: a header and a line per run. A folder that does not exist is named.
  QTemporaryDir folder;
  const QString csv = folder.filePath("study.csv");
  ASSERT_TRUE(dialog->saveCsv(csv)) << dialog->statusText().toStdString();
  QFile file(csv);
  ASSERT_TRUE(file.open(QIODevice::ReadOnly));
  const QList<QByteArray> lines = file.readAll().trimmed().split('\n');
  EXPECT_EQ(lines.size(), 7);
  EXPECT_TRUE(lines.front().startsWith("tets,effects,integrator,"));
  const QString missing = folder.filePath("no-such-folder/study.csv");
  EXPECT_FALSE(dialog->saveCsv(missing));
  EXPECT_TRUE(dialog->statusText().contains(QDir::toNativeSeparators(missing)))
      << dialog->statusText().toStdString();
}

TEST(AccuracyStudyWindow, CancelStopsTheRunUnderWayAndClosingTheDialogCancelsToo) {
  QSettings().clear();
  auto window = openWindow();
  AccuracyStudyDialog* dialog = openStudy(*window);
  ASSERT_NE(dialog, nullptr);
  // A study of minutes: the default liver, a second of simulated time, every integrator.
  chooseStudy(*dialog, kDefaultLiverTetCount, 1000, {});
  for (IntegratorKind kind : kAllIntegrators)
    dialog->findChild<QCheckBox*>(QStringLiteral("studyIntegrator_%1").arg(static_cast<int>(kind)))
        ->setChecked(true);
  QSignalSpy cancelled(dialog, &AccuracyStudyDialog::cancelled);
  QSignalSpy finished(dialog, &AccuracyStudyDialog::finished);
  auto* progress = dialog->findChild<QProgressBar*>("studyProgress");
  ASSERT_TRUE(dialog->start());
  // The reference has begun and advanced: progress moves within a run.
  QTRY_VERIFY_WITH_TIMEOUT(progress->value() > 0, kTimeoutMs);
  EXPECT_TRUE(dialog->statusText().startsWith("Run 1 of")) << dialog->statusText().toStdString();
  QTest::mouseClick(dialog->findChild<QPushButton*>("cancelStudy"), Qt::LeftButton);
  ASSERT_TRUE(cancelled.wait(kTimeoutMs));
  EXPECT_EQ(finished.count(), 0);
  EXPECT_FALSE(dialog->result().has_value());
  EXPECT_EQ(dialog->findChild<QTableWidget*>("studyResults")->rowCount(), 0);
  EXPECT_TRUE(dialog->findChild<QPushButton*>("runStudy")->isEnabled());
  EXPECT_TRUE(dialog->statusText().contains("Cancelled")) << dialog->statusText().toStdString();

  // Closing the dialog mid-run stops the study: nobody would see it.
  ASSERT_TRUE(dialog->start());
  QTRY_VERIFY_WITH_TIMEOUT(progress->value() > 0, kTimeoutMs);
  dialog->close();
  ASSERT_TRUE(cancelled.wait(kTimeoutMs));
  EXPECT_FALSE(dialog->running());
  // Nothing checked: refused with the reason, nothing started.
  chooseStudy(*dialog, 1000, 2, {});
  EXPECT_FALSE(dialog->start());
  EXPECT_TRUE(dialog->statusText().contains("at least one integrator"));
}

// Ten minutes at 1 kHz, written as the recorder does (a chunk per commit), with one event.
std::int64_t writeTenMinuteSession(const QString& database) {
  constexpr int kFrames = 600'000, kFramesPerChunk = 500;
  SqliteSessionStore store(database.toStdString());
  SessionStart start;
  start.trainee = "Trainee L";
  start.scenario_title = "Long practice";
  start.scenario_text = "{}";
  start.device = "Scripted";
  const std::int64_t session = store.begin_session(start);
  std::vector<ServoFrame> chunk(kFramesPerChunk);
  for (int first = 0; first < kFrames; first += kFramesPerChunk) {
    for (int i = 0; i < kFramesPerChunk; ++i) {
      const double t = (first + i) * 1e-3;
      chunk[static_cast<std::size_t>(i)].time_s = t;
      chunk[static_cast<std::size_t>(i)].force_n = Eigen::Vector3d(0.0, 0.0, 1.0 + std::sin(t));
    }
    store.append_frames(session, chunk);
    store.commit();
  }
  const SessionEvent grasp{60.0, SessionEventKind::grasp, ""};
  store.append_events(session, std::span(&grasp, 1));
  store.end_session(session, 1'795'000'600'000, SessionServoFigures{.ticks = kFrames});
  return session;
}

// Presses the reading dialog's Cancel once it has shown progress; what it saw is kept.
struct ReadingCanceller {
  QTimer timer;
  int valueAtCancel = -1;
  int maximum = 0;
  ReadingCanceller() {
    timer.setInterval(1);
    QObject::connect(&timer, &QTimer::timeout, [this] {
      for (QWidget* widget : QApplication::topLevelWidgets()) {
        auto* dialog = qobject_cast<QProgressDialog*>(widget);
        if (dialog == nullptr || dialog->objectName() != "sessionReadingProgress" ||
            !dialog->isVisible() || dialog->value() <= 0 || dialog->wasCanceled())
          continue;
        valueAtCancel = dialog->value();
        maximum = dialog->maximum();
        QTest::mouseClick(dialog->findChild<QPushButton*>(), Qt::LeftButton);
        timer.stop();
      }
    });
    timer.start();
  }
};

TEST(SessionReading, ATenMinuteSessionIsReadWithProgressAndCanBeCancelled) {
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QString database = folder.filePath("sessions.sqlite");
  const std::int64_t session = writeTenMinuteSession(database);

  SessionReviewWindow review(database);
  review.setReadingDialogDelayMs(0);  // shown at once: this machine may read it quickly
  review.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&review));
  ASSERT_TRUE(review.problem().isEmpty()) << review.problem().toStdString();
  {
    ReadingCanceller canceller;
    ASSERT_TRUE(review.openSession(session));
    // Cancelled part-way: no trace and no events (their times are from the first frame), the
    // window says so, and nothing else was lost.
    EXPECT_GT(canceller.valueAtCancel, 0);
    EXPECT_LT(canceller.valueAtCancel, canceller.maximum);
    EXPECT_FALSE(review.traceRead());
    EXPECT_EQ(review.forcePointCount(), 0);
    EXPECT_EQ(review.eventCount(), 0);
  }
  // Opened again, it is read whole.
  ASSERT_TRUE(review.openSession(session));
  EXPECT_TRUE(review.traceRead());
  EXPECT_GT(review.forcePointCount(), 0);
  EXPECT_EQ(review.eventCount(), 1);

  // An export cancelled while it reads writes nothing, and says so.
  {
    ReadingCanceller canceller;
    EXPECT_FALSE(review.exportCsv(folder.path()));
    EXPECT_TRUE(review.problem().contains("cancelled")) << review.problem().toStdString();
    EXPECT_FALSE(QFile::exists(folder.filePath(QString("session-%1-frames.csv").arg(session))));
  }
}

}  // namespace
}  // namespace liversim
