// The main window as a desktop product: the toolbar, trainee and instructor modes, the layout
// remembered between starts, and the Material panel changing the running liver's tissue and
// switching gravity.
#include <gtest/gtest.h>

#include <QAction>
#include <QCheckBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QSettings>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>
#include <QToolBar>

#include <cmath>
#include <limits>
#include <memory>

#include "instructor_login_dialog.h"
#include "liversim/meshing/default_scene.h"
#include "main_window.h"
#include "material_panel.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kTetCount = 3841;  // as the other window tests: small enough for Xvfb
constexpr int kTimeoutMs = liversim::test::waitLimitMs(60'000);

std::unique_ptr<MainWindow> openWindow() {
  auto window = std::make_unique<MainWindow>(default_scene(kTetCount));
  window->show();
  EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
  return window;
}

QAction* action(const MainWindow& window, const char* name) {
  return window.findChild<QAction*>(name);
}

double simulatedTime(const MainWindow& window) {
  return const_cast<MainWindow&>(window).simulation().snapshot().time_s;
}

TEST(Workstation, TheToolbarAndTheModesOfferWhatEachUserMayDo) {
  QSettings().clear();
  auto window = openWindow();
  QToolBar* toolbar = window->mainToolBar();
  ASSERT_NE(toolbar, nullptr);
  for (const char* name :
       {"openScenarioAction", "scenarioEditorAction", "seeThroughAction", "markLesionAction",
        "traineeHistoryAction", "reviewSessionsAction", "instructorModeAction"})
    EXPECT_TRUE(toolbar->actions().contains(action(*window, name))) << name;
  // A shortcut is named in its tooltip.
  EXPECT_TRUE(action(*window, "seeThroughAction")->toolTip().contains("(T)"))
      << action(*window, "seeThroughAction")->toolTip().toStdString();

  // A new workstation starts in trainee mode: the tissue read-only, no authoring or grading.
  EXPECT_FALSE(window->instructorMode());
  EXPECT_FALSE(action(*window, "scenarioEditorAction")->isVisible());
  EXPECT_FALSE(action(*window, "reviewSessionsAction")->isVisible());
  EXPECT_TRUE(action(*window, "traineeHistoryAction")->isVisible());
  auto* modulus = window->findChild<QDoubleSpinBox*>("materialYoungsModulus");
  ASSERT_NE(modulus, nullptr);
  EXPECT_TRUE(modulus->isReadOnly());
  // Nor does a call change it: the rule holds below the interface too.
  EXPECT_FALSE(window->applyTissue(window->materialPanel()->tissueInUse()));
  EXPECT_TRUE(window->materialPanel()->errorText().contains("for instructors"))
      << window->materialPanel()->errorText().toStdString();
  const double before = modulus->value();
  modulus->setFocus();
  QTest::keyClick(modulus, Qt::Key_Up);  // a read-only spin box does not step
  EXPECT_EQ(modulus->value(), before);
  EXPECT_FALSE(window->changingTissue());

  // Ambient occlusion: off by default (its frame-rate cost), on from the View menu.
  EXPECT_FALSE(window->scene().ambient_occlusion());
  action(*window, "ambientOcclusionAction")->trigger();
  EXPECT_TRUE(window->scene().ambient_occlusion());

  // Instructor mode asks for a log-in: on a database without accounts, the first account's form.
  QTemporaryDir folder;
  ASSERT_TRUE(window->setSessionsDatabase(folder.filePath("sessions.sqlite")));
  action(*window, "instructorModeAction")->trigger();
  EXPECT_FALSE(window->instructorMode());
  EXPECT_FALSE(action(*window, "instructorModeAction")->isChecked());
  auto* login = window->findChild<InstructorLoginDialog*>("instructorLoginDialog");
  ASSERT_NE(login, nullptr);
  EXPECT_EQ(login->purpose(), InstructorLoginDialog::Purpose::create_first_account);
  login->submit("Dr. Grey", "long enough", "long enougH");
  EXPECT_TRUE(login->errorText().contains("differ")) << login->errorText().toStdString();
  EXPECT_FALSE(window->instructorMode());
  login->submit("Dr. Grey", "long enough", "long enough");
  EXPECT_TRUE(window->instructorMode());
  EXPECT_TRUE(action(*window, "instructorModeAction")->isChecked());
  EXPECT_TRUE(action(*window, "scenarioEditorAction")->isVisible());
  EXPECT_TRUE(action(*window, "reviewSessionsAction")->isVisible());
  EXPECT_TRUE(action(*window, "addInstructorAction")->isVisible());
  EXPECT_FALSE(modulus->isReadOnly());
  // Turning it off logs out; turning it on again asks for the password, and a wrong one is
  // refused in the form.
  action(*window, "instructorModeAction")->trigger();
  EXPECT_FALSE(window->instructorMode());
  EXPECT_FALSE(window->instructor().has_value());
  EXPECT_TRUE(modulus->isReadOnly());
  QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete);  // the first form goes
  action(*window, "instructorModeAction")->trigger();
  login = window->findChild<InstructorLoginDialog*>("instructorLoginDialog");
  ASSERT_NE(login, nullptr);
  EXPECT_EQ(login->purpose(), InstructorLoginDialog::Purpose::log_in);
  login->submit("Dr. Grey", "not the password");
  EXPECT_EQ(login->errorText(), "Wrong name or password.");
  EXPECT_FALSE(window->instructorMode());
  login->submit("Dr. Grey", "long enough");
  EXPECT_TRUE(window->instructorMode());

  // A new start is a trainee's: the mode is not remembered, the view is.
  window.reset();
  window = openWindow();
  EXPECT_FALSE(window->instructorMode());
  EXPECT_FALSE(action(*window, "instructorModeAction")->isChecked());
  EXPECT_TRUE(window->scene().ambient_occlusion());
}

TEST(Workstation, TheWindowLayoutIsRememberedBetweenStarts) {
  QSettings().clear();
  auto window = openWindow();
  auto* material = window->findChild<QDockWidget*>("materialDock");
  auto* device = window->findChild<QDockWidget*>("deviceDock");
  ASSERT_TRUE(material && device);
  EXPECT_EQ(window->dockWidgetArea(material), Qt::RightDockWidgetArea);
  window->addDockWidget(Qt::LeftDockWidgetArea, material);
  device->toggleViewAction()->trigger();  // View ▸ Panels: closed
  EXPECT_TRUE(device->isHidden());
  window->resize(1000, 700);  // the docks' least heights may make it taller
  QTest::qWait(50);
  const QSize size = window->size();
  EXPECT_EQ(size.width(), 1000);
  window->close();  // saved as it closes
  window.reset();

  window = openWindow();
  material = window->findChild<QDockWidget*>("materialDock");
  device = window->findChild<QDockWidget*>("deviceDock");
  EXPECT_EQ(window->dockWidgetArea(material), Qt::LeftDockWidgetArea);
  EXPECT_TRUE(device->isHidden());
  EXPECT_EQ(window->size(), size);
  window.reset();

  // A damaged layout (another version's, a broken file) is ignored: the default layout.
  QSettings().setValue("window/state", QByteArray("not a window state"));
  QSettings().setValue("window/geometry", QByteArray("\x01\x02"));
  window = openWindow();
  material = window->findChild<QDockWidget*>("materialDock");
  EXPECT_EQ(window->dockWidgetArea(material), Qt::RightDockWidgetArea);
  EXPECT_FALSE(window->findChild<QDockWidget*>("deviceDock")->isHidden());
}

TEST(Workstation, TheMaterialPanelChangesTheRunningLiversTissue) {
  QSettings().clear();
  auto window = openWindow();
  QTemporaryDir folder;
  ASSERT_TRUE(window->setSessionsDatabase(folder.filePath("sessions.sqlite")));
  QString why;
  ASSERT_TRUE(window->logInInstructor("Dr. Grey", "long enough", &why)) << why.toStdString();
  ASSERT_TRUE(QTest::qWaitFor([&] { return simulatedTime(*window) > 0.0; }, kTimeoutMs));
  const SimModel& original = window->simulation().model();
  const double stepBefore_s = original.stable_time_step_s;
  const double nu = original.regions[0].tissue.poisson_ratio;

  // Twice the default modulus, entered in the panel in kPa.
  auto* modulus = window->findChild<QDoubleSpinBox*>("materialYoungsModulus");
  ASSERT_NE(modulus, nullptr);
  const double newModulusPa = 2.0 * original.regions[0].tissue.youngs_modulus_pa;
  QSignalSpy finished(window.get(), &MainWindow::tissueChangeFinished);
  const double timeBefore_s = simulatedTime(*window);
  modulus->setValue(newModulusPa / 1e3);
  ASSERT_TRUE(finished.wait(kTimeoutMs));
  ASSERT_TRUE(finished.first().first().toBool());
  const SimModel& changed = window->simulation().model();
  // μ = E / (2 (1 + ν)) in every element of the parenchyma (the only region here).
  EXPECT_DOUBLE_EQ(changed.shear_modulus_pa[0], newModulusPa / (2.0 * (1.0 + nu)));
  // Stiffer at the same mass: ω_max rises by √2, so the stable step shrinks.
  EXPECT_LT(changed.stable_time_step_s, stepBefore_s);
  // The liver went on from where it was: no restart from rest.
  EXPECT_GE(window->simulation().state().time_s, timeBefore_s);
  EXPECT_EQ(window->materialPanel()->tissueInUse().elastic.youngs_modulus_pa, newModulusPa);
  EXPECT_TRUE(window->materialPanel()->errorText().isEmpty());

  // A value no liver has is refused by name; the tissue in use stays.
  finished.clear();
  TissueSpec bad = window->materialPanel()->tissueInUse();
  bad.elastic.poisson_ratio = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(window->applyTissue(bad));
  ASSERT_TRUE(finished.wait(kTimeoutMs));
  EXPECT_FALSE(finished.first().first().toBool());
  EXPECT_TRUE(window->materialPanel()->errorText().contains("Poisson"))
      << window->materialPanel()->errorText().toStdString();
  EXPECT_DOUBLE_EQ(window->simulation().model().shear_modulus_pa[0],
                   newModulusPa / (2.0 * (1.0 + nu)));
  EXPECT_EQ(modulus->value(), newModulusPa / 1e3);

  // Entries made while one is applied: the newest is applied after it.
  finished.clear();
  TissueSpec first = window->materialPanel()->tissueInUse();
  first.elastic.density_kg_per_m3 = 1100.0;
  TissueSpec newest = first;
  newest.elastic.density_kg_per_m3 = 1000.0;
  ASSERT_TRUE(window->applyTissue(first));
  ASSERT_TRUE(window->applyTissue(newest));
  ASSERT_TRUE(QTest::qWaitFor([&] { return finished.size() == 2; }, kTimeoutMs));
  EXPECT_EQ(window->simulation().model().regions[0].tissue.density_kg_per_m3, 1000.0);
  EXPECT_FALSE(window->changingTissue());

  // What the scalpel will be held back by, entered in the panel: the fracture toughness and the
  // friction on the blade's sides, each from its default into the running liver's model.
  const auto enter = [&](const char* name, double shown, double entered) {
    finished.clear();
    auto* box = window->findChild<QDoubleSpinBox*>(name);
    ASSERT_NE(box, nullptr) << name;
    EXPECT_EQ(box->value(), shown) << name;
    box->setValue(entered);
    ASSERT_TRUE(finished.wait(kTimeoutMs)) << name;
    ASSERT_TRUE(finished.first().first().toBool()) << name;
  };
  enter("materialFractureToughness", 200.0, 450.0);
  EXPECT_EQ(window->simulation().model().regions[0].fracture_toughness_j_per_m2, 450.0);
  EXPECT_EQ(window->materialPanel()->tissueInUse().fracture_toughness_j_per_m2, 450.0);
  enter("materialBladeFriction", 70.0, 120.0);
  EXPECT_EQ(window->simulation().model().regions[0].blade_friction_n_per_m, 120.0);
  EXPECT_EQ(window->materialPanel()->tissueInUse().blade_friction_n_per_m, 120.0);
  EXPECT_EQ(window->simulation().model().regions[0].fracture_toughness_j_per_m2, 450.0);
}

// Gravity is free practice's to choose, for a trainee too: switched on, the liver carries its
// weight onto its bed (the support costs the step 1 − 1/√1.04, its contact frequency a fifth of the
// mesh's); switched off, the model is as it was.
TEST(Workstation, ATraineeSwitchesGravityInFreePracticeAndTheLiverSettlesOnItsBed) {
  QSettings().clear();
  auto window = openWindow();
  ASSERT_FALSE(window->instructorMode());
  ASSERT_TRUE(QTest::qWaitFor([&] { return simulatedTime(*window) > 0.0; }, kTimeoutMs));
  auto* gravity = window->findChild<QCheckBox*>("materialGravity");
  ASSERT_NE(gravity, nullptr);
  EXPECT_TRUE(gravity->isEnabled());
  EXPECT_FALSE(gravity->isChecked());
  const double stepBefore_s = window->simulation().model().stable_time_step_s;
  EXPECT_FALSE(window->simulation().model().effects.gravity);

  QSignalSpy finished(window.get(), &MainWindow::gravityChangeFinished);
  QTest::mouseClick(gravity, Qt::LeftButton, {}, QPoint(8, gravity->height() / 2));
  ASSERT_TRUE(finished.wait(kTimeoutMs));
  ASSERT_TRUE(finished.first().first().toBool())
      << window->materialPanel()->errorText().toStdString();
  {
    const SimModel& model = window->simulation().model();
    EXPECT_TRUE(model.effects.gravity);
    EXPECT_EQ(model.gravity_m_per_s2, Eigen::Vector3d(0.0, 0.0, -9.81));
    ASSERT_NE(model.support, nullptr);
    EXPECT_NEAR(model.stable_time_step_s / stepBefore_s, 1.0 / std::sqrt(1.04), 1e-4);
  }
  EXPECT_TRUE(gravity->isChecked());
  EXPECT_TRUE(window->station().described_scenario().effects.gravity);

  // A fifth of a second later the free nodes have come down: each is 0.1 mm above its bed at rest,
  // so all but those the ligament holds fall at least that far.
  const double switched_s = simulatedTime(*window);
  ASSERT_TRUE(
      QTest::qWaitFor([&] { return simulatedTime(*window) > switched_s + 0.2; }, kTimeoutMs));
  {
    const SimModel& model = window->simulation().model();
    const SimulationSnapshot& snapshot = window->simulation().snapshot();
    double drop_m = 0.0;
    int free = 0;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      if (model.is_fixed[n]) continue;
      drop_m += model.rest_position_m.z[n] - snapshot.position_m.z[n];
      ++free;
    }
    drop_m /= free;
    EXPECT_GT(drop_m, 0.5e-4) << "the liver did not come down";
  }

  finished.clear();
  QTest::mouseClick(gravity, Qt::LeftButton, {}, QPoint(8, gravity->height() / 2));
  ASSERT_TRUE(finished.wait(kTimeoutMs));
  ASSERT_TRUE(finished.first().first().toBool());
  const SimModel& model = window->simulation().model();
  EXPECT_FALSE(model.effects.gravity);
  EXPECT_EQ(model.support, nullptr);
  EXPECT_DOUBLE_EQ(model.stable_time_step_s, stepBefore_s);
  EXPECT_FALSE(gravity->isChecked());
}

}  // namespace
}  // namespace liversim
