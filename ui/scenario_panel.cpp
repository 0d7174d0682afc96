#include "scenario_panel.h"

#include "liversim/interaction/tools.h"

#include <QFileInfo>
#include <QLabel>
#include <QStringList>
#include <QVBoxLayout>

namespace liversim {
namespace {

QLabel* addLabel(QVBoxLayout* layout, QWidget* parent, const char* name) {
  auto* label = new QLabel(parent);
  label->setObjectName(name);
  label->setWordWrap(true);
  label->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(label);
  return label;
}

QString toolText(ToolKind kind) {
  switch (kind) {
    case ToolKind::probe:
      return ScenarioPanel::tr("probe");
    case ToolKind::forceps:
      return ScenarioPanel::tr("forceps");
    case ToolKind::scalpel:
      return ScenarioPanel::tr("scalpel");
  }
  return {};
}

}  // namespace

QString describeTask(const TaskSpec& task) {
  QString text;
  switch (task.kind) {
    case TaskKind::palpate_lesion:
      text = ScenarioPanel::tr("Palpate the liver and locate the lesion.");
      break;
    case TaskKind::retract_lobe:
      text = ScenarioPanel::tr("Grasp the lobe and lift it by %1 mm.").arg(task.lift_mm, 0, 'f', 0);
      break;
    case TaskKind::resect_lesion:
      text = ScenarioPanel::tr("Resect the lesion with a margin of at least %1 mm.")
                 .arg(task.margin_mm, 0, 'f', 0);
      break;
  }
  if (!task.instructions.empty()) text = QString::fromStdString(task.instructions);
  const int minutes = static_cast<int>(task.time_limit_s) / 60;
  const int seconds = static_cast<int>(task.time_limit_s) % 60;
  return ScenarioPanel::tr("%1\nTime limit: %2:%3.")
      .arg(text)
      .arg(minutes)
      .arg(seconds, 2, 10, QLatin1Char('0'));
}

ScenarioPanel::ScenarioPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  title_ = addLabel(layout, this, "scenarioTitle");
  QFont bold = title_->font();
  bold.setBold(true);
  title_->setFont(bold);
  description_ = addLabel(layout, this, "scenarioDescription");
  task_ = addLabel(layout, this, "scenarioTask");
  setup_ = addLabel(layout, this, "scenarioSetup");
  file_ = addLabel(layout, this, "scenarioFile");
  problem_ = addLabel(layout, this, "scenarioProblem");
  problem_->setStyleSheet("color: #b00020;");
  problem_->hide();
  result_ = addLabel(layout, this, "sessionResult");
  result_->setStyleSheet("font-weight: bold;");
  result_->hide();
  layout->addStretch(1);
  showScenario(nullptr, {});
}

void ScenarioPanel::showScenario(const Scenario* scenario, const QString& file) {
  problem_->clear();
  problem_->hide();
  if (!scenario) {
    title_->setText(tr("Free practice"));
    description_->setText(tr("The built-in liver, no task. File ▸ Open Scenario… loads one."));
    task_->clear();
    setup_->clear();
    file_->clear();
    return;
  }
  title_->setText(QString::fromStdString(scenario->title));
  description_->setText(QString::fromStdString(scenario->description));
  task_->setText(describeTask(scenario->task));
  QStringList tools;
  for (const ToolKind kind : scenario->tools) tools << toolText(kind);
  QStringList effects;
  if (scenario->effects.near_incompressibility) effects << tr("near-incompressibility");
  if (scenario->effects.viscoelastic) effects << tr("viscoelasticity");
  if (scenario->effects.viscoplastic) effects << tr("viscoplasticity");
  if (scenario->effects.fibres) effects << tr("fibres");
  if (scenario->effects.gravity) effects << tr("gravity");
  if (effects.isEmpty()) effects << tr("elasticity only");
  int hidden = 0;
  for (const LesionSpec& lesion : scenario->lesions) hidden += lesion.hidden ? 1 : 0;
  QString lesions = tr("%n lesion(s)", nullptr, static_cast<int>(scenario->lesions.size()));
  if (hidden > 0) lesions += tr(", %n hidden", nullptr, hidden);
  setup_->setText(
      tr("Tools: %1.\nSimulated: %2.\n%3.")
          .arg(tools.join(QStringLiteral(", ")), effects.join(QStringLiteral(", ")), lesions));
  file_->setText(tr("File: %1").arg(QFileInfo(file).fileName()));
  file_->setToolTip(file);
}

void ScenarioPanel::showProblem(const QString& text) {
  problem_->setText(text);
  problem_->setVisible(!text.isEmpty());
}

QString ScenarioPanel::taskText() const {
  return task_->text();
}

// The trainee's summary of a session just ended: its score against the rubric and what it did
// not pass, or (free practice) its peak force.
void ScenarioPanel::showSessionResult(const RubricResult& rubric,
                                      const std::vector<MetricValue>& metrics) {
  if (!rubric.score_percent) {
    for (const MetricValue& m : metrics)
      if (m.name == "peak_force_n")
        return showResult(tr("Last session: peak force %1 N (free practice: no rubric).")
                              .arg(m.value, 0, 'f', 2));
    return showResult(tr("Last session stored (no rubric)."));
  }
  QStringList missed;
  for (const CriterionResult& r : rubric.criteria)
    if (!r.passed)
      missed << QString("%1 %2 %3 (%4)")
                    .arg(QString::fromStdString(r.criterion.metric),
                         r.criterion.rule == PassRule::at_most ? "≤" : "≥",
                         QString::number(r.criterion.threshold),
                         r.value ? tr("was %1").arg(r.value.value(), 0, 'g', 3) : tr("not done"));
  QString text = tr("Last session: score %1 %").arg(*rubric.score_percent, 0, 'f', 0);
  text += missed.isEmpty() ? tr(", every criterion passed.")
                           : tr(". Not passed: %1.").arg(missed.join("; "));
  showResult(text);
}

void ScenarioPanel::showResult(const QString& text) {
  result_->setText(text);
  result_->setVisible(!text.isEmpty());
}

QString ScenarioPanel::resultText() const {
  return result_->text();
}

QString ScenarioPanel::problemText() const {
  return problem_->text();
}

}  // namespace liversim
