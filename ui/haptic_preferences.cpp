#include "haptic_preferences.h"

#include <QSettings>
#include <QVariant>

#include <cmath>
#include <optional>

namespace liversim {
namespace {

// A finite number stored under `key`, or nothing.
std::optional<double> number(QSettings& settings, const QString& key) {
  bool ok = false;
  const double value = settings.value(key).toDouble(&ok);
  return ok && std::isfinite(value) ? std::optional<double>(value) : std::nullopt;
}

}  // namespace

bool valid_omni_configuration(const QString& name) {
  if (name.isEmpty() || name.size() > kMaxOmniConfigurationLength || name != name.trimmed())
    return false;
  for (const QChar c : name)
    if (!c.isPrint()) return false;
  return true;
}

HapticPreferences load_haptic_preferences(QSettings& settings) {
  HapticPreferences preferences;
  settings.beginGroup("haptics");
  const QString device = settings.value("device").toString();
  if (device == "openhaptics") preferences.device = DeviceChoice::openhaptics;
  if (device == "scripted") preferences.device = DeviceChoice::scripted;
  preferences.trajectory_file = settings.value("trajectoryFile").toString();
  bool ok = false;
  const uint buttons = settings.value("actionButtons").toUInt(&ok);
  if (ok && buttons >= 1 && buttons <= 3) preferences.action_buttons = buttons;
  if (const QString name = settings.value("leftOmniConfiguration").toString().trimmed();
      valid_omni_configuration(name))
    preferences.left_omni_configuration = name;

  WorkspaceMapping mapping;
  const auto scale = number(settings, "mapping/scale");
  const auto qw = number(settings, "mapping/rotationW"), qx = number(settings, "mapping/rotationX"),
             qy = number(settings, "mapping/rotationY"), qz = number(settings, "mapping/rotationZ");
  const auto x = number(settings, "mapping/offsetXMm"), y = number(settings, "mapping/offsetYMm"),
             z = number(settings, "mapping/offsetZMm");
  settings.endGroup();
  if (!(scale && qw && qx && qy && qz && x && y && z)) return preferences;
  mapping.scale = *scale;
  const Eigen::Quaterniond rotation(*qw, *qx, *qy, *qz);
  if (!(rotation.norm() > 0.5)) return preferences;
  mapping.rotation = rotation.normalized();
  mapping.offset_m = Eigen::Vector3d(*x, *y, *z) * 1e-3;
  if (validate(mapping)) return preferences;
  preferences.mapping = mapping;
  preferences.mapping_set = true;
  return preferences;
}

void save_haptic_preferences(QSettings& settings, const HapticPreferences& preferences) {
  settings.beginGroup("haptics");
  const char* device = preferences.device == DeviceChoice::openhaptics ? "openhaptics"
                       : preferences.device == DeviceChoice::scripted  ? "scripted"
                       : preferences.device == DeviceChoice::replay    ? "replay"
                                                                       : "mouse";
  settings.setValue("device", device);
  settings.setValue("trajectoryFile", preferences.trajectory_file);
  settings.setValue("actionButtons", preferences.action_buttons);
  settings.setValue("leftOmniConfiguration", preferences.left_omni_configuration);
  if (preferences.mapping_set) {
    const WorkspaceMapping& m = preferences.mapping;
    settings.setValue("mapping/scale", m.scale);
    settings.setValue("mapping/rotationW", m.rotation.w());
    settings.setValue("mapping/rotationX", m.rotation.x());
    settings.setValue("mapping/rotationY", m.rotation.y());
    settings.setValue("mapping/rotationZ", m.rotation.z());
    settings.setValue("mapping/offsetXMm", m.offset_m.x() * 1e3);
    settings.setValue("mapping/offsetYMm", m.offset_m.y() * 1e3);
    settings.setValue("mapping/offsetZMm", m.offset_m.z() * 1e3);
  } else {
    settings.remove("mapping");
  }
  settings.endGroup();
}

}  // namespace liversim
