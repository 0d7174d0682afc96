#pragma once
// The haptic device the workstation uses and how it is mapped, kept in the user's settings
// (QSettings, group "haptics") so that a trainee's calibration survives a restart.

#include "liversim/haptics/haptics.h"
#include "liversim/station/workstation.h"

#include <QString>

#include <cstdint>

class QSettings;

namespace liversim {

// A replay is never restored at start, nor a script (played on request only).
struct HapticPreferences {
  DeviceChoice device = DeviceChoice::mouse;
  QString trajectory_file;  // the scripted device's
  // Set once calibrated (or saved); until then the mapping is made from the view on first use.
  bool mapping_set = false;
  WorkspaceMapping mapping;
  std::uint32_t action_buttons = 1;  // device buttons that grasp or cut (bit mask)
  // The Touch Setup name of the Omni the left hand opens: "Left Device" for a second Omni beside
  // the right hand's, "Default Device" for a single Omni in the left hand beside the mouse.
  QString left_omni_configuration = QStringLiteral("Left Device");
};

// The longest left-hand Omni name kept (Touch Setup's names are short; a longer stored value is a
// damaged file).
inline constexpr int kMaxOmniConfigurationLength = 64;
// A name OpenHaptics could know a device by: not empty, at most kMaxOmniConfigurationLength
// printable characters, no leading or trailing spaces.
bool valid_omni_configuration(const QString& name);

// What is stored; a value that is missing, unreadable or out of range gives the default, so a
// damaged settings file never stops the workstation.
HapticPreferences load_haptic_preferences(QSettings& settings);
void save_haptic_preferences(QSettings& settings, const HapticPreferences& preferences);

}  // namespace liversim
