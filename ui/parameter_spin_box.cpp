#include "parameter_spin_box.h"

#include "liversim/engine/parameter_ranges.h"

#include <QDoubleSpinBox>

namespace liversim {

QDoubleSpinBox* spinBox(const char* name, double min, double max, int decimals,
                        const QString& suffix, const QString& tip) {
  auto* box = new QDoubleSpinBox;
  box->setObjectName(name);
  box->setRange(min, max);
  box->setDecimals(decimals);
  box->setSuffix(suffix);
  box->setToolTip(tip);
  box->setKeyboardTracking(false);  // an edit when the value is entered, not at each key
  return box;
}

QDoubleSpinBox* rangeSpinBox(std::string_view key, double scale, const QString& suffix,
                             int decimals) {
  const ParameterRange& range = parameter_range(key);
  return spinBox("", range.min / scale, range.max / scale, decimals, suffix,
                 QString::fromUtf8("%1: %2 to %3%4. %5")
                     .arg(QString::fromUtf8(range.label.data(), int(range.label.size())))
                     .arg(range.min / scale)
                     .arg(range.max / scale)
                     .arg(suffix)
                     .arg(QString::fromUtf8(range.why.data(), int(range.why.size()))));
}

}  // namespace liversim
