#pragma once
// The haptic device: which one moves the tool (the mouse, a Phantom Omni through OpenHaptics, or
// a scripted trajectory), why a device is not offered or has stopped, the workspace calibration,
// and the 1 kHz servo's statistics.

#include "haptic_preferences.h"

#include "liversim/haptics/haptics.h"

#include <QWidget>

class QComboBox;
class QLabel;
class QPushButton;

namespace liversim {

class DevicePanel : public QWidget {
  Q_OBJECT

 public:
  explicit DevicePanel(QWidget* parent = nullptr);

  // Shows `device` as the one in use (without emitting deviceChosen).
  void showDevice(DeviceChoice device);
  DeviceChoice shownDevice() const;
  // Why the Omni did not open (empty: it did); its entry then says it was not found, and why.
  void setOpenHapticsProblem(const QString& problem);
  bool openHapticsOffered() const;
  QString openHapticsToolTip() const;
  void setCalibrationAvailable(bool available);
  // What the device is doing, or what went wrong with it.
  void showStatus(const QString& text, bool problem = false);
  QString statusText() const;
  // The servo's figures (nothing: no servo runs, the mouse moves the tool directly).
  void showServoStats(const ServoStats* stats);
  QString servoText() const;

  static QString servoSummary(const ServoStats& stats);

 signals:
  void deviceChosen(liversim::DeviceChoice device);
  void calibrateRequested();

 private:
  QComboBox* devices_ = nullptr;
  QLabel* status_ = nullptr;
  QPushButton* calibrate_ = nullptr;
  QLabel* servo_ = nullptr;
  QString omniProblem_;
};

}  // namespace liversim
