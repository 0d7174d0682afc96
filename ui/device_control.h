#pragma once
// The device that moves the tool, as the user chooses and sets it up: the Device panel's choice
// put to the station, the preferences remembered between starts (haptic_preferences.h), the
// calibration dialog, the replay of a recorded session, and what is said when a device stops.

#include "haptic_preferences.h"
#include "mouse_tool_control.h"

#include "liversim/sessions/session_store.h"
#include "liversim/station/workstation.h"

#include <QObject>
#include <QPointer>
#include <QString>

#include <functional>
#include <optional>
#include <vector>

namespace liversim {

class CalibrationDialog;
class DevicePanel;

class ToolPanel;

class DeviceControl : public QObject {
  Q_OBJECT

 public:
  struct Context {
    QWidget* window = nullptr;  // the dialogs' parent
    DevicePanel* panel = nullptr;
    ToolPanel* tools = nullptr;
    std::function<Eigen::Quaterniond()> viewAxes;     // device axes → scene, for the current view
    std::function<void(const QString&)> showMessage;  // in the status bar
    // The sessions the user may replay, and why there are none to choose from.
    std::function<std::vector<SessionSummary>()> replayableSessions;
    std::function<QString()> sessionsProblem;
  };
  DeviceControl(Workstation& station, MouseToolControl& mouse, Context context);

  // The device of the last start: the Omni if it is there again (a script is played on request
  // only), otherwise the mouse.
  void useLastDevice();
  // False, saying why in the panel, when the device cannot be used; the device in use stays.
  bool useDevice(DeviceChoice choice, const QString& trajectoryFile = {});
  // Plays a recorded session's device input; false, saying why, when it cannot be read or is not
  // the user's to replay.
  bool replaySession(std::int64_t session);
  // Asks which of the user's recorded sessions to replay, then replays it.
  void chooseSessionToReplay();
  CalibrationDialog* openCalibration();
  // The station's report of a device that stopped (the mouse has taken over).
  void deviceStopped(DeviceChoice choice, const std::string& device, const std::string& fault);
  // What the device holds now: the mouse's tool while pressed; another device's, the Tool
  // panel's, its shaft along the view.
  std::optional<DeviceToolSettings> deviceTool() const;
  const HapticPreferences& preferences() const { return haptics_; }

  // The left hand's device (issue 43): a scripted trajectory played beside the device in use, or
  // none. The servo is made again with it, which restarts the device in use (and its session).
  // False, saying why in the panel, when it cannot be played; the left hand then stays as it was.
  bool useLeftDevice(const QString& trajectoryFile);
  // The same with the Omni Touch Setup knows by the name the panel sets (HapticPreferences::
  // left_omni_configuration: "Left Device" for a second Omni, "Default Device" for a single one
  // beside the mouse).
  bool useLeftOmni();
  void clearLeftDevice();
  // What the left hand's device holds: the panel's tool, its shaft along the view.
  std::optional<DeviceToolSettings> leftDeviceTool() const;
  // The tools a scenario allows the left hand too; a tool no longer offered is put down.
  void setLeftHandTools(const std::vector<ToolKind>& tools);

 private:
  void showDeviceInUse();
  void showLeftDeviceInUse();
  void save();
  void leftToolChanged();  // tells the station
  // A device's hold of `kind`: its shaft along the view, the calibrated action buttons.
  DeviceToolSettings heldAlongTheView(ToolKind kind) const;

  Workstation& station_;
  MouseToolControl& mouse_;
  Context context_;
  HapticPreferences haptics_;
  QPointer<CalibrationDialog> calibration_;
};

}  // namespace liversim
