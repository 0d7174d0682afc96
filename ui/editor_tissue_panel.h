#pragma once
// The scenario editor's Tissue and effects panel: the parenchyma's stiffness, Poisson's ratio and
// fracture toughness and blade friction,
// the effects simulated with what they cost (measured by the editor), gravity's direction and
// strength, the laws of the effects that are on, the fibres' direction, and the fixed regions: the
// brush that paints them on the organ, what is painted, and the built-in liver's ligament.

#include "editor_panel.h"

#include <Eigen/Core>

#include <functional>
#include <optional>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;

namespace liversim {

class EditorTissuePanel : public EditorPanel {
  Q_OBJECT

 public:
  // `screenHorizontal`: the direction from the view's left to its right, as the organ is seen now
  // (none while no organ is shown), for the fibres across the view.
  EditorTissuePanel(ScenarioDocument& scenarioDocument,
                    std::function<std::optional<Eigen::Vector3d>()> screenHorizontal,
                    QWidget* parent = nullptr);

  void refresh();  // the fields from the document

  double brushRadius_mm() const;  // of Paint fixed
  // The effects' cost, as measured.
  void showCost(const QString& text);
  QString costText() const;

 private:
  std::function<std::optional<Eigen::Vector3d>()> screenHorizontal_;
  QDoubleSpinBox* youngsModulus_ = nullptr;
  QDoubleSpinBox* poissonRatio_ = nullptr;
  QDoubleSpinBox* fractureToughness_ = nullptr;  // J/m²
  QDoubleSpinBox* bladeFriction_ = nullptr;      // N/m
  QCheckBox* effects_[4] = {};  // near-incompressibility, viscoelastic, viscoplastic, fibres
  QDoubleSpinBox* viscoelasticE1_ = nullptr;
  QDoubleSpinBox* viscoelasticEta1_ = nullptr;
  QDoubleSpinBox* yieldLimit_ = nullptr;
  QDoubleSpinBox* viscoplasticEta2_ = nullptr;
  QDoubleSpinBox* creepIndex_ = nullptr;
  QDoubleSpinBox* fibreK1_ = nullptr;
  QDoubleSpinBox* fibreK2_ = nullptr;
  QDoubleSpinBox* fibreDirection_[3] = {};
  QPushButton* fibreAlongView_ = nullptr;
  QDoubleSpinBox* brushRadius_ = nullptr;
  QLabel* fixedRegions_ = nullptr;
  QCheckBox* fixLigament_ = nullptr;
  QLabel* cost_ = nullptr;
  QCheckBox* gravity_ = nullptr;
  QComboBox* gravityDirection_ = nullptr;  // the patient's positions, and "as the file sets it"
  QDoubleSpinBox* gravityStrength_ = nullptr;
};

}  // namespace liversim
