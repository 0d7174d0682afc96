#include "editor_task_panel.h"

#include "parameter_spin_box.h"

#include "liversim/interaction/tools.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>

#include <algorithm>

namespace liversim {

EditorTaskPanel::EditorTaskPanel(ScenarioDocument& scenarioDocument, QWidget* parent)
    : EditorPanel(scenarioDocument, parent) {
  auto* form = new QFormLayout(this);
  title_ = new QLineEdit;
  title_->setObjectName("scenarioTitle");
  form->addRow(tr("Title"), title_);
  connect(title_, &QLineEdit::editingFinished, this, [this] {
    const std::string text = title_->text().toStdString();
    document().edit(
        tr("Change the title"), [&](Scenario& s) { s.title = text; }, kTitle);
  });
  description_ = new QPlainTextEdit;
  description_->setObjectName("scenarioDescription");
  description_->setMaximumHeight(70);
  form->addRow(tr("Description"), description_);
  connect(description_, &QPlainTextEdit::textChanged, this, [this] {
    if (refreshing()) return;
    const std::string text = description_->toPlainText().toStdString();
    document().edit(
        tr("Change the description"), [&](Scenario& s) { s.description = text; }, kDescription);
  });
  taskKind_ = new QComboBox;
  taskKind_->setObjectName("taskKind");
  taskKind_->addItem(tr("Palpate a hidden lesion"), int(TaskKind::palpate_lesion));
  taskKind_->addItem(tr("Retract a lobe"), int(TaskKind::retract_lobe));
  taskKind_->addItem(tr("Resect a lesion"), int(TaskKind::resect_lesion));
  form->addRow(tr("Task"), taskKind_);
  connect(taskKind_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing()) return;
    const auto kind = TaskKind(taskKind_->itemData(index).toInt());
    document().edit(tr("Change the task"), [&](Scenario& s) {
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
    document().edit(
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
    if (!refreshing())
      document().edit(tr("Choose the task's lesion"),
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
      if (refreshing()) return;
      document().edit(on ? tr("Allow a tool") : tr("Withdraw a tool"), [&](Scenario& s) {
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
}

void EditorTaskPanel::refresh() {
  const Scenario& s = document().scenario();
  fillFields([&] {
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
    for (std::size_t i = 0; i < kToolKinds.size(); ++i)
      tools_[i]->setChecked(std::find(s.tools.begin(), s.tools.end(), kToolKinds[i]) !=
                            s.tools.end());
    safeForce_->setValue(s.task.safe_force_n);
  });
}

}  // namespace liversim
