#pragma once
// What the scenario editor's panels share: the document they show and edit, the filling of their
// fields from it (which is not an edit), the undo merge keys of every field of the editor, and the
// rows its fields are made of.

#include "scenario_document.h"

#include <QWidget>

#include <functional>

class QDoubleSpinBox;
class QHBoxLayout;
class QLabel;

namespace liversim {

class EditorPanel : public QWidget {
  Q_OBJECT

 public:
  // Undo merge keys: consecutive edits of one field (typing, a spin box's arrows, a drag) are one
  // step. One list for the editor and all its panels, so that no two fields share a key.
  enum MergeKey : int {
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
    kGravityStrength,
    kFractureToughness,
    kLesionFractureToughness,
    kBladeFriction,
    kLesionBladeFriction,
  };

 protected:
  explicit EditorPanel(ScenarioDocument& document, QWidget* parent = nullptr);

  ScenarioDocument& document() const { return document_; }

  // Sets the fields from the document by `show`, their signals blocked: what it sets is no edit.
  void fillFields(const std::function<void()>& show);
  bool refreshing() const { return refreshing_; }  // in fillFields

  // A label of what is set, and a button that clears it (an edit named `editText`).
  QHBoxLayout* clearableRow(QLabel*& label, const char* labelName, const QString& buttonText,
                            const char* buttonName, const QString& editText,
                            std::function<void(Scenario&)> clear);
  // A spin box's entered value as an edit (`set` puts it in the scenario).
  void bindSpinBox(QDoubleSpinBox* box, const QString& text, int mergeKey,
                   std::function<void(Scenario&, double)> set);

 private:
  ScenarioDocument& document_;
  bool refreshing_ = false;  // the fields being filled from the document: not edits
};

// A length in millimetres, from min_mm to max_mm.
QDoubleSpinBox* lengthSpinBox(double min_mm, double max_mm, const QString& tip);

// The scene's axes, as the fields of a point or a direction name them.
inline constexpr const char* kAxisNames[3] = {"x", "y", "z"};

}  // namespace liversim
