// The instructor's scenario editor under a real X server, driven as an instructor would: clicks and
// drags on the organ in its viewport, values typed into its panels, its menu actions.
#include <gtest/gtest.h>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFile>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMessageBox>
#include <QPushButton>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>

#include <vtkCamera.h>
#include <vtkRenderer.h>

#include <memory>

#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "main_window.h"
#include "render/liver_scene.h"
#include "render/scenario_overlay.h"
#include "scenario_editor.h"
#include "viewport_input.h"
#include "vtk_viewport.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kTimeoutMs = liversim::test::waitLimitMs(60'000);

class ScenarioEditorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QSettings().clear();
    ASSERT_TRUE(folder_.isValid());
    editor_ = std::make_unique<ScenarioEditor>();
    editor_->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(editor_.get()));
    ASSERT_NE(editor_->scene(), nullptr) << editor_->organProblem().toStdString();
    editor_->viewport()->grabRendering();  // the camera and sizes as shown
  }
  void TearDown() override {
    if (editor_) editor_->document().undoStack()->setClean();  // no question on closing
    editor_.reset();
  }

  const Scenario& scenario() const { return editor_->document().scenario(); }
  VtkViewport* viewport() const { return editor_->viewport(); }
  LiverScene& scene() const { return *editor_->scene(); }

  QPoint toWidget(const Eigen::Vector2d& display) const {
    return widget_point(*viewport(), display);
  }
  QPoint toDisplay(QPoint widget) const { return display_point(*viewport(), widget); }
  std::optional<ScenePick> pickAt(QPoint widget) const {
    const QPoint display = toDisplay(widget);
    return scene().pick(display.x(), display.y());
  }
  Eigen::Vector3d viewDirection() const {
    double d[3];
    scene().renderer()->GetActiveCamera()->GetDirectionOfProjection(d);
    return Eigen::Vector3d(d[0], d[1], d[2]).normalized();
  }

  void sendMouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons,
                 Qt::KeyboardModifiers modifiers = Qt::NoModifier) {
    send_mouse(*viewport(), type, pos, button, buttons, modifiers);
  }
  void click(QPoint at) {
    sendMouse(QEvent::MouseButtonPress, at, Qt::LeftButton, Qt::LeftButton);
    sendMouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
  }
  void drag(QPoint from, QPoint to, Qt::KeyboardModifiers modifiers = Qt::NoModifier,
            int moves = 10) {
    sendMouse(QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton, modifiers);
    for (int step = 1; step <= moves; ++step)
      sendMouse(QEvent::MouseMove, from + (to - from) * step / moves, Qt::NoButton, Qt::LeftButton,
                modifiers);
    sendMouse(QEvent::MouseButtonRelease, to, Qt::LeftButton, Qt::NoButton, modifiers);
  }

  void trigger(const char* action) {
    auto* a = editor_->findChild<QAction*>(action);
    ASSERT_NE(a, nullptr) << action;
    ASSERT_TRUE(a->isEnabled()) << action;
    a->trigger();
  }
  template <typename T>
  T* field(const char* name) const {
    auto* widget = editor_->findChild<T*>(name);
    EXPECT_NE(widget, nullptr) << name;
    return widget;
  }

  // The widget point over the middle of the organ (it is picked there).
  QPoint organMiddle() const {
    const BoundarySurface& surface = scene().surface();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const TetMesh& mesh = *mesh_;
    for (NodeIndex n : surface.nodes) sum += mesh.rest_position_m.at(n);
    return toWidget(scene().world_to_display(sum / double(surface.nodes.size())));
  }

  QTemporaryDir folder_;
  std::unique_ptr<ScenarioEditor> editor_;
  std::unique_ptr<TetMesh> mesh_ = std::make_unique<TetMesh>(default_scene().mesh);
};

TEST_F(ScenarioEditorTest, ALesionPlacedByClickingIsEditedUndoneRedoneSavedAndReopened) {
  // The new scenario's own lesion removed: the placed one becomes the task's.
  field<QPushButton>("removeLesionButton")->click();
  const std::size_t before = scenario().lesions.size();
  ASSERT_EQ(before, 0u);
  editor_->setMode(ScenarioEditor::Mode::placeLesion);
  const QPoint at = organMiddle();
  const std::optional<ScenePick> hit = pickAt(at);
  ASSERT_TRUE(hit) << "no organ under the click";
  click(at);
  ASSERT_EQ(scenario().lesions.size(), before + 1);
  const LesionSpec placed = scenario().lesions.back();
  EXPECT_EQ(editor_->selectedLesion(), int(before));
  // Under the clicked point, away from the viewer by its radius and 2 mm.
  const Eigen::Vector3d expected =
      hit->point_m + viewDirection() * (placed.radii_mm[0] + 2.0) * 1e-3;
  EXPECT_LT((to_metres(placed.centre_mm) - expected).norm(), 1e-6);
  EXPECT_EQ(editor_->overlay()->shown_lesion_count(), before + 1);

  // Its stiffness, typed into the Lesion panel.
  auto* stiffness = field<QDoubleSpinBox>("lesionStiffness");
  ASSERT_TRUE(stiffness);
  stiffness->setFocus();
  stiffness->selectAll();
  QTest::keyClicks(stiffness, "25");
  QTest::keyClick(stiffness, Qt::Key_Return);
  EXPECT_DOUBLE_EQ(scenario().lesions.back().youngs_modulus_pa, 25'000.0);

  trigger("undoAction");
  EXPECT_DOUBLE_EQ(scenario().lesions.back().youngs_modulus_pa, placed.youngs_modulus_pa);
  EXPECT_DOUBLE_EQ(stiffness->value() * 1e3, placed.youngs_modulus_pa);  // the panel follows
  trigger("undoAction");
  EXPECT_EQ(scenario().lesions.size(), before);  // the placing, undone
  EXPECT_EQ(editor_->overlay()->shown_lesion_count(), before);
  trigger("redoAction");
  trigger("redoAction");
  ASSERT_EQ(scenario().lesions.size(), before + 1);
  EXPECT_DOUBLE_EQ(scenario().lesions.back().youngs_modulus_pa, 25'000.0);
  EXPECT_FALSE(editor_->findChild<QAction*>("redoAction")->isEnabled());
  EXPECT_TRUE(stiffness->isEnabled());  // the lesion the redo brought back is the panel's
  EXPECT_DOUBLE_EQ(stiffness->value(), 25.0);

  const QString file = folder_.filePath("placed.json");
  ASSERT_TRUE(editor_->saveAs(file));
  EXPECT_FALSE(editor_->document().isModified());
  EXPECT_FALSE(editor_->windowTitle().contains('*'));
  const Scenario saved = scenario();
  editor_.reset();

  editor_ = std::make_unique<ScenarioEditor>();
  editor_->show();
  ASSERT_TRUE(editor_->openFile(file));
  EXPECT_EQ(scenario(), saved);
  EXPECT_DOUBLE_EQ(scenario().lesions.back().youngs_modulus_pa, 25'000.0);
  EXPECT_EQ(scenario().task.lesion, placed.name);
  EXPECT_EQ(editor_->document().file(), QFileInfo(file).absoluteFilePath());
  EXPECT_FALSE(editor_->document().isModified());
}

TEST_F(ScenarioEditorTest, DraggingALesionMovesItInTheViewPlaneAndShiftDraggingResizesIt) {
  ASSERT_FALSE(scenario().lesions.empty());
  const LesionSpec start = scenario().lesions[0];
  const QPoint centre = toWidget(scene().world_to_display(to_metres(start.centre_mm)));
  const QPoint to = centre + QPoint(30, 12);
  const Eigen::Vector3d expected =
      scene().display_to_world(toDisplay(to).x(), toDisplay(to).y(), to_metres(start.centre_mm));
  drag(centre, to);
  const LesionSpec moved = scenario().lesions[0];
  // Within the pixel rounding of a 2 cm-wide view.
  EXPECT_LT((to_metres(moved.centre_mm) - expected).norm(), 1e-3);
  EXPECT_GT((to_metres(moved.centre_mm) - to_metres(start.centre_mm)).norm(), 5e-3);
  // In the plane facing the viewer: no move along the view.
  EXPECT_NEAR((to_metres(moved.centre_mm) - to_metres(start.centre_mm)).dot(viewDirection()), 0.0,
              1e-6);
  EXPECT_EQ(moved.radii_mm, start.radii_mm);
  trigger("undoAction");  // the whole drag is one step
  EXPECT_EQ(scenario().lesions[0], start);

  // Shift: the cursor's distance from the centre doubles, so do the semi-axes (to the rounding
  // of the centre to a pixel: ±0.5 px in 20 px).
  drag(centre + QPoint(0, -20), centre + QPoint(0, -40), Qt::ShiftModifier);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(scenario().lesions[0].radii_mm[k], 2.0 * start.radii_mm[k],
                2.0 * start.radii_mm[k] * 0.5 / 20.0 * 2.0);
  EXPECT_EQ(scenario().lesions[0].centre_mm, start.centre_mm);
}

TEST_F(ScenarioEditorTest, PaintingAStrokeHoldsTheSurfaceUnderItAsOneStep) {
  editor_->setMode(ScenarioEditor::Mode::paintFixed);
  field<QDoubleSpinBox>("brushRadius")->setValue(8.0);
  const QPoint from = organMiddle() + QPoint(-60, 0), to = organMiddle() + QPoint(60, 0);
  ASSERT_TRUE(pickAt(from) && pickAt(to));
  drag(from, to, Qt::NoModifier, 24);
  const std::vector<FixedBall>& balls = scenario().organ.fixed_balls;
  ASSERT_GE(balls.size(), 3u);
  for (std::size_t i = 0; i < balls.size(); ++i) {
    EXPECT_EQ(balls[i].radius_mm, 8.0);
    // Each on the surface: where a pick along the view meets it.
    const Eigen::Vector2d d = scene().world_to_display(to_metres(balls[i].centre_mm));
    const auto hit = scene().pick(int(std::lround(d.x())), int(std::lround(d.y())));
    ASSERT_TRUE(hit);
    EXPECT_LT((hit->point_m - to_metres(balls[i].centre_mm)).norm(), 2e-3);
    // Half a brush radius apart at least: a stroke, not a pile.
    if (i > 0) {
      EXPECT_GE((to_metres(balls[i].centre_mm) - to_metres(balls[i - 1].centre_mm)).norm(), 4e-3);
    }
  }
  EXPECT_EQ(editor_->overlay()->shown_fixed_ball_count(), balls.size());
  // The painted balls hold nodes in the built model.
  const SceneSetup setup = build_scene(scenario(), folder_.path().toStdString());
  const SceneSetup unpainted = [&] {
    Scenario s = scenario();
    s.organ.fixed_balls.clear();
    return build_scene(s, folder_.path().toStdString());
  }();
  EXPECT_GT(setup.model_options.fixed_nodes.size(), unpainted.model_options.fixed_nodes.size());
  trigger("undoAction");
  EXPECT_TRUE(scenario().organ.fixed_balls.empty());
}

TEST_F(ScenarioEditorTest, ADrawnPlaneHoldsTheLineAndTheDirectionOfView) {
  auto* drawPlane = editor_->findChild<QAction*>("drawPlaneModeAction");
  ASSERT_TRUE(drawPlane);
  EXPECT_FALSE(drawPlane->isEnabled());  // the new scenario is a palpation
  auto* kind = field<QComboBox>("taskKind");
  kind->setCurrentIndex(kind->findData(int(TaskKind::resect_lesion)));
  ASSERT_EQ(scenario().task.kind, TaskKind::resect_lesion);
  ASSERT_TRUE(drawPlane->isEnabled());
  drawPlane->trigger();
  const QPoint from = organMiddle() + QPoint(-20, -70), to = organMiddle() + QPoint(25, 60);
  const auto start = pickAt(from);
  ASSERT_TRUE(start);
  drag(from, to);
  ASSERT_TRUE(scenario().task.planned_plane);
  const PlaneSpec& plane = *scenario().task.planned_plane;
  const Eigen::Vector3d n(plane.normal[0], plane.normal[1], plane.normal[2]);
  EXPECT_NEAR(n.norm(), 1.0, 1e-9);
  EXPECT_NEAR(n.dot(viewDirection()), 0.0, 1e-9);
  const Eigen::Vector3d end =
      scene().display_to_world(toDisplay(to).x(), toDisplay(to).y(), start->point_m);
  EXPECT_NEAR(n.dot((end - start->point_m).normalized()), 0.0, 1e-9);
  EXPECT_NEAR(n.dot(start->point_m - to_metres(plane.point_mm)), 0.0, 1e-9);  // the line in it
  // Another task drops it: a plane belongs to a resection.
  kind->setCurrentIndex(kind->findData(int(TaskKind::palpate_lesion)));
  EXPECT_FALSE(scenario().task.planned_plane);
  trigger("undoAction");
  EXPECT_TRUE(scenario().task.planned_plane);
}

TEST_F(ScenarioEditorTest, TheRubricTheLawsTheIntegratorAndTheGraspPointAreEditedAndSaved) {
  // Grading: a criterion added, its rule and threshold set in the table.
  ASSERT_TRUE(scenario().rubric.empty());
  field<QPushButton>("addCriterionButton")->click();
  ASSERT_EQ(scenario().rubric.size(), 1u);
  auto* table = field<QTableWidget>("rubricTable");
  ASSERT_EQ(table->rowCount(), 1);
  auto* rule = qobject_cast<QComboBox*>(table->cellWidget(0, 2));
  auto* threshold = qobject_cast<QDoubleSpinBox*>(table->cellWidget(0, 3));
  ASSERT_TRUE(rule && threshold);
  rule->setCurrentIndex(1);
  threshold->setValue(2.5);
  EXPECT_EQ(scenario().rubric[0].rule, PassRule::at_least);
  EXPECT_EQ(scenario().rubric[0].threshold, 2.5);
  EXPECT_EQ(table->cellWidget(0, 3), threshold);  // not rebuilt under the widget being edited
  trigger("undoAction");
  EXPECT_EQ(scenario().rubric[0].threshold, 0.0);
  EXPECT_EQ(qobject_cast<QDoubleSpinBox*>(table->cellWidget(0, 3))->value(), 0.0);
  trigger("redoAction");

  // The laws: viscoplasticity brings viscoelasticity; E1 keeps E = E1 + E2.
  field<QCheckBox>("effectViscoplastic")->setChecked(true);
  ASSERT_TRUE(scenario().effects.viscoelastic && scenario().effects.viscoplastic);
  field<QDoubleSpinBox>("viscoplasticYieldLimit")->setValue(120.0);
  field<QDoubleSpinBox>("viscoelasticE1")->setValue(2500.0);
  const TissueSpec& t = scenario().parenchyma;
  EXPECT_EQ(t.viscoplastic->yield_limit_pa, 120.0);
  EXPECT_EQ(t.viscoelastic->e1_pa, 2500.0);
  EXPECT_DOUBLE_EQ(t.viscoelastic->e1_pa + t.viscoelastic->e2_pa, t.elastic.youngs_modulus_pa);

  // How hard it is to cut: the parenchyma's toughness, and the lesion's own, which below its
  // range reads "the parenchyma's" and is then none of its own.
  field<QDoubleSpinBox>("parenchymaFractureToughness")->setValue(180.0);
  EXPECT_EQ(scenario().parenchyma.fracture_toughness_j_per_m2, 180.0);
  ASSERT_FALSE(scenario().lesions.empty());
  field<QListWidget>("lesionList")->setCurrentRow(0);
  auto* lesionToughness = field<QDoubleSpinBox>("lesionFractureToughness");
  ASSERT_TRUE(lesionToughness->isEnabled());
  EXPECT_EQ(lesionToughness->text(), "the parenchyma's");
  lesionToughness->setValue(600.0);
  EXPECT_EQ(scenario().lesions[0].fracture_toughness_j_per_m2, 600.0);
  trigger("undoAction");
  EXPECT_FALSE(scenario().lesions[0].fracture_toughness_j_per_m2);
  EXPECT_EQ(lesionToughness->text(), "the parenchyma's");  // the panel follows
  trigger("redoAction");
  EXPECT_EQ(scenario().lesions[0].fracture_toughness_j_per_m2, 600.0);
  EXPECT_EQ(lesionToughness->value(), 600.0);
  // And what rubs on the blade's sides: the parenchyma's friction (0 allowed: a frictionless
  // blade), and the lesion's own or the parenchyma's.
  auto* friction = field<QDoubleSpinBox>("parenchymaBladeFriction");
  EXPECT_EQ(friction->value(), 70.0);
  friction->setValue(0.0);
  EXPECT_EQ(scenario().parenchyma.blade_friction_n_per_m, 0.0);
  auto* lesionFriction = field<QDoubleSpinBox>("lesionBladeFriction");
  EXPECT_EQ(lesionFriction->text(), "the parenchyma's");
  lesionFriction->setValue(150.0);
  EXPECT_EQ(scenario().lesions[0].blade_friction_n_per_m, 150.0);
  trigger("undoAction");
  EXPECT_FALSE(scenario().lesions[0].blade_friction_n_per_m);
  EXPECT_EQ(lesionFriction->text(), "the parenchyma's");

  // The integrator, through the same panel as the workstation's.
  auto* accuracy = field<QWidget>("accuracyPanel");
  auto* integrator = accuracy->findChild<QComboBox*>("integratorChoice");
  auto* step = accuracy->findChild<QDoubleSpinBox*>("integratorStepMs");
  ASSERT_TRUE(integrator && step);
  integrator->setCurrentIndex(integrator->findData(int(IntegratorKind::bdf2)));
  ASSERT_GE(integrator->currentIndex(), 0);
  step->setValue(1.0);
  accuracy->findChild<QPushButton*>("applyAccuracy")->click();
  EXPECT_EQ(scenario().integrator.kind, IntegratorKind::bdf2);
  EXPECT_EQ(scenario().integrator.step_s, 1e-3);

  // A retraction's grasp point, picked on the organ.
  auto* kind = field<QComboBox>("taskKind");
  kind->setCurrentIndex(kind->findData(int(TaskKind::retract_lobe)));
  EXPECT_TRUE(scenario().task.lesion.empty());
  field<QPushButton>("pickGraspPointButton")->click();
  const QPoint at = organMiddle() + QPoint(60, 10);
  const auto hit = pickAt(at);
  ASSERT_TRUE(hit);
  click(at);
  EXPECT_LT((to_metres(scenario().task.grasp_point_mm) - hit->point_m).norm(), 1e-9);
  EXPECT_EQ(editor_->mode(), ScenarioEditor::Mode::view);
  field<QDoubleSpinBox>("liftMm")->setValue(40.0);

  const QString file = folder_.filePath("edited.json");
  ASSERT_TRUE(editor_->saveAs(file));
  const ScenarioReading reading = read_scenario_file(file.toStdString());
  ASSERT_TRUE(reading.scenario);
  EXPECT_EQ(*reading.scenario, scenario());
  EXPECT_EQ(reading.scenario->task.lift_mm, 40.0);
}

TEST_F(ScenarioEditorTest, TheOrganIsRebuiltFromASurfaceModelAndABadFileKeepsTheOldOne) {
  const std::size_t builtInTriangles = editor_->scene()->surface().triangles.size();
  auto* geometry = field<QComboBox>("organGeometry");
  geometry->setCurrentIndex(geometry->findData(int(OrganGeometry::surface_file)));
  // No file yet: it cannot be built; the organ shown stays.
  EXPECT_FALSE(editor_->organProblem().isEmpty());
  ASSERT_NE(editor_->scene(), nullptr);
  EXPECT_EQ(editor_->scene()->surface().triangles.size(), builtInTriangles);
  EXPECT_TRUE(field<QLabel>("organStatus")->text().contains("cannot be built"));

  auto* file = field<QLineEdit>("organFile");
  file->setText(QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/cube-40mm.obj");
  emit file->editingFinished();
  auto* count = field<QSpinBox>("targetTetCount");
  count->setValue(1000);
  EXPECT_TRUE(editor_->organProblem().isEmpty()) << editor_->organProblem().toStdString();
  // The cube's own 192 triangles are the organ's surface now.
  EXPECT_EQ(editor_->scene()->surface().triangles.size(), 192u);
  EXPECT_EQ(scenario().organ.metres_per_unit, 1e-3);  // mm, the first unit offered
  trigger("undoAction");
  trigger("undoAction");
  trigger("undoAction");
  EXPECT_EQ(scenario().organ.geometry, OrganGeometry::built_in_liver);
  EXPECT_EQ(editor_->scene()->surface().triangles.size(), builtInTriangles);
}

TEST_F(ScenarioEditorTest, SavingIsRefusedWithTheErrorsOfTheScenarioAndWritesNothing) {
  // 200 times the parenchyma's 3.5 kPa: beyond the lesion stiffness ratio's range.
  field<QDoubleSpinBox>("lesionStiffness")->setValue(700.0);
  const QString file = folder_.filePath("refused.json");
  EXPECT_FALSE(editor_->saveAs(file));
  EXPECT_FALSE(QFile::exists(file));
  auto* box = editor_->findChild<QMessageBox*>("saveErrorsBox");
  ASSERT_TRUE(box);
  EXPECT_TRUE(box->text().contains("lesions[0].youngs_modulus_pa")) << box->text().toStdString();
  EXPECT_TRUE(box->text().contains("700000")) << box->text().toStdString();
  EXPECT_TRUE(editor_->document().isModified());
  box->close();
  // A lesion named as another is refused too, naming the field.
  trigger("undoAction");
  field<QPushButton>("addLesionButton")->click();
  auto* name = field<QLineEdit>("lesionName");
  name->setText(QString::fromStdString(scenario().lesions[0].name));
  emit name->editingFinished();
  EXPECT_FALSE(editor_->saveAs(file));
  box = editor_->findChildren<QMessageBox*>("saveErrorsBox").last();
  EXPECT_TRUE(box->text().contains("lesions[1].name")) << box->text().toStdString();
  EXPECT_FALSE(QFile::exists(file));
}

TEST_F(ScenarioEditorTest, ABadFileIsRefusedWithItsErrorsAndAFailedWriteLosesNothing) {
  const Scenario before = scenario();
  const QString bad =
      QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenarios/schema-negative-radius.json";
  EXPECT_FALSE(editor_->openFile(bad));
  EXPECT_EQ(scenario(), before);
  EXPECT_TRUE(editor_->document().file().isEmpty());
  auto* box = editor_->findChild<QMessageBox*>("scenarioErrorBox");
  ASSERT_TRUE(box);
  EXPECT_TRUE(box->text().contains("radii_mm")) << box->text().toStdString();
  box->close();

  // A folder that does not exist: the write fails, naming the file; the edits stay unsaved.
  field<QDoubleSpinBox>("timeLimit")->setValue(200.0);
  const QString nowhere = folder_.filePath("missing-folder/s.json");
  EXPECT_FALSE(editor_->saveAs(nowhere));
  box = editor_->findChildren<QMessageBox*>("saveErrorsBox").last();
  EXPECT_TRUE(box->text().contains("missing-folder")) << box->text().toStdString();
  EXPECT_TRUE(editor_->document().isModified());
  EXPECT_TRUE(editor_->document().file().isEmpty());
  EXPECT_EQ(scenario().task.time_limit_s, 200.0);
}

TEST_F(ScenarioEditorTest, ClosingWithUnsavedChangesAsksAndCancelKeepsTheEditorOpen) {
  field<QDoubleSpinBox>("timeLimit")->setValue(240.0);
  ASSERT_TRUE(editor_->document().isModified());
  EXPECT_TRUE(editor_->windowTitle().contains('*'));
  const auto answer = [&](QMessageBox::StandardButton button) {
    QTimer::singleShot(0, [this, button] {
      auto* box = editor_->findChild<QMessageBox*>("unsavedChangesBox");
      ASSERT_TRUE(box) << "no question about the unsaved changes";
      box->button(button)->click();
    });
  };
  answer(QMessageBox::Cancel);
  EXPECT_FALSE(editor_->close());
  EXPECT_TRUE(editor_->isVisible());
  EXPECT_EQ(scenario().task.time_limit_s, 240.0);
  answer(QMessageBox::Discard);
  EXPECT_TRUE(editor_->close());
}

TEST_F(ScenarioEditorTest, SwitchingAnEffectOnIsMeasuredAgainAndShowsTheCostBeside) {
  QSignalSpy measured(editor_.get(), &ScenarioEditor::costMeasured);
  ASSERT_TRUE(QTest::qWaitFor([&] { return editor_->stepsPerSecond().has_value(); }, kTimeoutMs))
      << editor_->costText().toStdString();
  const int count = editor_->costMeasurementCount();
  field<QCheckBox>("effectViscoelastic")->setChecked(true);
  ASSERT_TRUE(scenario().effects.viscoelastic);
  ASSERT_TRUE(scenario().parenchyma.viscoelastic);  // its parameters filled in: E = E1 + E2
  EXPECT_DOUBLE_EQ(scenario().parenchyma.viscoelastic->instantaneous_modulus_pa(),
                   scenario().parenchyma.elastic.youngs_modulus_pa);
  ASSERT_TRUE(QTest::qWaitFor([&] { return editor_->costMeasurementCount() > count; }, kTimeoutMs));
  EXPECT_GT(*editor_->stepsPerSecond(), 0.0);
  EXPECT_TRUE(editor_->costText().contains("steps/s")) << editor_->costText().toStdString();
  EXPECT_TRUE(editor_->costText().contains("before the last change"))
      << editor_->costText().toStdString();
  // A change the cost does not depend on is not measured.
  const int after = editor_->costMeasurementCount();
  field<QLineEdit>("scenarioTitle")->setText("Costless");
  emit field<QLineEdit>("scenarioTitle")->editingFinished();
  QTest::qWait(300);
  EXPECT_EQ(editor_->costMeasurementCount(), after);
  EXPECT_EQ(scenario().title, "Costless");
}

// Gravity is switched on, pointed and sized in the Tissue and effects panel; each is one undo step,
// the file keeps them, and while gravity is off its direction and strength are kept but greyed.
TEST_F(ScenarioEditorTest, GravityIsSwitchedOnPointedSizedSavedAndUndone) {
  auto* gravity = field<QCheckBox>("effectGravity");
  auto* direction = field<QComboBox>("gravityDirection");
  auto* strength = field<QDoubleSpinBox>("gravityStrength");
  ASSERT_FALSE(scenario().effects.gravity);
  EXPECT_FALSE(direction->isEnabled());
  EXPECT_FALSE(strength->isEnabled());
  EXPECT_EQ(direction->currentIndex(), 0);  // supine: the default direction
  gravity->setChecked(true);
  EXPECT_TRUE(scenario().effects.gravity);
  EXPECT_TRUE(direction->isEnabled());
  EXPECT_TRUE(strength->isEnabled());
  direction->setCurrentIndex(1);
  emit direction->activated(1);
  EXPECT_EQ(scenario().effects.gravity_direction, (std::array<double, 3>{0.0, -1.0, 0.0}));
  strength->setValue(4.9);
  EXPECT_DOUBLE_EQ(scenario().effects.gravity_m_per_s2, 4.9);

  const QString file = folder_.filePath("gravity.json");
  ASSERT_TRUE(editor_->saveAs(file));
  const ScenarioReading reading = read_scenario_file(file.toStdString());
  ASSERT_TRUE(reading.scenario);
  EXPECT_EQ(reading.scenario->effects, scenario().effects);

  editor_->document().undoStack()->undo();  // the strength
  EXPECT_DOUBLE_EQ(scenario().effects.gravity_m_per_s2, kEarthGravityMPerS2);
  editor_->document().undoStack()->undo();  // the direction
  EXPECT_EQ(direction->currentIndex(), 0);
  editor_->document().undoStack()->undo();  // switched on
  EXPECT_FALSE(scenario().effects.gravity);
  EXPECT_FALSE(gravity->isChecked());
  EXPECT_FALSE(strength->isEnabled());
}

TEST(ScenarioEditorInTheWorkstation, TryItRunsTheEditedScenarioAndTheEditorStartsFromTheShownOne) {
  QSettings().clear();
  MainWindow window(default_scene(1000));
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  // Authoring is an instructor's: refused to a trainee, offered after the log-in.
  EXPECT_EQ(window.openScenarioEditor(), nullptr);
  QTemporaryDir folder;
  ASSERT_TRUE(window.setSessionsDatabase(folder.filePath("sessions.sqlite")));
  QString why;
  ASSERT_TRUE(window.logInInstructor("Dr. Grey", "long enough", &why)) << why.toStdString();
  ScenarioEditor* editor = window.openScenarioEditor();
  ASSERT_TRUE(editor);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(editor));
  editor->findChild<QDoubleSpinBox*>("lesionStiffness")->setValue(30.0);
  ASSERT_TRUE(editor->document().isModified());
  QSignalSpy opened(&window, &MainWindow::scenarioOpenFinished);
  editor->findChild<QAction*>("tryScenarioAction")->trigger();
  ASSERT_TRUE(opened.wait(kTimeoutMs));
  ASSERT_TRUE(opened.first().first().toBool());
  ASSERT_TRUE(window.scenario());
  EXPECT_EQ(window.scenario()->scenario, editor->document().scenario());
  EXPECT_TRUE(window.scenario()->file.empty());  // not saved
  // What a session records is the scenario as tried.
  const ScenarioReading recorded = read_scenario(window.scenario()->text);
  ASSERT_TRUE(recorded.scenario);
  EXPECT_EQ(*recorded.scenario, editor->document().scenario());
  const std::size_t regions = 1 + editor->document().scenario().lesions.size();
  EXPECT_TRUE(QTest::qWaitFor(
      [&] { return window.simulation().snapshot().model->regions.size() == regions; }, kTimeoutMs));
  editor->document().undoStack()->setClean();
  editor->close();
}

}  // namespace
}  // namespace liversim
