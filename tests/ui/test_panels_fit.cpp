// Panels that fit (issue 41, item 5): at 1280 × 800, the smallest screen a workstation is used
// on, and at 1920 × 1080, every field of every panel dock is shown whole, none squeezed below the
// least size its layout promises it. Each size leaves a screenshot in the test output folder for a
// person to look at.
#include <gtest/gtest.h>

#include <QAbstractScrollArea>
#include <QApplication>
#include <QDir>
#include <QDockWidget>
#include <QLabel>
#include <QLayout>
#include <QSettings>
#include <QSignalSpy>
#include <QTest>

#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "liversim/meshing/default_scene.h"
#include "main_window.h"
#include "wait_limits.h"

namespace liversim {
namespace {

constexpr int kTetCount = 3841;  // as the other window tests: small enough for Xvfb
constexpr int kTimeoutMs = liversim::test::waitLimitMs(60'000);
const QString kSmallScenario =
    QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenario-small-resection.json";
const char* const kDocks[] = {"scenarioDock", "accuracyDock", "materialDock", "toolDock",
                              "deviceDock"};

bool layoutHolds(const QLayout* layout, const QWidget* widget) {
  for (int i = 0; i < layout->count(); ++i) {
    QLayoutItem* item = layout->itemAt(i);
    if (item->widget() == widget) return true;
    if (item->layout() && layoutHolds(item->layout(), widget)) return true;
  }
  return false;
}

// A field, label or plot a panel lays out; not the insides of a composite widget (a spin box's
// line edit, a scroll area's bars), which their owner sizes as its style wants.
bool laidOut(const QWidget* widget) {
  const QWidget* parent = widget->parentWidget();
  return parent && parent->layout() && layoutHolds(parent->layout(), widget);
}

// The "no widget smaller than its size hint", made exact: the least size a layout gives a
// widget when it has the room (Qt's qSmartMinSize). That is the size hint in a direction the
// widget's size policy says it cannot shrink in (a spin box's width: its longest value; a
// button's or a spin box's height), else its minimum size hint (a word-wrapped label's width: its
// longest word), an explicit minimum size before either. Not the size hint throughout: a panel in
// a scroll area narrower than the panel's preferred width is fine as long as nothing goes below
// this (its fields still show their longest value), and a word-wrapped label's size hint is only
// a preferred shape (its height for its width is checked instead). Below this size, the layout
// had less room than its minimum and clipped the widget.
QSize leastSize(const QWidget* widget) {
  const QSizePolicy policy = widget->sizePolicy();
  const QSize hint = widget->sizeHint();
  const QSize minHint = widget->minimumSizeHint();
  const auto least = [](QSizePolicy::Policy p, int hint, int minHint) {
    if (p == QSizePolicy::Ignored) return 0;
    return (p & QSizePolicy::ShrinkFlag) ? minHint : std::max(hint, minHint);
  };
  QSize size(least(policy.horizontalPolicy(), hint.width(), minHint.width()),
             least(policy.verticalPolicy(), hint.height(), minHint.height()));
  size = size.boundedTo(widget->maximumSize());
  if (widget->minimumWidth() > 0) size.setWidth(widget->minimumWidth());
  if (widget->minimumHeight() > 0) size.setHeight(widget->minimumHeight());
  return size.expandedTo(QSize(0, 0));
}

// The nearest scroll area that `widget` is in, below `dock`, if any.
const QAbstractScrollArea* scrolledIn(const QWidget* widget, const QWidget* dock) {
  for (const QWidget* up = widget->parentWidget(); up && up != dock; up = up->parentWidget())
    if (const auto* area = qobject_cast<const QAbstractScrollArea*>(up)) return area;
  return nullptr;
}

// A scroll bar of a scroll area or its container: placed by the scroll area, beside what scrolls.
bool scrollAreaPart(const QWidget* widget, const QWidget* dock) {
  const QAbstractScrollArea* area = scrolledIn(widget, dock);
  return area && !area->viewport()->isAncestorOf(widget);
}

std::string describe(const QWidget* widget) {
  std::ostringstream out;
  out << widget->metaObject()->className();
  if (!widget->objectName().isEmpty()) out << " " << widget->objectName().toStdString();
  if (const auto* label = qobject_cast<const QLabel*>(widget))
    out << " \"" << label->text().left(40).toStdString() << "\"";
  const QWidget* named = widget->parentWidget();
  while (named && named->objectName().isEmpty()) named = named->parentWidget();
  if (named) out << " in " << named->objectName().toStdString();
  return out.str();
}

std::string sizeText(QSize size) {
  return std::to_string(size.width()) + "×" + std::to_string(size.height());
}

// Every widget the dock shows is at least its least size, a word-wrapped one tall enough for its
// lines at its width, and none is cut off at the dock's edge. Inside a scroll area only the
// horizontal extent counts: its vertical scroll bar reaches the rest.
void expectShownWhole(const QDockWidget* dock) {
  const QWidget* content = dock->widget();
  ASSERT_NE(content, nullptr) << dock->objectName().toStdString();
  for (const QWidget* widget : content->findChildren<QWidget*>()) {
    if (!widget->isVisible() || !laidOut(widget) || scrollAreaPart(widget, dock)) continue;
    const QSize least = leastSize(widget);
    EXPECT_GE(widget->width(), least.width())
        << describe(widget) << " is " << sizeText(widget->size()) << ", its least size "
        << sizeText(least);
    EXPECT_GE(widget->height(), least.height())
        << describe(widget) << " is " << sizeText(widget->size()) << ", its least size "
        << sizeText(least);
    if (widget->hasHeightForWidth()) {
      EXPECT_GE(widget->height(), widget->heightForWidth(widget->width()))
          << describe(widget) << " is " << sizeText(widget->size()) << ": its lines need "
          << widget->heightForWidth(widget->width());
    }
    const QAbstractScrollArea* scroll = scrolledIn(widget, dock);
    const QWidget* frame = scroll ? scroll->viewport() : content;
    const QRect shown(frame->mapTo(dock, QPoint(0, 0)), frame->size());
    const QRect rect(widget->mapTo(dock, QPoint(0, 0)), widget->size());
    EXPECT_TRUE(rect.left() >= shown.left() && rect.right() <= shown.right())
        << describe(widget) << " is cut off at the side of " << dock->objectName().toStdString();
    if (!scroll) {
      EXPECT_TRUE(rect.top() >= shown.top() && rect.bottom() <= shown.bottom())
          << describe(widget) << " is cut off at the bottom of "
          << dock->objectName().toStdString();
    }
  }
}

// Events handled, then the layout requests they posted (a panel's text changes with the timers:
// the servo's figures), none left for the checks that follow.
void settle() {
  QApplication::processEvents();
  QCoreApplication::sendPostedEvents();
}

// A window whose panels' least heights do not fit is made taller than asked.
void expectSize(const MainWindow& window, QSize size) {
  EXPECT_EQ(sizeText(window.size()), sizeText(size)) << "the panels' least heights do not fit";
}

// The window at `size`, the default layout (no saved one), exposed and laid out; a window that
// cannot be that small (its panels' least heights do not fit) is taller, and the test says so.
std::unique_ptr<MainWindow> openWindow(QSize size) {
  QSettings().clear();
  auto window = std::make_unique<MainWindow>(default_scene(kTetCount));
  window->resize(size);  // larger than Xvfb's screen for 1920 × 1080: no window manager clips it
  window->show();
  EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
  // X configures the window as asked, or the least size it can have, in a round trip or two.
  static_cast<void>(QTest::qWaitFor([&] { return window->size() == size; }, kTimeoutMs));
  settle();
  expectSize(*window, size);
  return window;
}

void saveScreenshot(MainWindow& window, const QString& name) {
  const QString path = QDir(LIVERSIM_TEST_OUTPUT_DIR).filePath(name + ".png");
  EXPECT_TRUE(window.grab().save(path)) << path.toStdString();
  std::cerr << "screenshot saved to " << path.toStdString() << '\n';
}

// Each dock raised in turn and checked: a dock tabbed behind another is put outside the window.
// The window as it opens and with the docks raised last are saved.
void checkEveryPanel(MainWindow& window, QSize size, const QString& name) {
  saveScreenshot(window, name);
  for (const char* dockName : kDocks) {
    auto* dock = window.findChild<QDockWidget*>(dockName);
    ASSERT_NE(dock, nullptr) << dockName;
    EXPECT_FALSE(dock->isHidden()) << dockName << " is closed";
    dock->raise();
    settle();
    expectSize(window, size);
    EXPECT_TRUE(window.rect().contains(dock->geometry()))
        << dockName << " reaches out of the window";
    SCOPED_TRACE(dockName);
    expectShownWhole(dock);
  }
  saveScreenshot(window, name + "_raised");
}

TEST(PanelsFit, EveryPanelIsShownWholeAt1280x800) {
  const QSize size(1280, 800);
  auto window = openWindow(size);
  checkEveryPanel(*window, size, "panels_fit_1280x800");
}

TEST(PanelsFit, EveryPanelIsShownWholeAt1920x1080) {
  const QSize size(1920, 1080);
  auto window = openWindow(size);
  checkEveryPanel(*window, size, "panels_fit_1920x1080");
}

// A scenario with viscoelasticity and viscoplasticity: the Material panel has eight fields and the
// derived E2, the Scenario panel a task and a description.
TEST(PanelsFit, AViscousScenariosPanelsAreShownWholeAt1280x800) {
  const QSize size(1280, 800);
  auto window = openWindow(size);
  QSignalSpy finished(window.get(), &MainWindow::scenarioOpenFinished);
  ASSERT_TRUE(window->openScenario(kSmallScenario));
  ASSERT_TRUE(!finished.isEmpty() || finished.wait(kTimeoutMs));
  ASSERT_TRUE(finished.first().first().toBool());
  settle();
  checkEveryPanel(*window, size, "panels_fit_1280x800_scenario");
}

// A user's own arrangement, the five docks stacked as they were before, fits the window too: each
// panel scrolls in its share of the height, none is clipped, the window does not grow.
TEST(PanelsFit, FiveStackedPanelsStillFitAt1280x800) {
  const QSize size(1280, 800);
  auto window = openWindow(size);
  for (const char* dockName : kDocks) {
    auto* dock = window->findChild<QDockWidget*>(dockName);
    ASSERT_NE(dock, nullptr) << dockName;
    window->addDockWidget(Qt::RightDockWidgetArea, dock, Qt::Vertical);  // out of its tabs
  }
  settle();
  expectSize(*window, size);
  EXPECT_TRUE(window->tabifiedDockWidgets(window->findChild<QDockWidget*>("materialDock")).empty());
  checkEveryPanel(*window, size, "panels_fit_1280x800_stacked");
}

}  // namespace
}  // namespace liversim
