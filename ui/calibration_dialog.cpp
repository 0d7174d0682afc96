#include "calibration_dialog.h"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QTimer>

#include <algorithm>

namespace liversim {

CalibrationDialog::CalibrationDialog(const HapticPreferences& preferences, Context context,
                                     QWidget* parent)
    : QDialog(parent), context_(std::move(context)), rotation_(preferences.mapping.rotation) {
  setWindowTitle(tr("Calibrate %1").arg(context_.device_name));
  setObjectName("calibrationDialog");
  auto* form = new QFormLayout(this);
  if (!context_.calibration.isEmpty()) {
    auto* calibration = new QLabel(context_.calibration, this);
    calibration->setObjectName("calibrationCheck");
    calibration->setWordWrap(true);
    form->addRow(tr("Device calibration:"), calibration);
  }
  position_ = new QLabel(this);
  position_->setObjectName("calibrationDevicePosition");
  form->addRow(tr("Stylus at:"), position_);

  scale_ = new QDoubleSpinBox(this);
  scale_->setObjectName("calibrationScale");
  scale_->setRange(0.1, 10.0);
  scale_->setDecimals(2);
  scale_->setSingleStep(0.1);
  scale_->setSuffix(tr(" ×"));
  scale_->setToolTip(
      tr("Scene distance per device distance: above 1 the tool moves farther "
         "than the hand, and forces are felt weaker by the same factor"));
  scale_->setValue(preferences.mapping.scale);
  form->addRow(tr("Motion scale:"), scale_);

  auto* offsets = new QHBoxLayout;
  const char* names[3] = {"calibrationOffsetX", "calibrationOffsetY", "calibrationOffsetZ"};
  for (int axis = 0; axis < 3; ++axis) {
    offset_mm_[axis] = new QDoubleSpinBox(this);
    offset_mm_[axis]->setObjectName(names[axis]);
    offset_mm_[axis]->setRange(-10'000.0, 10'000.0);
    offset_mm_[axis]->setDecimals(1);
    offset_mm_[axis]->setSuffix(tr(" mm"));
    offset_mm_[axis]->setValue(preferences.mapping.offset_m[axis] * 1e3);
    offsets->addWidget(offset_mm_[axis]);
  }
  form->addRow(tr("Scene point of the device's origin (x, y, z):"), offsets);

  axes_ = new QLabel(this);
  axes_->setObjectName("calibrationRotation");
  form->addRow(tr("Device axes in the scene:"), axes_);

  auto* buttons = new QHBoxLayout;
  auto* align = new QPushButton(tr("&Align with the view"), this);
  align->setObjectName("calibrationAlign");
  align->setToolTip(tr("Turn the device's axes to the screen's: right, up and toward you"));
  connect(align, &QPushButton::clicked, this, &CalibrationDialog::alignWithView);
  buttons->addWidget(align);
  auto* centre = new QPushButton(tr("&Centre here"), this);
  centre->setObjectName("calibrationCentre");
  centre->setToolTip(
      tr("Hold the stylus in the middle of its workspace and press: the tool "
         "will be just in front of the liver there"));
  connect(centre, &QPushButton::clicked, this, &CalibrationDialog::centreHere);
  buttons->addWidget(centre);
  form->addRow(buttons);

  action_ = new QComboBox(this);
  action_->setObjectName("calibrationAction");
  action_->addItem(tr("First button"), 1u);
  action_->addItem(tr("Second button"), 2u);
  action_->addItem(tr("Either button"), 3u);
  action_->setCurrentIndex(std::max(0, action_->findData(preferences.action_buttons)));
  action_->setToolTip(tr("Held, this button closes the forceps or lets the scalpel cut"));
  form->addRow(tr("Grasp / cut button:"), action_);

  message_ = new QLabel(this);
  message_->setObjectName("calibrationMessage");
  message_->setWordWrap(true);
  form->addRow(message_);

  auto* box = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  connect(box, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(box, &QDialogButtonBox::rejected, this, &QDialog::reject);
  form->addRow(box);

  showRotation();
  showDevicePosition();
  auto* timer = new QTimer(this);
  connect(timer, &QTimer::timeout, this, &CalibrationDialog::showDevicePosition);
  timer->start(50);
}

WorkspaceMapping CalibrationDialog::mapping() const {
  WorkspaceMapping mapping;
  mapping.scale = scale_->value();
  mapping.rotation = rotation_;
  for (int axis = 0; axis < 3; ++axis) mapping.offset_m[axis] = offset_mm_[axis]->value() * 1e-3;
  return mapping;
}

std::uint32_t CalibrationDialog::actionButtons() const {
  return action_->currentData().toUInt();
}

void CalibrationDialog::alignWithView() {
  rotation_ = context_.view_rotation.normalized();
  showRotation();
}

bool CalibrationDialog::centreHere() {
  const auto stylus_mm = context_.device_position_mm ? context_.device_position_mm() : std::nullopt;
  if (!stylus_mm) {
    message_->setText(tr("The device has reported no position yet: is it connected?"));
    return false;
  }
  WorkspaceMapping centred = mapping();
  centred.offset_m = Eigen::Vector3d::Zero();
  const Eigen::Vector3d offset_m = context_.home_m - centred.scene_position_m(*stylus_mm);
  for (int axis = 0; axis < 3; ++axis) offset_mm_[axis]->setValue(offset_m[axis] * 1e3);
  message_->setText(tr("Centred: the stylus is now just in front of the liver."));
  return true;
}

void CalibrationDialog::showDevicePosition() {
  const auto stylus_mm = context_.device_position_mm ? context_.device_position_mm() : std::nullopt;
  position_->setText(stylus_mm ? tr("%1, %2, %3 mm")
                                     .arg(stylus_mm->x(), 0, 'f', 1)
                                     .arg(stylus_mm->y(), 0, 'f', 1)
                                     .arg(stylus_mm->z(), 0, 'f', 1)
                               : tr("no position yet"));
}

void CalibrationDialog::showRotation() {
  // Where the device's x, y and z axes point in the scene, rounded: enough to check by eye.
  auto axis = [&](const Eigen::Vector3d& unit) {
    const Eigen::Vector3d a = rotation_ * unit;
    return tr("(%1, %2, %3)").arg(a.x(), 0, 'f', 2).arg(a.y(), 0, 'f', 2).arg(a.z(), 0, 'f', 2);
  };
  axes_->setText(tr("x → %1, y → %2, z → %3")
                     .arg(axis(Eigen::Vector3d::UnitX()), axis(Eigen::Vector3d::UnitY()),
                          axis(Eigen::Vector3d::UnitZ())));
}

}  // namespace liversim
