#pragma once
// The scenario editor's Lesions panel: the scenario's lesions, and the one selected in the editor
// with its name, centre, semi-axes, stiffness, its own yield limit, viscosity, fracture
// toughness and blade friction (or the parenchyma's) and whether the trainee sees it. Lesions are
// added and removed here; which one is selected is the editor's (the view shows it too).

#include "editor_panel.h"

#include <optional>
#include <string_view>

class QCheckBox;
class QDoubleSpinBox;
class QFormLayout;
class QLineEdit;
class QListWidget;
class QPushButton;

namespace liversim {

class EditorLesionPanel : public EditorPanel {
  Q_OBJECT

 public:
  explicit EditorLesionPanel(ScenarioDocument& scenarioDocument, QWidget* parent = nullptr);

  // The document's lesions, with the fields of lesion `selected` (-1: none).
  void refresh(int selected);

 signals:
  // A lesion chosen in the list, or the one to select after a removal (-1: none).
  void lesionSelected(int index);
  // Add: a new lesion at the organ's centre.
  void addRequested();

 private:
  // A lesion's value that defaults to the parenchyma's (`field`), in the range named `range`.
  QDoubleSpinBox* optionalLesionValue(QFormLayout* form, std::string_view range,
                                      const QString& suffix, const char* name, const QString& label,
                                      const QString& editText, int mergeKey,
                                      std::optional<double> LesionSpec::*field);
  // Edits of the selected lesion (`change` its spec).
  void editLesion(const QString& text, int mergeKey,
                  const std::function<void(LesionSpec&)>& change);

  int selected_ = -1;
  QListWidget* lesionList_ = nullptr;
  QLineEdit* lesionName_ = nullptr;
  QDoubleSpinBox* lesionCentre_[3] = {};
  QDoubleSpinBox* lesionRadius_[3] = {};
  QDoubleSpinBox* lesionStiffness_ = nullptr;          // kPa
  QDoubleSpinBox* lesionYieldLimit_ = nullptr;         // Pa; its minimum: the parenchyma's
  QDoubleSpinBox* lesionViscosity_ = nullptr;          // Pa·s; its minimum: the parenchyma's
  QDoubleSpinBox* lesionFractureToughness_ = nullptr;  // J/m²; its minimum: the parenchyma's
  QDoubleSpinBox* lesionBladeFriction_ = nullptr;      // N/m; its minimum: the parenchyma's
  QCheckBox* lesionHidden_ = nullptr;
  QPushButton* removeLesion_ = nullptr;
  QWidget* lesionFields_ = nullptr;
};

}  // namespace liversim
