#include "editor_panel.h"

#include "parameter_spin_box.h"

#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>

#include <vector>

namespace liversim {

EditorPanel::EditorPanel(ScenarioDocument& document, QWidget* parent)
    : QWidget(parent), document_(document) {}

void EditorPanel::fillFields(const std::function<void()>& show) {
  refreshing_ = true;
  std::vector<QSignalBlocker> blockers;
  for (QWidget* w : findChildren<QWidget*>()) blockers.emplace_back(w);
  show();
  blockers.clear();
  refreshing_ = false;
}

QHBoxLayout* EditorPanel::clearableRow(QLabel*& label, const char* labelName,
                                       const QString& buttonText, const char* buttonName,
                                       const QString& editText,
                                       std::function<void(Scenario&)> clear) {
  label = new QLabel;
  label->setObjectName(labelName);
  label->setWordWrap(true);
  auto* button = new QPushButton(buttonText);
  button->setObjectName(buttonName);
  connect(button, &QPushButton::clicked, this,
          [this, editText, clear] { document_.edit(editText, clear); });
  auto* row = new QHBoxLayout;
  row->addWidget(label, 1);
  row->addWidget(button);
  return row;
}

void EditorPanel::bindSpinBox(QDoubleSpinBox* box, const QString& text, int mergeKey,
                              std::function<void(Scenario&, double)> set) {
  connect(box, &QDoubleSpinBox::valueChanged, this, [this, text, mergeKey, set](double value) {
    if (!refreshing_)
      document_.edit(
          text, [&](Scenario& s) { set(s, value); }, mergeKey);
  });
}

QDoubleSpinBox* lengthSpinBox(double min_mm, double max_mm, const QString& tip) {
  return spinBox("", min_mm, max_mm, 1, " mm", tip);
}

}  // namespace liversim
