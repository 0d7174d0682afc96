#pragma once
// The haptic device: which one moves the tool (the mouse, a Phantom Omni through OpenHaptics, or
// a scripted trajectory), why a device is not offered or has stopped, the workspace calibration,
// and the 1 kHz servo's statistics; and the left hand (issue 43): a device of its own (a scripted
// trajectory, as an assistant's hand) and the tool it holds, beside the right hand's.

#include "haptic_preferences.h"

#include "liversim/haptics/haptics.h"

#include <QWidget>

#include <optional>
#include <vector>

class QComboBox;
class QLabel;
class QLineEdit;
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

  // The left hand: whether a device is in it (its name, shown; `omni`: an Omni, else a scripted
  // trajectory), and the tool it holds.
  enum class LeftDevice { none, scripted, omni };
  void showLeftDevice(const QString& name, bool omni = false);
  bool leftDeviceShown() const;
  LeftDevice shownLeftDevice() const;
  std::optional<ToolKind> leftTool() const;
  void setLeftTool(std::optional<ToolKind> tool);
  // The tools a scenario allows (the hand always is); a held tool no longer offered is put down.
  void setLeftHandTools(const std::vector<ToolKind>& tools);
  // The Touch Setup name of the Omni the left hand's entry opens.
  void setLeftOmniName(const QString& name);
  QString leftOmniName() const;

 signals:
  void deviceChosen(liversim::DeviceChoice device);
  void calibrateRequested();
  // The left hand's device asked for.
  void leftDeviceChosen(liversim::DevicePanel::LeftDevice device);
  void leftToolChanged();
  // The left hand's Omni name edited (trimmed; valid_omni_configuration may still refuse it).
  void leftOmniNameChanged(const QString& name);

 private:
  QComboBox* devices_ = nullptr;
  QLabel* status_ = nullptr;
  QPushButton* calibrate_ = nullptr;
  QLabel* servo_ = nullptr;
  QComboBox* leftDevice_ = nullptr;
  QComboBox* leftTool_ = nullptr;
  QLineEdit* leftOmniName_ = nullptr;
  // The left hand's Omni entry: `device` and the Touch Setup name it is opened by.
  QString omniEntry(const QString& device) const;
  QString omniProblem_;
};

}  // namespace liversim
