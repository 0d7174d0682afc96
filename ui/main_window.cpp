#include "main_window.h"

#include "render/liver_scene.h"
#include "vtk_viewport.h"

#include "liversim/core/surface.h"

#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>
#include <QLabel>
#include <QStatusBar>

namespace liversim {

MainWindow::MainWindow(SceneSetup setup, QWidget* parent)
    : QMainWindow(parent), setup_(std::move(setup)) {
  setWindowTitle(tr("LiverSim — %1").arg(QString::fromStdString(setup_.description)));
  auto model = std::make_shared<const SimModel>(build_model(setup_.mesh, setup_.model_options));
  simulation_ = std::make_unique<RealtimeSimulation>(model, make_rest_state(*model));
  scene_ = std::make_unique<LiverScene>(setup_.mesh, setup_.visual);

  viewport_ = new VtkViewport(this);
  viewport_->setObjectName("liverViewport");
  viewport_->renderWindow()->AddRenderer(scene_->renderer());
  viewport_->setPressFilter(
      [this](QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers) {
        return beginGrab(pos, button, modifiers);
      });
  connect(viewport_, &VtkViewport::mouseMovedTo, this, [this](QPoint pos, Qt::MouseButtons) {
    if (grab_) moveGrab(pos);
  });
  connect(viewport_, &VtkViewport::mouseReleasedAt, this, [this](QPoint, Qt::MouseButton button) {
    if (grab_ && button == Qt::LeftButton) endGrab();
  });
  connect(viewport_, &QOpenGLWidget::frameSwapped, this, [this] { ++framesInWindow_; });
  setCentralWidget(viewport_);

  statusLabel_ = new QLabel(this);
  statusLabel_->setObjectName("simulationStatus");
  statusBar()->addPermanentWidget(statusLabel_, 1);
  statusBar()->showMessage(
      tr("Drag the liver with the left mouse button; drag the background to "
         "turn the view, wheel to zoom."));
  resize(1200, 800);

  frameTimer_.setTimerType(Qt::PreciseTimer);
  connect(&frameTimer_, &QTimer::timeout, this, &MainWindow::showNewestSnapshot);
  frameTimer_.start(16);
  connect(&statusTimer_, &QTimer::timeout, this, &MainWindow::updateStatus);
  statusTimer_.start(500);
  frameWindow_.start();
  simulation_->start();
}

MainWindow::~MainWindow() {
  simulation_->stop();
}

bool MainWindow::beginGrab(QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers) {
  // While the tissue is held, other buttons must not move the camera under the handle.
  if (grab_) return true;
  if (button != Qt::LeftButton || modifiers != Qt::NoModifier) return false;
  const auto hit = scene_->pick(pos.x(), pos.y());
  if (!hit) return false;  // background: the camera takes the drag
  grab_ = grab_surface(scene_->surface(), simulation_->snapshot().position_m,
                       simulation_->model().lumped_mass_kg, hit->point_m, kGrabRadiusM,
                       kGrabStiffnessNPerM);
  handle_m_ = hit->point_m;
  scene_->show_grab_marker(handle_m_);
  grab_springs(*grab_, handle_m_, springs_);
  simulation_->set_springs(springs_);
  return true;
}

void MainWindow::moveGrab(QPoint pos) {
  handle_m_ = scene_->display_to_world(pos.x(), pos.y(), handle_m_);
  scene_->show_grab_marker(handle_m_);
  grab_springs(*grab_, handle_m_, springs_);
  simulation_->set_springs(springs_);
}

void MainWindow::endGrab() {
  grab_.reset();
  simulation_->clear_springs();
  scene_->show_grab_marker(std::nullopt);
}

void MainWindow::showNewestSnapshot() {
  if (simulation_->update_snapshot()) {
    scene_->update_positions(simulation_->snapshot().position_m);
    viewport_->scheduleRender();
  }
}

void MainWindow::updateStatus() {
  const double window_s = frameWindow_.restart() / 1000.0;
  framesPerSecond_ = window_s > 0 ? framesInWindow_ / window_s : 0.0;
  framesInWindow_ = 0;
  const RealtimeStats stats = simulation_->stats();
  QString text = tr("%1 fps | %2 steps/s | real-time factor %3 | step %4 ms")
                     .arg(framesPerSecond_, 0, 'f', 0)
                     .arg(stats.steps_per_second, 0, 'f', 0)
                     .arg(stats.real_time_factor, 0, 'f', 2)
                     .arg(stats.step_s * 1e3, 0, 'f', 3);
  if (stats.behind) text += tr(" | slower than real time");
  if (grab_) {
    const Eigen::Vector3d force =
        grab_reaction_force_n(*grab_, handle_m_, simulation_->snapshot().position_m);
    text += tr(" | pulling %1 N").arg(force.norm(), 0, 'f', 2);
  }
  statusLabel_->setText(text);
}

}  // namespace liversim
