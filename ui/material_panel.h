#pragma once
// The tissue of the scene running, live-editable: the parenchyma's parameters, each with its unit
// and documented range (parameter_ranges.h), and gravity. A value entered is applied to the running
// liver at once, which goes on from where it is; whoever applies it reports back. The laws of
// effects the scene leaves off are not shown: they are not simulated. In trainee mode the values
// are shown but cannot be changed; gravity can, in free practice.

#include "liversim/scenario/scenario.h"

#include <QWidget>

class QCheckBox;
class QDoubleSpinBox;
class QFormLayout;
class QLabel;

namespace liversim {

class MaterialPanel : public QWidget {
  Q_OBJECT

 public:
  explicit MaterialPanel(QWidget* parent = nullptr);

  // The tissue in use and the effects simulated: shown in the fields; clears any error.
  void showTissue(const TissueSpec& tissue, const EffectsSpec& effects);
  TissueSpec tissueInUse() const { return inUse_; }
  // What the fields ask for (E2 follows as E − E1).
  TissueSpec requestedTissue() const;

  void setEditable(bool editable);
  bool editable() const { return editable_; }
  // Whether gravity may be switched (free practice, or an instructor).
  void setGravityEditable(bool editable);
  bool gravityOn() const;
  // While a change is being applied: says so (entries made meanwhile are applied after it).
  void setBusy(bool busy);
  void setSwitchingGravity();
  // Why the requested tissue could not be applied (the tissue in use stays).
  void showError(const QString& message);
  QString errorText() const;

 signals:
  void tissueRequested(const liversim::TissueSpec& tissue);
  void gravityRequested(bool on);

 private:
  void request();
  void updateNotes();

  TissueSpec inUse_;
  EffectsSpec effects_;
  bool editable_ = true;
  bool refreshing_ = false;
  double shownModulusKpa_ = 0.0;  // E as last shown, to scale E1 and E2 with a new E
  QFormLayout* form_ = nullptr;
  QDoubleSpinBox* youngsModulusKpa_ = nullptr;
  QDoubleSpinBox* poissonRatio_ = nullptr;
  QDoubleSpinBox* density_ = nullptr;
  QDoubleSpinBox* fractureToughness_ = nullptr;  // J/m²
  QDoubleSpinBox* bladeFriction_ = nullptr;      // N/m
  QDoubleSpinBox* e1_ = nullptr;
  QDoubleSpinBox* eta1_ = nullptr;
  QDoubleSpinBox* yieldLimit_ = nullptr;
  QDoubleSpinBox* eta2_ = nullptr;
  QDoubleSpinBox* creepIndex_ = nullptr;
  QDoubleSpinBox* fibreK1_ = nullptr;
  QDoubleSpinBox* fibreK2_ = nullptr;
  QCheckBox* gravity_ = nullptr;
  QLabel* derived_ = nullptr;  // E2 and the relaxation time that follow
  QLabel* status_ = nullptr;
  QLabel* error_ = nullptr;
  QLabel* readOnlyNote_ = nullptr;
};

}  // namespace liversim
