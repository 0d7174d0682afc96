#pragma once
// The scenario's accuracy setting: which time integrator advances the liver and with what step
// (or, for the adaptive dopri5, what error tolerance). Shows the setting in use, lets the user edit
// it and asks for it to be applied; whoever applies it reports back whether that worked.

#include "liversim/engine/model.h"

#include <QWidget>

class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;

namespace liversim {

class AccuracyPanel : public QWidget {
  Q_OBJECT

 public:
  explicit AccuracyPanel(QWidget* parent = nullptr);

  // The setting in use: shown in the fields and in the "in use" line; clears any error.
  void setSettings(const IntegratorSettings& settings);
  // What the fields ask for (settings not shown here are kept from the setting in use).
  IntegratorSettings requestedSettings() const;
  IntegratorSettings settingsInUse() const { return inUse_; }

  // While a change is being applied: Apply is disabled and says so.
  void setBusy(bool busy);

  // Shows why the requested setting could not be applied (the setting in use stays).
  void showError(const QString& message);
  QString errorText() const;

  // The integrator's name as the interface shows it ("Central difference", "Runge–Kutta 4"...),
  // translated; integrator_name() is the one of files and the command line.
  static QString integratorName(IntegratorKind kind);

  // Unit conversions of the fields: the step in milliseconds, the tolerance in micrometres.
  static constexpr double kSecondsPerMs = 1e-3;
  static constexpr double kMetresPerUm = 1e-6;

 signals:
  void applyRequested(const liversim::IntegratorSettings& settings);
  // "Compare Integrators…": the accuracy study, which measures each setting's error and cost.
  void studyRequested();

 private:
  void updateFieldsForIntegrator();
  QString describe(const IntegratorSettings& settings) const;

  IntegratorSettings inUse_;
  QComboBox* integrator_ = nullptr;
  QLabel* stepLabel_ = nullptr;
  QDoubleSpinBox* stepMs_ = nullptr;
  QLabel* toleranceLabel_ = nullptr;
  QDoubleSpinBox* toleranceUm_ = nullptr;
  QPushButton* apply_ = nullptr;
  QPushButton* study_ = nullptr;
  QLabel* inUseLabel_ = nullptr;
  QLabel* error_ = nullptr;
};

}  // namespace liversim
