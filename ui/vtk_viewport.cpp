#include "vtk_viewport.h"

#include <qopengl.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkOpenGLState.h>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QScreen>
#include <QSurfaceFormat>
#include <QWheelEvent>
#include <array>
#include <cmath>

namespace liversim {

namespace {

// One wheel notch in Qt's angle units; VTK zooms one step per notch.
constexpr int kWheelNotch = 120;

unsigned long vtkPressEvent(Qt::MouseButton button) {
  switch (button) {
    case Qt::LeftButton:
      return vtkCommand::LeftButtonPressEvent;
    case Qt::MiddleButton:
      return vtkCommand::MiddleButtonPressEvent;
    case Qt::RightButton:
      return vtkCommand::RightButtonPressEvent;
    default:
      return vtkCommand::NoEvent;
  }
}

unsigned long vtkReleaseEvent(Qt::MouseButton button) {
  switch (button) {
    case Qt::LeftButton:
      return vtkCommand::LeftButtonReleaseEvent;
    case Qt::MiddleButton:
      return vtkCommand::MiddleButtonReleaseEvent;
    case Qt::RightButton:
      return vtkCommand::RightButtonReleaseEvent;
    default:
      return vtkCommand::NoEvent;
  }
}

// X11 key symbol names, which VTK uses for its KeySym, of the printable ASCII characters.
constexpr std::array<const char*, 95> kPrintableKeySyms = {"space",       "exclam",
                                                           "quotedbl",    "numbersign",
                                                           "dollar",      "percent",
                                                           "ampersand",   "quoteright",
                                                           "parenleft",   "parenright",
                                                           "asterisk",    "plus",
                                                           "comma",       "minus",
                                                           "period",      "slash",
                                                           "0",           "1",
                                                           "2",           "3",
                                                           "4",           "5",
                                                           "6",           "7",
                                                           "8",           "9",
                                                           "colon",       "semicolon",
                                                           "less",        "equal",
                                                           "greater",     "question",
                                                           "at",          "A",
                                                           "B",           "C",
                                                           "D",           "E",
                                                           "F",           "G",
                                                           "H",           "I",
                                                           "J",           "K",
                                                           "L",           "M",
                                                           "N",           "O",
                                                           "P",           "Q",
                                                           "R",           "S",
                                                           "T",           "U",
                                                           "V",           "W",
                                                           "X",           "Y",
                                                           "Z",           "bracketleft",
                                                           "backslash",   "bracketright",
                                                           "asciicircum", "underscore",
                                                           "quoteleft",   "a",
                                                           "b",           "c",
                                                           "d",           "e",
                                                           "f",           "g",
                                                           "h",           "i",
                                                           "j",           "k",
                                                           "l",           "m",
                                                           "n",           "o",
                                                           "p",           "q",
                                                           "r",           "s",
                                                           "t",           "u",
                                                           "v",           "w",
                                                           "x",           "y",
                                                           "z",           "braceleft",
                                                           "bar",         "braceright",
                                                           "asciitilde"};

constexpr std::array<const char*, 12> kFunctionKeySyms = {"F1", "F2", "F3", "F4",  "F5",  "F6",
                                                          "F7", "F8", "F9", "F10", "F11", "F12"};

const char* vtkKeySym(int qtKey, char keyCode) {
  switch (qtKey) {
    case Qt::Key_Backspace:
      return "BackSpace";
    case Qt::Key_Tab:
    case Qt::Key_Backtab:
      return "Tab";
    case Qt::Key_Return:
    case Qt::Key_Enter:
      return "Return";
    case Qt::Key_Escape:
      return "Escape";
    case Qt::Key_Delete:
      return "Delete";
    case Qt::Key_Insert:
      return "Insert";
    case Qt::Key_Home:
      return "Home";
    case Qt::Key_End:
      return "End";
    case Qt::Key_PageUp:
      return "Prior";
    case Qt::Key_PageDown:
      return "Next";
    case Qt::Key_Left:
      return "Left";
    case Qt::Key_Up:
      return "Up";
    case Qt::Key_Right:
      return "Right";
    case Qt::Key_Down:
      return "Down";
    case Qt::Key_Shift:
      return "Shift_L";
    case Qt::Key_Control:
      return "Control_L";
    case Qt::Key_Alt:
      return "Alt_L";
    default:
      break;
  }
  if (qtKey >= Qt::Key_F1 && qtKey <= Qt::Key_F12) {
    return kFunctionKeySyms[qtKey - Qt::Key_F1];
  }
  if (keyCode >= ' ' && keyCode <= '~') {
    return kPrintableKeySyms[keyCode - ' '];
  }
  return "None";
}

}  // namespace

VtkViewport::VtkViewport(QWidget* parent) : QOpenGLWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);
  // VTK's interactor styles and widgets react to hover moves, not only to drags.
  setMouseTracking(true);
  // VTK redraws the whole picture every frame.
  setUpdateBehavior(QOpenGLWidget::NoPartialUpdate);

  // Until initializeGL there is no context: any Render() before that must be a no-op.
  renderWindow_->SetReadyForRendering(false);
  // VTK keeps the finished frame in its display framebuffer; paintGL blits it into the widget.
  renderWindow_->SetFrameBlitModeToNoBlit();
  for (unsigned long eventId : {vtkCommand::WindowMakeCurrentEvent,
                                vtkCommand::WindowIsCurrentEvent, vtkCommand::WindowFrameEvent}) {
    renderWindowObserverTags_.push_back(
        renderWindow_->AddObserver(eventId, this, &VtkViewport::onRenderWindowEvent));
  }

  interactor_->SetRenderWindow(renderWindow_);
  vtkNew<vtkInteractorStyleTrackballCamera> style;
  interactor_->SetInteractorStyle(style);
  // Enables the interactor; its initial render is skipped since rendering is not ready yet.
  interactor_->Initialize();

  // `resized` also fires when the device pixel ratio changes (window moved to another screen).
  connect(this, &QOpenGLWidget::resized, this, &VtkViewport::updateSize);
}

VtkViewport::~VtkViewport() {
  releaseGraphicsResources();
  // Another owner may keep the render window alive; it must no longer call back into us.
  for (unsigned long tag : renderWindowObserverTags_) {
    renderWindow_->RemoveObserver(tag);
  }
}

void VtkViewport::setDefaultSurfaceFormat() {
  QSurfaceFormat format;
  format.setRenderableType(QSurfaceFormat::OpenGL);
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setSwapBehavior(QSurfaceFormat::DoubleBuffer);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  // VTK renders into its own framebuffers and does its own anti-aliasing (SetMultiSamples);
  // multisampling Qt's framebuffer as well would only cost memory and a resolve per frame.
  format.setSamples(0);
  QSurfaceFormat::setDefaultFormat(format);
}

vtkGenericOpenGLRenderWindow* VtkViewport::renderWindow() const {
  return renderWindow_;
}

vtkRenderWindowInteractor* VtkViewport::interactor() const {
  return interactor_;
}

void VtkViewport::setInteractionEnabled(bool enabled) {
  interactionEnabled_ = enabled;
}

void VtkViewport::setPressFilter(PressFilter filter) {
  pressFilter_ = std::move(filter);
}

void VtkViewport::setWheelFilter(WheelFilter filter) {
  wheelFilter_ = std::move(filter);
}

QImage VtkViewport::grabRendering() {
  renderPending_ = true;
  return grabFramebuffer();
}

void VtkViewport::scheduleRender() {
  renderPending_ = true;
  update();
}

void VtkViewport::initializeGL() {
  renderWindow_->SetOwnContext(false);
  renderWindow_->OpenGLInitContext();
  vtkOpenGLState* state = renderWindow_->GetState();
  state->Reset();
  // Qt leaves GL_LESS; VTK's passes expect GL_LEQUAL.
  state->vtkglDepthFunc(GL_LEQUAL);
  renderWindow_->SetReadyForRendering(true);

  // The context goes away when the widget moves to another top-level window; VTK's GL objects
  // must be released with it, and initializeGL runs again for the new context.
  contextDestroyedConnection_ =
      connect(context(), &QOpenGLContext::aboutToBeDestroyed, this,
              &VtkViewport::releaseGraphicsResources, Qt::DirectConnection);
  updateSize();
}

void VtkViewport::paintGL() {
  vtkOpenGLState* state = renderWindow_->GetState();
  // Qt changes GL state behind VTK's cache between frames: re-read it, and restore Qt's
  // afterwards.
  state->Reset();
  state->Push();
  state->vtkglDepthFunc(GL_LEQUAL);

  if (renderPending_) {
    inPaintGL_ = true;
    interactor_->Render();
    inPaintGL_ = false;
  }

  const int deviceWidth = renderWindow_->GetSize()[0];
  const int deviceHeight = renderWindow_->GetSize()[1];
  state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, defaultFramebufferObject());
  unsigned int colorAttachment = GL_COLOR_ATTACHMENT0;
  state->vtkglDrawBuffers(1, &colorAttachment);
  // The scissor box left by VTK's last renderer would clip the blit.
  state->vtkglDisable(GL_SCISSOR_TEST);
  renderWindow_->BlitDisplayFramebuffer();

  // VTK's background alpha is 0 by default; Qt composes the widget with blending, so the
  // picture would show through (black or garbage). Force the alpha channel to opaque.
  state->vtkglColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_TRUE);
  state->vtkglClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  state->vtkglViewport(0, 0, deviceWidth, deviceHeight);
  state->vtkglClear(GL_COLOR_BUFFER_BIT);

  state->Pop();
}

void VtkViewport::updateSize() {
  const qreal dpr = devicePixelRatioF();
  const QSize deviceSize = size() * dpr;
  interactor_->UpdateSize(deviceSize.width(), deviceSize.height());
  renderWindow_->SetSize(deviceSize.width(), deviceSize.height());
  if (const QScreen* widgetScreen = screen()) {
    const QSize screenDeviceSize = widgetScreen->size() * dpr;
    renderWindow_->SetScreenSize(screenDeviceSize.width(), screenDeviceSize.height());
  }
  // VTK scales text and line widths by DPI / 72.
  renderWindow_->SetDPI(static_cast<int>(std::lround(72 * dpr)));
  renderPending_ = true;
}

void VtkViewport::releaseGraphicsResources() {
  QOpenGLContext* glContext = context();
  if (glContext == nullptr) {
    return;
  }
  disconnect(contextDestroyedConnection_);
  glContext->makeCurrent(glContext->surface());
  renderWindow_->Finalize();
  renderWindow_->SetReadyForRendering(false);
  renderPending_ = true;
}

void VtkViewport::onRenderWindowEvent(vtkObject*, unsigned long eventId, void* callData) {
  QOpenGLContext* glContext = context();
  switch (eventId) {
    case vtkCommand::WindowMakeCurrentEvent:
      // Not QOpenGLWidget::makeCurrent(): that also binds Qt's framebuffer, under VTK's feet
      // in the middle of its render (black picture, GL_FRAMEBUFFER_UNSUPPORTED).
      if (glContext != nullptr) {
        glContext->makeCurrent(glContext->surface());
      }
      break;
    case vtkCommand::WindowIsCurrentEvent:
      *static_cast<bool*>(callData) =
          glContext != nullptr && QOpenGLContext::currentContext() == glContext;
      break;
    case vtkCommand::WindowFrameEvent:
      onFrameRendered();
      break;
    default:
      break;
  }
}

void VtkViewport::onFrameRendered() {
  // Internal passes (e.g. hardware picking) render to the back buffer without swapping: those
  // frames are not for display.
  if (renderWindow_->GetDoubleBuffer() && !renderWindow_->GetSwapBuffers()) {
    return;
  }
  renderPending_ = false;
  // A Render() from outside paintGL (camera interaction, the owner) has a new frame to show.
  if (!inPaintGL_) {
    update();
  }
}

QPoint VtkViewport::toDevicePixels(QPointF widgetPos) const {
  const qreal dpr = devicePixelRatioF();
  return {static_cast<int>(std::lround(widgetPos.x() * dpr)),
          static_cast<int>(std::lround(widgetPos.y() * dpr))};
}

QPoint VtkViewport::toVtkDisplay(QPointF widgetPos) const {
  const QPoint device = toDevicePixels(widgetPos);
  // Same flip as vtkRenderWindowInteractor::SetEventInformationFlipY.
  return {device.x(), interactor_->GetSize()[1] - device.y() - 1};
}

void VtkViewport::forwardMouseEvent(QMouseEvent* event, unsigned long vtkEventId) {
  const QPoint device = toDevicePixels(event->position());
  const Qt::KeyboardModifiers modifiers = event->modifiers();
  const int repeatCount = event->type() == QEvent::MouseButtonDblClick ? 1 : 0;
  interactor_->SetEventInformationFlipY(
      device.x(), device.y(), modifiers.testFlag(Qt::ControlModifier) ? 1 : 0,
      modifiers.testFlag(Qt::ShiftModifier) ? 1 : 0, 0, repeatCount);
  interactor_->SetAltKey(modifiers.testFlag(Qt::AltModifier) ? 1 : 0);
  interactor_->InvokeEvent(vtkEventId, event);
}

void VtkViewport::mousePressEvent(QMouseEvent* event) {
  const QPoint vtkPos = toVtkDisplay(event->position());
  const Qt::MouseButton button = event->button();
  if (pressFilter_ && pressFilter_(vtkPos, button, event->modifiers())) {
    ownerDragButtons_.setFlag(button);
  }
  emit mousePressedAt(vtkPos, button, event->modifiers());

  const unsigned long vtkEventId = vtkPressEvent(button);
  if (!ownerDragButtons_.testFlag(button) && interactionEnabled_ &&
      vtkEventId != vtkCommand::NoEvent) {
    vtkDragButtons_.setFlag(button);
    forwardMouseEvent(event, vtkEventId);
  }
  event->accept();
}

void VtkViewport::mouseMoveEvent(QMouseEvent* event) {
  emit mouseMovedTo(toVtkDisplay(event->position()), event->buttons());
  if (ownerDragButtons_ == Qt::NoButton &&
      (interactionEnabled_ || vtkDragButtons_ != Qt::NoButton)) {
    forwardMouseEvent(event, vtkCommand::MouseMoveEvent);
  }
  event->accept();
}

void VtkViewport::mouseReleaseEvent(QMouseEvent* event) {
  const Qt::MouseButton button = event->button();
  emit mouseReleasedAt(toVtkDisplay(event->position()), button);
  if (ownerDragButtons_.testFlag(button)) {
    ownerDragButtons_.setFlag(button, false);
  } else if (vtkDragButtons_.testFlag(button)) {
    vtkDragButtons_.setFlag(button, false);
    forwardMouseEvent(event, vtkReleaseEvent(button));
  }
  event->accept();
}

void VtkViewport::wheelEvent(QWheelEvent* event) {
  if (!interactionEnabled_) {
    event->ignore();
    return;
  }
  const QPoint device = toDevicePixels(event->position());
  const Qt::KeyboardModifiers modifiers = event->modifiers();
  interactor_->SetEventInformationFlipY(device.x(), device.y(),
                                        modifiers.testFlag(Qt::ControlModifier) ? 1 : 0,
                                        modifiers.testFlag(Qt::ShiftModifier) ? 1 : 0);
  interactor_->SetAltKey(modifiers.testFlag(Qt::AltModifier) ? 1 : 0);

  // Touchpads send many small deltas: zoom once per accumulated notch.
  accumulatedWheelDelta_ += event->angleDelta().y();
  if (const int notches = accumulatedWheelDelta_ / kWheelNotch;
      notches != 0 && wheelFilter_ && wheelFilter_(notches)) {
    accumulatedWheelDelta_ -= notches * kWheelNotch;
    event->accept();
    return;
  }
  if (accumulatedWheelDelta_ >= kWheelNotch) {
    interactor_->InvokeEvent(vtkCommand::MouseWheelForwardEvent, event);
    accumulatedWheelDelta_ = 0;
  } else if (accumulatedWheelDelta_ <= -kWheelNotch) {
    interactor_->InvokeEvent(vtkCommand::MouseWheelBackwardEvent, event);
    accumulatedWheelDelta_ = 0;
  }
  event->accept();
}

void VtkViewport::keyPressEvent(QKeyEvent* event) {
  forwardKeyEvent(event, true);
  QOpenGLWidget::keyPressEvent(event);
}

void VtkViewport::keyReleaseEvent(QKeyEvent* event) {
  forwardKeyEvent(event, false);
  QOpenGLWidget::keyReleaseEvent(event);
}

void VtkViewport::forwardKeyEvent(QKeyEvent* event, bool pressed) {
  const QString text = event->text();
  const char keyCode =
      text.size() == 1 && text.at(0).unicode() < 128 ? static_cast<char>(text.at(0).unicode()) : 0;
  const Qt::KeyboardModifiers modifiers = event->modifiers();
  interactor_->SetKeyEventInformation(modifiers.testFlag(Qt::ControlModifier) ? 1 : 0,
                                      modifiers.testFlag(Qt::ShiftModifier) ? 1 : 0, keyCode,
                                      event->isAutoRepeat() ? 1 : 0,
                                      vtkKeySym(event->key(), keyCode));
  interactor_->SetAltKey(modifiers.testFlag(Qt::AltModifier) ? 1 : 0);
  if (!pressed) {
    interactor_->InvokeEvent(vtkCommand::KeyReleaseEvent, event);
    return;
  }
  interactor_->InvokeEvent(vtkCommand::KeyPressEvent, event);
  // VTK's interactor styles act on CharEvent, which only exists for characters.
  if (keyCode != 0) {
    interactor_->InvokeEvent(vtkCommand::CharEvent, event);
  }
}

}  // namespace liversim
