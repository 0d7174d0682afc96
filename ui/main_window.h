#pragma once
// The workstation's main window: the liver viewport in the middle, the accuracy setting (time
// integrator and step) beside it, live statistics in the status bar. The simulation runs on its own
// thread; the viewport renders from its newest snapshot.

#include "liversim/core/default_scene.h"
#include "liversim/core/grab.h"
#include "liversim/core/realtime_simulation.h"

#include <QElapsedTimer>
#include <QMainWindow>
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
  void showTool();
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

  // Builds the model of an integrator change; reads setup_.mesh, which never changes.
  std::thread modelBuilder_;
  bool changingIntegrator_ = false;
};

}  // namespace liversim
