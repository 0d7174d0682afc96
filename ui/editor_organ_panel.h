#pragma once
// The scenario editor's Organ and accuracy panel: the organ (the built-in liver, a surface model
// or a tetrahedral mesh), its file, length unit, element count and fixed node set, whether it
// could be built, and the time integrator that advances it (the workstation's Accuracy panel).

#include "editor_panel.h"

class QComboBox;
class QLabel;
class QLineEdit;
class QSpinBox;

namespace liversim {

class AccuracyPanel;

class EditorOrganPanel : public EditorPanel {
  Q_OBJECT

 public:
  explicit EditorOrganPanel(ScenarioDocument& scenarioDocument, QWidget* parent = nullptr);

  void refresh();  // the fields from the document
  // The organ built, or why it cannot be.
  void showStatus(const QString& text);

 private:
  QComboBox* organGeometry_ = nullptr;
  QLineEdit* organFile_ = nullptr;
  QComboBox* lengthUnit_ = nullptr;
  QSpinBox* targetTetCount_ = nullptr;
  QLineEdit* fixedNodeSet_ = nullptr;
  QLabel* organStatus_ = nullptr;
  AccuracyPanel* accuracy_ = nullptr;
};

}  // namespace liversim
