#pragma once
// A session's force over time as a chart draws it: the force on the tissue (the device's force
// over the mapping's scale), each bucket of frames shown as its largest force, so that a peak is
// never averaged away however long the session.

#include "liversim/haptics/servo_loop.h"

#include <QAbstractSeries>
#include <QChart>
#include <QList>
#include <QPointF>

#include <cstddef>
#include <initializer_list>
#include <span>

namespace liversim {

struct ForceCurve {
  QList<QPointF> points;  // (s from t0, N)
  double largest_n = 0.0;
};

// `force_factor` turns the recorded device force into the one plotted (1 / mapping scale).
ForceCurve force_curve(std::span<const ServoFrame> frames, double force_factor, double t0_s,
                       std::size_t max_points = 4000);

// A new chart of force (N) over time (s), the series on its two axes.
QChart* force_chart(std::initializer_list<QAbstractSeries*> series);

}  // namespace liversim
