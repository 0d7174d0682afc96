#include "scenario_editor.h"

#include "editor_grading_panel.h"
#include "editor_lesion_panel.h"
#include "editor_organ_panel.h"
#include "editor_task_panel.h"
#include "editor_tissue_panel.h"
#include "recent_scenarios.h"
#include "render/liver_scene.h"
#include "render/scenario_overlay.h"
#include "vtk_viewport.h"

#include "liversim/studies/performance.h"

#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>

#include <Eigen/Geometry>

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QDir>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenuBar>
#include <QMessageBox>
#include <QStatusBar>
#include <QToolBar>

#include <algorithm>
#include <cmath>

namespace liversim {
namespace {

constexpr double kMetresPerMm = 1e-3;

// The parts of a scenario that decide its cost.
bool sameCost(const Scenario& a, const Scenario& b) {
  return a.organ == b.organ && a.parenchyma == b.parenchyma && a.lesions == b.lesions &&
         a.effects == b.effects && a.integrator.kind == b.integrator.kind &&
         a.integrator.step_s == b.integrator.step_s;
}

}  // namespace

ScenarioEditor::ScenarioEditor(QWidget* parent) : QMainWindow(parent) {
  setObjectName("scenarioEditor");
  viewport_ = new VtkViewport(this);
  viewport_->setObjectName("editorViewport");
  viewport_->setMinimumSize(480, 360);
  setCentralWidget(viewport_);
  viewport_->setPressFilter(
      [this](QPoint p, Qt::MouseButton b, Qt::KeyboardModifiers m) { return pressAt(p, b, m); });
  connect(viewport_, &VtkViewport::mouseMovedTo, this, [this](QPoint p) { moveTo(p); });
  connect(viewport_, &VtkViewport::mouseReleasedAt, this, [this](QPoint p) { releaseAt(p); });

  buildActions();
  lesionPanel_ = new EditorLesionPanel(document_);
  connect(lesionPanel_, &EditorLesionPanel::lesionSelected, this, &ScenarioEditor::selectLesion);
  connect(lesionPanel_, &EditorLesionPanel::addRequested, this,
          [this] { addLesion(tr("Add a lesion"), organCentre_m_, 0.0); });
  taskPanel_ = new EditorTaskPanel(document_);
  tissuePanel_ = new EditorTissuePanel(document_, [this] { return screenHorizontal(); });
  organPanel_ = new EditorOrganPanel(document_);
  gradingPanel_ = new EditorGradingPanel(document_);
  connect(gradingPanel_, &EditorGradingPanel::graspPointPickRequested, this,
          [this] { setMode(Mode::pickGraspPoint); });
  addDock(tr("Lesions"), "lesionDock", lesionPanel_);
  QDockWidget* task = addDock(tr("Task"), "taskDock", taskPanel_);
  QDockWidget* tissue = addDock(tr("Tissue and effects"), "tissueDock", tissuePanel_);
  QDockWidget* organ = addDock(tr("Organ and accuracy"), "organDock", organPanel_);
  QDockWidget* grading = addDock(tr("Grading"), "gradingDock", gradingPanel_);
  tabifyDockWidget(task, tissue);
  tabifyDockWidget(tissue, organ);
  tabifyDockWidget(organ, grading);
  task->raise();

  connect(&document_, &ScenarioDocument::organChanged, this, &ScenarioEditor::rebuildOrgan);
  connect(&document_, &ScenarioDocument::changed, this, &ScenarioEditor::showDocument);
  connect(&document_, &ScenarioDocument::fileChanged, this, &ScenarioEditor::updateTitle);
  connect(document_.undoStack(), &QUndoStack::cleanChanged, this, &ScenarioEditor::updateTitle);
  rebuildOrgan();
  selectLesion(document_.scenario().lesions.empty() ? -1 : 0);
  showDocument();
  updateTitle();
  resize(1280, 820);
}

ScenarioEditor::~ScenarioEditor() {
  *alive_ = false;
  if (costWorker_.started()) costWorker_.wait();
  overlay_.reset();
}

QDockWidget* ScenarioEditor::addDock(const QString& title, const char* name, QWidget* panel) {
  auto* dock = new QDockWidget(title, this);
  dock->setObjectName(name);
  dock->setWidget(panel);
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  addDockWidget(Qt::RightDockWidgetArea, dock);
  return dock;
}

void ScenarioEditor::buildActions() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  QToolBar* bar = addToolBar(tr("Editor"));
  bar->setObjectName("editorToolBar");
  const auto add = [&](QMenu* menu, const QString& text, const char* name, const QKeySequence& key,
                       auto slot) {
    QAction* action = menu->addAction(text, this, slot);
    action->setObjectName(name);
    action->setShortcut(key);
    return action;
  };
  add(file, tr("&New Scenario"), "newScenarioAction", QKeySequence::New, [this] {
    if (maybeSave()) newScenario();
  });
  add(file, tr("&Open…"), "openScenarioAction", QKeySequence::Open, [this] {
    if (!maybeSave()) return;
    const QString chosen =
        QFileDialog::getOpenFileName(this, tr("Open a scenario"), scenarioFolderToOpen(),
                                     tr("LiverSim scenarios (*.json);;All files (*)"));
    if (!chosen.isEmpty()) openFile(chosen);
  });
  recentMenu_ = file->addMenu(tr("Open &Recent"));
  recentMenu_->setObjectName("recentScenariosMenu");
  updateRecentMenu();
  add(file, tr("&Save"), "saveScenarioAction", QKeySequence::Save, [this] { save(); });
  add(file, tr("Save &As…"), "saveScenarioAsAction", QKeySequence::SaveAs, [this] {
    const QString chosen = QFileDialog::getSaveFileName(
        this, tr("Save the scenario"), document_.file(), tr("LiverSim scenarios (*.json)"));
    if (!chosen.isEmpty()) saveAs(chosen);
  });
  file->addSeparator();
  add(file, tr("&Close"), "closeEditorAction", QKeySequence::Close, [this] { close(); });

  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  QAction* undo = document_.undoStack()->createUndoAction(this, tr("&Undo"));
  undo->setObjectName("undoAction");
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = document_.undoStack()->createRedoAction(this, tr("&Redo"));
  redo->setObjectName("redoAction");
  redo->setShortcut(QKeySequence::Redo);
  edit->addAction(undo);
  edit->addAction(redo);
  // The toolbar's buttons keep short names; what they undo is in their tooltips.
  QUndoStack* stack = document_.undoStack();
  QAction* undoButton = bar->addAction(tr("Undo"), stack, &QUndoStack::undo);
  QAction* redoButton = bar->addAction(tr("Redo"), stack, &QUndoStack::redo);
  undoButton->setEnabled(false);
  redoButton->setEnabled(false);
  connect(stack, &QUndoStack::canUndoChanged, undoButton, &QAction::setEnabled);
  connect(stack, &QUndoStack::canRedoChanged, redoButton, &QAction::setEnabled);
  connect(stack, &QUndoStack::undoTextChanged, undoButton, &QAction::setToolTip);
  connect(stack, &QUndoStack::redoTextChanged, redoButton, &QAction::setToolTip);
  bar->addSeparator();

  modes_ = new QActionGroup(this);
  const auto mode = [&](const QString& text, const char* name, const QString& tip, Mode m) {
    QAction* action = bar->addAction(text);
    action->setObjectName(name);
    action->setCheckable(true);
    action->setToolTip(tip);
    modes_->addAction(action);
    connect(action, &QAction::triggered, this, [this, m] { setMode(m); });
    return action;
  };
  viewAction_ =
      mode(tr("Turn"), "viewModeAction",
           tr("Drag to turn the view; drag a lesion to move it (Shift: resize it)"), Mode::view);
  placeLesionAction_ =
      mode(tr("Place lesion"), "placeLesionModeAction",
           tr("Click on the organ to put a lesion under its surface there"), Mode::placeLesion);
  drawPlaneAction_ = mode(tr("Draw plane"), "drawPlaneModeAction",
                          tr("Drag across the organ: the planned resection plane runs along the "
                             "line, straight away from you (resection tasks)"),
                          Mode::drawPlane);
  paintFixedAction_ = mode(
      tr("Paint fixed"), "paintFixedModeAction",
      tr("Drag over the surface to hold it fixed there (ligament attachments)"), Mode::paintFixed);
  viewAction_->setChecked(true);
  bar->addSeparator();
  QAction* tryAction = bar->addAction(tr("Try it"), this, &ScenarioEditor::tryIt);
  tryAction->setObjectName("tryScenarioAction");
  tryAction->setToolTip(tr("Run the scenario as it is now in the workstation"));
  tryAction->setShortcut(QKeySequence(Qt::Key_F5));
}

void ScenarioEditor::rebuildOrgan() {
  // The organ alone: lesions and fixed regions do not change its mesh, and a lesion not (yet) in
  // it must not keep it from being shown.
  Scenario organOnly = document_.scenario();
  organOnly.lesions.clear();
  organOnly.organ.fixed_balls.clear();
  organOnly.task = TaskSpec{};
  organOnly.task.kind = TaskKind::retract_lobe;
  QApplication::setOverrideCursor(Qt::WaitCursor);
  std::optional<SceneSetup> organ;
  try {
    organ = build_scene(organOnly, document_.organFolder());
    organProblem_.clear();
  } catch (const std::exception& e) {
    organProblem_ = tr("The organ cannot be built: %1").arg(QString::fromUtf8(e.what()));
  }
  QApplication::restoreOverrideCursor();
  if (!organ) {
    statusBar()->showMessage(organProblem_);
    organPanel_->showStatus(organProblem_ + tr(" (the organ shown is the one before)"));
    return;  // the organ shown before stays
  }
  if (scene_) viewport_->renderWindow()->RemoveRenderer(scene_->renderer());
  overlay_.reset();
  organ_ = std::move(organ);
  const NodeArray& p = organ_->mesh.rest_position_m;
  organCentre_m_.setZero();
  for (std::size_t i = 0; i < p.size(); ++i)
    organCentre_m_ += Eigen::Vector3d(p.x[i], p.y[i], p.z[i]);
  if (p.size() > 0) organCentre_m_ /= double(p.size());
  scene_ = std::make_unique<LiverScene>(organ_->mesh, organ_->visual);
  scene_->set_opacity(kSeeThroughOpacity);
  overlay_ = std::make_unique<ScenarioOverlay>(scene_->renderer());
  viewport_->renderWindow()->AddRenderer(scene_->renderer());
  fitCamera();
  showOverlay();
  organPanel_->showStatus(QString::fromStdString(organ_->description));
  statusBar()->showMessage(tr("Organ: %1").arg(QString::fromStdString(organ_->description)));
}

void ScenarioEditor::showDocument() {
  const Scenario& s = document_.scenario();
  // A lesion is selected whenever there is one (an undo may have taken the selected one away).
  if (selectedLesion_ >= int(s.lesions.size()) || selectedLesion_ < 0)
    selectedLesion_ = int(s.lesions.size()) - 1;
  lesionPanel_->refresh(selectedLesion_);
  taskPanel_->refresh();
  drawPlaneAction_->setEnabled(s.task.kind == TaskKind::resect_lesion);
  if (mode_ == Mode::drawPlane && s.task.kind != TaskKind::resect_lesion) setMode(Mode::view);
  tissuePanel_->refresh();
  organPanel_->refresh();
  gradingPanel_->refresh();

  showOverlay();
  measureCost();
}

void ScenarioEditor::showOverlay() {
  if (!overlay_) return;
  const Scenario& s = document_.scenario();
  std::vector<LesionMarker> lesions;
  for (std::size_t i = 0; i < s.lesions.size(); ++i)
    lesions.push_back({to_metres(s.lesions[i].centre_mm), to_metres(s.lesions[i].radii_mm),
                       int(i) == selectedLesion_});
  overlay_->show_lesions(lesions);
  std::vector<std::pair<Eigen::Vector3d, double>> balls;
  for (const FixedBall& b : s.organ.fixed_balls)
    balls.emplace_back(to_metres(b.centre_mm), b.radius_mm * kMetresPerMm);
  overlay_->show_fixed_balls(balls);
  if (s.task.planned_plane)
    overlay_->show_plane(PlaneMarker{
        to_metres(s.task.planned_plane->point_mm),
        Eigen::Vector3d(s.task.planned_plane->normal[0], s.task.planned_plane->normal[1],
                        s.task.planned_plane->normal[2])});
  else if (drag_ != Drag::plane)
    overlay_->show_plane(std::nullopt);
  if (s.effects.fibres && s.parenchyma.fibres) {
    const auto& d = s.parenchyma.fibres->direction;
    const Eigen::Vector3d direction(d[0], d[1], d[2]);
    if (direction.norm() > 0.0)
      overlay_->show_fibre_direction(ArrowMarker{organCentre_m_, direction.normalized(), 0.08});
    else
      overlay_->show_fibre_direction(std::nullopt);
  } else {
    overlay_->show_fibre_direction(std::nullopt);
  }
  viewport_->scheduleRender();
}

void ScenarioEditor::fitCamera() {
  if (!scene_) return;
  scene_->reset_camera(viewport_->height() > 0 ? double(viewport_->width()) / viewport_->height()
                                               : 1.0);
  viewport_->scheduleRender();
}

void ScenarioEditor::showEvent(QShowEvent* event) {
  QMainWindow::showEvent(event);
  if (!shown_) fitCamera();  // the view's shape is known now
  shown_ = true;
}

void ScenarioEditor::updateTitle() {
  const QString name =
      document_.file().isEmpty() ? tr("untitled") : QFileInfo(document_.file()).fileName();
  setWindowTitle(tr("Scenario editor — %1%2").arg(name, document_.isModified() ? "*" : ""));
}

void ScenarioEditor::setMode(Mode mode) {
  mode_ = mode;
  if (mode == Mode::pickGraspPoint) {  // a one-click mode, not on the toolbar
    mode_ = mode;
    statusBar()->showMessage(tr("Click where the lobe is to be grasped."));
    return;
  }
  QAction* action = mode == Mode::view          ? viewAction_
                    : mode == Mode::placeLesion ? placeLesionAction_
                    : mode == Mode::drawPlane   ? drawPlaneAction_
                                                : paintFixedAction_;
  action->setChecked(true);
}

void ScenarioEditor::selectLesion(int index) {
  selectedLesion_ = index;
  showDocument();
}

void ScenarioEditor::addLesion(const QString& text, const Eigen::Vector3d& point_m,
                               double depth_mm) {
  const Scenario& s = document_.scenario();
  LesionSpec lesion;
  const auto taken = [&](const std::string& name) {
    return std::any_of(s.lesions.begin(), s.lesions.end(),
                       [&](const LesionSpec& l) { return l.name == name; });
  };
  int n = int(s.lesions.size()) + 1;
  while (taken("lesion " + std::to_string(n))) ++n;
  lesion.name = "lesion " + std::to_string(n);
  lesion.centre_mm = to_millimetres(
      depth_mm > 0.0 ? point_m + viewDirection() * (lesion.radii_mm[0] + depth_mm) * kMetresPerMm
                     : point_m);
  const int index = int(s.lesions.size());
  document_.edit(text, [&](Scenario& e) {
    e.lesions.push_back(lesion);
    if (e.lesions.size() == 1 && e.task.kind != TaskKind::retract_lobe)
      e.task.lesion = lesion.name;  // the task's, when it is the only one
  });
  selectLesion(index);
}

// ---- Mouse ------------------------------------------------------------------------------------

Eigen::Vector3d ScenarioEditor::viewDirection() const {
  double d[3];
  scene_->renderer()->GetActiveCamera()->GetDirectionOfProjection(d);
  return Eigen::Vector3d(d[0], d[1], d[2]).normalized();
}

std::optional<Eigen::Vector3d> ScenarioEditor::screenHorizontal() const {
  if (!scene_) return std::nullopt;
  vtkCamera* camera = scene_->renderer()->GetActiveCamera();
  double up[3], dop[3];
  camera->GetViewUp(up);
  camera->GetDirectionOfProjection(dop);
  return Eigen::Vector3d(dop[0], dop[1], dop[2]).cross(Eigen::Vector3d(up[0], up[1], up[2]));
}

int ScenarioEditor::lesionAt(QPoint display) const {
  if (!scene_) return -1;
  const Scenario& s = document_.scenario();
  double up[3];
  scene_->renderer()->GetActiveCamera()->GetViewUp(up);
  const Eigen::Vector3d screenUp = Eigen::Vector3d(up[0], up[1], up[2]).normalized();
  const Eigen::Vector2d at(display.x(), display.y());
  int best = -1;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.lesions.size(); ++i) {
    const Eigen::Vector3d centre = to_metres(s.lesions[i].centre_mm);
    const double radius_m =
        *std::max_element(s.lesions[i].radii_mm.begin(), s.lesions[i].radii_mm.end()) *
        kMetresPerMm;
    const Eigen::Vector2d c = scene_->world_to_display(centre);
    const double radiusOnScreen =
        (scene_->world_to_display(centre + screenUp * radius_m) - c).norm();
    const double d = (at - c).norm();
    if (d <= radiusOnScreen && d < bestDistance) {
      bestDistance = d;
      best = int(i);
    }
  }
  return best;
}

bool ScenarioEditor::pressAt(QPoint display, Qt::MouseButton button,
                             Qt::KeyboardModifiers modifiers) {
  if (button != Qt::LeftButton || !scene_) return false;
  document_.endMergeRun();  // each drag is its own undo step
  pressAt_ = display;
  const Scenario& s = document_.scenario();
  if (mode_ != Mode::paintFixed) {
    if (const int lesion = lesionAt(display); lesion >= 0) {
      selectLesion(lesion);
      lesionAtPress_ = s.lesions[lesion];
      const Eigen::Vector3d centre = to_metres(lesionAtPress_.centre_mm);
      dragOffset_m_ = centre - scene_->display_to_world(display.x(), display.y(), centre);
      drag_ = modifiers & Qt::ShiftModifier ? Drag::resizeLesion : Drag::moveLesion;
      return true;
    }
  }
  const std::optional<ScenePick> hit = scene_->pick(display.x(), display.y());
  switch (mode_) {
    case Mode::view:
      return false;
    case Mode::placeLesion: {
      if (!hit) return true;
      // Under the surface by its radius and 2 mm more, straight away from the viewer.
      addLesion(tr("Place a lesion"), hit->point_m, 2.0);
      return true;
    }
    case Mode::pickGraspPoint:
      if (!hit) return true;
      document_.edit(tr("Set the grasp point"),
                     [&](Scenario& e) { e.task.grasp_point_mm = to_millimetres(hit->point_m); });
      setMode(Mode::view);
      statusBar()->showMessage(tr("The grasp point is set."));
      return true;
    case Mode::drawPlane:
      planeStart_m_ =
          hit ? hit->point_m : scene_->display_to_world(display.x(), display.y(), organCentre_m_);
      drag_ = Drag::plane;
      return true;
    case Mode::paintFixed:
      drag_ = Drag::paint;
      lastPaint_m_.reset();
      paintAt(display);
      return true;
  }
  return false;
}

void ScenarioEditor::paintAt(QPoint display) {
  const std::optional<ScenePick> hit = scene_->pick(display.x(), display.y());
  if (!hit) return;
  const double radius_mm = tissuePanel_->brushRadius_mm();
  // Balls half a radius apart make a continuous stroke.
  if (lastPaint_m_ && (hit->point_m - *lastPaint_m_).norm() < 0.5 * radius_mm * kMetresPerMm)
    return;
  lastPaint_m_ = hit->point_m;
  document_.edit(
      tr("Paint a fixed region"),
      [&](Scenario& s) {
        s.organ.fixed_balls.push_back(FixedBall{to_millimetres(hit->point_m), radius_mm});
      },
      EditorPanel::kPaint);
}

void ScenarioEditor::moveTo(QPoint display) {
  if (!scene_ || drag_ == Drag::none) return;
  switch (drag_) {
    case Drag::moveLesion: {
      const Eigen::Vector3d centre = to_metres(lesionAtPress_.centre_mm);
      const Eigen::Vector3d moved =
          scene_->display_to_world(display.x(), display.y(), centre) + dragOffset_m_;
      const int index = selectedLesion_;
      document_.edit(
          tr("Move the lesion"),
          [&](Scenario& s) { s.lesions.at(index).centre_mm = to_millimetres(moved); },
          EditorPanel::kMoveLesion);
      break;
    }
    case Drag::resizeLesion: {
      // The radii scale with the cursor's distance from the centre on the screen.
      const Eigen::Vector2d c = scene_->world_to_display(to_metres(lesionAtPress_.centre_mm));
      const double from = (Eigen::Vector2d(pressAt_.x(), pressAt_.y()) - c).norm();
      const double to = (Eigen::Vector2d(display.x(), display.y()) - c).norm();
      if (from < 1.0) return;
      const double scale = std::clamp(to / from, 0.1, 10.0);
      const int index = selectedLesion_;
      document_.edit(
          tr("Resize the lesion"),
          [&](Scenario& s) {
            for (int k = 0; k < 3; ++k)
              s.lesions.at(index).radii_mm[k] =
                  std::clamp(lesionAtPress_.radii_mm[k] * scale, 1.0, 80.0);
          },
          EditorPanel::kResizeLesion);
      break;
    }
    case Drag::plane: {
      const Eigen::Vector3d end = scene_->display_to_world(display.x(), display.y(), planeStart_m_);
      const Eigen::Vector3d along = end - planeStart_m_;
      if (along.norm() < 1e-4) return;
      overlay_->show_plane(
          PlaneMarker{0.5 * (planeStart_m_ + end), along.cross(viewDirection()).normalized()});
      viewport_->scheduleRender();
      break;
    }
    case Drag::paint:
      paintAt(display);
      break;
    case Drag::none:
      break;
  }
}

void ScenarioEditor::releaseAt(QPoint display) {
  if (drag_ == Drag::plane && scene_) {
    const Eigen::Vector3d end = scene_->display_to_world(display.x(), display.y(), planeStart_m_);
    const Eigen::Vector3d along = end - planeStart_m_;
    if ((display - pressAt_).manhattanLength() >= 5 && along.norm() > 0.0) {
      // The plane holds the drawn line and the direction of view.
      const Eigen::Vector3d normal = along.cross(viewDirection()).normalized();
      const Eigen::Vector3d middle = 0.5 * (planeStart_m_ + end);
      drag_ = Drag::none;
      document_.edit(tr("Draw the planned plane"), [&](Scenario& s) {
        s.task.planned_plane =
            PlaneSpec{to_millimetres(middle), {normal.x(), normal.y(), normal.z()}};
      });
    }
  }
  drag_ = Drag::none;
  document_.endMergeRun();
  showOverlay();
}

// ---- Files ------------------------------------------------------------------------------------

void ScenarioEditor::showErrors(const QString& title, const char* boxName,
                                const std::vector<ScenarioError>& errors) {
  statusBar()->showMessage(title);
  // Window-modal but not blocking, so that the caller (and a test) goes on.
  auto* box = new QMessageBox(QMessageBox::Warning, title, scenarioErrorsText(errors),
                              QMessageBox::Ok, this);
  box->setObjectName(boxName);
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

bool ScenarioEditor::openFile(const QString& file) {
  const std::vector<ScenarioError> errors = document_.open(file);
  if (!errors.empty()) {
    showErrors(tr("Cannot open the scenario %1").arg(QFileInfo(file).fileName()),
               "scenarioErrorBox", errors);
    return false;
  }
  rememberScenarioFile(file);
  updateRecentMenu();
  selectLesion(document_.scenario().lesions.empty() ? -1 : 0);
  fitCamera();
  statusBar()->showMessage(tr("Opened %1.").arg(QFileInfo(file).fileName()));
  return true;
}

void ScenarioEditor::newScenario() {
  document_.reset(ScenarioDocument::newScenario(), QString());
  selectLesion(0);
}

bool ScenarioEditor::save() {
  if (document_.file().isEmpty()) {
    const QString chosen = QFileDialog::getSaveFileName(
        this, tr("Save the scenario"), QDir::currentPath(), tr("LiverSim scenarios (*.json)"));
    return !chosen.isEmpty() && saveAs(chosen);
  }
  return saveAs(document_.file());
}

bool ScenarioEditor::saveAs(const QString& file) {
  const std::vector<ScenarioError> errors = document_.saveAs(file);
  if (!errors.empty()) {
    showErrors(tr("The scenario is not saved: fix these first"), "saveErrorsBox", errors);
    return false;
  }
  rememberScenarioFile(file);
  updateRecentMenu();
  statusBar()->showMessage(tr("Saved %1.").arg(QFileInfo(file).fileName()));
  return true;
}

bool ScenarioEditor::maybeSave() {
  if (!document_.isModified()) return true;
  QMessageBox box(QMessageBox::Question, tr("Unsaved changes"),
                  tr("The scenario has changes that are not saved. Save them?"),
                  QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, this);
  box.setObjectName("unsavedChangesBox");
  box.setDefaultButton(QMessageBox::Save);
  switch (box.exec()) {
    case QMessageBox::Save:
      return save();
    case QMessageBox::Discard:
      return true;
    default:
      return false;
  }
}

void ScenarioEditor::closeEvent(QCloseEvent* event) {
  if (maybeSave())
    event->accept();
  else
    event->ignore();
}

void ScenarioEditor::updateRecentMenu() {
  recentMenu_->clear();
  const QStringList recent = recentScenarioFiles();
  for (const QString& file : recent) {
    QAction* action = recentMenu_->addAction(QFileInfo(file).fileName(), this, [this, file] {
      if (maybeSave()) openFile(file);
    });
    action->setToolTip(file);
    action->setData(file);
  }
  recentMenu_->setEnabled(!recent.isEmpty());
}

void ScenarioEditor::tryIt() {
  // What would be refused on saving is refused here too, with the same messages.
  const std::vector<ScenarioError> errors = ScenarioDocument::problems(document_.scenario());
  if (!errors.empty()) {
    showErrors(tr("The scenario cannot run: fix these first"), "tryErrorsBox", errors);
    return;
  }
  emit tryScenario(document_.scenario(), document_.isModified() ? QString() : document_.file());
  statusBar()->showMessage(tr("Running the scenario in the workstation."));
}

// ---- Cost -------------------------------------------------------------------------------------

void ScenarioEditor::measureCost() {
  // Only a change of what the cost depends on is measured again (not a new title).
  if (costScenario_ && sameCost(*costScenario_, document_.scenario())) return;
  if (costBusy_) {
    costAgain_ = true;
    return;
  }
  costScenario_ = document_.scenario();
  costBusy_ = true;
  costAgain_ = false;
  if (costWorker_.started()) costWorker_.wait();
  tissuePanel_->showCost(stepsPerSecond_
                             ? tr("%1 steps/s — measuring again…").arg(*stepsPerSecond_, 0, 'f', 0)
                             : tr("Measuring the cost…"));
  costWorker_.start(
      [this, scenario = document_.scenario(), folder = document_.organFolder(), alive = alive_] {
        std::optional<double> rate;
        double realTime = 0.0;
        int tets = 0;
        QString problem;
        try {
          const SceneSetup setup = build_scene(scenario, folder);
          tets = int(setup.mesh.tet_count());
          const SteppingTiming timing = time_scene_under_pull(setup, 0.5);
          rate = timing.steps_per_s();
          realTime = timing.real_time_factor();
        } catch (const std::exception& e) {
          problem = QString::fromUtf8(e.what());
        }
        if (!*alive) return;
        QMetaObject::invokeMethod(
            this,
            [this, rate, realTime, tets, problem] {
              finishCostMeasurement(rate, realTime, tets, problem);
            },
            Qt::QueuedConnection);
      });
}

void ScenarioEditor::finishCostMeasurement(std::optional<double> stepsPerSecond,
                                           double realTimeFactor, int tetCount, QString problem) {
  costBusy_ = false;
  ++costMeasurements_;
  if (stepsPerSecond) {
    if (stepsPerSecond_) previousStepsPerSecond_ = stepsPerSecond_;
    stepsPerSecond_ = stepsPerSecond;
    QString text = tr("%1 steps/s, %2× real time (%3 elements)")
                       .arg(*stepsPerSecond, 0, 'f', 0)
                       .arg(realTimeFactor, 0, 'f', 2)
                       .arg(tetCount);
    if (previousStepsPerSecond_)
      text += tr("; before the last change %1 steps/s").arg(*previousStepsPerSecond_, 0, 'f', 0);
    tissuePanel_->showCost(text);
  } else {
    tissuePanel_->showCost(tr("Not measured: %1").arg(problem));
  }
  if (costAgain_) {
    costAgain_ = false;
    measureCost();
    return;
  }
  emit costMeasured();
}

QString ScenarioEditor::costText() const {
  return tissuePanel_->costText();
}

}  // namespace liversim
