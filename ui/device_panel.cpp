#include "device_panel.h"

#include <QComboBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>

namespace liversim {

DevicePanel::DevicePanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  devices_ = new QComboBox(this);
  devices_->setObjectName("deviceChoice");
  devices_->addItem(tr("Mouse and keyboard"), static_cast<int>(DeviceChoice::mouse));
  devices_->addItem(tr("Phantom Omni (OpenHaptics)"), static_cast<int>(DeviceChoice::openhaptics));
  devices_->addItem(tr("Scripted trajectory…"), static_cast<int>(DeviceChoice::scripted));
  devices_->addItem(tr("Replay of a session…"), static_cast<int>(DeviceChoice::replay));
  devices_->setItemData(0, tr("Move the tool with the mouse in the viewport"), Qt::ToolTipRole);
  devices_->setItemData(2,
                        tr("Play a trajectory file (time s, x y z mm, buttons per line) on the "
                           "tool"),
                        Qt::ToolTipRole);
  layout->addWidget(devices_);
  status_ = new QLabel(this);
  status_->setObjectName("deviceStatus");
  status_->setWordWrap(true);
  layout->addWidget(status_);
  calibrate_ = new QPushButton(tr("&Calibrate…"), this);
  calibrate_->setObjectName("deviceCalibrate");
  layout->addWidget(calibrate_);
  servo_ = new QLabel(this);
  servo_->setObjectName("servoStats");
  servo_->setWordWrap(true);
  servo_->setToolTip(
      tr("The haptic servo loop: tick rate, tick periods (median and 99th "
         "percentile), late ticks, and the safety limits it applied"));
  layout->addWidget(servo_);

  auto* left = new QGroupBox(tr("Left hand"), this);
  left->setObjectName("leftHand");
  left->setToolTip(
      tr("A second instrument: a device of its own moves it, beside the one above (forceps "
         "holding the lobe while the other hand cuts)"));
  auto* form = new QFormLayout(left);
  leftDevice_ = new QComboBox(left);
  leftDevice_->setObjectName("leftHandDevice");
  leftDevice_->addItem(tr("None"));
  leftDevice_->addItem(tr("Scripted trajectory…"));
  // An Omni, as Touch Setup names it (OpenHaptics opens devices by their configured name).
  leftDevice_->addItem(QString());
  form->addRow(tr("Device:"), leftDevice_);
  leftOmniName_ = new QLineEdit(left);
  leftOmniName_->setObjectName("leftOmniName");
  leftOmniName_->setMaxLength(kMaxOmniConfigurationLength);
  leftOmniName_->setToolTip(
      tr("The name Touch Setup gives the Omni in the left hand: “Left Device” for a second Omni "
         "beside the right hand's, “Default Device” for a single Omni beside the mouse"));
  form->addRow(tr("Name in Touch Setup:"), leftOmniName_);
  setLeftOmniName(QStringLiteral("Left Device"));
  leftTool_ = new QComboBox(left);
  leftTool_->setObjectName("leftHandTool");
  form->addRow(tr("Holds:"), leftTool_);
  layout->addWidget(left);
  setLeftHandTools({kToolKinds.begin(), kToolKinds.end()});
  setLeftTool(ToolKind::forceps);
  connect(leftDevice_, &QComboBox::activated, this,
          [this](int index) { emit leftDeviceChosen(static_cast<LeftDevice>(index)); });
  connect(leftTool_, &QComboBox::activated, this, [this] { emit leftToolChanged(); });
  connect(leftOmniName_, &QLineEdit::editingFinished, this,
          [this] { emit leftOmniNameChanged(leftOmniName_->text().trimmed()); });
  layout->addStretch(1);
  showServoStats(nullptr);
  setCalibrationAvailable(false);
  connect(devices_, &QComboBox::activated, this, [this](int index) {
    emit deviceChosen(static_cast<DeviceChoice>(devices_->itemData(index).toInt()));
  });
  connect(calibrate_, &QPushButton::clicked, this, &DevicePanel::calibrateRequested);
}

void DevicePanel::showDevice(DeviceChoice device) {
  devices_->setCurrentIndex(devices_->findData(static_cast<int>(device)));
}

DeviceChoice DevicePanel::shownDevice() const {
  return static_cast<DeviceChoice>(devices_->currentData().toInt());
}

void DevicePanel::setOpenHapticsProblem(const QString& problem) {
  // Still offered when missing: choosing it looks again (a device plugged in since).
  const int index = devices_->findData(static_cast<int>(DeviceChoice::openhaptics));
  omniProblem_ = problem;
  devices_->setItemText(index, problem.isEmpty() ? tr("Phantom Omni (OpenHaptics)")
                                                 : tr("Phantom Omni (OpenHaptics): not found"));
  devices_->setItemData(index,
                        problem.isEmpty() ? tr("The Phantom Omni found through OpenHaptics")
                                          : tr("Not available: %1. Choose it again to look "
                                               "again.")
                                                .arg(problem),
                        Qt::ToolTipRole);
}

bool DevicePanel::openHapticsOffered() const {
  return omniProblem_.isEmpty();
}

QString DevicePanel::openHapticsToolTip() const {
  return devices_
      ->itemData(devices_->findData(static_cast<int>(DeviceChoice::openhaptics)), Qt::ToolTipRole)
      .toString();
}

void DevicePanel::setCalibrationAvailable(bool available) {
  calibrate_->setEnabled(available);
  calibrate_->setToolTip(available ? tr("Map the device's workspace onto the scene and choose its "
                                        "buttons")
                                   : tr("Choose a device first: the mouse needs no calibration"));
}

void DevicePanel::showStatus(const QString& text, bool problem) {
  status_->setText(text);
  status_->setStyleSheet(problem ? QStringLiteral("color: #b00020") : QString());
}

QString DevicePanel::statusText() const {
  return status_->text();
}

QString DevicePanel::servoSummary(const ServoStats& stats) {
  if (stats.ticks < 2) return tr("Servo: starting");
  return tr("Servo: %1 Hz · period %2 ms median, %3 ms p99 · %4 late · clamped: stiffness %5, "
            "force %6, rate %7 · watchdog %8 · device faults %9")
      .arg(stats.rate_hz(), 0, 'f', 0)
      .arg(stats.period_percentile_s(0.5) * 1e3, 0, 'f', 2)
      .arg(stats.period_percentile_s(0.99) * 1e3, 0, 'f', 2)
      .arg(stats.missed_deadlines)
      .arg(stats.stiffness_clamps)
      .arg(stats.force_clamps)
      .arg(stats.rate_limited)
      .arg(stats.watchdog_trips)
      .arg(stats.device_faults);
}

void DevicePanel::showServoStats(const ServoStats* stats) {
  servo_->setText(stats ? servoSummary(*stats)
                        : tr("Servo: not running (the mouse moves the tool)"));
}

QString DevicePanel::servoText() const {
  return servo_->text();
}

void DevicePanel::showLeftDevice(const QString& name, bool omni) {
  const LeftDevice shown = name.isEmpty() ? LeftDevice::none
                           : omni         ? LeftDevice::omni
                                          : LeftDevice::scripted;
  leftDevice_->setItemText(1, shown == LeftDevice::scripted ? name : tr("Scripted trajectory…"));
  leftDevice_->setItemText(2, omniEntry(shown == LeftDevice::omni ? name : tr("Phantom Omni")));
  leftDevice_->setCurrentIndex(static_cast<int>(shown));
}

void DevicePanel::setLeftOmniName(const QString& name) {
  leftOmniName_->setText(name);
  if (shownLeftDevice() != LeftDevice::omni)
    leftDevice_->setItemText(2, omniEntry(tr("Phantom Omni")));
}

QString DevicePanel::omniEntry(const QString& device) const {
  return tr("%1 (“%2”)").arg(device, leftOmniName_->text());
}

QString DevicePanel::leftOmniName() const {
  return leftOmniName_->text();
}

bool DevicePanel::leftDeviceShown() const {
  return shownLeftDevice() != LeftDevice::none;
}

DevicePanel::LeftDevice DevicePanel::shownLeftDevice() const {
  return static_cast<LeftDevice>(leftDevice_->currentIndex());
}

std::optional<ToolKind> DevicePanel::leftTool() const {
  const int kind = leftTool_->currentData().toInt();
  if (kind < 0) return std::nullopt;
  return static_cast<ToolKind>(kind);
}

void DevicePanel::setLeftTool(std::optional<ToolKind> tool) {
  const int index = leftTool_->findData(tool ? static_cast<int>(*tool) : -1);
  leftTool_->setCurrentIndex(index >= 0 ? index : 0);
}

void DevicePanel::setLeftHandTools(const std::vector<ToolKind>& tools) {
  const std::optional<ToolKind> held = leftTool_->count() > 0 ? leftTool() : std::nullopt;
  leftTool_->clear();
  leftTool_->addItem(tr("Nothing (the hand)"), -1);
  for (ToolKind kind : tools) {
    const QString name = kind == ToolKind::probe     ? tr("Probe")
                         : kind == ToolKind::forceps ? tr("Forceps")
                                                     : tr("Scalpel");
    leftTool_->addItem(name, static_cast<int>(kind));
  }
  setLeftTool(held);
}

}  // namespace liversim
