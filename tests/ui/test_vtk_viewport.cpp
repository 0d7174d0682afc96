// VtkViewport under a real X server (Xvfb in CI): the VTK picture reaches the widget, and Qt
// mouse events reach VTK's interactor unless interaction is disabled or the owner takes the drag.
#include <gtest/gtest.h>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkNew.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <QApplication>
#include <QDir>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QScreen>
#include <QSignalSpy>
#include <QTest>
#include <QWheelEvent>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>

#include "vtk_viewport.h"

// Readable gtest failure messages.
void PrintTo(const QColor& colour, std::ostream* out) {
  *out << colour.name(QColor::HexArgb).toStdString();
}
void PrintTo(const QPoint& point, std::ostream* out) {
  *out << '(' << point.x() << ", " << point.y() << ')';
}
void PrintTo(const QSize& size, std::ostream* out) {
  *out << size.width() << 'x' << size.height();
}

namespace liversim {
namespace {

constexpr int kWidth = 400;
constexpr int kHeight = 300;
const QColor kSphereColour(255, 0, 0);
const QColor kBackgroundColour(0, 0, 0);

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

int countPixels(const QImage& image, const QColor& colour) {
  int count = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      count += image.pixelColor(x, y) == colour ? 1 : 0;
    }
  }
  return count;
}

class VtkViewportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    vtkNew<vtkSphereSource> sphere;
    sphere->SetThetaResolution(32);
    sphere->SetPhiResolution(32);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(sphere->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    // Unlit, so every covered pixel has exactly the actor's colour.
    actor->GetProperty()->SetColor(kSphereColour.redF(), kSphereColour.greenF(),
                                   kSphereColour.blueF());
    actor->GetProperty()->LightingOff();
    renderer_->AddActor(actor);
    renderer_->SetBackground(kBackgroundColour.redF(), kBackgroundColour.greenF(),
                             kBackgroundColour.blueF());
    renderer_->ResetCamera();
    viewport_.renderWindow()->AddRenderer(renderer_);

    viewport_.resize(kWidth, kHeight);
    viewport_.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&viewport_));
  }

  // Leaves the last picture where a failing test can be inspected.
  void TearDown() override {
    if (HasFailure() && !picture_.isNull()) {
      const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
      const QString path = QDir(LIVERSIM_TEST_OUTPUT_DIR)
                               .filePath(QStringLiteral("vtk_viewport_%1.png").arg(info->name()));
      picture_.save(path);
      std::cerr << "picture saved to " << path.toStdString() << '\n';
    }
  }

  std::array<double, 3> cameraPosition() {
    std::array<double, 3> position{};
    renderer_->GetActiveCamera()->GetPosition(position.data());
    return position;
  }

  QPoint centre() const { return {kWidth / 2, kHeight / 2}; }

  // Qt composes the widget into its window on its own schedule: poll what the X server shows
  // (not the widget's framebuffer) until it passes `check`. The last look is kept in picture_.
  bool waitForScreen(const std::function<bool(const QImage&)>& check) {
    return QTest::qWaitFor([&] {
      picture_ = viewport_.screen()->grabWindow(viewport_.winId()).toImage();
      return !picture_.isNull() && check(picture_);
    });
  }

  void sendMouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    QMouseEvent event(type, QPointF(pos), QPointF(viewport_.mapToGlobal(pos)), button, buttons,
                      Qt::NoModifier);
    QCoreApplication::sendEvent(&viewport_, &event);
  }

  void drag(Qt::MouseButton button, QPoint from, QPoint to) {
    constexpr int kSteps = 6;
    sendMouse(QEvent::MouseButtonPress, from, button, button);
    for (int step = 1; step <= kSteps; ++step) {
      sendMouse(QEvent::MouseMove, from + (to - from) * step / kSteps, Qt::NoButton, button);
    }
    sendMouse(QEvent::MouseButtonRelease, to, button, Qt::NoButton);
  }

  // Where VTK sees a widget position: device pixels, y up from the bottom row.
  QPoint vtkDisplay(QPoint widgetPos) const {
    const qreal dpr = viewport_.devicePixelRatioF();
    const int deviceHeight = static_cast<int>(std::lround(kHeight * dpr));
    return {static_cast<int>(std::lround(widgetPos.x() * dpr)),
            deviceHeight - static_cast<int>(std::lround(widgetPos.y() * dpr)) - 1};
  }

  VtkViewport viewport_;
  vtkNew<vtkRenderer> renderer_;
  QImage picture_;
};

TEST_F(VtkViewportTest, ShowsTheVtkPicture) {
  picture_ = viewport_.grabRendering();
  ASSERT_FALSE(picture_.isNull());
  const qreal dpr = viewport_.devicePixelRatioF();
  EXPECT_EQ(picture_.size(), QSize(kWidth, kHeight) * dpr);

  EXPECT_EQ(picture_.pixelColor(picture_.width() / 2, picture_.height() / 2), kSphereColour);
  EXPECT_EQ(picture_.pixelColor(2, 2), kBackgroundColour);
  EXPECT_EQ(picture_.pixelColor(picture_.width() - 3, picture_.height() - 3), kBackgroundColour);
}

TEST_F(VtkViewportTest, TheWidgetFramebufferIsOpaque) {
  picture_ = viewport_.grabRendering();
  // VTK's background alpha is 0; Qt would let that show through wherever it composes the
  // widget with alpha (translucent widget or window), so the viewport must write alpha 1.
  viewport_.makeCurrent();
  QOpenGLFunctions* gl = viewport_.context()->functions();
  gl->glBindFramebuffer(GL_FRAMEBUFFER, viewport_.defaultFramebufferObject());
  std::array<unsigned char, 4> corner{};
  gl->glReadPixels(2, 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, corner.data());
  viewport_.doneCurrent();
  EXPECT_EQ(corner[3], 255);
}

TEST_F(VtkViewportTest, TheWindowOnScreenShowsThePicture) {
  viewport_.scheduleRender();
  ASSERT_TRUE(waitForScreen([](const QImage& screen) {
    return screen.pixelColor(screen.width() / 2, screen.height() / 2) == kSphereColour;
  }));
  EXPECT_EQ(picture_.pixelColor(2, 2), kBackgroundColour);
}

TEST_F(VtkViewportTest, KeepsRenderingAfterMovingToAnotherWindow) {
  picture_ = viewport_.grabRendering();
  // Qt destroys the widget's GL context when it changes top-level window; VTK must release its
  // GL objects with it and rebuild them in the new context.
  QWidget window;
  viewport_.setParent(&window);
  window.resize(kWidth, kHeight);
  viewport_.show();
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));

  picture_ = viewport_.grabRendering();
  ASSERT_FALSE(picture_.isNull());
  EXPECT_EQ(picture_.pixelColor(picture_.width() / 2, picture_.height() / 2), kSphereColour);
  EXPECT_EQ(picture_.pixelColor(2, 2), kBackgroundColour);
  viewport_.setParent(nullptr);
}

TEST_F(VtkViewportTest, LeftDragRotatesTheCamera) {
  picture_ = viewport_.grabRendering();
  const auto before = cameraPosition();

  drag(Qt::LeftButton, centre(), centre() + QPoint(80, 40));

  EXPECT_GT(distance(before, cameraPosition()), 1e-3);
  // The camera orbits the focal point, so the sphere stays in the middle of the picture.
  picture_ = viewport_.grabRendering();
  EXPECT_EQ(picture_.pixelColor(picture_.width() / 2, picture_.height() / 2), kSphereColour);
}

TEST_F(VtkViewportTest, WheelZoomReachesTheScreenWithoutRenderingAgain) {
  picture_ = viewport_.grabRendering();
  const int sphereAreaBefore = countPixels(picture_, kSphereColour);
  ASSERT_TRUE(waitForScreen([&](const QImage& screen) {
    return countPixels(screen, kSphereColour) == sphereAreaBefore;
  }));
  int renders = 0;
  vtkNew<vtkCallbackCommand> countRender;
  countRender->SetClientData(&renders);
  countRender->SetCallback(
      [](vtkObject*, unsigned long, void* count, void*) { ++*static_cast<int*>(count); });
  viewport_.renderWindow()->AddObserver(vtkCommand::StartEvent, countRender);

  QWheelEvent notch(QPointF(centre()), QPointF(viewport_.mapToGlobal(centre())), QPoint(),
                    QPoint(0, 120), Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
  QCoreApplication::sendEvent(&viewport_, &notch);
  const int rendersByVtk = renders;
  EXPECT_GE(rendersByVtk, 1);

  // VTK renders the zoomed frame itself during the wheel event; nothing here asks for a
  // repaint, so the window only changes if that frame makes the widget update, and the repaint
  // must show that frame rather than render it again.
  EXPECT_TRUE(waitForScreen(
      [&](const QImage& screen) { return countPixels(screen, kSphereColour) > sphereAreaBefore; }));
  EXPECT_EQ(renders, rendersByVtk);
}

TEST_F(VtkViewportTest, DisabledInteractionLeavesTheCameraAlone) {
  viewport_.setInteractionEnabled(false);
  QSignalSpy pressed(&viewport_, &VtkViewport::mousePressedAt);
  QSignalSpy released(&viewport_, &VtkViewport::mouseReleasedAt);
  const auto before = cameraPosition();

  drag(Qt::LeftButton, centre(), centre() + QPoint(80, 40));

  EXPECT_EQ(distance(before, cameraPosition()), 0.0);
  ASSERT_EQ(pressed.count(), 1);
  EXPECT_EQ(pressed.at(0).at(0).toPoint(), vtkDisplay(centre()));
  EXPECT_EQ(pressed.at(0).at(1).value<Qt::MouseButton>(), Qt::LeftButton);
  ASSERT_EQ(released.count(), 1);
  EXPECT_EQ(released.at(0).at(0).toPoint(), vtkDisplay(centre() + QPoint(80, 40)));

  viewport_.setInteractionEnabled(true);
  drag(Qt::LeftButton, centre(), centre() + QPoint(80, 40));
  EXPECT_GT(distance(before, cameraPosition()), 1e-3);
}

TEST_F(VtkViewportTest, PressFilterTakesTheDragAwayFromVtk) {
  std::vector<QPoint> filteredPresses;
  bool ownerTakesDrags = true;
  viewport_.setPressFilter(
      [&](QPoint vtkDisplayPos, Qt::MouseButton button, Qt::KeyboardModifiers) {
        filteredPresses.push_back(vtkDisplayPos);
        return ownerTakesDrags && button == Qt::LeftButton;
      });
  QSignalSpy moved(&viewport_, &VtkViewport::mouseMovedTo);
  const auto before = cameraPosition();

  drag(Qt::LeftButton, centre(), centre() + QPoint(80, 40));

  EXPECT_EQ(distance(before, cameraPosition()), 0.0);
  ASSERT_EQ(filteredPresses.size(), 1u);
  EXPECT_EQ(filteredPresses.front(), vtkDisplay(centre()));
  ASSERT_FALSE(moved.isEmpty());
  EXPECT_EQ(moved.last().at(0).toPoint(), vtkDisplay(centre() + QPoint(80, 40)));
  EXPECT_EQ(moved.last().at(1).value<Qt::MouseButtons>(), Qt::MouseButtons(Qt::LeftButton));

  // The release ended the owner's drag: the next drag the filter declines goes to VTK.
  ownerTakesDrags = false;
  drag(Qt::LeftButton, centre(), centre() + QPoint(80, 40));
  EXPECT_GT(distance(before, cameraPosition()), 1e-3);
}

}  // namespace
}  // namespace liversim
