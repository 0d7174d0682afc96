#include "device_control.h"

#include "calibration_dialog.h"
#include "device_panel.h"
#include "session_reading.h"
#include "storage_messages.h"
#include "tool_panel.h"

#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/openhaptics_device.h"

#include <QDateTime>
#include <QFileDialog>
#include <QInputDialog>
#include <QSettings>

#include <algorithm>

namespace liversim {
namespace {

QString qstring(const std::string& text) {
  return QString::fromStdString(text);
}

}  // namespace

DeviceControl::DeviceControl(Workstation& station, MouseToolControl& mouse, Context context)
    : QObject(context.window), station_(station), mouse_(mouse), context_(std::move(context)) {
  QSettings settings;
  haptics_ = load_haptic_preferences(settings);
  const QByteArray library = qgetenv("LIVERSIM_OPENHAPTICS_LIBRARY");
  context_.panel->setOpenHapticsProblem(
      qstring(station_.open_omni(library.isEmpty() ? "libHD.so" : library.toStdString())));
  connect(context_.panel, &DevicePanel::deviceChosen, this, [this](DeviceChoice device) {
    if (device == DeviceChoice::replay) return chooseSessionToReplay();
    if (device != DeviceChoice::scripted) return void(useDevice(device));
    const QString file = QFileDialog::getOpenFileName(
        context_.window, tr("Trajectory to play"), haptics_.trajectory_file,
        tr("Trajectories (*.txt *.trajectory);;All files (*)"));
    if (file.isEmpty())
      context_.panel->showDevice(station_.device());  // cancelled: the device in use stays
    else
      useDevice(device, file);
  });
  connect(context_.panel, &DevicePanel::calibrateRequested, this, [this] { openCalibration(); });
  connect(context_.panel, &DevicePanel::leftDeviceChosen, this,
          [this](DevicePanel::LeftDevice chosen) {
            if (chosen == DevicePanel::LeftDevice::none) return clearLeftDevice();
            if (chosen == DevicePanel::LeftDevice::omni) {
              useLeftOmni();
              return;
            }
            const QString file = QFileDialog::getOpenFileName(
                context_.window, tr("Trajectory for the left hand"), haptics_.trajectory_file,
                tr("Trajectories (*.txt *.trajectory);;All files (*)"));
            if (file.isEmpty())  // cancelled: the left hand stays as it was
              showLeftDeviceInUse();
            else
              useLeftDevice(file);
          });
  connect(context_.panel, &DevicePanel::leftToolChanged, this, [this] { leftToolChanged(); });
  context_.panel->setLeftOmniName(haptics_.left_omni_configuration);
  connect(context_.panel, &DevicePanel::leftOmniNameChanged, this, [this](const QString& name) {
    if (name == haptics_.left_omni_configuration) return;
    if (!valid_omni_configuration(name)) {
      context_.panel->setLeftOmniName(haptics_.left_omni_configuration);
      context_.panel->showStatus(
          tr("The left hand's Omni keeps the name “%1”: a Touch Setup name is 1 to %2 printable "
             "characters")
              .arg(haptics_.left_omni_configuration)
              .arg(kMaxOmniConfigurationLength),
          true);
      return;
    }
    haptics_.left_omni_configuration = name;
    context_.panel->setLeftOmniName(name);
    save();
  });
}

DeviceToolSettings DeviceControl::heldAlongTheView(ToolKind kind) const {
  DeviceToolSettings settings;
  settings.kind = kind;
  settings.orientation = tool_orientation_from_view(context_.viewAxes());
  settings.action_buttons = haptics_.action_buttons;
  return settings;
}

std::optional<DeviceToolSettings> DeviceControl::leftDeviceTool() const {
  const std::optional<ToolKind> kind = context_.panel->leftTool();
  if (!kind) return std::nullopt;
  return heldAlongTheView(*kind);
}

void DeviceControl::leftToolChanged() {
  if (ServoLoop* servo = station_.servo()) {
    station_.device_tool_changed(Hand::left, servo->now_s());
    station_.record_tool_choice(Hand::left);
  }
}

void DeviceControl::setLeftHandTools(const std::vector<ToolKind>& tools) {
  const std::optional<ToolKind> held = context_.panel->leftTool();
  context_.panel->setLeftHandTools(tools);
  if (context_.panel->leftTool() != held) leftToolChanged();
}

bool DeviceControl::useLeftDevice(const QString& trajectoryFile) {
  auto refuse = [&](const QString& why) {
    context_.panel->showStatus(why, true);
    showLeftDeviceInUse();
    return false;
  };
  std::vector<TrajectoryPoint> script;
  try {
    script = load_trajectory(trajectoryFile.toStdString());  // its errors name the file and line
  } catch (const std::exception& e) {
    return refuse(
        tr("Cannot play the trajectory in the left hand: %1").arg(QString::fromUtf8(e.what())));
  }
  if (!haptics_.mapping_set) {
    haptics_.mapping =
        first_use_mapping(station_.simulation().snapshot().position_m, context_.viewAxes());
    haptics_.mapping_set = true;
    save();
  }
  if (const std::optional<DeviceRefusal> refusal = station_.use_left_device(
          std::move(script), trajectoryFile.toStdString(), haptics_.mapping))
    return refuse(
        tr("Cannot play the trajectory in the left hand: %1").arg(qstring(refusal->detail)));
  // Taken with the next device change: the device in use again, with the left hand's beside it.
  if (!useDevice(station_.device())) {
    station_.clear_left_device();
    return refuse(context_.panel->statusText());
  }
  showLeftDeviceInUse();
  return true;
}

bool DeviceControl::useLeftOmni() {
  auto refuse = [&](const QString& why) {
    context_.panel->showStatus(why, true);
    showLeftDeviceInUse();
    return false;
  };
  if (station_.left_device_is_omni()) return true;  // in the left hand already
  if (!haptics_.mapping_set) {
    haptics_.mapping =
        first_use_mapping(station_.simulation().snapshot().position_m, context_.viewAxes());
    haptics_.mapping_set = true;
    save();
  }
  if (const std::optional<DeviceRefusal> refusal =
          station_.use_left_omni(haptics_.left_omni_configuration.toStdString(), haptics_.mapping))
    return refuse(tr("The Omni cannot be the left hand's: %1").arg(qstring(refusal->detail)));
  if (!useDevice(station_.device())) {
    station_.clear_left_device();
    return refuse(context_.panel->statusText());
  }
  showLeftDeviceInUse();
  return true;
}

void DeviceControl::showLeftDeviceInUse() {
  context_.panel->showLeftDevice(QString::fromStdString(station_.left_device_name()),
                                 station_.left_device_is_omni());
}

void DeviceControl::clearLeftDevice() {
  if (station_.left_device_name().empty()) return context_.panel->showLeftDevice({});
  station_.clear_left_device();
  useDevice(station_.device());
  showLeftDeviceInUse();
}

void DeviceControl::useLastDevice() {
  const DeviceChoice last = haptics_.device;
  haptics_.device = DeviceChoice::mouse;
  useDevice(DeviceChoice::mouse);
  if (last == DeviceChoice::openhaptics && !useDevice(DeviceChoice::openhaptics)) {
    HapticPreferences remembered = haptics_;  // tried again at the next start
    remembered.device = last;
    QSettings settings;
    save_haptic_preferences(settings, remembered);
  }
}

void DeviceControl::save() {
  QSettings settings;
  save_haptic_preferences(settings, haptics_);
}

std::optional<DeviceToolSettings> DeviceControl::deviceTool() const {
  if (station_.mouse()) return mouse_.deviceTool();
  const auto kind = context_.tools ? context_.tools->tool() : std::nullopt;
  if (!kind) return std::nullopt;  // the hand: the device holds nothing
  return heldAlongTheView(*kind);
}

bool DeviceControl::useDevice(DeviceChoice choice, const QString& trajectoryFile) {
  auto refuse = [&](const QString& why) {
    context_.panel->showStatus(why, true);
    context_.panel->showDevice(station_.device());
    return false;
  };
  const QString file = trajectoryFile.isEmpty() ? haptics_.trajectory_file : trajectoryFile;
  std::vector<TrajectoryPoint> script;
  if (choice == DeviceChoice::scripted) {
    if (file.isEmpty()) return refuse(tr("Choose a trajectory file to play."));
    try {
      script = load_trajectory(file.toStdString());  // its errors name the file and the line
    } catch (const std::exception& e) {
      return refuse(tr("Cannot play the trajectory: %1").arg(QString::fromUtf8(e.what())));
    }
  }
  if (choice != DeviceChoice::mouse && !haptics_.mapping_set) {
    // First use: the device's axes the screen's, its origin just in front of the liver.
    haptics_.mapping =
        first_use_mapping(station_.simulation().snapshot().position_m, context_.viewAxes());
    haptics_.mapping_set = true;
  }
  // The mouse lets go of its tool; the device's tool appears with its first frame.
  if (mouse_.tool()) mouse_.endTool();
  if (const std::optional<DeviceRefusal> refusal =
          station_.use_device(choice, haptics_.mapping, std::move(script), file.toStdString())) {
    switch (refusal->reason) {
      case DeviceRefusal::Reason::omni_unavailable:
        context_.panel->setOpenHapticsProblem(qstring(refusal->detail));
        return refuse(tr("The Phantom Omni is not available: %1").arg(qstring(refusal->detail)));
      case DeviceRefusal::Reason::no_replay_loaded:
        return refuse(tr("Choose a recorded session to replay."));
      case DeviceRefusal::Reason::no_trajectory:
        return refuse(tr("Cannot play the trajectory: %1").arg(qstring(refusal->detail)));
      case DeviceRefusal::Reason::servo_failed:
        return refuse(tr("Cannot run the device: %1").arg(qstring(refusal->detail)));
    }
  }
  haptics_.device = choice;
  if (choice == DeviceChoice::scripted) haptics_.trajectory_file = file;
  if (choice == DeviceChoice::openhaptics) context_.panel->setOpenHapticsProblem({});  // found
  save();
  showDeviceInUse();
  return true;
}

void DeviceControl::showDeviceInUse() {
  const bool mouse = station_.device() == DeviceChoice::mouse;
  DevicePanel& panel = *context_.panel;
  panel.showDevice(station_.device());
  panel.setCalibrationAvailable(!mouse);
  panel.showServoStats(nullptr);
  const std::string left = station_.left_device_name();
  panel.showLeftDevice(QString::fromStdString(left), station_.left_device_is_omni());
  const QString leftHand =
      left.empty() ? QString()
                   : tr(" In the left hand, %1 moves the tool chosen below.").arg(qstring(left));
  panel.showStatus((mouse ? tr("The mouse moves the tool: press on the liver to put the tool "
                               "chosen in the Tool panel there.")
                          : tr("%1 moves the tool chosen in the Tool panel.")
                                .arg(qstring(station_.device_name()))) +
                   leftHand);
}

void DeviceControl::deviceStopped(DeviceChoice choice, const std::string& device,
                                  const std::string& fault) {
  // A vanished or broken device: its force is off already; the mouse has taken over.
  const QString name = choice == DeviceChoice::openhaptics ? qstring(device) : tr("The device");
  const QString why = tr("%1 stopped: %2. The mouse moves the tool now; choose the device again "
                         "once it is back.")
                          .arg(name, qstring(fault));
  haptics_.device = DeviceChoice::mouse;
  save();
  showDeviceInUse();
  // Its fault sticks: choosing it again opens it anew.
  if (choice == DeviceChoice::openhaptics) context_.panel->setOpenHapticsProblem(qstring(fault));
  context_.panel->showStatus(why, true);
  context_.showMessage(why);
}

CalibrationDialog* DeviceControl::openCalibration() {
  if (calibration_) {
    calibration_->raise();
    return calibration_;
  }
  const DeviceChoice device = station_.device();
  HapticDevice* omni = device == DeviceChoice::openhaptics ? station_.omni() : nullptr;
  CalibrationDialog::Context context;
  context.device_name = omni                               ? qstring(omni->name())
                        : device == DeviceChoice::scripted ? tr("the scripted device")
                                                           : tr("the device");
  if (auto* openhaptics = dynamic_cast<OpenHapticsDevice*>(omni))
    context.calibration = openhaptics->calibration_ok()
                              ? tr("calibrated")
                              : tr("not calibrated: put the stylus in its inkwell (or move it "
                                   "through its whole range), then open this dialog again");
  context.view_rotation = context_.viewAxes();
  context.home_m =
      device_home_m(station_.simulation().snapshot().position_m, context.view_rotation);
  context.device_position_mm = [this]() -> std::optional<Eigen::Vector3d> {
    const auto& sample = station_.simulation().snapshot().hand(Hand::right).device_sample;
    return sample ? std::optional<Eigen::Vector3d>(sample->position_mm) : std::nullopt;
  };
  HapticPreferences shown = haptics_;
  if (!shown.mapping_set) shown.mapping.rotation = context.view_rotation;
  calibration_ = new CalibrationDialog(shown, std::move(context), context_.window);
  calibration_->setAttribute(Qt::WA_DeleteOnClose);
  connect(calibration_, &QDialog::accepted, this, [this] {
    haptics_.mapping = calibration_->mapping();
    haptics_.action_buttons = calibration_->actionButtons();
    haptics_.mapping_set = true;
    save();
    if (station_.servo()) useDevice(station_.device());  // the servo takes the new mapping
  });
  calibration_->show();
  return calibration_;
}

bool DeviceControl::replaySession(std::int64_t session) {
  auto refuse = [&](const QString& why) {
    context_.panel->showStatus(why, true);
    context_.panel->showDevice(station_.device());
    return false;
  };
  SessionStore* sessions = station_.sessions();
  if (!sessions) {
    const QString problem = context_.sessionsProblem();
    return refuse(problem.isEmpty() ? tr("There is no sessions database.") : problem);
  }
  try {
    const std::vector<SessionSummary> replayable = context_.replayableSessions();
    if (std::none_of(replayable.begin(), replayable.end(),
                     [&](const SessionSummary& s) { return s.id == session; }))
      return refuse(tr("Session %1 is not yours to replay: trainees replay their own sessions "
                       "(an instructor may replay any).")
                        .arg(session));
    const std::optional<std::vector<ServoFrame>> frames =
        readSessionFrames(*sessions, session, context_.window);
    if (!frames)
      return refuse(tr("Session %1 is not replayed: reading it was cancelled.").arg(session));
    if (frames->empty())
      return refuse(tr("Session %1 has no device input to replay.").arg(session));
    station_.load_replay(session, *frames, haptics_.mapping);
  } catch (const StorageError& e) {
    return refuse(storageProblemText(tr("Cannot replay session %1: %2").arg(session), e));
  }
  return useDevice(DeviceChoice::replay);
}

void DeviceControl::chooseSessionToReplay() {
  std::vector<SessionSummary> sessions;
  QString problem = context_.sessionsProblem();
  try {
    if (station_.sessions()) sessions = context_.replayableSessions();
  } catch (const StorageError& e) {
    problem = storageProblemText(QStringLiteral("%1"), e);
  }
  QStringList items;
  for (auto it = sessions.rbegin(); it != sessions.rend(); ++it)
    if (it->frame_count > 0)
      items << tr("%1: %2, %3, %4 (%5)")
                   .arg(it->id)
                   .arg(qstring(it->trainee), qstring(it->scenario_title),
                        QDateTime::fromMSecsSinceEpoch(it->started_unix_ms)
                            .toString("yyyy-MM-dd hh:mm"),
                        QString::fromUtf8(session_status_name(it->status).data()));
  if (items.isEmpty()) {
    context_.panel->showStatus(
        station_.sessions() ? tr("No recorded session has device input to replay.") : problem,
        true);
    context_.panel->showDevice(station_.device());
    return;
  }
  bool ok = false;
  const QString item = QInputDialog::getItem(context_.window, tr("Replay a session"),
                                             tr("Session:"), items, 0, false, &ok);
  if (!ok) return context_.panel->showDevice(station_.device());  // cancelled
  replaySession(item.section(':', 0, 0).toLongLong());
}

}  // namespace liversim
