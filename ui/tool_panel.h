#pragma once
// The tool in the trainee's hand: the hand (a plain mouse grab), the probe, the forceps or the
// scalpel, the force the tissue puts on it, live as a number and as a trace of the last seconds,
// and the scalpel's depth in the tissue.

#include "liversim/interaction/tools.h"

#include <QWidget>

#include <optional>
#include <vector>

class QButtonGroup;
class QLabel;

namespace liversim {

// |F| over the last seconds as a line, newest on the right; the scale grows to the largest force
// shown.
class ForceTrace : public QWidget {
  Q_OBJECT

 public:
  explicit ForceTrace(QWidget* parent = nullptr);
  void addSample(double time_s, double force_n);
  void clear();
  std::size_t sampleCount() const { return time_s_.size(); }
  QSize sizeHint() const override { return {220, 70}; }

  static constexpr double kSpanS = 5.0;

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  std::vector<double> time_s_, force_n_;
};

class ToolPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ToolPanel(QWidget* parent = nullptr);

  // The chosen tool; nothing: the hand.
  std::optional<ToolKind> tool() const;
  void setTool(std::optional<ToolKind> tool);
  // The tools a scenario allows (the hand always is); a held tool no longer offered is put down.
  void setAvailableTools(const std::vector<ToolKind>& tools);
  bool offers(ToolKind kind) const;

  // The tissue's force on the tool at simulated time t (N); the label shows its magnitude.
  void showForce(double time_s, const Eigen::Vector3d& force_n, bool holding);
  QString forceText() const;
  // How much of the scalpel's edge is in the tissue (m) and whether it cuts; none: no scalpel in
  // the scene (the line is hidden).
  void showBlade(std::optional<double> edge_in_tissue_m, bool cutting);
  ForceTrace* trace() const { return trace_; }

 signals:
  void toolChanged(std::optional<liversim::ToolKind> tool);

 private:
  QButtonGroup* tools_ = nullptr;
  QLabel* force_ = nullptr;
  QLabel* blade_ = nullptr;  // the scalpel's depth in the tissue
  ForceTrace* trace_ = nullptr;
};

}  // namespace liversim
