#pragma once
// The workstation's main window: the liver viewport in the middle, live statistics in the status
// bar. The simulation runs on its own thread; the viewport renders from its newest snapshot.

#include "liversim/core/default_scene.h"
#include "liversim/core/grab.h"
#include "liversim/core/realtime_simulation.h"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QTimer>

#include <memory>
#include <optional>

class QLabel;

namespace liversim {

class LiverScene;
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

  // Spring stiffness of a mouse grab and the radius of tissue it holds.
  static constexpr double kGrabStiffnessNPerM = 300.0;
  static constexpr double kGrabRadiusM = 0.02;

 private:
  bool beginGrab(QPoint vtkDisplayPos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers);
  void moveGrab(QPoint vtkDisplayPos);
  void endGrab();
  void showNewestSnapshot();
  void updateStatus();

  SceneSetup setup_;
  std::unique_ptr<RealtimeSimulation> simulation_;
  std::unique_ptr<LiverScene> scene_;
  VtkViewport* viewport_ = nullptr;
  QLabel* statusLabel_ = nullptr;
  QTimer frameTimer_;
  QTimer statusTimer_;

  std::optional<Grab> grab_;
  Eigen::Vector3d handle_m_ = Eigen::Vector3d::Zero();
  std::vector<NodeSpring> springs_;

  int framesInWindow_ = 0;
  QElapsedTimer frameWindow_;
  double framesPerSecond_ = 0.0;
};

}  // namespace liversim
