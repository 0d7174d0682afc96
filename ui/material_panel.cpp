#include "material_panel.h"

#include "parameter_spin_box.h"

#include "liversim/engine/parameter_ranges.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QVBoxLayout>

#include <initializer_list>

namespace liversim {

MaterialPanel::MaterialPanel(QWidget* parent) : QWidget(parent) {
  form_ = new QFormLayout;
  const auto add = [&](QDoubleSpinBox*& box, std::string_view range, double scale,
                       const QString& suffix, int decimals, const char* name,
                       const QString& label) {
    box = rangeSpinBox(range, scale, suffix, decimals);
    box->setParent(this);
    box->setObjectName(name);
    // The documented range, in the interface's language (docs/tissue-model.md says why).
    box->setToolTip(
        tr("%1: %2 to %3%4").arg(label).arg(box->minimum()).arg(box->maximum()).arg(suffix));
    form_->addRow(label, box);
    connect(box, &QDoubleSpinBox::valueChanged, this, [this] { request(); });
  };
  add(youngsModulusKpa_, parameter::youngs_modulus, 1e3, tr(" kPa"), 2, "materialYoungsModulus",
      tr("Young's modulus E"));
  add(poissonRatio_, parameter::poisson_ratio, 1.0, QString(), 3, "materialPoissonRatio",
      tr("Poisson's ratio ν"));
  poissonRatio_->setSingleStep(0.005);
  add(density_, parameter::density, 1.0, tr(" kg/m³"), 0, "materialDensity", tr("Density ρ"));
  add(fractureToughness_, parameter::fracture_toughness, 1.0, tr(" J/m²"), 0,
      "materialFractureToughness", tr("Fracture toughness J"));
  fractureToughness_->setToolTip(fractureToughness_->toolTip() +
                                 tr(". What holds the scalpel back as it cuts."));
  add(bladeFriction_, parameter::blade_friction, 1.0, tr(" N/m"), 0, "materialBladeFriction",
      tr("Blade friction"));
  bladeFriction_->setToolTip(bladeFriction_->toolTip() +
                             tr(". The friction on the scalpel's sides as it cuts."));
  add(e1_, parameter::e1, 1.0, tr(" Pa"), 0, "materialE1", tr("Maxwell arm E1"));
  e1_->setToolTip(e1_->toolTip() + tr(". E2 = E − E1 follows."));
  add(eta1_, parameter::eta1, 1.0, tr(" Pa·s"), 0, "materialEta1", tr("Maxwell arm η1"));
  add(yieldLimit_, parameter::yield_limit, 1.0, tr(" Pa"), 0, "materialYieldLimit",
      tr("Yield limit σs"));
  add(eta2_, parameter::eta2, 1.0, tr(" Pa·sⁿ"), 0, "materialEta2", tr("Viscoplastic η2"));
  add(creepIndex_, parameter::creep_index, 1.0, QString(), 2, "materialCreepIndex",
      tr("Creep index n"));
  add(fibreK1_, parameter::fibre_k1, 1.0, tr(" Pa"), 0, "materialFibreK1", tr("Fibre k1"));
  add(fibreK2_, parameter::fibre_k2, 1.0, QString(), 2, "materialFibreK2", tr("Fibre k2"));
  gravity_ = new QCheckBox(tr("The organ's weight pulls it onto its bed"), this);
  gravity_->setObjectName("materialGravity");
  form_->addRow(tr("Gravity"), gravity_);
  connect(gravity_, &QCheckBox::toggled, this, [this](bool on) {
    if (!refreshing_) emit gravityRequested(on);
  });

  derived_ = new QLabel(this);
  derived_->setObjectName("materialDerived");
  derived_->setWordWrap(true);
  status_ = new QLabel(this);
  status_->setObjectName("materialStatus");
  status_->setWordWrap(true);
  error_ = new QLabel(this);
  error_->setObjectName("materialError");
  error_->setWordWrap(true);
  error_->setStyleSheet("color: #b00020;");
  error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_->hide();
  readOnlyNote_ = new QLabel(tr("Trainee mode: the tissue is the scenario's. An instructor can "
                                "change it in instructor mode (Settings menu)."),
                             this);
  readOnlyNote_->setObjectName("materialReadOnlyNote");
  readOnlyNote_->setWordWrap(true);
  readOnlyNote_->hide();

  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form_);
  layout->addWidget(derived_);
  layout->addWidget(status_);
  layout->addWidget(error_);
  layout->addWidget(readOnlyNote_);
  layout->addStretch(1);
  setToolTip(
      tr("A value entered is applied to the running liver at once; it goes on from where "
         "it is. The laws of effects the scene leaves off are not simulated and not "
         "shown."));
  showTissue(TissueSpec{}, EffectsSpec{});
}

void MaterialPanel::showTissue(const TissueSpec& tissue, const EffectsSpec& effects) {
  inUse_ = tissue;
  effects_ = effects;
  refreshing_ = true;
  youngsModulusKpa_->setValue(tissue.elastic.youngs_modulus_pa / 1e3);
  shownModulusKpa_ = youngsModulusKpa_->value();
  poissonRatio_->setValue(tissue.elastic.poisson_ratio);
  density_->setValue(tissue.elastic.density_kg_per_m3);
  fractureToughness_->setValue(tissue.fracture_toughness_j_per_m2);
  bladeFriction_->setValue(tissue.blade_friction_n_per_m);
  const bool viscoelastic = effects.viscoelastic && tissue.viscoelastic;
  const bool viscoplastic = effects.viscoplastic && tissue.viscoplastic;
  const bool fibres = effects.fibres && tissue.fibres;
  if (viscoelastic) {
    e1_->setValue(tissue.viscoelastic->e1_pa);
    eta1_->setValue(tissue.viscoelastic->eta1_pa_s);
  }
  if (viscoplastic) {
    yieldLimit_->setValue(tissue.viscoplastic->yield_limit_pa);
    eta2_->setValue(tissue.viscoplastic->eta2_pa_s_pow_n);
    creepIndex_->setValue(tissue.viscoplastic->creep_index_n);
  }
  if (fibres) {
    fibreK1_->setValue(tissue.fibres->k1_pa);
    fibreK2_->setValue(tissue.fibres->k2);
  }
  for (QDoubleSpinBox* box : {e1_, eta1_}) form_->setRowVisible(box, viscoelastic);
  for (QDoubleSpinBox* box : {yieldLimit_, eta2_, creepIndex_})
    form_->setRowVisible(box, viscoplastic);
  for (QDoubleSpinBox* box : {fibreK1_, fibreK2_}) form_->setRowVisible(box, fibres);
  gravity_->setChecked(effects.gravity);
  const auto& down = effects.gravity_direction;
  gravity_->setToolTip(tr("g = %1 m/s² toward (%2, %3, %4), the scene's axes; it rests on a bed "
                          "shaped as its underside, and on a tray around it")
                           .arg(effects.gravity_m_per_s2, 0, 'g', 3)
                           .arg(down[0], 0, 'g', 3)
                           .arg(down[1], 0, 'g', 3)
                           .arg(down[2], 0, 'g', 3));
  refreshing_ = false;
  error_->hide();
  error_->clear();
  status_->setText(tr("In use. Effects left off (not simulated): %1.").arg([&] {
    QStringList off;
    if (!effects.viscoelastic) off << tr("viscoelasticity");
    if (!effects.viscoplastic) off << tr("viscoplasticity");
    if (!effects.fibres) off << tr("fibres");
    if (!effects.gravity) off << tr("gravity");
    return off.isEmpty() ? tr("none") : off.join(tr(", "));
  }()));
  updateNotes();
}

TissueSpec MaterialPanel::requestedTissue() const {
  TissueSpec tissue = inUse_;
  tissue.elastic.youngs_modulus_pa = youngsModulusKpa_->value() * 1e3;
  tissue.elastic.poisson_ratio = poissonRatio_->value();
  tissue.elastic.density_kg_per_m3 = density_->value();
  tissue.fracture_toughness_j_per_m2 = fractureToughness_->value();
  tissue.blade_friction_n_per_m = bladeFriction_->value();
  if (effects_.viscoelastic && tissue.viscoelastic) {
    tissue.viscoelastic =
        with_maxwell_arm(*tissue.viscoelastic, e1_->value(), tissue.elastic.youngs_modulus_pa);
    tissue.viscoelastic->eta1_pa_s = eta1_->value();
  }
  if (effects_.viscoplastic && tissue.viscoplastic)
    tissue.viscoplastic =
        ViscoplasticParameters{yieldLimit_->value(), eta2_->value(), creepIndex_->value()};
  if (effects_.fibres && tissue.fibres) {
    tissue.fibres->k1_pa = fibreK1_->value();
    tissue.fibres->k2 = fibreK2_->value();
  }
  return tissue;
}

void MaterialPanel::request() {
  if (refreshing_) return;
  // With viscoelasticity E = E1 + E2: a new E scales both arms, so the relaxation keeps its shape.
  if (youngsModulusKpa_->value() != shownModulusKpa_ && effects_.viscoelastic &&
      inUse_.viscoelastic && shownModulusKpa_ > 0.0) {
    refreshing_ = true;
    const ViscoelasticParameters shown{e1_->value(), shownModulusKpa_ * 1e3 - e1_->value(), 0.0};
    e1_->setValue(with_instantaneous_modulus(shown, youngsModulusKpa_->value() * 1e3).e1_pa);
    refreshing_ = false;
  }
  shownModulusKpa_ = youngsModulusKpa_->value();
  updateNotes();
  emit tissueRequested(requestedTissue());
}

void MaterialPanel::updateNotes() {
  const TissueSpec tissue = requestedTissue();
  if (effects_.viscoelastic && tissue.viscoelastic) {
    const ViscoelasticParameters& law = *tissue.viscoelastic;
    derived_->setText(tr("E2 = E − E1 = %1 Pa; relaxation time τ = η1/E1 = %2 s")
                          .arg(law.e2_pa, 0, 'f', 0)
                          .arg(law.relaxation_time_s(), 0, 'g', 3));
    derived_->show();
  } else {
    derived_->hide();
  }
}

void MaterialPanel::setEditable(bool editable) {
  editable_ = editable;
  for (QDoubleSpinBox* box : findChildren<QDoubleSpinBox*>()) box->setReadOnly(!editable);
  readOnlyNote_->setVisible(!editable);
}

void MaterialPanel::setGravityEditable(bool editable) {
  gravity_->setEnabled(editable);
}

bool MaterialPanel::gravityOn() const {
  return gravity_->isChecked();
}

void MaterialPanel::setSwitchingGravity() {
  status_->setText(gravity_->isChecked() ? tr("Switching gravity on…")
                                         : tr("Switching gravity off…"));
}

void MaterialPanel::setBusy(bool busy) {
  if (busy) status_->setText(tr("Applying the new tissue to the running liver…"));
}

void MaterialPanel::showError(const QString& message) {
  showTissue(inUse_, effects_);  // the fields go back to the tissue in use, which stays
  error_->setText(tr("Not applied: %1").arg(message));
  error_->show();
}

QString MaterialPanel::errorText() const {
  return error_->isHidden() ? QString() : error_->text();
}

}  // namespace liversim
