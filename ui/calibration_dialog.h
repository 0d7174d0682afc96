#pragma once
// Calibrating the haptic device: its workspace onto the scene (scale, rotation, offset) and the
// button that grasps or cuts. "Align with the view" turns the device's axes to the screen's (the
// stylus moved right moves the tool right on screen); "Centre here" puts the scene point the
// workstation chose (just in front of the liver) where the stylus is now.

#include "haptic_preferences.h"

#include <QDialog>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <functional>
#include <optional>

class QComboBox;
class QDoubleSpinBox;
class QLabel;

namespace liversim {

class CalibrationDialog : public QDialog {
  Q_OBJECT

 public:
  struct Context {
    QString device_name;
    QString calibration;  // the device's own calibration check, when it has one
    Eigen::Quaterniond view_rotation = Eigen::Quaterniond::Identity();  // device axes → scene
    Eigen::Vector3d home_m = Eigen::Vector3d::Zero();  // where "Centre here" maps the stylus
    std::function<std::optional<Eigen::Vector3d>()> device_position_mm;  // newest, if any
  };

  CalibrationDialog(const HapticPreferences& preferences, Context context,
                    QWidget* parent = nullptr);

  WorkspaceMapping mapping() const;
  std::uint32_t actionButtons() const;

  void alignWithView();
  // False (and says why) when the device has reported no position yet.
  bool centreHere();

 private:
  void showDevicePosition();
  void showRotation();

  Context context_;
  Eigen::Quaterniond rotation_;
  QDoubleSpinBox* scale_ = nullptr;
  QDoubleSpinBox* offset_mm_[3] = {};
  QLabel* axes_ = nullptr;
  QLabel* position_ = nullptr;
  QLabel* message_ = nullptr;
  QComboBox* action_ = nullptr;
};

}  // namespace liversim
