#pragma once
// The scenario editor's Grading panel: the rubric (each criterion a metric, its weight, whether it
// passes at most or at least its threshold, and the threshold), the strains past which tissue is
// damaged, and a retraction's grasp point (picked on the organ in the editor's view) and lift.

#include "editor_panel.h"

#include <optional>
#include <vector>

class QDoubleSpinBox;
class QLabel;
class QTableWidget;

namespace liversim {

class EditorGradingPanel : public EditorPanel {
  Q_OBJECT

 public:
  explicit EditorGradingPanel(ScenarioDocument& scenarioDocument, QWidget* parent = nullptr);

  void refresh();  // the fields from the document

 signals:
  // "Pick on the organ": the next click on the organ is to set the grasp point.
  void graspPointPickRequested();

 private:
  void showRubric();  // rebuilt only when the rubric differs from what the table shows

  QTableWidget* rubricTable_ = nullptr;
  std::optional<std::vector<RubricCriterion>> shownRubric_;
  QDoubleSpinBox* damageTension_ = nullptr;
  QDoubleSpinBox* damageCompression_ = nullptr;
  QLabel* graspPoint_ = nullptr;
  QDoubleSpinBox* lift_ = nullptr;
};

}  // namespace liversim
