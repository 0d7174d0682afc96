#include "accuracy_panel.h"

#include "liversim/engine/integrator.h"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>

namespace liversim {
QString AccuracyPanel::integratorName(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::central_difference:
      return tr("Central difference");
    case IntegratorKind::rk4:
      return tr("Runge–Kutta 4");
    case IntegratorKind::dopri5:
      return tr("Dormand–Prince 5(4)");
    case IntegratorKind::backward_euler:
      return tr("Backward Euler");
    case IntegratorKind::bdf2:
      return tr("BDF2");
  }
  const std::string_view name = integrator_name(kind);
  return QString::fromUtf8(name.data(), static_cast<qsizetype>(name.size()));
}

AccuracyPanel::AccuracyPanel(QWidget* parent) : QWidget(parent) {
  integrator_ = new QComboBox(this);
  integrator_->setObjectName("integratorChoice");
  for (IntegratorKind kind : kAllIntegrators) {
    const QString kindText = is_explicit(kind) ? tr("explicit") : tr("implicit");
    integrator_->addItem(
        tr("%1 (%2, order %3)").arg(integratorName(kind), kindText).arg(integrator_order(kind)),
        static_cast<int>(kind));
  }

  stepMs_ = new QDoubleSpinBox(this);
  stepMs_->setObjectName("integratorStepMs");
  stepMs_->setDecimals(4);
  stepMs_->setRange(0.0, 1000.0);
  stepMs_->setSingleStep(0.01);
  stepMs_->setSuffix(tr(" ms"));
  stepLabel_ = new QLabel(tr("Step:"), this);
  stepLabel_->setBuddy(stepMs_);

  toleranceUm_ = new QDoubleSpinBox(this);
  toleranceUm_->setObjectName("integratorToleranceUm");
  toleranceUm_->setDecimals(4);
  toleranceUm_->setRange(0.0, 1e6);
  toleranceUm_->setSingleStep(0.1);
  toleranceUm_->setSuffix(tr(" µm"));
  toleranceLabel_ = new QLabel(tr("Error tolerance:"), this);
  toleranceLabel_->setBuddy(toleranceUm_);
  toleranceUm_->setToolTip(tr("Local error allowed per step (node positions)."));

  apply_ = new QPushButton(tr("Apply"), this);
  apply_->setObjectName("applyAccuracy");
  apply_->setToolTip(
      tr("Rebuilds the model with this integrator and carries the liver's current motion over."));

  study_ = new QPushButton(tr("Compare Integrators…"), this);
  study_->setObjectName("openAccuracyStudy");
  study_->setToolTip(
      tr("Measure what each integrator and step costs in time and how far it is from a reference "
         "(the accuracy study)"));

  inUseLabel_ = new QLabel(this);
  inUseLabel_->setObjectName("accuracyInUse");
  inUseLabel_->setWordWrap(true);
  error_ = new QLabel(this);
  error_->setObjectName("accuracyError");
  error_->setWordWrap(true);
  error_->setStyleSheet("color: #b00020;");
  error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_->hide();

  auto* form = new QFormLayout;
  form->addRow(tr("Integrator:"), integrator_);
  form->addRow(stepLabel_, stepMs_);
  form->addRow(toleranceLabel_, toleranceUm_);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form);
  layout->addWidget(apply_);
  layout->addWidget(study_);
  layout->addWidget(inUseLabel_);
  layout->addWidget(error_);
  layout->addStretch(1);

  connect(integrator_, &QComboBox::currentIndexChanged, this,
          &AccuracyPanel::updateFieldsForIntegrator);
  connect(apply_, &QPushButton::clicked, this,
          [this] { emit applyRequested(requestedSettings()); });
  connect(study_, &QPushButton::clicked, this, &AccuracyPanel::studyRequested);
  setSettings(inUse_);
}

void AccuracyPanel::setSettings(const IntegratorSettings& settings) {
  inUse_ = settings;
  integrator_->setCurrentIndex(integrator_->findData(static_cast<int>(settings.kind)));
  stepMs_->setValue(settings.step_s / kSecondsPerMs);
  toleranceUm_->setValue(settings.tolerance_m / kMetresPerUm);
  updateFieldsForIntegrator();
  inUseLabel_->setText(tr("In use: %1").arg(describe(settings)));
  error_->clear();
  error_->hide();
}

IntegratorSettings AccuracyPanel::requestedSettings() const {
  IntegratorSettings settings = inUse_;
  settings.kind = static_cast<IntegratorKind>(integrator_->currentData().toInt());
  settings.step_s = stepMs_->value() * kSecondsPerMs;
  settings.tolerance_m = toleranceUm_->value() * kMetresPerUm;
  return settings;
}

void AccuracyPanel::setBusy(bool busy) {
  apply_->setEnabled(!busy);
  apply_->setText(busy ? tr("Rebuilding the model…") : tr("Apply"));
  if (busy) {
    error_->clear();
    error_->hide();
  }
}

void AccuracyPanel::showError(const QString& message) {
  error_->setText(tr("Not applied: %1").arg(message));
  error_->show();
}

QString AccuracyPanel::errorText() const {
  return error_->isHidden() ? QString() : error_->text();
}

void AccuracyPanel::updateFieldsForIntegrator() {
  const auto kind = static_cast<IntegratorKind>(integrator_->currentData().toInt());
  // A step of 0 asks an explicit scheme for its largest stable step; implicit schemes need one.
  stepMs_->setSpecialValueText(is_explicit(kind) ? tr("largest stable") : QString());
  stepLabel_->setText(kind == IntegratorKind::dopri5 ? tr("First step:") : tr("Step:"));
  const bool adaptive = kind == IntegratorKind::dopri5;
  toleranceLabel_->setVisible(adaptive);
  toleranceUm_->setVisible(adaptive);
}

QString AccuracyPanel::describe(const IntegratorSettings& settings) const {
  const QString step = settings.step_s > 0.0
                           ? tr("step %1 ms").arg(settings.step_s / kSecondsPerMs, 0, 'g', 4)
                           : tr("largest stable step");
  if (settings.kind == IntegratorKind::dopri5)
    return tr("%1, first %2, tolerance %3 µm")
        .arg(integratorName(settings.kind), step)
        .arg(settings.tolerance_m / kMetresPerUm, 0, 'g', 3);
  return tr("%1, %2").arg(integratorName(settings.kind), step);
}

}  // namespace liversim
