// The workstation opening scenario files under a real X server: a valid one replaces the running
// scene (mesh, lesion regions, effects, tools offered, task shown, integrator) and goes to the
// recent list; a bad one, or one whose mesh cannot be built, is refused with its errors and the
// scene that was running goes on.
#include <gtest/gtest.h>

#include <QAction>
#include <QApplication>
#include <QFile>
#include <QFileInfo>
#include <QMenu>
#include <QMessageBox>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QSignalSpy>
#include <QStatusBar>
#include <QTemporaryDir>
#include <QTest>

#include <filesystem>
#include <fstream>
#include <memory>

#include "accuracy_panel.h"
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "main_window.h"
#include "recent_scenarios.h"
#include "scenario_panel.h"
#include "tool_panel.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kStartTimeoutMs = liversim::test::waitLimitMs(30'000);
constexpr int kBuildTimeoutMs = liversim::test::waitLimitMs(60'000);
constexpr int kSimulatedTimeTimeoutMs = liversim::test::waitLimitMs(90'000);

const QString kSmallScenario =
    QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenario-small-resection.json";
const QString kNegativeRadius =
    QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenarios/schema-negative-radius.json";

class ScenarioWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QSettings().clear();  // no recent scenarios from an earlier test
    window_ = std::make_unique<MainWindow>(default_scene(1000));
    window_->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(window_.get()));
    ASSERT_TRUE(QTest::qWaitFor([&] { return simulatedTime() > 0.0; }, kStartTimeoutMs));
  }
  void TearDown() override { window_.reset(); }

  double simulatedTime() const { return window_->simulation().snapshot().time_s; }
  bool waitSimulated(double duration_s) {
    const double until_s = simulatedTime() + duration_s;
    return QTest::qWaitFor([&] { return simulatedTime() >= until_s; }, kSimulatedTimeTimeoutMs);
  }

  // Opens `file` and waits for the window to say whether it did.
  std::optional<bool> open(const QString& file) {
    QSignalSpy finished(window_.get(), &MainWindow::scenarioOpenFinished);
    if (!window_->openScenario(file)) {
      ADD_FAILURE() << "the window refused to start opening " << file.toStdString();
      return std::nullopt;
    }
    if (finished.isEmpty() && !finished.wait(kBuildTimeoutMs)) {
      ADD_FAILURE() << "opening " << file.toStdString() << " did not finish";
      return std::nullopt;
    }
    return finished.first().first().toBool();
  }

  QString errorBoxText() const {
    auto* box = window_->findChild<QMessageBox*>("scenarioErrorBox");
    return box ? box->text() : QString();
  }

  std::unique_ptr<MainWindow> window_;
};

TEST_F(ScenarioWindowTest, OpeningAScenarioRunsItsSceneInPlaceOfTheOldOne) {
  const ScenarioReading reading = read_scenario_file(kSmallScenario.toStdString());
  ASSERT_TRUE(reading.scenario);
  const Scenario& expected = *reading.scenario;
  const std::size_t expected_tets =
      build_scene(expected, QFileInfo(kSmallScenario).absolutePath().toStdString())
          .mesh.tet_count();
  const std::size_t old_tets = window_->simulation().snapshot().model->tet_count;
  ASSERT_NE(old_tets, expected_tets);
  // A tool the scenario does not offer is put down when it opens.
  window_->toolPanel()->setTool(ToolKind::probe);

  ASSERT_EQ(open(kSmallScenario), true) << window_->scenarioPanel()->problemText().toStdString();

  ASSERT_TRUE(waitSimulated(0.05)) << "the scenario's simulation does not run";
  const SimModel& model = *window_->simulation().snapshot().model;
  EXPECT_EQ(model.tet_count, expected_tets);
  EXPECT_EQ(model.regions.size(), 1 + expected.lesions.size());  // the lesion is a region
  EXPECT_TRUE(model.effects.viscous);                            // the scenario's effects
  EXPECT_TRUE(window_->windowTitle().contains(QString::fromStdString(expected.title)));
  ASSERT_TRUE(window_->scenario());
  EXPECT_EQ(window_->scenario()->scenario, expected);
  EXPECT_TRUE(window_->scenarioPanel()->taskText().contains(
      QString::fromStdString(expected.task.instructions)));
  EXPECT_TRUE(window_->scenarioPanel()->problemText().isEmpty());
  EXPECT_FALSE(window_->toolPanel()->offers(ToolKind::probe));
  EXPECT_TRUE(window_->toolPanel()->offers(ToolKind::forceps));
  EXPECT_TRUE(window_->toolPanel()->offers(ToolKind::scalpel));
  EXPECT_EQ(window_->toolPanel()->tool(), std::nullopt);
  EXPECT_EQ(window_->accuracyPanel()->settingsInUse().kind, expected.integrator.kind);

  const QString absolute = QFileInfo(kSmallScenario).absoluteFilePath();
  ASSERT_FALSE(recentScenarioFiles().isEmpty());
  EXPECT_EQ(recentScenarioFiles().front(), absolute);
  auto* recent = window_->findChild<QMenu*>("recentScenariosMenu");
  ASSERT_NE(recent, nullptr);
  ASSERT_EQ(recent->actions().size(), 1);
  EXPECT_EQ(recent->actions().front()->data().toString(), absolute);

  // The recent entry opens it again, from rest.
  QSignalSpy finished(window_.get(), &MainWindow::scenarioOpenFinished);
  recent->actions().front()->trigger();
  ASSERT_TRUE(finished.wait(kBuildTimeoutMs));
  EXPECT_TRUE(finished.first().first().toBool());
  EXPECT_EQ(recentScenarioFiles().size(), 1);  // not listed twice
  EXPECT_TRUE(waitSimulated(0.02));
}

// A scenario whose organ is a surface model (issue 9): the real liver's boundary written as an OBJ
// in millimetres; the window meshes it at the scenario's count, saying so in the status bar, and
// runs it. The same model with a hole is refused, naming the file and the hole.
TEST_F(ScenarioWindowTest, AScenarioOfASurfaceModelIsMeshedShowingProgressAndRuns) {
  const TetMesh liver = read_tet_mesh(std::filesystem::path(LIVERSIM_SHARED_DIR) /
                                      "data/external/zhang-liver/Liver_Iso.inp");
  const BoundarySurface boundary = extract_surface(liver);
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  auto write_obj = [&](const QString& name, std::size_t triangles) {
    std::ofstream obj(folder.filePath(name).toStdString());
    obj.precision(17);
    for (NodeIndex n : boundary.nodes) {
      const Eigen::Vector3d p = liver.rest_position_m.at(n) * 1e3;
      obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
    for (std::size_t t = 0; t < triangles; ++t)
      obj << "f " << boundary.triangles[t][0] + 1 << ' ' << boundary.triangles[t][1] + 1 << ' '
          << boundary.triangles[t][2] + 1 << '\n';
  };
  write_obj("liver.obj", boundary.triangles.size());
  write_obj("holed.obj", boundary.triangles.size() - 1);
  ScenarioReading reading = read_scenario_file(kSmallScenario.toStdString());
  ASSERT_TRUE(reading.scenario);
  Scenario scenario = *reading.scenario;
  scenario.organ = OrganSpec{};
  scenario.organ.geometry = OrganGeometry::surface_file;
  scenario.organ.file = "liver.obj";
  scenario.organ.metres_per_unit = 1e-3;
  scenario.organ.target_tet_count = 2000;
  scenario.lesions.clear();
  scenario.task.kind = TaskKind::retract_lobe;  // needs no lesion
  scenario.rubric.clear();
  scenario.tools = {ToolKind::forceps};
  const QString file = folder.filePath("imported.json");
  write_scenario_file(scenario, file.toStdString());
  ASSERT_TRUE(read_scenario_file(file.toStdString()).scenario)
      << read_scenario_file(file.toStdString()).errors.front().text();

  QStringList shown;
  QObject::connect(window_->statusBar(), &QStatusBar::messageChanged,
                   [&](const QString& message) { shown << message; });
  ASSERT_EQ(open(file), true) << window_->scenarioPanel()->problemText().toStdString();
  EXPECT_TRUE(shown.filter("meshing the organ, attempt 1").size() == 1)
      << shown.join('\n').toStdString();
  EXPECT_FALSE(shown.filter("elements…").isEmpty()) << shown.join('\n').toStdString();
  ASSERT_TRUE(waitSimulated(0.05)) << "the imported organ does not simulate";
  const std::size_t tets = window_->simulation().snapshot().model->tet_count;
  EXPECT_NEAR(static_cast<double>(tets), 2000.0, 0.05 * 2000.0);

  scenario.organ.file = "holed.obj";
  const QString holed = folder.filePath("holed.json");
  write_scenario_file(scenario, holed.toStdString());
  EXPECT_EQ(open(holed), false);
  EXPECT_TRUE(window_->scenarioPanel()->problemText().contains("holed.obj"))
      << window_->scenarioPanel()->problemText().toStdString();
  EXPECT_TRUE(window_->scenarioPanel()->problemText().contains("not closed"))
      << window_->scenarioPanel()->problemText().toStdString();
  EXPECT_EQ(window_->simulation().snapshot().model->tet_count, tets) << "the scene was replaced";

  // Meshing shows its progress and can be cancelled: the scene running goes on, without an error.
  auto* progress = window_->findChild<QProgressBar*>("buildProgress");
  auto* cancel = window_->findChild<QPushButton*>("cancelBuild");
  ASSERT_TRUE(progress && cancel);
  EXPECT_TRUE(progress->isHidden() && cancel->isHidden());
  const auto running = window_->simulation().snapshot().model;
  const QString problemBefore = window_->scenarioPanel()->problemText();
  bool progressShown = false;
  const auto onMessage = QObject::connect(
      window_->statusBar(), &QStatusBar::messageChanged, [&](const QString& message) {
        if (!message.contains("meshing the organ") || !cancel->isVisible()) return;
        progressShown = progress->isVisible() && progress->maximum() > 0;
        QTest::mouseClick(cancel, Qt::LeftButton);
      });
  EXPECT_EQ(open(file), false);
  QObject::disconnect(onMessage);
  EXPECT_TRUE(progressShown) << "no meshing progress was shown before the cancel";
  EXPECT_TRUE(window_->statusBar()->currentMessage().contains("cancelled"))
      << window_->statusBar()->currentMessage().toStdString();
  EXPECT_EQ(window_->simulation().snapshot().model, running) << "the scene was replaced";
  EXPECT_EQ(window_->scenarioPanel()->problemText(), problemBefore) << "a cancel is no error";
  EXPECT_TRUE(progress->isHidden() && cancel->isHidden());
}

TEST_F(ScenarioWindowTest, ABadScenarioIsRefusedWithItsErrorsAndTheSceneGoesOn) {
  const auto running = window_->simulation().snapshot().model;
  const QString title = window_->windowTitle();

  EXPECT_EQ(open(kNegativeRadius), false);

  // The error names the field at fault, in the panel and in a message box.
  EXPECT_TRUE(window_->scenarioPanel()->problemText().contains("lesions[0].radii_mm"))
      << window_->scenarioPanel()->problemText().toStdString();
  EXPECT_TRUE(errorBoxText().contains("lesions[0].radii_mm")) << errorBoxText().toStdString();
  // Nothing was half-loaded: the same model runs on.
  EXPECT_EQ(window_->simulation().snapshot().model, running);
  EXPECT_FALSE(window_->scenario());
  EXPECT_EQ(window_->windowTitle(), title);
  EXPECT_TRUE(waitSimulated(0.02));
  EXPECT_TRUE(recentScenarioFiles().isEmpty());
}

TEST_F(ScenarioWindowTest, AScenarioWhoseMeshCannotBeBuiltIsRefusedAndTheSceneGoesOn) {
  // Valid as a file, but its mesh file is not there: found while the scene is built.
  QFile source(kSmallScenario);
  ASSERT_TRUE(source.open(QIODevice::ReadOnly));
  ScenarioReading reading = read_scenario(source.readAll().toStdString());
  ASSERT_TRUE(reading.scenario);
  Scenario scenario = *reading.scenario;
  scenario.organ.geometry = OrganGeometry::tet_mesh_file;
  scenario.organ.file = "missing-liver.inp";
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QString file = folder.filePath("missing-mesh.json");
  write_scenario_file(scenario, file.toStdString());
  ASSERT_TRUE(read_scenario_file(file.toStdString()).scenario) << "the file itself must be valid";
  const auto running = window_->simulation().snapshot().model;

  EXPECT_EQ(open(file), false);

  EXPECT_TRUE(window_->scenarioPanel()->problemText().contains("missing-liver.inp"))
      << window_->scenarioPanel()->problemText().toStdString();
  EXPECT_EQ(window_->simulation().snapshot().model, running);
  EXPECT_TRUE(waitSimulated(0.02));
  // The integrator can be changed again: nothing is left building.
  EXPECT_FALSE(window_->changingIntegrator());
  auto* apply = window_->accuracyPanel()->findChild<QPushButton*>("applyAccuracy");
  ASSERT_NE(apply, nullptr);
  EXPECT_TRUE(apply->isEnabled());
}

}  // namespace
}  // namespace liversim

namespace liversim {
namespace {

TEST_F(ScenarioWindowTest, SeeThroughShowsTheScenariosLesionAndIsRemembered) {
  ASSERT_EQ(open(kSmallScenario), true) << window_->scenarioPanel()->problemText().toStdString();
  // Solid: the lesion is drawn but hidden inside the liver.
  EXPECT_FALSE(window_->seeThrough());
  EXPECT_DOUBLE_EQ(window_->scene().opacity(), 1.0);
  EXPECT_GT(window_->scene().shown_lesion_triangle_count(), 0u);

  auto* action = window_->findChild<QAction*>("seeThroughAction");
  ASSERT_NE(action, nullptr);
  action->trigger();
  EXPECT_TRUE(window_->seeThrough());
  EXPECT_DOUBLE_EQ(window_->scene().opacity(), kSeeThroughOpacity);

  // The next window starts see-through.
  window_.reset();
  window_ = std::make_unique<MainWindow>(default_scene(1000));
  EXPECT_TRUE(window_->seeThrough());
  EXPECT_DOUBLE_EQ(window_->scene().opacity(), kSeeThroughOpacity);
  // Free practice has no lesions.
  EXPECT_EQ(window_->scene().shown_lesion_triangle_count(), 0u);
  window_->setSeeThrough(false);
  EXPECT_DOUBLE_EQ(window_->scene().opacity(), 1.0);
}

}  // namespace
}  // namespace liversim
