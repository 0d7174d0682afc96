#pragma once
// What the GUI tests do to a VtkViewport as a user would: VTK display coordinates (device
// pixels, origin bottom-left, y up) ↔ the widget's, the same mapping as VtkViewport's, and mouse
// and wheel events sent to it.

#include "vtk_viewport.h"

#include <vtkGenericOpenGLRenderWindow.h>
#include <Eigen/Core>
#include <QCoreApplication>
#include <QMouseEvent>
#include <QPoint>
#include <QWheelEvent>

#include <cmath>

namespace liversim {

inline int viewport_device_height(const VtkViewport& viewport) {
  return static_cast<int>(std::lround(viewport.height() * viewport.devicePixelRatioF()));
}

inline QPoint widget_point(const VtkViewport& viewport, const Eigen::Vector2d& display) {
  const double dpr = viewport.devicePixelRatioF();
  return {
      static_cast<int>(std::lround(display.x() / dpr)),
      static_cast<int>(std::lround((viewport_device_height(viewport) - 1 - display.y()) / dpr))};
}

inline QPoint display_point(const VtkViewport& viewport, QPoint widget) {
  const double dpr = viewport.devicePixelRatioF();
  return {static_cast<int>(std::lround(widget.x() * dpr)),
          viewport_device_height(viewport) - 1 - static_cast<int>(std::lround(widget.y() * dpr))};
}

inline void send_mouse(VtkViewport& viewport, QEvent::Type type, QPoint pos, Qt::MouseButton button,
                       Qt::MouseButtons buttons, Qt::KeyboardModifiers modifiers = Qt::NoModifier) {
  QMouseEvent event(type, QPointF(pos), QPointF(viewport.mapToGlobal(pos)), button, buttons,
                    modifiers);
  QCoreApplication::sendEvent(&viewport, &event);
}

// `notches` turns of the wheel at `pos` (positive: away from the user) with `buttons` held.
inline void send_wheel(VtkViewport& viewport, QPoint pos, int notches, Qt::MouseButtons buttons) {
  QWheelEvent event(QPointF(pos), QPointF(viewport.mapToGlobal(pos)), QPoint(),
                    QPoint(0, 120 * notches), buttons, Qt::NoModifier, Qt::NoScrollPhase, false);
  QCoreApplication::sendEvent(&viewport, &event);
}

}  // namespace liversim
