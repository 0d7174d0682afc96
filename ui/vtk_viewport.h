#pragma once

#include <vtkNew.h>
#include <QImage>
#include <QMetaObject>
#include <QOpenGLWidget>
#include <QPoint>
#include <functional>
#include <vector>

class vtkGenericOpenGLRenderWindow;
class vtkGenericRenderWindowInteractor;
class vtkObject;
class vtkRenderWindowInteractor;

namespace liversim {

// A QOpenGLWidget that hosts a VTK render window. VTK renders into its own framebuffers inside
// the widget's OpenGL context; paintGL blits the result into the widget's framebuffer.
//
// VTK's own Qt widget (QVTKOpenGLNativeWidget) is built against Qt 5 on Debian and cannot be
// linked into this Qt 6 program, hence this class.
//
// Rendering: change the scene, then call renderWindow()->Render() (renders now, repaints the
// widget) or scheduleRender() (renders at the next repaint, coalescing several requests).
//
// Mouse input is reported through the mouse* signals in VTK display coordinates (device pixels,
// origin bottom-left, y up) and forwarded to the VTK interactor unless interaction is disabled or
// the press filter claims the drag.
class VtkViewport : public QOpenGLWidget {
  Q_OBJECT

 public:
  // Decides, on a mouse press, whether the owner takes the drag. Returning true keeps this press,
  // the moves that follow and the matching release away from VTK.
  using PressFilter =
      std::function<bool(QPoint vtkDisplayPos, Qt::MouseButton, Qt::KeyboardModifiers)>;
  // Decides, for each whole notch the wheel turns (positive: away from the user), whether the
  // owner takes it; the camera zooms by the notches it does not take.
  using WheelFilter = std::function<bool(int notches)>;

  explicit VtkViewport(QWidget* parent = nullptr);
  ~VtkViewport() override;

  // Must be called before the QApplication is constructed: every QOpenGLWidget context in the
  // process is created from it, and VTK needs an OpenGL 3.2 core context.
  static void setDefaultSurfaceFormat();

  vtkGenericOpenGLRenderWindow* renderWindow() const;
  vtkRenderWindowInteractor* interactor() const;

  // When disabled, mouse buttons, moves and the wheel are no longer forwarded to VTK (the signals
  // are still emitted); keys still are. A VTK drag already in progress still gets its release.
  void setInteractionEnabled(bool enabled);
  bool isInteractionEnabled() const { return interactionEnabled_; }

  void setPressFilter(PressFilter filter);
  void setWheelFilter(WheelFilter filter);

  // Renders the current scene and returns the picture the widget shows.
  QImage grabRendering();

 public slots:
  // Renders the scene at the next repaint; several calls before it cost one render.
  void scheduleRender();

 signals:
  void mousePressedAt(QPoint vtkDisplayPos, Qt::MouseButton button,
                      Qt::KeyboardModifiers modifiers);
  void mouseMovedTo(QPoint vtkDisplayPos, Qt::MouseButtons buttons);
  void mouseReleasedAt(QPoint vtkDisplayPos, Qt::MouseButton button);

 protected:
  void initializeGL() override;
  void paintGL() override;

  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;
  void keyReleaseEvent(QKeyEvent* event) override;

 private:
  void updateSize();
  void releaseGraphicsResources();
  void onRenderWindowEvent(vtkObject* caller, unsigned long eventId, void* callData);
  void onFrameRendered();
  QPoint toDevicePixels(QPointF widgetPos) const;
  QPoint toVtkDisplay(QPointF widgetPos) const;
  void forwardMouseEvent(QMouseEvent* event, unsigned long vtkEventId);
  void forwardKeyEvent(QKeyEvent* event, bool pressed);

  vtkNew<vtkGenericOpenGLRenderWindow> renderWindow_;
  vtkNew<vtkGenericRenderWindowInteractor> interactor_;
  std::vector<unsigned long> renderWindowObserverTags_;
  QMetaObject::Connection contextDestroyedConnection_;

  // True when the scene must be rendered at the next paintGL; false when VTK has already
  // rendered the frame (e.g. during camera interaction) and paintGL only has to blit it.
  bool renderPending_ = true;
  bool inPaintGL_ = false;

  bool interactionEnabled_ = true;
  PressFilter pressFilter_;
  WheelFilter wheelFilter_;
  Qt::MouseButtons ownerDragButtons_;
  Qt::MouseButtons vtkDragButtons_;
  int accumulatedWheelDelta_ = 0;
};

}  // namespace liversim
