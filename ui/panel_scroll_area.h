#pragma once
// A panel in its dock: scrolled up and down when the dock is shorter than the panel (a dock the
// user made small, a long scenario, the Material panel's eight fields), never sideways: the dock
// is at least as wide as the panel's narrowest layout, so no field is cut off at its side, and
// its least height is a few lines, so that any arrangement of the docks fits the window.

#include <QEvent>
#include <QScrollArea>
#include <QScrollBar>

#include <algorithm>

namespace liversim {

class PanelScrollArea : public QScrollArea {
 public:
  PanelScrollArea(QWidget* panel, QWidget* parent) : QScrollArea(parent) {
    setFrameShape(QFrame::NoFrame);
    setWidgetResizable(true);
    setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    setWidget(panel);
  }

  QSize minimumSizeHint() const override {
    const QSize panel = widget()->minimumSizeHint();
    constexpr int kLeastLines = 6;
    return {panel.width() + verticalScrollBar()->sizeHint().width(),
            std::min(panel.height(), kLeastLines * fontMetrics().lineSpacing())};
  }
  QSize sizeHint() const override { return QScrollArea::sizeHint().expandedTo(minimumSizeHint()); }

 protected:
  // The panel's least width changes with what it shows (a row shown, a longer item): so does
  // the dock's.
  bool eventFilter(QObject* watched, QEvent* event) override {
    if (watched == widget() && event->type() == QEvent::LayoutRequest) updateGeometry();
    return QScrollArea::eventFilter(watched, event);
  }
};

}  // namespace liversim
