#pragma once
// The workstation's main window: the liver viewport in the middle, the accuracy setting (time
// integrator and step) beside it, live statistics in the status bar. The simulation runs on its own
// thread; the viewport renders from its newest snapshot.

#include "haptic_preferences.h"

#include "liversim/core/default_scene.h"
#include "liversim/core/grab.h"
#include "liversim/core/haptic_device.h"
#include "liversim/core/realtime_simulation.h"
#include "liversim/core/servo_loop.h"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QPointer>
#include <QTimer>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <thread>

class QLabel;

namespace liversim {

class AccuracyPanel;
class CalibrationDialog;
class DevicePanel;
class LiverScene;
class ToolPanel;
class VtkViewport;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(SceneSetup setup, QWidget* parent = nullptr);
  ~MainWindow() override;

  VtkViewport* viewport() const { return viewport_; }
  LiverScene& scene() { return *scene_; }
  RealtimeSimulation& simulation() { return *simulation_; }
  const Grab* activeGrab() const { return grab_ ? &*grab_ : nullptr; }
  AccuracyPanel* accuracyPanel() const { return accuracyPanel_; }
  ToolPanel* toolPanel() const { return toolPanel_; }
  // The tool the mouse holds in the scene, if any (tools other than the hand).
  const std::optional<Tool>& heldTool() const { return tool_; }

  // Rebuilds the model with these integrator settings on a worker thread (the simulation runs on
  // meanwhile; a large mesh takes seconds), then restarts the simulation from the liver's current
  // positions and velocities. When the settings are invalid the panel shows why and the running
  // simulation stays. integratorChangeFinished tells which. Returns false, and does nothing, while
  // an earlier change is still being built.
  bool applyIntegratorSettings(const IntegratorSettings& settings);
  bool changingIntegrator() const { return changingIntegrator_; }

  // Haptic devices (Device panel). The mouse moves the tool directly; any other device drives it
  // through the 1 kHz servo, holding the tool chosen in the Tool panel (the hand: none). The
  // Phantom Omni is looked for at start, in the OpenHaptics runtime libHD.so (or the library
  // named by LIVERSIM_OPENHAPTICS_LIBRARY). Returns false, saying why in the panel, when the
  // device cannot be used; the device in use then stays.
  bool useDevice(DeviceChoice device, const QString& trajectoryFile = {});
  DeviceChoice device() const { return haptics_.device; }
  DevicePanel* devicePanel() const { return devicePanel_; }
  ServoLoop* servo() const { return servo_.get(); }
  const HapticPreferences& hapticPreferences() const { return haptics_; }
  // Opens the calibration dialog for the device in use (not modal); accepting it saves and uses
  // the new mapping.
  CalibrationDialog* openCalibration();

  // Spring stiffness of a mouse grab and the radius of tissue it holds.
  static constexpr double kGrabStiffnessNPerM = 300.0;
  static constexpr double kGrabRadiusM = 0.02;

 signals:
  void integratorChangeFinished(bool applied);

 private:
  // A panel docked on the right, movable and floatable.
  void addPanelDock(const QString& title, const char* name, QWidget* panel);
  bool beginGrab(QPoint vtkDisplayPos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers);
  void moveGrab(QPoint vtkDisplayPos);
  void endGrab();
  bool beginTool(ToolKind kind, QPoint vtkDisplayPos);
  void moveTool(QPoint vtkDisplayPos);
  void endTool();
  void showTool(const std::optional<Tool>& tool);
  // The shaft's direction for a tool put on the liver: toward the viewer, tilted up by 35°.
  Eigen::Quaterniond toolOrientationFromView() const;
  // Device axes (x right, y up, z toward the user) → scene, for the current view.
  Eigen::Quaterniond deviceAxesFromView() const;
  // Just in front of the liver, seen from the camera: where a centred stylus puts the tool.
  Eigen::Vector3d deviceHome_m() const;
  std::optional<DeviceToolSettings> deviceToolSettings() const;
  void attachDevice();  // the servo and the device's tool to the (stopped) simulation
  void detachDevice();  // stops the servo; the simulation must be stopped
  void checkDevice();   // servo statistics and faults, with the status
  void saveHapticPreferences();
  void openOmni();  // looks for the Phantom Omni: omni_, or why not in omniProblem_
  void finishIntegratorChange(const IntegratorSettings& settings,
                              std::shared_ptr<const SimModel> model, const QString& error);
  void showNewestSnapshot();
  void updateStatus();
  QString accuracyStatus(const RealtimeStats& stats) const;
  static QString healthProblemText(HealthProblem problem);
  static QString formatError(double error_m);

  SceneSetup setup_;
  std::unique_ptr<RealtimeSimulation> simulation_;
  std::unique_ptr<LiverScene> scene_;
  VtkViewport* viewport_ = nullptr;
  AccuracyPanel* accuracyPanel_ = nullptr;
  ToolPanel* toolPanel_ = nullptr;
  DevicePanel* devicePanel_ = nullptr;
  QPointer<CalibrationDialog> calibration_;
  QLabel* statusLabel_ = nullptr;
  QTimer frameTimer_;
  QTimer statusTimer_;

  std::optional<Grab> grab_;
  Eigen::Vector3d handle_m_ = Eigen::Vector3d::Zero();
  std::vector<NodeSpring> springs_;

  std::optional<Tool> tool_;
  Eigen::Vector3d toolPoint_m_ = Eigen::Vector3d::Zero();  // where the mouse holds the tool

  std::uint64_t shownTopology_ = 0;  // the cut the scene shows (SimulationSnapshot)
  // The smooth visual vertex of each node of the organ's surface, by the node's rest position
  // (a cut's copy of a node sits where it did).
  std::map<std::array<double, 3>, Eigen::Vector3d> smoothVertexAt_;

  int framesInWindow_ = 0;
  QElapsedTimer frameWindow_;
  double framesPerSecond_ = 0.0;

  HapticPreferences haptics_;
  std::unique_ptr<HapticDevice> omni_;  // opened at start when its runtime and device are there
  QString omniProblem_;                 // why not, otherwise
  std::unique_ptr<HapticDevice> scripted_;
  std::unique_ptr<ServoLoop> servo_;  // runs while a device other than the mouse is in use

  // Builds the model of an integrator change; reads setup_.mesh, which never changes.
  std::thread modelBuilder_;
  bool changingIntegrator_ = false;
};

}  // namespace liversim
