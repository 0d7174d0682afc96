#include "scenario_editor.h"

#include "accuracy_panel.h"
#include "parameter_spin_box.h"
#include "recent_scenarios.h"
#include "render/liver_scene.h"
#include "render/scenario_overlay.h"
#include "vtk_viewport.h"

#include "liversim/engine/parameter_ranges.h"
#include "liversim/meshing/surface_import.h"
#include "liversim/studies/performance.h"

#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>

#include <Eigen/Geometry>

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QStatusBar>
#include <QTableWidget>
#include <QToolBar>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace liversim {
namespace {

// Undo merge keys: consecutive edits of one field (typing, a spin box's arrows, a drag) are one
// step.
enum MergeKey {
  kNoMerge = 0,
  kMoveLesion = 1,
  kResizeLesion,
  kPaint,
  kLesionName,
  kLesionCentre,
  kLesionRadius = kLesionCentre + 3,
  kLesionStiffness = kLesionRadius + 3,
  kLesionYield,
  kLesionViscosity,
  kTitle,
  kDescription,
  kInstructions,
  kTimeLimit,
  kMargin,
  kSafeForce,
  kYoungsModulus,
  kPoissonRatio,
  kFibreDirection,
  kViscoelasticE1,
  kViscoelasticEta1,
  kYieldLimit,
  kViscoplasticEta2,
  kCreepIndex,
  kFibreK1,
  kFibreK2,
  kTargetTetCount,
  kRubricWeight,
  kRubricThreshold = kRubricWeight + 1000,  // one key per criterion
  kDamageTension = kRubricThreshold + 1000,
  kDamageCompression,
  kLift,
};

constexpr double kMetresPerMm = 1e-3;

QDoubleSpinBox* lengthSpinBox(double min_mm, double max_mm, const QString& tip) {
  return spinBox("", min_mm, max_mm, 1, " mm", tip);
}

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
  addDock(tr("Lesions"), "lesionDock", buildLesionPanel());
  QDockWidget* task = addDock(tr("Task"), "taskDock", buildTaskPanel());
  QDockWidget* tissue = addDock(tr("Tissue and effects"), "tissueDock", buildTissuePanel());
  QDockWidget* organ = addDock(tr("Organ and accuracy"), "organDock", buildOrganPanel());
  QDockWidget* grading = addDock(tr("Grading"), "gradingDock", buildGradingPanel());
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

QWidget* ScenarioEditor::buildLesionPanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  lesionList_ = new QListWidget;
  lesionList_->setObjectName("lesionList");
  lesionList_->setMaximumHeight(90);
  layout->addWidget(lesionList_);
  connect(lesionList_, &QListWidget::currentRowChanged, this, [this](int row) {
    if (!refreshing_) selectLesion(row);
  });
  auto* buttons = new QHBoxLayout;
  auto* addButton = new QPushButton(tr("Add"));
  addButton->setObjectName("addLesionButton");
  addButton->setToolTip(tr("A new lesion at the organ's centre (or use Place lesion)"));
  removeLesion_ = new QPushButton(tr("Remove"));
  removeLesion_->setObjectName("removeLesionButton");
  buttons->addWidget(addButton);
  buttons->addWidget(removeLesion_);
  layout->addLayout(buttons);
  connect(addButton, &QPushButton::clicked, this,
          [this] { addLesion(tr("Add a lesion"), organCentre_m_, 0.0); });
  connect(removeLesion_, &QPushButton::clicked, this, [this] {
    const int index = selectedLesion_;
    if (index < 0) return;
    document_.edit(tr("Remove the lesion"),
                   [&](Scenario& s) { s.lesions.erase(s.lesions.begin() + index); });
    selectLesion(std::min(index, int(document_.scenario().lesions.size()) - 1));
  });

  lesionFields_ = new QWidget;
  auto* form = new QFormLayout(lesionFields_);
  form->setContentsMargins(0, 0, 0, 0);
  lesionName_ = new QLineEdit;
  lesionName_->setObjectName("lesionName");
  lesionName_->setToolTip(tr("The lesion's name, which the task refers to"));
  form->addRow(tr("Name"), lesionName_);
  connect(lesionName_, &QLineEdit::editingFinished, this, [this] {
    const std::string name = lesionName_->text().toStdString();
    const std::string old = document_.scenario().lesions.at(selectedLesion_).name;
    document_.edit(tr("Rename the lesion"), [&](Scenario& s) {
      s.lesions[selectedLesion_].name = name;
      if (s.task.lesion == old) s.task.lesion = name;  // the task follows its lesion
    });
  });
  static const char* const axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    lesionCentre_[k] = lengthSpinBox(
        -250.0, 250.0, tr("The lesion's centre along the scene's %1 axis").arg(axes[k]));
    lesionCentre_[k]->setObjectName(QString("lesionCentre%1").arg(axes[k]));
    lesionRadius_[k] = lengthSpinBox(1.0, 80.0,
                                     tr("The lesion's semi-axis along the scene's %1 axis "
                                        "(Shift-drag the lesion in the view to resize it)")
                                         .arg(axes[k]));
    lesionRadius_[k]->setObjectName(QString("lesionRadius%1").arg(axes[k]));
    connect(lesionCentre_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      editLesion(tr("Move the lesion"), kLesionCentre + k,
                 [&](LesionSpec& l) { l.centre_mm[k] = v; });
    });
    connect(lesionRadius_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      editLesion(tr("Resize the lesion"), kLesionRadius + k,
                 [&](LesionSpec& l) { l.radii_mm[k] = v; });
    });
  }
  const auto row = [](QDoubleSpinBox* const boxes[3]) {
    auto* w = new QWidget;
    auto* h = new QHBoxLayout(w);
    h->setContentsMargins(0, 0, 0, 0);
    for (int k = 0; k < 3; ++k) h->addWidget(boxes[k]);
    return w;
  };
  form->addRow(tr("Centre (x, y, z)"), row(lesionCentre_));
  form->addRow(tr("Semi-axes"), row(lesionRadius_));

  // A lesion's modulus is the parenchyma's times a ratio in range (validated on save).
  lesionStiffness_ = spinBox("lesionStiffness", 1.0, 2000.0, 2, " kPa", QString());
  {
    const ParameterRange& ratio = parameter_range(parameter::lesion_stiffness_ratio);
    lesionStiffness_->setToolTip(
        tr("Young's modulus of the lesion (instantaneous, with viscoelasticity): %1 to %2 times "
           "the parenchyma's. %3")
            .arg(ratio.min)
            .arg(ratio.max)
            .arg(QString::fromUtf8(ratio.why.data(), int(ratio.why.size()))));
  }
  form->addRow(tr("Stiffness E"), lesionStiffness_);
  connect(lesionStiffness_, &QDoubleSpinBox::valueChanged, this, [this](double kpa) {
    editLesion(tr("Change the lesion's stiffness"), kLesionStiffness,
               [&](LesionSpec& l) { l.youngs_modulus_pa = kpa * 1e3; });
  });
  lesionYieldLimit_ = optionalLesionValue(form, parameter::yield_limit, " Pa", "lesionYieldLimit",
                                          tr("Yield limit"), tr("Change the lesion's yield limit"),
                                          kLesionYield, &LesionSpec::yield_limit_pa);
  lesionViscosity_ = optionalLesionValue(form, parameter::eta1, " Pa·s", "lesionViscosity",
                                         tr("Viscosity η1"), tr("Change the lesion's viscosity"),
                                         kLesionViscosity, &LesionSpec::viscosity_pa_s);
  lesionHidden_ = new QCheckBox(tr("Hidden from the trainee"));
  lesionHidden_->setObjectName("lesionHidden");
  lesionHidden_->setToolTip(tr("Not drawn in the workstation (palpation tasks)"));
  form->addRow(QString(), lesionHidden_);
  connect(lesionHidden_, &QCheckBox::toggled, this, [this](bool hidden) {
    editLesion(hidden ? tr("Hide the lesion") : tr("Show the lesion"), kNoMerge,
               [&](LesionSpec& l) { l.hidden = hidden; });
  });
  layout->addWidget(lesionFields_);
  layout->addStretch(1);
  return panel;
}

QWidget* ScenarioEditor::buildTaskPanel() {
  auto* panel = new QWidget;
  auto* form = new QFormLayout(panel);
  title_ = new QLineEdit;
  title_->setObjectName("scenarioTitle");
  form->addRow(tr("Title"), title_);
  connect(title_, &QLineEdit::editingFinished, this, [this] {
    const std::string text = title_->text().toStdString();
    document_.edit(
        tr("Change the title"), [&](Scenario& s) { s.title = text; }, kTitle);
  });
  description_ = new QPlainTextEdit;
  description_->setObjectName("scenarioDescription");
  description_->setMaximumHeight(70);
  form->addRow(tr("Description"), description_);
  connect(description_, &QPlainTextEdit::textChanged, this, [this] {
    if (refreshing_) return;
    const std::string text = description_->toPlainText().toStdString();
    document_.edit(
        tr("Change the description"), [&](Scenario& s) { s.description = text; }, kDescription);
  });
  taskKind_ = new QComboBox;
  taskKind_->setObjectName("taskKind");
  taskKind_->addItem(tr("Palpate a hidden lesion"), int(TaskKind::palpate_lesion));
  taskKind_->addItem(tr("Retract a lobe"), int(TaskKind::retract_lobe));
  taskKind_->addItem(tr("Resect a lesion"), int(TaskKind::resect_lesion));
  form->addRow(tr("Task"), taskKind_);
  connect(taskKind_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing_) return;
    const auto kind = TaskKind(taskKind_->itemData(index).toInt());
    document_.edit(tr("Change the task"), [&](Scenario& s) {
      // A field of another task is not written (docs/scenario-format.md): it goes back to its
      // default, so that what is saved reads back equal.
      TaskSpec& t = s.task;
      const TaskSpec defaults;
      t.kind = kind;
      if (kind == TaskKind::retract_lobe) {
        t.lesion.clear();
      } else {
        t.grasp_point_mm = defaults.grasp_point_mm;
        t.lift_mm = defaults.lift_mm;
        if (t.lesion.empty() && !s.lesions.empty()) t.lesion = s.lesions.front().name;
      }
      if (kind != TaskKind::resect_lesion) {
        t.margin_mm = defaults.margin_mm;
        t.planned_plane.reset();
      }
    });
  });
  instructions_ = new QLineEdit;
  instructions_->setObjectName("taskInstructions");
  instructions_->setToolTip(tr("Shown to the trainee"));
  form->addRow(tr("Instructions"), instructions_);
  connect(instructions_, &QLineEdit::editingFinished, this, [this] {
    const std::string text = instructions_->text().toStdString();
    document_.edit(
        tr("Change the instructions"), [&](Scenario& s) { s.task.instructions = text; },
        kInstructions);
  });
  timeLimit_ =
      spinBox("timeLimit", 10.0, 7200.0, 0, " s", tr("The time the trainee has: 10 s to 2 h"));
  form->addRow(tr("Time limit"), timeLimit_);
  bindSpinBox(timeLimit_, tr("Change the time limit"), kTimeLimit,
              [](Scenario& s, double v) { s.task.time_limit_s = v; });
  taskLesion_ = new QComboBox;
  taskLesion_->setObjectName("taskLesion");
  taskLesion_->setToolTip(tr("The lesion to find or to resect"));
  form->addRow(tr("Lesion"), taskLesion_);
  connect(taskLesion_, &QComboBox::currentTextChanged, this, [this](const QString& name) {
    if (!refreshing_)
      document_.edit(tr("Choose the task's lesion"),
                     [&](Scenario& s) { s.task.lesion = name.toStdString(); });
  });
  margin_ =
      lengthSpinBox(0.0, 50.0, tr("Resection: the least distance from the cut to the lesion"));
  margin_->setObjectName("resectionMargin");
  form->addRow(tr("Margin"), margin_);
  bindSpinBox(margin_, tr("Change the margin"), kMargin,
              [](Scenario& s, double v) { s.task.margin_mm = v; });
  QHBoxLayout* planeRow = clearableRow(plane_, "plannedPlane", tr("Clear"), "clearPlaneButton",
                                       tr("Clear the planned plane"),
                                       [](Scenario& s) { s.task.planned_plane.reset(); });
  form->addRow(tr("Planned plane"), planeRow);
  auto* toolsRow = new QHBoxLayout;
  for (std::size_t i = 0; i < kToolKinds.size(); ++i) {
    const ToolKind kind = kToolKinds[i];
    tools_[i] = new QCheckBox(QString::fromUtf8(tool_name(kind).data()));
    tools_[i]->setObjectName(QString("tool_%1").arg(tool_name(kind).data()));
    toolsRow->addWidget(tools_[i]);
    connect(tools_[i], &QCheckBox::toggled, this, [this, kind](bool on) {
      if (refreshing_) return;
      document_.edit(on ? tr("Allow a tool") : tr("Withdraw a tool"), [&](Scenario& s) {
        std::vector<ToolKind> tools;
        for (ToolKind k : kToolKinds) {
          const bool had = std::find(s.tools.begin(), s.tools.end(), k) != s.tools.end();
          if (k == kind ? on : had) tools.push_back(k);
        }
        s.tools = tools;
      });
    });
  }
  form->addRow(tr("Tools"), toolsRow);
  safeForce_ = spinBox("safeForce", 0.1, 20.0, 2, " N",
                       tr("A force on the tissue above this is excessive (graded)"));
  form->addRow(tr("Safe force"), safeForce_);
  bindSpinBox(safeForce_, tr("Change the safe force"), kSafeForce,
              [](Scenario& s, double v) { s.task.safe_force_n = v; });
  return panel;
}

QWidget* ScenarioEditor::buildTissuePanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  auto* form = new QFormLayout;
  youngsModulus_ = rangeSpinBox(parameter::youngs_modulus, 1e3, " kPa", 2);
  youngsModulus_->setObjectName("parenchymaStiffness");
  form->addRow(tr("Parenchyma E"), youngsModulus_);
  connect(youngsModulus_, &QDoubleSpinBox::valueChanged, this, [this](double kpa) {
    if (refreshing_) return;
    document_.edit(
        tr("Change the parenchyma's stiffness"),
        [&](Scenario& s) {
          const double old = s.parenchyma.elastic.youngs_modulus_pa;
          s.parenchyma.elastic.youngs_modulus_pa = kpa * 1e3;
          // With viscoelasticity E = E1 + E2: both arms follow.
          if (auto& ve = s.parenchyma.viscoelastic; ve && old > 0.0)
            ve = with_instantaneous_modulus(*ve, kpa * 1e3);
        },
        kYoungsModulus);
  });
  poissonRatio_ = rangeSpinBox(parameter::poisson_ratio, 1.0, QString(), 3);
  poissonRatio_->setObjectName("parenchymaPoissonRatio");
  poissonRatio_->setSingleStep(0.005);
  form->addRow(tr("Poisson's ratio ν"), poissonRatio_);
  bindSpinBox(poissonRatio_, tr("Change Poisson's ratio"), kPoissonRatio,
              [](Scenario& s, double v) { s.parenchyma.elastic.poisson_ratio = v; });
  layout->addLayout(form);

  auto* effects = new QGroupBox(tr("Effects simulated (an effect off costs nothing)"));
  auto* effectsLayout = new QVBoxLayout(effects);
  const QString names[4] = {
      tr("Near-incompressibility (averaged pressure)"), tr("Viscoelasticity (relaxation, creep)"),
      tr("Viscoplasticity above the yield limit"), tr("Fibre anisotropy (HGO)")};
  const char* objects[4] = {"effectIncompressibility", "effectViscoelastic", "effectViscoplastic",
                            "effectFibres"};
  for (int i = 0; i < 4; ++i) {
    effects_[i] = new QCheckBox(names[i]);
    effects_[i]->setObjectName(objects[i]);
    effectsLayout->addWidget(effects_[i]);
    connect(effects_[i], &QCheckBox::toggled, this, [this, i](bool on) {
      if (refreshing_) return;
      document_.edit(on ? tr("Switch an effect on") : tr("Switch an effect off"), [&](Scenario& s) {
        TissueSpec& t = s.parenchyma;
        const double e = t.elastic.youngs_modulus_pa;
        switch (i) {
          case 0:
            s.effects.near_incompressibility = on;
            break;
          case 1:
            s.effects.viscoelastic = on;
            if (!on) s.effects.viscoplastic = false;  // it needs viscoelasticity
            // The seed's split of E and its η1 when none was set (kept when switched off).
            if (on && !t.viscoelastic) t.viscoelastic = seed_viscoelastic_split(e);
            break;
          case 2:
            s.effects.viscoplastic = on;
            if (on) s.effects.viscoelastic = true;
            if (on && !t.viscoelastic) t.viscoelastic = seed_viscoelastic_split(e);
            if (on && !t.viscoplastic) t.viscoplastic = ViscoplasticParameters{50.0, 2000.0, 0.5};
            break;
          case 3:
            s.effects.fibres = on;
            if (on && !t.fibres) t.fibres = FibreSpec{1000.0, 2.0, {1.0, 0.0, 0.0}};
            break;
        }
      });
    });
  }
  cost_ = new QLabel;
  cost_->setObjectName("effectsCost");
  cost_->setWordWrap(true);
  cost_->setToolTip(
      tr("Steps per second of this scenario on this machine, measured now: its "
         "model stepped for half a second under a 0.5 N pull"));
  effectsLayout->addWidget(cost_);
  layout->addWidget(effects);

  // The laws' parameters: shown while their effect is on (kept, not shown, while it is off).
  auto* laws = new QGroupBox(tr("Laws of the effects"));
  auto* lawForm = new QFormLayout(laws);
  const auto law = [&](QDoubleSpinBox*& box, std::string_view range, double scale,
                       const QString& suffix, int decimals, const char* name, const QString& label,
                       int mergeKey, std::function<void(TissueSpec&, double)> set) {
    box = rangeSpinBox(range, scale, suffix, decimals);
    box->setObjectName(name);
    lawForm->addRow(label, box);
    bindSpinBox(box, tr("Change %1").arg(label), mergeKey,
                [set](Scenario& s, double v) { set(s.parenchyma, v); });
  };
  law(viscoelasticE1_, parameter::e1, 1.0, " Pa", 0, "viscoelasticE1", tr("Maxwell arm E1"),
      kViscoelasticE1, [](TissueSpec& t, double v) {
        // E = E1 + E2 stays the parenchyma's E.
        if (t.viscoelastic)
          t.viscoelastic = with_maxwell_arm(*t.viscoelastic, v, t.elastic.youngs_modulus_pa);
      });
  viscoelasticE1_->setToolTip(viscoelasticE1_->toolTip() +
                              tr(" E2 = E − E1 follows, so that E stays the parenchyma's."));
  law(viscoelasticEta1_, parameter::eta1, 1.0, " Pa·s", 0, "viscoelasticEta1", tr("Maxwell arm η1"),
      kViscoelasticEta1, [](TissueSpec& t, double v) {
        if (t.viscoelastic) t.viscoelastic->eta1_pa_s = v;
      });
  law(yieldLimit_, parameter::yield_limit, 1.0, " Pa", 0, "viscoplasticYieldLimit",
      tr("Yield limit σs"), kYieldLimit, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->yield_limit_pa = v;
      });
  law(viscoplasticEta2_, parameter::eta2, 1.0, " Pa·sⁿ", 0, "viscoplasticEta2",
      tr("Viscoplastic η2"), kViscoplasticEta2, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->eta2_pa_s_pow_n = v;
      });
  law(creepIndex_, parameter::creep_index, 1.0, QString(), 2, "creepIndex", tr("Creep index n"),
      kCreepIndex, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->creep_index_n = v;
      });
  law(fibreK1_, parameter::fibre_k1, 1.0, " Pa", 0, "fibreK1", tr("Fibre k1"), kFibreK1,
      [](TissueSpec& t, double v) {
        if (t.fibres) t.fibres->k1_pa = v;
      });
  law(fibreK2_, parameter::fibre_k2, 1.0, QString(), 2, "fibreK2", tr("Fibre k2"), kFibreK2,
      [](TissueSpec& t, double v) {
        if (t.fibres) t.fibres->k2 = v;
      });
  layout->addWidget(laws);

  auto* fibres = new QGroupBox(tr("Fibre direction"));
  auto* fibreLayout = new QHBoxLayout(fibres);
  static const char* const axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    fibreDirection_[k] = new QDoubleSpinBox;
    fibreDirection_[k]->setObjectName(QString("fibreDirection%1").arg(axes[k]));
    fibreDirection_[k]->setRange(-1.0, 1.0);
    fibreDirection_[k]->setDecimals(3);
    fibreDirection_[k]->setSingleStep(0.1);
    fibreDirection_[k]->setKeyboardTracking(false);
    fibreDirection_[k]->setToolTip(tr("The fibres' reference direction (normalised on saving)"));
    fibreLayout->addWidget(fibreDirection_[k]);
    connect(fibreDirection_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      if (refreshing_ || !document_.scenario().parenchyma.fibres) return;
      document_.edit(
          tr("Change the fibre direction"),
          [&](Scenario& s) { s.parenchyma.fibres->direction[k] = v; }, kFibreDirection);
    });
  }
  fibreAlongView_ = new QPushButton(tr("Across the view"));
  fibreAlongView_->setObjectName("fibreAlongViewButton");
  fibreAlongView_->setToolTip(tr("Fibres along the screen's horizontal, as the organ is seen now"));
  fibreLayout->addWidget(fibreAlongView_);
  connect(fibreAlongView_, &QPushButton::clicked, this, [this] {
    if (!scene_ || !document_.scenario().parenchyma.fibres) return;
    vtkCamera* camera = scene_->renderer()->GetActiveCamera();
    double up[3], dop[3];
    camera->GetViewUp(up);
    camera->GetDirectionOfProjection(dop);
    const Eigen::Vector3d right =
        Eigen::Vector3d(dop[0], dop[1], dop[2]).cross(Eigen::Vector3d(up[0], up[1], up[2]));
    const Eigen::Vector3d d = right.normalized();
    document_.edit(tr("Set the fibre direction"), [&](Scenario& s) {
      s.parenchyma.fibres->direction = {d.x(), d.y(), d.z()};
    });
  });
  layout->addWidget(fibres);

  auto* fixed = new QGroupBox(tr("Fixed regions"));
  auto* fixedForm = new QFormLayout(fixed);
  brushRadius_ = lengthSpinBox(2.0, 40.0, tr("Radius of the painting brush (Paint fixed)"));
  brushRadius_->setObjectName("brushRadius");
  brushRadius_->setValue(10.0);
  fixedForm->addRow(tr("Brush"), brushRadius_);
  QHBoxLayout* fixedRow = clearableRow(fixedRegions_, "fixedRegions", tr("Clear painted"),
                                       "clearFixedButton", tr("Clear the painted fixed regions"),
                                       [](Scenario& s) { s.organ.fixed_balls.clear(); });
  fixedForm->addRow(tr("Painted"), fixedRow);
  fixLigament_ = new QCheckBox(tr("Coronary ligament (built-in liver)"));
  fixLigament_->setObjectName("fixLigament");
  fixedForm->addRow(QString(), fixLigament_);
  connect(fixLigament_, &QCheckBox::toggled, this, [this](bool on) {
    if (!refreshing_)
      document_.edit(tr("Change the ligament"), [&](Scenario& s) { s.organ.fix_ligament = on; });
  });
  layout->addWidget(fixed);
  layout->addStretch(1);
  return panel;
}

QWidget* ScenarioEditor::buildOrganPanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  auto* form = new QFormLayout;
  organGeometry_ = new QComboBox;
  organGeometry_->setObjectName("organGeometry");
  organGeometry_->addItem(tr("Built-in liver"), int(OrganGeometry::built_in_liver));
  organGeometry_->addItem(tr("Surface model (OBJ, STL, PLY, glTF, FBX, 3DS)"),
                          int(OrganGeometry::surface_file));
  organGeometry_->addItem(tr("Tetrahedral mesh (.inp, .msh)"), int(OrganGeometry::tet_mesh_file));
  form->addRow(tr("Organ"), organGeometry_);
  connect(organGeometry_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing_) return;
    const auto geometry = OrganGeometry(organGeometry_->itemData(index).toInt());
    document_.edit(tr("Change the organ"), [&](Scenario& s) {
      // Fields of another geometry are not written: back to their defaults.
      OrganSpec& o = s.organ;
      const OrganSpec defaults;
      o.geometry = geometry;
      if (geometry == OrganGeometry::built_in_liver) o.file.clear();
      if (geometry != OrganGeometry::tet_mesh_file) o.fixed_node_set.clear();
      if (geometry != OrganGeometry::surface_file) o.metres_per_unit = defaults.metres_per_unit;
      if (geometry != OrganGeometry::built_in_liver) o.fix_ligament = defaults.fix_ligament;
      if (geometry == OrganGeometry::tet_mesh_file) o.target_tet_count = defaults.target_tet_count;
    });
  });
  organFile_ = new QLineEdit;
  organFile_->setObjectName("organFile");
  organFile_->setToolTip(tr("The organ's file: relative to the scenario's folder, or absolute"));
  auto* choose = new QPushButton(tr("Choose…"));
  choose->setObjectName("chooseOrganFileButton");
  auto* fileRow = new QHBoxLayout;
  fileRow->addWidget(organFile_, 1);
  fileRow->addWidget(choose);
  form->addRow(tr("File"), fileRow);
  const auto setFile = [this](const QString& file) {
    document_.edit(tr("Choose the organ's file"),
                   [&](Scenario& s) { s.organ.file = file.toStdString(); });
  };
  connect(organFile_, &QLineEdit::editingFinished, this,
          [this, setFile] { setFile(organFile_->text()); });
  connect(choose, &QPushButton::clicked, this, [this, setFile] {
    const bool surface = document_.scenario().organ.geometry == OrganGeometry::surface_file;
    QStringList patterns;
    if (surface)
      for (const std::string& extension : surface_file_extensions())
        patterns << "*" + QString::fromStdString(extension);
    else
      patterns << "*.inp"
               << "*.msh";
    const QString folder = QString::fromStdString(document_.organFolder().string());
    const QString chosen =
        QFileDialog::getOpenFileName(this, tr("The organ's file"), folder,
                                     tr("Organ files (%1);;All files (*)").arg(patterns.join(' ')));
    if (chosen.isEmpty()) return;
    // Named relative to the scenario's folder when it is saved, so the two move together.
    setFile(document_.file().isEmpty() ? chosen : QDir(folder).relativeFilePath(chosen));
  });
  lengthUnit_ = new QComboBox;
  lengthUnit_->setObjectName("organLengthUnit");
  for (const LengthUnit& unit : kLengthUnits)
    lengthUnit_->addItem(QString::fromUtf8(unit.name.data(), int(unit.name.size())), unit.metres);
  lengthUnit_->setToolTip(tr("The unit of the surface model's lengths (never guessed)"));
  form->addRow(tr("Length unit"), lengthUnit_);
  connect(lengthUnit_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing_) return;
    const double metres = lengthUnit_->itemData(index).toDouble();
    document_.edit(tr("Change the organ's unit"),
                   [&](Scenario& s) { s.organ.metres_per_unit = metres; });
  });
  targetTetCount_ = new QSpinBox;
  targetTetCount_->setObjectName("targetTetCount");
  targetTetCount_->setRange(1000, 50000);
  targetTetCount_->setSingleStep(500);
  targetTetCount_->setKeyboardTracking(false);
  targetTetCount_->setToolTip(
      tr("Elements of the organ's mesh: 1000 to 50000 (more is more accurate and slower: see "
         "the cost in Tissue and effects)"));
  form->addRow(tr("Elements"), targetTetCount_);
  connect(targetTetCount_, &QSpinBox::valueChanged, this, [this](int count) {
    if (!refreshing_)
      document_.edit(
          tr("Change the element count"), [&](Scenario& s) { s.organ.target_tet_count = count; },
          kTargetTetCount);
  });
  fixedNodeSet_ = new QLineEdit;
  fixedNodeSet_->setObjectName("fixedNodeSet");
  fixedNodeSet_->setToolTip(tr("A node set of the mesh file held fixed (empty: none)"));
  form->addRow(tr("Fixed node set"), fixedNodeSet_);
  connect(fixedNodeSet_, &QLineEdit::editingFinished, this, [this] {
    const std::string set = fixedNodeSet_->text().toStdString();
    document_.edit(tr("Change the fixed node set"),
                   [&](Scenario& s) { s.organ.fixed_node_set = set; });
  });
  organStatus_ = new QLabel;
  organStatus_->setObjectName("organStatus");
  organStatus_->setWordWrap(true);
  form->addRow(QString(), organStatus_);
  layout->addLayout(form);

  accuracy_ = new AccuracyPanel;
  accuracy_->setObjectName("accuracyPanel");
  connect(
      accuracy_, &AccuracyPanel::applyRequested, this, [this](const IntegratorSettings& settings) {
        document_.edit(tr("Change the integrator"), [&](Scenario& s) { s.integrator = settings; });
      });
  layout->addWidget(accuracy_);
  layout->addStretch(1);
  return panel;
}

QWidget* ScenarioEditor::buildGradingPanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  rubricTable_ = new QTableWidget(0, 4);
  rubricTable_->setObjectName("rubricTable");
  rubricTable_->setHorizontalHeaderLabels(
      {tr("Metric"), tr("Weight"), tr("Pass if"), tr("Threshold")});
  rubricTable_->horizontalHeader()->setSectionResizeMode(0, QHeaderView::Stretch);
  rubricTable_->verticalHeader()->hide();
  rubricTable_->setSelectionBehavior(QAbstractItemView::SelectRows);
  rubricTable_->setToolTip(
      tr("The rubric: each criterion passes when its metric is at most or at least the "
         "threshold; the score is the passed criteria's share of the weights"));
  layout->addWidget(rubricTable_, 1);
  auto* buttons = new QHBoxLayout;
  auto* add = new QPushButton(tr("Add criterion"));
  add->setObjectName("addCriterionButton");
  auto* remove = new QPushButton(tr("Remove"));
  remove->setObjectName("removeCriterionButton");
  buttons->addWidget(add);
  buttons->addWidget(remove);
  layout->addLayout(buttons);
  connect(add, &QPushButton::clicked, this, [this] {
    document_.edit(tr("Add a criterion"), [](Scenario& s) {
      // The first metric not graded yet.
      RubricCriterion c;
      c.metric = std::string(gradable_metrics().front().name);
      for (const MetricInfo& m : gradable_metrics())
        if (std::none_of(s.rubric.begin(), s.rubric.end(),
                         [&](const RubricCriterion& r) { return r.metric == m.name; })) {
          c.metric = std::string(m.name);
          break;
        }
      s.rubric.push_back(c);
    });
  });
  connect(remove, &QPushButton::clicked, this, [this] {
    const int row = rubricTable_->currentRow();
    if (row < 0 || row >= int(document_.scenario().rubric.size())) return;
    document_.edit(tr("Remove a criterion"),
                   [&](Scenario& s) { s.rubric.erase(s.rubric.begin() + row); });
  });

  auto* form = new QFormLayout;
  damageTension_ = spinBox("damageTensionStrain", 0.05, 2.0, 2, QString(),
                           tr("Tissue stretched past 1 + this is damaged (graded): 0.05 to 2"));
  form->addRow(tr("Damage in tension"), damageTension_);
  bindSpinBox(damageTension_, tr("Change the damage strain"), kDamageTension,
              [](Scenario& s, double v) { s.task.damage_tension_strain = v; });
  damageCompression_ =
      spinBox("damageCompressionStrain", 0.05, 0.95, 2, QString(),
              tr("Tissue squeezed below 1 − this is damaged (graded): 0.05 to 0.95"));
  form->addRow(tr("Damage in compression"), damageCompression_);
  bindSpinBox(damageCompression_, tr("Change the damage strain"), kDamageCompression,
              [](Scenario& s, double v) { s.task.damage_compression_strain = v; });
  graspPoint_ = new QLabel;
  graspPoint_->setObjectName("graspPoint");
  graspPoint_->setWordWrap(true);
  auto* pick = new QPushButton(tr("Pick on the organ"));
  pick->setObjectName("pickGraspPointButton");
  pick->setToolTip(tr("Retraction: click where the lobe is to be grasped"));
  connect(pick, &QPushButton::clicked, this, [this] { setMode(Mode::pickGraspPoint); });
  auto* graspRow = new QHBoxLayout;
  graspRow->addWidget(graspPoint_, 1);
  graspRow->addWidget(pick);
  form->addRow(tr("Grasp point"), graspRow);
  lift_ = spinBox("liftMm", 5.0, 100.0, 0, " mm", tr("Retraction: how far to lift: 5 to 100 mm"));
  form->addRow(tr("Lift"), lift_);
  bindSpinBox(lift_, tr("Change the lift"), kLift,
              [](Scenario& s, double v) { s.task.lift_mm = v; });
  layout->addLayout(form);
  return panel;
}

void ScenarioEditor::showRubric() {
  const std::vector<RubricCriterion>& rubric = document_.scenario().rubric;
  if (shownRubric_ && *shownRubric_ == rubric) return;  // the table made this edit itself
  shownRubric_ = rubric;
  rubricTable_->setRowCount(int(rubric.size()));
  // An edit in a row: the table shows it already, so it is not rebuilt under the editing widget.
  const auto editRow = [this](int row, const QString& text, int mergeKey,
                              std::function<void(RubricCriterion&)> change) {
    if (refreshing_) return;
    std::vector<RubricCriterion> next = document_.scenario().rubric;
    change(next.at(row));
    shownRubric_ = next;
    document_.edit(
        text, [&](Scenario& s) { s.rubric = next; }, mergeKey);
  };
  for (int row = 0; row < int(rubric.size()); ++row) {
    const RubricCriterion& c = rubric[row];
    auto* metric = new QComboBox;
    for (const MetricInfo& m : gradable_metrics())
      metric->addItem(QString::fromUtf8(m.name.data(), int(m.name.size())));
    metric->setCurrentText(QString::fromStdString(c.metric));
    const MetricInfo* info = find_metric(c.metric);
    if (info)
      metric->setToolTip(QString::fromUtf8(info->meaning.data(), int(info->meaning.size())));
    auto* weight = spinBox("", 0.0, 100.0, 1, QString(), tr("The criterion's weight in the score"));
    weight->setValue(c.weight);
    auto* rule = new QComboBox;
    rule->addItem(tr("at most"), int(PassRule::at_most));
    rule->addItem(tr("at least"), int(PassRule::at_least));
    rule->setCurrentIndex(c.rule == PassRule::at_most ? 0 : 1);
    const QString unit = info && !info->unit.empty()
                             ? " " + QString::fromUtf8(info->unit.data(), int(info->unit.size()))
                             : QString();
    auto* threshold = spinBox("", -1e6, 1e6, 2, unit, tr("The threshold, in the metric's unit"));
    threshold->setValue(c.threshold);
    rubricTable_->setCellWidget(row, 0, metric);
    rubricTable_->setCellWidget(row, 1, weight);
    rubricTable_->setCellWidget(row, 2, rule);
    rubricTable_->setCellWidget(row, 3, threshold);
    connect(metric, &QComboBox::currentTextChanged, this, [=, this](const QString& name) {
      editRow(row, tr("Change a criterion's metric"), kNoMerge,
              [&](RubricCriterion& r) { r.metric = name.toStdString(); });
      shownRubric_.reset();  // the unit of the threshold changes with it
      QMetaObject::invokeMethod(
          this, [this] { showRubric(); }, Qt::QueuedConnection);
    });
    connect(weight, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
      editRow(row, tr("Change a criterion's weight"), kRubricWeight + row,
              [&](RubricCriterion& r) { r.weight = v; });
    });
    connect(rule, &QComboBox::currentIndexChanged, this, [=, this](int index) {
      const auto pass = PassRule(rule->itemData(index).toInt());
      editRow(row, tr("Change a criterion's rule"), kNoMerge,
              [&](RubricCriterion& r) { r.rule = pass; });
    });
    connect(threshold, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
      editRow(row, tr("Change a criterion's threshold"), kRubricThreshold + row,
              [&](RubricCriterion& r) { r.threshold = v; });
    });
  }
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
    organStatus_->setText(organProblem_ + tr(" (the organ shown is the one before)"));
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
  organStatus_->setText(QString::fromStdString(organ_->description));
  statusBar()->showMessage(tr("Organ: %1").arg(QString::fromStdString(organ_->description)));
}

void ScenarioEditor::showDocument() {
  const Scenario& s = document_.scenario();
  // A lesion is selected whenever there is one (an undo may have taken the selected one away).
  if (selectedLesion_ >= int(s.lesions.size()) || selectedLesion_ < 0)
    selectedLesion_ = int(s.lesions.size()) - 1;
  refreshing_ = true;
  std::vector<QSignalBlocker> blockers;
  for (QWidget* w : findChildren<QWidget*>()) blockers.emplace_back(w);

  lesionList_->clear();
  for (const LesionSpec& l : s.lesions) lesionList_->addItem(QString::fromStdString(l.name));
  lesionList_->setCurrentRow(selectedLesion_);
  removeLesion_->setEnabled(selectedLesion_ >= 0);
  lesionFields_->setEnabled(selectedLesion_ >= 0);
  if (selectedLesion_ >= 0) {
    const LesionSpec& l = s.lesions[selectedLesion_];
    lesionName_->setText(QString::fromStdString(l.name));
    for (int k = 0; k < 3; ++k) {
      lesionCentre_[k]->setValue(l.centre_mm[k]);
      lesionRadius_[k]->setValue(l.radii_mm[k]);
    }
    lesionStiffness_->setValue(l.youngs_modulus_pa / 1e3);
    lesionYieldLimit_->setValue(l.yield_limit_pa.value_or(lesionYieldLimit_->minimum()));
    lesionViscosity_->setValue(l.viscosity_pa_s.value_or(lesionViscosity_->minimum()));
    lesionHidden_->setChecked(l.hidden);
  }
  lesionYieldLimit_->setEnabled(s.effects.viscoplastic);
  lesionViscosity_->setEnabled(s.effects.viscoelastic);

  title_->setText(QString::fromStdString(s.title));
  if (description_->toPlainText().toStdString() != s.description)
    description_->setPlainText(QString::fromStdString(s.description));
  taskKind_->setCurrentIndex(taskKind_->findData(int(s.task.kind)));
  instructions_->setText(QString::fromStdString(s.task.instructions));
  timeLimit_->setValue(s.task.time_limit_s);
  taskLesion_->clear();
  for (const LesionSpec& l : s.lesions) taskLesion_->addItem(QString::fromStdString(l.name));
  if (taskLesion_->findText(QString::fromStdString(s.task.lesion)) < 0)
    taskLesion_->addItem(QString::fromStdString(s.task.lesion));  // shown, invalid on save
  taskLesion_->setCurrentText(QString::fromStdString(s.task.lesion));
  taskLesion_->setEnabled(s.task.kind != TaskKind::retract_lobe);
  margin_->setValue(s.task.margin_mm);
  margin_->setEnabled(s.task.kind == TaskKind::resect_lesion);
  const auto& plane = s.task.planned_plane;
  plane_->setText(plane ? tr("through (%1, %2, %3) mm, normal (%4, %5, %6)")
                              .arg(plane->point_mm[0], 0, 'f', 1)
                              .arg(plane->point_mm[1], 0, 'f', 1)
                              .arg(plane->point_mm[2], 0, 'f', 1)
                              .arg(plane->normal[0], 0, 'f', 2)
                              .arg(plane->normal[1], 0, 'f', 2)
                              .arg(plane->normal[2], 0, 'f', 2)
                  : s.task.kind == TaskKind::resect_lesion
                      ? tr("none: draw it across the organ (Draw plane)")
                      : tr("resection tasks only"));
  drawPlaneAction_->setEnabled(s.task.kind == TaskKind::resect_lesion);
  if (mode_ == Mode::drawPlane && s.task.kind != TaskKind::resect_lesion) setMode(Mode::view);
  for (std::size_t i = 0; i < kToolKinds.size(); ++i)
    tools_[i]->setChecked(std::find(s.tools.begin(), s.tools.end(), kToolKinds[i]) !=
                          s.tools.end());
  safeForce_->setValue(s.task.safe_force_n);

  youngsModulus_->setValue(s.parenchyma.elastic.youngs_modulus_pa / 1e3);
  poissonRatio_->setValue(s.parenchyma.elastic.poisson_ratio);
  const bool on[4] = {s.effects.near_incompressibility, s.effects.viscoelastic,
                      s.effects.viscoplastic, s.effects.fibres};
  for (int i = 0; i < 4; ++i) effects_[i]->setChecked(on[i]);
  for (int k = 0; k < 3; ++k) {
    fibreDirection_[k]->setEnabled(s.parenchyma.fibres.has_value());
    if (s.parenchyma.fibres) fibreDirection_[k]->setValue(s.parenchyma.fibres->direction[k]);
  }
  fibreAlongView_->setEnabled(s.parenchyma.fibres.has_value());
  const TissueSpec& t = s.parenchyma;
  const auto showLaw = [](QDoubleSpinBox* box, bool on, double value) {
    box->setEnabled(on);
    if (on) box->setValue(value);
  };
  const bool ve = s.effects.viscoelastic && t.viscoelastic,
             vp = s.effects.viscoplastic && t.viscoplastic, fi = s.effects.fibres && t.fibres;
  showLaw(viscoelasticE1_, ve, ve ? t.viscoelastic->e1_pa : 0.0);
  showLaw(viscoelasticEta1_, ve, ve ? t.viscoelastic->eta1_pa_s : 0.0);
  showLaw(yieldLimit_, vp, vp ? t.viscoplastic->yield_limit_pa : 0.0);
  showLaw(viscoplasticEta2_, vp, vp ? t.viscoplastic->eta2_pa_s_pow_n : 0.0);
  showLaw(creepIndex_, vp, vp ? t.viscoplastic->creep_index_n : 0.0);
  showLaw(fibreK1_, fi, fi ? t.fibres->k1_pa : 0.0);
  showLaw(fibreK2_, fi, fi ? t.fibres->k2 : 0.0);
  fixedRegions_->setText(tr("%n ball(s)", "", int(s.organ.fixed_balls.size())));
  fixLigament_->setChecked(s.organ.fix_ligament);
  fixLigament_->setEnabled(s.organ.geometry == OrganGeometry::built_in_liver);
  const OrganSpec& o = s.organ;
  organGeometry_->setCurrentIndex(organGeometry_->findData(int(o.geometry)));
  organFile_->setText(QString::fromStdString(o.file));
  organFile_->setEnabled(o.geometry != OrganGeometry::built_in_liver);
  lengthUnit_->setCurrentIndex(lengthUnit_->findData(o.metres_per_unit));
  lengthUnit_->setEnabled(o.geometry == OrganGeometry::surface_file);
  targetTetCount_->setValue(o.target_tet_count);
  targetTetCount_->setEnabled(o.geometry != OrganGeometry::tet_mesh_file);
  fixedNodeSet_->setText(QString::fromStdString(o.fixed_node_set));
  fixedNodeSet_->setEnabled(o.geometry == OrganGeometry::tet_mesh_file);
  accuracy_->setSettings(s.integrator);
  damageTension_->setValue(s.task.damage_tension_strain);
  damageCompression_->setValue(s.task.damage_compression_strain);
  const bool retract = s.task.kind == TaskKind::retract_lobe;
  graspPoint_->setText(retract ? tr("(%1, %2, %3) mm")
                                     .arg(s.task.grasp_point_mm[0], 0, 'f', 1)
                                     .arg(s.task.grasp_point_mm[1], 0, 'f', 1)
                                     .arg(s.task.grasp_point_mm[2], 0, 'f', 1)
                               : tr("retraction tasks only"));
  lift_->setValue(s.task.lift_mm);
  lift_->setEnabled(retract);
  blockers.clear();
  refreshing_ = false;
  showRubric();  // after the blockers: it may delete the widgets they hold

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

QHBoxLayout* ScenarioEditor::clearableRow(QLabel*& label, const char* labelName,
                                          const QString& buttonText, const char* buttonName,
                                          const QString& editText,
                                          std::function<void(Scenario&)> clear) {
  label = new QLabel;
  label->setObjectName(labelName);
  label->setWordWrap(true);
  auto* button = new QPushButton(buttonText);
  button->setObjectName(buttonName);
  connect(button, &QPushButton::clicked, this,
          [this, editText, clear] { document_.edit(editText, clear); });
  auto* row = new QHBoxLayout;
  row->addWidget(label, 1);
  row->addWidget(button);
  return row;
}

void ScenarioEditor::bindSpinBox(QDoubleSpinBox* box, const QString& text, int mergeKey,
                                 std::function<void(Scenario&, double)> set) {
  connect(box, &QDoubleSpinBox::valueChanged, this, [this, text, mergeKey, set](double value) {
    if (!refreshing_)
      document_.edit(
          text, [&](Scenario& s) { set(s, value); }, mergeKey);
  });
}

QDoubleSpinBox* ScenarioEditor::optionalLesionValue(QFormLayout* form, std::string_view range,
                                                    const QString& suffix, const char* name,
                                                    const QString& label, const QString& editText,
                                                    int mergeKey,
                                                    std::optional<double> LesionSpec::*field) {
  // Below the range's minimum it reads "the parenchyma's": the lesion has no value of its own.
  QDoubleSpinBox* box = rangeSpinBox(range, 1.0, suffix, 0);
  box->setObjectName(name);
  box->setMinimum(box->minimum() - 1.0);
  box->setSpecialValueText(tr("the parenchyma's"));
  form->addRow(label, box);
  connect(box, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
    const bool own = v > box->minimum();
    editLesion(editText, mergeKey,
               [&](LesionSpec& l) { l.*field = own ? std::optional<double>(v) : std::nullopt; });
  });
  return box;
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

void ScenarioEditor::editLesion(const QString& text, int mergeKey,
                                const std::function<void(LesionSpec&)>& change) {
  if (refreshing_ || selectedLesion_ < 0) return;
  const int index = selectedLesion_;
  document_.edit(
      text, [&](Scenario& s) { change(s.lesions.at(index)); }, mergeKey);
}

// ---- Mouse ------------------------------------------------------------------------------------

Eigen::Vector3d ScenarioEditor::viewDirection() const {
  double d[3];
  scene_->renderer()->GetActiveCamera()->GetDirectionOfProjection(d);
  return Eigen::Vector3d(d[0], d[1], d[2]).normalized();
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
  const double radius_mm = brushRadius_->value();
  // Balls half a radius apart make a continuous stroke.
  if (lastPaint_m_ && (hit->point_m - *lastPaint_m_).norm() < 0.5 * radius_mm * kMetresPerMm)
    return;
  lastPaint_m_ = hit->point_m;
  document_.edit(
      tr("Paint a fixed region"),
      [&](Scenario& s) {
        s.organ.fixed_balls.push_back(FixedBall{to_millimetres(hit->point_m), radius_mm});
      },
      kPaint);
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
          [&](Scenario& s) { s.lesions.at(index).centre_mm = to_millimetres(moved); }, kMoveLesion);
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
          kResizeLesion);
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
  cost_->setText(stepsPerSecond_
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
    cost_->setText(text);
  } else {
    cost_->setText(tr("Not measured: %1").arg(problem));
  }
  if (costAgain_) {
    costAgain_ = false;
    measureCost();
    return;
  }
  emit costMeasured();
}

QString ScenarioEditor::costText() const {
  return cost_->text();
}

}  // namespace liversim
