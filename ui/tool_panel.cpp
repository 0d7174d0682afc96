#include "tool_panel.h"

#include <QButtonGroup>
#include <QLabel>
#include <QPainter>
#include <QPainterPath>
#include <QRadioButton>
#include <QVBoxLayout>

#include <algorithm>

namespace liversim {
namespace {

// Button ids: the tools' ToolKind, and for the hand (no tool) one past them (QButtonGroup gives
// buttons added with id −1 ids of its own).
constexpr int kHandId = 100;

}  // namespace

ForceTrace::ForceTrace(QWidget* parent) : QWidget(parent) {
  setMinimumHeight(50);
  setToolTip(tr("Force on the tool over the last %1 s").arg(kSpanS));
}

void ForceTrace::addSample(double time_s, double force_n) {
  if (!time_s_.empty() && time_s < time_s_.back()) clear();  // a new run started
  time_s_.push_back(time_s);
  force_n_.push_back(force_n);
  // Keep the span only (the front is dropped in blocks, not one sample at a time).
  const auto first = std::lower_bound(time_s_.begin(), time_s_.end(), time_s - kSpanS);
  if (first - time_s_.begin() > 256) {
    const auto dropped = first - time_s_.begin();
    time_s_.erase(time_s_.begin(), first);
    force_n_.erase(force_n_.begin(), force_n_.begin() + dropped);
  }
  update();
}

void ForceTrace::clear() {
  time_s_.clear();
  force_n_.clear();
  update();
}

void ForceTrace::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), palette().base());
  painter.setPen(palette().mid().color());
  painter.drawRect(rect().adjusted(0, 0, -1, -1));
  if (time_s_.size() < 2) return;
  const double end_s = time_s_.back(), start_s = end_s - kSpanS;
  double largest = 0.1;  // N: at least a tenth of a newton of scale
  for (std::size_t i = 0; i < time_s_.size(); ++i)
    if (time_s_[i] >= start_s) largest = std::max(largest, force_n_[i]);
  QPainterPath path;
  bool started = false;
  for (std::size_t i = 0; i < time_s_.size(); ++i) {
    if (time_s_[i] < start_s) continue;
    const QPointF p((time_s_[i] - start_s) / kSpanS * (width() - 2) + 1,
                    height() - 2 - force_n_[i] / largest * (height() - 4));
    if (started) {
      path.lineTo(p);
    } else {
      path.moveTo(p);
      started = true;
    }
  }
  painter.setRenderHint(QPainter::Antialiasing);
  painter.setPen(QPen(palette().highlight().color(), 1.5));
  painter.drawPath(path);
  painter.setPen(palette().text().color());
  painter.drawText(rect().adjusted(4, 2, -4, -2), Qt::AlignTop | Qt::AlignRight,
                   tr("%1 N").arg(largest, 0, 'f', 2));
}

ToolPanel::ToolPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  tools_ = new QButtonGroup(this);
  auto add = [&](const QString& text, const QString& name, int id, const QString& tip) {
    auto* button = new QRadioButton(text, this);
    button->setObjectName(name);
    button->setToolTip(tip);
    tools_->addButton(button, id);
    layout->addWidget(button);
    return button;
  };
  add(tr("&Hand"), "toolHand", kHandId,
      tr("Drag the liver with the left mouse button: the tissue under it follows the pointer"))
      ->setChecked(true);
  add(tr("&Probe"), "toolProbe", static_cast<int>(ToolKind::probe),
      tr("Press the left mouse button on the liver to put the probe's ball on it, drag to move it; "
         "while the button is down, the wheel (or Shift+drag) pushes it in or draws it back"));
  add(tr("&Forceps"), "toolForceps", static_cast<int>(ToolKind::forceps),
      tr("Press the left mouse button on the liver to close the jaws on it, drag to pull, release "
         "to let go"));
  add(tr("&Scalpel"), "toolScalpel", static_cast<int>(ToolKind::scalpel),
      tr("Press the left mouse button on the liver to put the blade in and drag: it cuts along its "
         "path. While the button is down, the wheel (or Shift+drag) pushes it deeper or draws it "
         "back; the panel shows how deep it is. Pressed on from outside, it breaks in once pressed "
         "hard enough to part the tissue"));
  force_ = new QLabel(this);
  force_->setObjectName("toolForce");
  layout->addWidget(force_);
  blade_ = new QLabel(this);
  blade_->setObjectName("toolBladeDepth");
  blade_->setToolTip(
      tr("How much of the scalpel's edge is inside the tissue: its depth along "
         "the edge"));
  blade_->hide();
  layout->addWidget(blade_);
  trace_ = new ForceTrace(this);
  trace_->setObjectName("toolForceTrace");
  layout->addWidget(trace_);
  layout->addStretch(1);
  showForce(0.0, Eigen::Vector3d::Zero(), false);
  connect(tools_, &QButtonGroup::idClicked, this, [this] { emit toolChanged(tool()); });
}

std::optional<ToolKind> ToolPanel::tool() const {
  const int id = tools_->checkedId();
  if (id == kHandId) return std::nullopt;
  return static_cast<ToolKind>(id);
}

void ToolPanel::setTool(std::optional<ToolKind> tool) {
  if (QAbstractButton* button = tools_->button(tool ? static_cast<int>(*tool) : kHandId))
    button->setChecked(true);
  emit toolChanged(this->tool());
}

void ToolPanel::setAvailableTools(const std::vector<ToolKind>& tools) {
  for (const ToolKind kind : kToolKinds)
    if (QAbstractButton* button = tools_->button(static_cast<int>(kind)))
      button->setVisible(std::find(tools.begin(), tools.end(), kind) != tools.end());
  // A tool the scene does not offer is put down: the hand takes over.
  if (const auto held = tool(); held && !offers(*held)) setTool(std::nullopt);
}

bool ToolPanel::offers(ToolKind kind) const {
  const QAbstractButton* button = tools_->button(static_cast<int>(kind));
  return button && !button->isHidden();
}

void ToolPanel::showForce(double time_s, const Eigen::Vector3d& force_n, bool holding) {
  force_->setText(
      holding ? tr("Force on the tool: %1 N (holding tissue)").arg(force_n.norm(), 0, 'f', 2)
              : tr("Force on the tool: %1 N").arg(force_n.norm(), 0, 'f', 2));
  trace_->addSample(time_s, force_n.norm());
}

QString ToolPanel::forceText() const {
  return force_->text();
}

void ToolPanel::showBlade(std::optional<double> edge_in_tissue_m, bool cutting) {
  blade_->setVisible(edge_in_tissue_m.has_value());
  if (!edge_in_tissue_m) return;
  const double mm = *edge_in_tissue_m * 1e3;
  if (mm < 0.05)
    blade_->setText(tr("Blade: not in the tissue"));
  else if (cutting)
    blade_->setText(tr("Blade: %1 mm in the tissue, cutting").arg(mm, 0, 'f', 1));
  else
    blade_->setText(tr("Blade: %1 mm in the tissue").arg(mm, 0, 'f', 1));
}

}  // namespace liversim
