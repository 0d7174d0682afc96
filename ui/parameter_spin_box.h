#pragma once
// Spin boxes for the tissue's parameters, shared by the scenario editor and the Material panel:
// each takes its limits from the documented range (parameter_ranges.h) and says the range and
// where it comes from in its tooltip.

#include <QString>

#include <string_view>

class QDoubleSpinBox;

namespace liversim {

// A spin box from min to max, edited when the value is entered (not at each key).
QDoubleSpinBox* spinBox(const char* name, double min, double max, int decimals,
                        const QString& suffix, const QString& tip);

// A spin box over the documented range with key `key`, shown in `scale` × its unit (e.g. 1e3 with
// " kPa" for a range in Pa).
QDoubleSpinBox* rangeSpinBox(std::string_view key, double scale, const QString& suffix,
                             int decimals);

}  // namespace liversim
