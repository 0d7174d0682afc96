#include "editor_lesion_panel.h"

#include "parameter_spin_box.h"

#include "liversim/engine/parameter_ranges.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QVBoxLayout>

#include <algorithm>

namespace liversim {

EditorLesionPanel::EditorLesionPanel(ScenarioDocument& scenarioDocument, QWidget* parent)
    : EditorPanel(scenarioDocument, parent) {
  auto* layout = new QVBoxLayout(this);
  lesionList_ = new QListWidget;
  lesionList_->setObjectName("lesionList");
  lesionList_->setMaximumHeight(90);
  layout->addWidget(lesionList_);
  connect(lesionList_, &QListWidget::currentRowChanged, this, [this](int row) {
    if (!refreshing()) emit lesionSelected(row);
  });
  auto* buttons = new QHBoxLayout;
  auto* addButton = new QPushButton(tr("Add"));
  addButton->setObjectName("addLesionButton");
  addButton->setToolTip(tr("A new lesion at the organ's centre (or use Place lesion)"));
  removeLesion_ = new QPushButton(tr("Remove"));
  removeLesion_->setObjectName("removeLesionButton");
  buttons->addWidget(addButton);
  buttons->addWidget(removeLesion_);
  layout->addLayout(buttons);
  connect(addButton, &QPushButton::clicked, this, &EditorLesionPanel::addRequested);
  connect(removeLesion_, &QPushButton::clicked, this, [this] {
    const int index = selected_;
    if (index < 0) return;
    document().edit(tr("Remove the lesion"),
                    [&](Scenario& s) { s.lesions.erase(s.lesions.begin() + index); });
    emit lesionSelected(std::min(index, int(document().scenario().lesions.size()) - 1));
  });

  lesionFields_ = new QWidget;
  auto* form = new QFormLayout(lesionFields_);
  form->setContentsMargins(0, 0, 0, 0);
  lesionName_ = new QLineEdit;
  lesionName_->setObjectName("lesionName");
  lesionName_->setToolTip(tr("The lesion's name, which the task refers to"));
  form->addRow(tr("Name"), lesionName_);
  connect(lesionName_, &QLineEdit::editingFinished, this, [this] {
    const std::string name = lesionName_->text().toStdString();
    const std::string old = document().scenario().lesions.at(selected_).name;
    document().edit(tr("Rename the lesion"), [&](Scenario& s) {
      s.lesions[selected_].name = name;
      if (s.task.lesion == old) s.task.lesion = name;  // the task follows its lesion
    });
  });
  for (int k = 0; k < 3; ++k) {
    lesionCentre_[k] = lengthSpinBox(
        -250.0, 250.0, tr("The lesion's centre along the scene's %1 axis").arg(kAxisNames[k]));
    lesionCentre_[k]->setObjectName(QString("lesionCentre%1").arg(kAxisNames[k]));
    lesionRadius_[k] = lengthSpinBox(1.0, 80.0,
                                     tr("The lesion's semi-axis along the scene's %1 axis "
                                        "(Shift-drag the lesion in the view to resize it)")
                                         .arg(kAxisNames[k]));
    lesionRadius_[k]->setObjectName(QString("lesionRadius%1").arg(kAxisNames[k]));
    connect(lesionCentre_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      editLesion(tr("Move the lesion"), kLesionCentre + k,
                 [&](LesionSpec& l) { l.centre_mm[k] = v; });
    });
    connect(lesionRadius_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      editLesion(tr("Resize the lesion"), kLesionRadius + k,
                 [&](LesionSpec& l) { l.radii_mm[k] = v; });
    });
  }
  const auto row = [](QDoubleSpinBox* const boxes[3]) {
    auto* w = new QWidget;
    auto* h = new QHBoxLayout(w);
    h->setContentsMargins(0, 0, 0, 0);
    for (int k = 0; k < 3; ++k) h->addWidget(boxes[k]);
    return w;
  };
  form->addRow(tr("Centre (x, y, z)"), row(lesionCentre_));
  form->addRow(tr("Semi-axes"), row(lesionRadius_));

  // A lesion's modulus is the parenchyma's times a ratio in range (validated on save).
  lesionStiffness_ = spinBox("lesionStiffness", 1.0, 2000.0, 2, " kPa", QString());
  {
    const ParameterRange& ratio = parameter_range(parameter::lesion_stiffness_ratio);
    lesionStiffness_->setToolTip(
        tr("Young's modulus of the lesion (instantaneous, with viscoelasticity): %1 to %2 times "
           "the parenchyma's. %3")
            .arg(ratio.min)
            .arg(ratio.max)
            .arg(QString::fromUtf8(ratio.why.data(), int(ratio.why.size()))));
  }
  form->addRow(tr("Stiffness E"), lesionStiffness_);
  connect(lesionStiffness_, &QDoubleSpinBox::valueChanged, this, [this](double kpa) {
    editLesion(tr("Change the lesion's stiffness"), kLesionStiffness,
               [&](LesionSpec& l) { l.youngs_modulus_pa = kpa * 1e3; });
  });
  lesionYieldLimit_ = optionalLesionValue(form, parameter::yield_limit, " Pa", "lesionYieldLimit",
                                          tr("Yield limit"), tr("Change the lesion's yield limit"),
                                          kLesionYield, &LesionSpec::yield_limit_pa);
  lesionViscosity_ = optionalLesionValue(form, parameter::eta1, " Pa·s", "lesionViscosity",
                                         tr("Viscosity η1"), tr("Change the lesion's viscosity"),
                                         kLesionViscosity, &LesionSpec::viscosity_pa_s);
  lesionFractureToughness_ =
      optionalLesionValue(form, parameter::fracture_toughness, " J/m²", "lesionFractureToughness",
                          tr("Fracture toughness J"), tr("Change the lesion's fracture toughness"),
                          kLesionFractureToughness, &LesionSpec::fracture_toughness_j_per_m2);
  lesionFractureToughness_->setToolTip(
      tr("How hard the lesion is to cut: the scalpel is held back by this times the length of "
         "its edge in the lesion. ") +
      lesionFractureToughness_->toolTip());
  lesionBladeFriction_ =
      optionalLesionValue(form, parameter::blade_friction, " N/m", "lesionBladeFriction",
                          tr("Blade friction"), tr("Change the lesion's blade friction"),
                          kLesionBladeFriction, &LesionSpec::blade_friction_n_per_m);
  lesionBladeFriction_->setToolTip(
      tr("The friction on the scalpel's sides in the lesion, per length of its edge in it. ") +
      lesionBladeFriction_->toolTip());
  lesionHidden_ = new QCheckBox(tr("Hidden from the trainee"));
  lesionHidden_->setObjectName("lesionHidden");
  lesionHidden_->setToolTip(tr("Not drawn in the workstation (palpation tasks)"));
  form->addRow(QString(), lesionHidden_);
  connect(lesionHidden_, &QCheckBox::toggled, this, [this](bool hidden) {
    editLesion(hidden ? tr("Hide the lesion") : tr("Show the lesion"), kNoMerge,
               [&](LesionSpec& l) { l.hidden = hidden; });
  });
  layout->addWidget(lesionFields_);
  layout->addStretch(1);
}

void EditorLesionPanel::refresh(int selected) {
  selected_ = selected;
  const Scenario& s = document().scenario();
  fillFields([&] {
    lesionList_->clear();
    for (const LesionSpec& l : s.lesions) lesionList_->addItem(QString::fromStdString(l.name));
    lesionList_->setCurrentRow(selected_);
    removeLesion_->setEnabled(selected_ >= 0);
    lesionFields_->setEnabled(selected_ >= 0);
    if (selected_ >= 0) {
      const LesionSpec& l = s.lesions[selected_];
      lesionName_->setText(QString::fromStdString(l.name));
      for (int k = 0; k < 3; ++k) {
        lesionCentre_[k]->setValue(l.centre_mm[k]);
        lesionRadius_[k]->setValue(l.radii_mm[k]);
      }
      lesionStiffness_->setValue(l.youngs_modulus_pa / 1e3);
      lesionYieldLimit_->setValue(l.yield_limit_pa.value_or(lesionYieldLimit_->minimum()));
      lesionViscosity_->setValue(l.viscosity_pa_s.value_or(lesionViscosity_->minimum()));
      lesionFractureToughness_->setValue(
          l.fracture_toughness_j_per_m2.value_or(lesionFractureToughness_->minimum()));
      lesionBladeFriction_->setValue(
          l.blade_friction_n_per_m.value_or(lesionBladeFriction_->minimum()));
      lesionHidden_->setChecked(l.hidden);
    }
    lesionYieldLimit_->setEnabled(s.effects.viscoplastic);
    lesionViscosity_->setEnabled(s.effects.viscoelastic);
  });
}

QDoubleSpinBox* EditorLesionPanel::optionalLesionValue(QFormLayout* form, std::string_view range,
                                                       const QString& suffix, const char* name,
                                                       const QString& label,
                                                       const QString& editText, int mergeKey,
                                                       std::optional<double> LesionSpec::*field) {
  // Below the range's minimum it reads "the parenchyma's": the lesion has no value of its own.
  QDoubleSpinBox* box = rangeSpinBox(range, 1.0, suffix, 0);
  box->setObjectName(name);
  box->setMinimum(box->minimum() - 1.0);
  box->setSpecialValueText(tr("the parenchyma's"));
  form->addRow(label, box);
  connect(box, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
    const bool own = v > box->minimum();
    editLesion(editText, mergeKey,
               [&](LesionSpec& l) { l.*field = own ? std::optional<double>(v) : std::nullopt; });
  });
  return box;
}

void EditorLesionPanel::editLesion(const QString& text, int mergeKey,
                                   const std::function<void(LesionSpec&)>& change) {
  if (refreshing() || selected_ < 0) return;
  const int index = selected_;
  document().edit(
      text, [&](Scenario& s) { change(s.lesions.at(index)); }, mergeKey);
}

}  // namespace liversim
