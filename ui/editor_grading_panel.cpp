#include "editor_grading_panel.h"

#include "parameter_spin_box.h"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QTableWidget>
#include <QVBoxLayout>

#include <algorithm>

namespace liversim {

EditorGradingPanel::EditorGradingPanel(ScenarioDocument& scenarioDocument, QWidget* parent)
    : EditorPanel(scenarioDocument, parent) {
  auto* layout = new QVBoxLayout(this);
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
    document().edit(tr("Add a criterion"), [](Scenario& s) {
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
    if (row < 0 || row >= int(document().scenario().rubric.size())) return;
    document().edit(tr("Remove a criterion"),
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
  connect(pick, &QPushButton::clicked, this, &EditorGradingPanel::graspPointPickRequested);
  auto* graspRow = new QHBoxLayout;
  graspRow->addWidget(graspPoint_, 1);
  graspRow->addWidget(pick);
  form->addRow(tr("Grasp point"), graspRow);
  lift_ = spinBox("liftMm", 5.0, 100.0, 0, " mm", tr("Retraction: how far to lift: 5 to 100 mm"));
  form->addRow(tr("Lift"), lift_);
  bindSpinBox(lift_, tr("Change the lift"), kLift,
              [](Scenario& s, double v) { s.task.lift_mm = v; });
  layout->addLayout(form);
}

void EditorGradingPanel::refresh() {
  const Scenario& s = document().scenario();
  fillFields([&] {
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
  });
  showRubric();  // after the fields' blockers: it may delete the widgets they hold
}

void EditorGradingPanel::showRubric() {
  const std::vector<RubricCriterion>& rubric = document().scenario().rubric;
  if (shownRubric_ && *shownRubric_ == rubric) return;  // the table made this edit itself
  shownRubric_ = rubric;
  rubricTable_->setRowCount(int(rubric.size()));
  // An edit in a row: the table shows it already, so it is not rebuilt under the editing widget.
  const auto editRow = [this](int row, const QString& text, int mergeKey,
                              std::function<void(RubricCriterion&)> change) {
    if (refreshing()) return;
    std::vector<RubricCriterion> next = document().scenario().rubric;
    change(next.at(row));
    shownRubric_ = next;
    document().edit(
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
    connect(weight, &QDoubleSpinBox::valueChanged, this, [=](double v) {
      editRow(row, tr("Change a criterion's weight"), kRubricWeight + row,
              [&](RubricCriterion& r) { r.weight = v; });
    });
    connect(rule, &QComboBox::currentIndexChanged, this, [=](int index) {
      const auto pass = PassRule(rule->itemData(index).toInt());
      editRow(row, tr("Change a criterion's rule"), kNoMerge,
              [&](RubricCriterion& r) { r.rule = pass; });
    });
    connect(threshold, &QDoubleSpinBox::valueChanged, this, [=](double v) {
      editRow(row, tr("Change a criterion's threshold"), kRubricThreshold + row,
              [&](RubricCriterion& r) { r.threshold = v; });
    });
  }
}

}  // namespace liversim
