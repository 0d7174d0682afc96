#include "force_curve.h"

#include <QCoreApplication>
#include <QValueAxis>

#include <algorithm>

namespace liversim {

ForceCurve force_curve(std::span<const ServoFrame> frames, double force_factor, double t0_s,
                       std::size_t max_points) {
  ForceCurve curve;
  const std::size_t bucket = std::max<std::size_t>(
      1, (frames.size() + max_points - 1) / std::max<std::size_t>(max_points, 1));
  for (std::size_t begin = 0; begin < frames.size(); begin += bucket) {
    std::size_t peak = begin;
    for (std::size_t i = begin; i < std::min(frames.size(), begin + bucket); ++i)
      if (frames[i].force_n.norm() > frames[peak].force_n.norm()) peak = i;
    const double force = frames[peak].force_n.norm() * force_factor;
    curve.largest_n = std::max(curve.largest_n, force);
    curve.points.append(QPointF(frames[peak].time_s - t0_s, force));
  }
  return curve;
}

QChart* force_chart(std::initializer_list<QAbstractSeries*> series) {
  auto* chart = new QChart();
  auto* time_axis = new QValueAxis();
  time_axis->setTitleText(QCoreApplication::translate("ForceChart", "Time (s)"));
  auto* force_axis = new QValueAxis();
  force_axis->setTitleText(QCoreApplication::translate("ForceChart", "Force (N)"));
  chart->addAxis(time_axis, Qt::AlignBottom);
  chart->addAxis(force_axis, Qt::AlignLeft);
  for (QAbstractSeries* one : series) {
    chart->addSeries(one);
    one->attachAxis(time_axis);
    one->attachAxis(force_axis);
  }
  return chart;
}

}  // namespace liversim
