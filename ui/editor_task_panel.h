#pragma once
// The scenario editor's Task panel: the scenario's title and description, and its task: what the
// trainee is to do (palpate, retract or resect), the instructions shown, the time limit, the
// lesion, the resection margin and planned plane, the tools allowed and the safe force.

#include "editor_panel.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPlainTextEdit;

namespace liversim {

class EditorTaskPanel : public EditorPanel {
  Q_OBJECT

 public:
  explicit EditorTaskPanel(ScenarioDocument& scenarioDocument, QWidget* parent = nullptr);

  void refresh();  // the fields from the document

 private:
  QLineEdit* title_ = nullptr;
  QPlainTextEdit* description_ = nullptr;
  QComboBox* taskKind_ = nullptr;
  QLineEdit* instructions_ = nullptr;
  QDoubleSpinBox* timeLimit_ = nullptr;
  QComboBox* taskLesion_ = nullptr;
  QDoubleSpinBox* margin_ = nullptr;
  QLabel* plane_ = nullptr;
  QCheckBox* tools_[3] = {};
  QDoubleSpinBox* safeForce_ = nullptr;
};

}  // namespace liversim
