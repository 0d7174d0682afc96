// The training centre from the workstation, under a real X server and against a real PostgreSQL
// server (a throwaway cluster on loopback): Settings ▸ Training Centre Server… refuses an address
// with a password and a wrong log-in, keeps the address and never the password in the settings
// file; the link uploads the workstation's finished sessions in the background and pulls the
// published scenarios, the status bar says so, and says the server is not reached when it is
// down; an instructor reviews and grades the uploaded session on the server, and the grade comes
// back to the workstation.
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"
#include "main_window.h"
#include "recorded_session.h"
#include "session_review_window.h"
#include "throwaway_postgres.h"
#include "training_centre_dialog.h"
#include "wait_limits.h"

#include <gtest/gtest.h>

#include <QFile>
#include <QLabel>
#include <QSettings>
#include <QStatusBar>
#include <QTemporaryDir>
#include <QTest>

#include <fstream>
#include <sstream>

namespace liversim {
namespace {

constexpr int kTimeoutMs = liversim::test::waitLimitMs(60'000);
constexpr const char* kWorkstationPassword = "workstation password 9";
constexpr const char* kInstructorPassword = "instructor password 9";

QString urlOf(const ServerSettings& s) {
  return QString::fromStdString("postgresql://" + s.user + "@" + s.host + ":" +
                                std::to_string(s.port) + "/" + s.database + "?sslmode=disable");
}

TEST(TrainingCentreWindow, UploadsInTheBackgroundKeepsNoPasswordAndBringsGradesBack) {
  QSettings().clear();
  testing::ThrowawayPostgres server;
  const ServerSettings admin = server.administrator();
  PostgresSessionStore::set_up_server(admin, testing::ThrowawayPostgres::kAdministratorPassword);
  PostgresSessionStore::add_server_login(admin, testing::ThrowawayPostgres::kAdministratorPassword,
                                         "ws-01", kWorkstationPassword,
                                         ServerLoginKind::workstation);
  PostgresSessionStore::add_server_login(admin, testing::ThrowawayPostgres::kAdministratorPassword,
                                         "dr_grey", kInstructorPassword,
                                         ServerLoginKind::instructor);
  {  // a scenario published from the office
    PostgresSessionStore office(server.as("dr_grey"), kInstructorPassword);
    std::ifstream in(std::string(LIVERSIM_TEST_DATA_DIR) + "/scenario-small-resection.json");
    std::ostringstream text;
    text << in.rdbuf();
    office.publish_scenario(*office.log_in_instructor("dr_grey", kInstructorPassword),
                            "small-resection", text.str());
  }

  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QString database = folder.filePath("sessions.sqlite");
  std::string uuid;
  {
    SqliteSessionStore local(std::filesystem::path(database.toStdString()));
    const testing::Recorded r = testing::record_session(local, "Trainee A", 3000, 31);
    uuid = local.transfer_of(r.id).summary.uuid;
  }
  MainWindow window(default_scene(1500));
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  ASSERT_TRUE(window.setSessionsDatabase(database)) << window.sessionsProblem().toStdString();
  auto* status = window.findChild<QLabel*>("trainingCentreStatus");
  ASSERT_NE(status, nullptr);
  EXPECT_FALSE(status->isVisible()) << "no server set, yet the status bar speaks of one";

  // The dialog: an address with a password, and a wrong password, are refused in it.
  TrainingCentreDialog* dialog = window.openTrainingCentreSettings();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(dialog));
  const QString url = urlOf(server.as("ws-01"));
  dialog->submit(QString(url).replace("ws-01@", "ws-01:hunter2@"), {});
  EXPECT_TRUE(dialog->isVisible());
  EXPECT_TRUE(dialog->errorText().contains("password")) << dialog->errorText().toStdString();
  EXPECT_FALSE(dialog->errorText().contains("hunter2"));
  dialog->submit(url, "not the password");
  EXPECT_TRUE(dialog->isVisible());
  EXPECT_TRUE(dialog->errorText().contains("refused the login"))
      << dialog->errorText().toStdString();
  EXPECT_EQ(window.trainingCentre(), nullptr);
  const QPointer<TrainingCentreDialog> open = dialog;
  dialog->submit(url, kWorkstationPassword);
  ASSERT_TRUE(QTest::qWaitFor([&] { return open.isNull() || !open->isVisible(); }, kTimeoutMs))
      << dialog->errorText().toStdString();
  ASSERT_NE(window.trainingCentre(), nullptr);

  // The settings file holds the address, and no password.
  QSettings().sync();
  QFile settingsFile(QSettings().fileName());
  ASSERT_TRUE(settingsFile.open(QIODevice::ReadOnly)) << QSettings().fileName().toStdString();
  const QByteArray settingsText = settingsFile.readAll();
  EXPECT_TRUE(settingsText.contains(QByteArray::fromStdString(server.as("ws-01").host)));
  EXPECT_FALSE(settingsText.contains(kWorkstationPassword)) << settingsText.toStdString();
  EXPECT_FALSE(settingsText.contains("not the password"));

  // Uploaded in the background; the published scenario pulled next to the database.
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return window.trainingCentre()->status().uploaded == 1; }, kTimeoutMs))
      << window.trainingCentreStatusText().toStdString();
  ASSERT_TRUE(QTest::qWaitFor([&] { return status->text().contains("up to date"); }, kTimeoutMs))
      << status->text().toStdString();
  EXPECT_TRUE(status->isVisible());
  EXPECT_TRUE(QFile::exists(window.pulledScenarioFolder() + "/small-resection.json"));
  {
    PostgresSessionStore check(admin, testing::ThrowawayPostgres::kAdministratorPassword);
    EXPECT_TRUE(check.has_session(uuid));
  }

  // The instructor grades it on the server from the workstation's review window.
  QString why;
  EXPECT_EQ(window.openServerReview("dr_grey", "wrong", &why), nullptr);
  EXPECT_TRUE(why.contains("refused the login")) << why.toStdString();
  SessionReviewWindow* review = window.openServerReview("dr_grey", kInstructorPassword, &why);
  ASSERT_NE(review, nullptr) << why.toStdString();
  ASSERT_EQ(review->listedSessionCount(), 1) << review->problem().toStdString();
  ASSERT_TRUE(review->openSession(1));
  EXPECT_EQ(review->forcePointCount() > 0, true);
  review->setGradeForm("B+", "clean margins");
  ASSERT_TRUE(review->saveGrade()) << review->gradesText().toStdString();
  review->close();

  // The server down: the status bar names it; back up, the grade reaches the workstation.
  server.stop();
  window.trainingCentre()->run_soon();
  ASSERT_TRUE(QTest::qWaitFor([&] { return status->text().contains("not reached"); }, kTimeoutMs))
      << status->text().toStdString();
  EXPECT_TRUE(status->toolTip().contains("cannot connect")) << status->toolTip().toStdString();
  server.start();
  window.trainingCentre()->run_soon();
  ASSERT_TRUE(QTest::qWaitFor([&] { return window.trainingCentre()->status().grades_pulled == 1; },
                              kTimeoutMs))
      << window.trainingCentreStatusText().toStdString();
  SqliteSessionStore local(std::filesystem::path(database.toStdString()),
                           SqliteSessionStore::Access::read_only);
  const std::vector<SessionGrade> grades = local.grades(1);
  ASSERT_EQ(grades.size(), 1u);
  EXPECT_EQ(grades[0].grade, "B+");
  EXPECT_EQ(grades[0].comment, "clean margins");
}

}  // namespace
}  // namespace liversim
