#include "editor_tissue_panel.h"

#include "parameter_spin_box.h"

#include "liversim/engine/parameter_ranges.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QStandardItemModel>
#include <QVBoxLayout>

#include <array>
#include <iterator>

namespace liversim {
namespace {

// Where "down" is for the usual positions of the patient, in the scene's axes (liver_geometry.h:
// x to the patient's left, y superior, z anterior).
struct PatientPosition {
  const char* name;
  std::array<double, 3> down;
};
const PatientPosition kPatientPositions[] = {
    {QT_TRANSLATE_NOOP("liversim::EditorTissuePanel", "Supine: toward the back (−z)"),
     {0.0, 0.0, -1.0}},
    {QT_TRANSLATE_NOOP("liversim::EditorTissuePanel", "Upright: toward the feet (−y)"),
     {0.0, -1.0, 0.0}},
    {QT_TRANSLATE_NOOP("liversim::EditorTissuePanel", "Prone: toward the front (+z)"),
     {0.0, 0.0, 1.0}},
};

}  // namespace

EditorTissuePanel::EditorTissuePanel(
    ScenarioDocument& scenarioDocument,
    std::function<std::optional<Eigen::Vector3d>()> screenHorizontal, QWidget* parent)
    : EditorPanel(scenarioDocument, parent), screenHorizontal_(std::move(screenHorizontal)) {
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  youngsModulus_ = rangeSpinBox(parameter::youngs_modulus, 1e3, " kPa", 2);
  youngsModulus_->setObjectName("parenchymaStiffness");
  form->addRow(tr("Parenchyma E"), youngsModulus_);
  connect(youngsModulus_, &QDoubleSpinBox::valueChanged, this, [this](double kpa) {
    if (refreshing()) return;
    document().edit(
        tr("Change the parenchyma's stiffness"),
        [&](Scenario& s) {
          const double old = s.parenchyma.elastic.youngs_modulus_pa;
          s.parenchyma.elastic.youngs_modulus_pa = kpa * 1e3;
          // With viscoelasticity E = E1 + E2: both arms follow.
          if (auto& ve = s.parenchyma.viscoelastic; ve && old > 0.0)
            ve = with_instantaneous_modulus(*ve, kpa * 1e3);
        },
        kYoungsModulus);
  });
  poissonRatio_ = rangeSpinBox(parameter::poisson_ratio, 1.0, QString(), 3);
  poissonRatio_->setObjectName("parenchymaPoissonRatio");
  poissonRatio_->setSingleStep(0.005);
  form->addRow(tr("Poisson's ratio ν"), poissonRatio_);
  bindSpinBox(poissonRatio_, tr("Change Poisson's ratio"), kPoissonRatio,
              [](Scenario& s, double v) { s.parenchyma.elastic.poisson_ratio = v; });
  // Not effects: what holds the scalpel back, in any scene that offers it.
  const auto cuttingValue = [&](std::string_view range, const char* suffix, const char* name,
                                const QString& label, const QString& what, const QString& editText,
                                int mergeKey, void (*set)(Scenario&, double)) {
    QDoubleSpinBox* box = rangeSpinBox(range, 1.0, suffix, 0);
    box->setObjectName(name);
    box->setToolTip(what + box->toolTip());
    form->addRow(label, box);
    bindSpinBox(box, editText, mergeKey, set);
    return box;
  };
  fractureToughness_ = cuttingValue(
      parameter::fracture_toughness, " J/m²", "parenchymaFractureToughness",
      tr("Fracture toughness J"),
      tr("The energy to cut new surface: the scalpel is held back by it times the length of its "
         "edge in the tissue, and breaks in when pressed that hard. "),
      tr("Change the fracture toughness"), kFractureToughness,
      [](Scenario& s, double v) { s.parenchyma.fracture_toughness_j_per_m2 = v; });
  bladeFriction_ = cuttingValue(
      parameter::blade_friction, " N/m", "parenchymaBladeFriction", tr("Blade friction"),
      tr("The friction on the scalpel's sides: it is held back by this times the length of its "
         "edge in the tissue, whichever way it moves while it cuts (assumed: 70 N/m). "),
      tr("Change the blade friction"), kBladeFriction,
      [](Scenario& s, double v) { s.parenchyma.blade_friction_n_per_m = v; });
  layout->addLayout(form);

  auto* effects = new QGroupBox(tr("Effects simulated (an effect off costs nothing)"));
  auto* effectsLayout = new QVBoxLayout(effects);
  const QString names[4] = {
      tr("Near-incompressibility (averaged pressure)"), tr("Viscoelasticity (relaxation, creep)"),
      tr("Viscoplasticity above the yield limit"), tr("Fibre anisotropy (HGO)")};
  const char* objects[4] = {"effectIncompressibility", "effectViscoelastic", "effectViscoplastic",
                            "effectFibres"};
  for (int i = 0; i < 4; ++i) {
    effects_[i] = new QCheckBox(names[i]);
    effects_[i]->setObjectName(objects[i]);
    effectsLayout->addWidget(effects_[i]);
    connect(effects_[i], &QCheckBox::toggled, this, [this, i](bool on) {
      if (refreshing()) return;
      const QString text = on ? tr("Switch an effect on") : tr("Switch an effect off");
      document().edit(text, [&](Scenario& s) {
        TissueSpec& t = s.parenchyma;
        const double e = t.elastic.youngs_modulus_pa;
        switch (i) {
          case 0:
            s.effects.near_incompressibility = on;
            break;
          case 1:
            s.effects.viscoelastic = on;
            if (!on) s.effects.viscoplastic = false;  // it needs viscoelasticity
            // The seed's split of E and its η1 when none was set (kept when switched off).
            if (on && !t.viscoelastic) t.viscoelastic = seed_viscoelastic_split(e);
            break;
          case 2:
            s.effects.viscoplastic = on;
            if (on) s.effects.viscoelastic = true;
            if (on && !t.viscoelastic) t.viscoelastic = seed_viscoelastic_split(e);
            if (on && !t.viscoplastic) t.viscoplastic = ViscoplasticParameters{50.0, 2000.0, 0.5};
            break;
          case 3:
            s.effects.fibres = on;
            if (on && !t.fibres) t.fibres = FibreSpec{1000.0, 2.0, {1.0, 0.0, 0.0}};
            break;
        }
      });
    });
  }
  gravity_ = new QCheckBox(tr("Gravity (the organ's weight)"));
  gravity_->setObjectName("effectGravity");
  effectsLayout->addWidget(gravity_);
  connect(gravity_, &QCheckBox::toggled, this, [this](bool on) {
    if (refreshing()) return;
    document().edit(on ? tr("Switch gravity on") : tr("Switch gravity off"),
                    [&](Scenario& s) { s.effects.gravity = on; });
  });
  auto* gravityForm = new QFormLayout;
  gravityDirection_ = new QComboBox;
  gravityDirection_->setObjectName("gravityDirection");
  gravityDirection_->setToolTip(tr("Which way is down: the patient's position on the table"));
  for (const PatientPosition& position : kPatientPositions)
    gravityDirection_->addItem(tr(position.name));
  gravityDirection_->addItem(tr("As the file sets it"));  // shown only for another direction
  if (auto* items = qobject_cast<QStandardItemModel*>(gravityDirection_->model()))
    items->item(gravityDirection_->count() - 1)->setEnabled(false);  // not a choice
  gravityForm->addRow(tr("Down"), gravityDirection_);
  connect(gravityDirection_, &QComboBox::activated, this, [this](int index) {
    if (refreshing() || index >= int(std::size(kPatientPositions))) return;
    document().edit(tr("Change gravity's direction"), [&](Scenario& s) {
      s.effects.gravity_direction = kPatientPositions[index].down;
    });
  });
  gravityStrength_ = new QDoubleSpinBox;
  gravityStrength_->setObjectName("gravityStrength");
  gravityStrength_->setRange(kMinGravityMPerS2, kMaxGravityMPerS2);
  gravityStrength_->setDecimals(2);
  gravityStrength_->setSingleStep(0.5);
  gravityStrength_->setSuffix(" m/s²");
  gravityStrength_->setKeyboardTracking(false);
  gravityStrength_->setToolTip(tr("Gravity's strength g: 9.81 m/s² on Earth"));
  gravityForm->addRow(tr("g"), gravityStrength_);
  bindSpinBox(gravityStrength_, tr("Change gravity's strength"), kGravityStrength,
              [](Scenario& s, double v) { s.effects.gravity_m_per_s2 = v; });
  effectsLayout->addLayout(gravityForm);
  cost_ = new QLabel;
  cost_->setObjectName("effectsCost");
  cost_->setWordWrap(true);
  cost_->setToolTip(
      tr("Steps per second of this scenario on this machine, measured now: its "
         "model stepped for half a second under a 0.5 N pull"));
  effectsLayout->addWidget(cost_);
  layout->addWidget(effects);

  // The laws' parameters: shown while their effect is on (kept, not shown, while it is off).
  auto* laws = new QGroupBox(tr("Laws of the effects"));
  auto* lawForm = new QFormLayout(laws);
  const auto law = [&](QDoubleSpinBox*& box, std::string_view range, double scale,
                       const QString& suffix, int decimals, const char* name, const QString& label,
                       int mergeKey, std::function<void(TissueSpec&, double)> set) {
    box = rangeSpinBox(range, scale, suffix, decimals);
    box->setObjectName(name);
    lawForm->addRow(label, box);
    bindSpinBox(box, tr("Change %1").arg(label), mergeKey,
                [set](Scenario& s, double v) { set(s.parenchyma, v); });
  };
  law(viscoelasticE1_, parameter::e1, 1.0, " Pa", 0, "viscoelasticE1", tr("Maxwell arm E1"),
      kViscoelasticE1, [](TissueSpec& t, double v) {
        // E = E1 + E2 stays the parenchyma's E.
        if (t.viscoelastic)
          t.viscoelastic = with_maxwell_arm(*t.viscoelastic, v, t.elastic.youngs_modulus_pa);
      });
  viscoelasticE1_->setToolTip(viscoelasticE1_->toolTip() +
                              tr(" E2 = E − E1 follows, so that E stays the parenchyma's."));
  law(viscoelasticEta1_, parameter::eta1, 1.0, " Pa·s", 0, "viscoelasticEta1", tr("Maxwell arm η1"),
      kViscoelasticEta1, [](TissueSpec& t, double v) {
        if (t.viscoelastic) t.viscoelastic->eta1_pa_s = v;
      });
  law(yieldLimit_, parameter::yield_limit, 1.0, " Pa", 0, "viscoplasticYieldLimit",
      tr("Yield limit σs"), kYieldLimit, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->yield_limit_pa = v;
      });
  law(viscoplasticEta2_, parameter::eta2, 1.0, " Pa·sⁿ", 0, "viscoplasticEta2",
      tr("Viscoplastic η2"), kViscoplasticEta2, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->eta2_pa_s_pow_n = v;
      });
  law(creepIndex_, parameter::creep_index, 1.0, QString(), 2, "creepIndex", tr("Creep index n"),
      kCreepIndex, [](TissueSpec& t, double v) {
        if (t.viscoplastic) t.viscoplastic->creep_index_n = v;
      });
  law(fibreK1_, parameter::fibre_k1, 1.0, " Pa", 0, "fibreK1", tr("Fibre k1"), kFibreK1,
      [](TissueSpec& t, double v) {
        if (t.fibres) t.fibres->k1_pa = v;
      });
  law(fibreK2_, parameter::fibre_k2, 1.0, QString(), 2, "fibreK2", tr("Fibre k2"), kFibreK2,
      [](TissueSpec& t, double v) {
        if (t.fibres) t.fibres->k2 = v;
      });
  layout->addWidget(laws);

  auto* fibres = new QGroupBox(tr("Fibre direction"));
  auto* fibreLayout = new QHBoxLayout(fibres);
  for (int k = 0; k < 3; ++k) {
    fibreDirection_[k] = new QDoubleSpinBox;
    fibreDirection_[k]->setObjectName(QString("fibreDirection%1").arg(kAxisNames[k]));
    fibreDirection_[k]->setRange(-1.0, 1.0);
    fibreDirection_[k]->setDecimals(3);
    fibreDirection_[k]->setSingleStep(0.1);
    fibreDirection_[k]->setKeyboardTracking(false);
    fibreDirection_[k]->setToolTip(tr("The fibres' reference direction (normalised on saving)"));
    fibreLayout->addWidget(fibreDirection_[k]);
    connect(fibreDirection_[k], &QDoubleSpinBox::valueChanged, this, [this, k](double v) {
      if (refreshing() || !document().scenario().parenchyma.fibres) return;
      document().edit(
          tr("Change the fibre direction"),
          [&](Scenario& s) { s.parenchyma.fibres->direction[k] = v; }, kFibreDirection);
    });
  }
  fibreAlongView_ = new QPushButton(tr("Across the view"));
  fibreAlongView_->setObjectName("fibreAlongViewButton");
  fibreAlongView_->setToolTip(tr("Fibres along the screen's horizontal, as the organ is seen now"));
  fibreLayout->addWidget(fibreAlongView_);
  connect(fibreAlongView_, &QPushButton::clicked, this, [this] {
    if (!document().scenario().parenchyma.fibres) return;
    const std::optional<Eigen::Vector3d> right = screenHorizontal_();
    if (!right) return;
    const Eigen::Vector3d d = right->normalized();
    document().edit(tr("Set the fibre direction"), [&](Scenario& s) {
      s.parenchyma.fibres->direction = {d.x(), d.y(), d.z()};
    });
  });
  layout->addWidget(fibres);

  auto* fixed = new QGroupBox(tr("Fixed regions"));
  auto* fixedForm = new QFormLayout(fixed);
  brushRadius_ = lengthSpinBox(2.0, 40.0, tr("Radius of the painting brush (Paint fixed)"));
  brushRadius_->setObjectName("brushRadius");
  brushRadius_->setValue(10.0);
  fixedForm->addRow(tr("Brush"), brushRadius_);
  QHBoxLayout* fixedRow = clearableRow(fixedRegions_, "fixedRegions", tr("Clear painted"),
                                       "clearFixedButton", tr("Clear the painted fixed regions"),
                                       [](Scenario& s) { s.organ.fixed_balls.clear(); });
  fixedForm->addRow(tr("Painted"), fixedRow);
  fixLigament_ = new QCheckBox(tr("Coronary ligament (built-in liver)"));
  fixLigament_->setObjectName("fixLigament");
  fixedForm->addRow(QString(), fixLigament_);
  connect(fixLigament_, &QCheckBox::toggled, this, [this](bool on) {
    if (!refreshing())
      document().edit(tr("Change the ligament"), [&](Scenario& s) { s.organ.fix_ligament = on; });
  });
  layout->addWidget(fixed);
  layout->addStretch(1);
}

void EditorTissuePanel::refresh() {
  const Scenario& s = document().scenario();
  fillFields([&] {
    youngsModulus_->setValue(s.parenchyma.elastic.youngs_modulus_pa / 1e3);
    poissonRatio_->setValue(s.parenchyma.elastic.poisson_ratio);
    fractureToughness_->setValue(s.parenchyma.fracture_toughness_j_per_m2);
    bladeFriction_->setValue(s.parenchyma.blade_friction_n_per_m);
    const bool on[4] = {s.effects.near_incompressibility, s.effects.viscoelastic,
                        s.effects.viscoplastic, s.effects.fibres};
    for (int i = 0; i < 4; ++i) effects_[i]->setChecked(on[i]);
    gravity_->setChecked(s.effects.gravity);
    int position = int(std::size(kPatientPositions));  // another direction: "as the file sets it"
    for (int p = 0; p < int(std::size(kPatientPositions)); ++p)
      if (kPatientPositions[p].down == s.effects.gravity_direction) position = p;
    gravityDirection_->setCurrentIndex(position);
    gravityDirection_->setEnabled(s.effects.gravity);
    gravityStrength_->setValue(s.effects.gravity_m_per_s2);
    gravityStrength_->setEnabled(s.effects.gravity);
    for (int k = 0; k < 3; ++k) {
      fibreDirection_[k]->setEnabled(s.parenchyma.fibres.has_value());
      if (s.parenchyma.fibres) fibreDirection_[k]->setValue(s.parenchyma.fibres->direction[k]);
    }
    fibreAlongView_->setEnabled(s.parenchyma.fibres.has_value());
    const TissueSpec& t = s.parenchyma;
    const auto showLaw = [](QDoubleSpinBox* box, bool on, double value) {
      box->setEnabled(on);
      if (on) box->setValue(value);
    };
    const bool ve = s.effects.viscoelastic && t.viscoelastic,
               vp = s.effects.viscoplastic && t.viscoplastic, fi = s.effects.fibres && t.fibres;
    showLaw(viscoelasticE1_, ve, ve ? t.viscoelastic->e1_pa : 0.0);
    showLaw(viscoelasticEta1_, ve, ve ? t.viscoelastic->eta1_pa_s : 0.0);
    showLaw(yieldLimit_, vp, vp ? t.viscoplastic->yield_limit_pa : 0.0);
    showLaw(viscoplasticEta2_, vp, vp ? t.viscoplastic->eta2_pa_s_pow_n : 0.0);
    showLaw(creepIndex_, vp, vp ? t.viscoplastic->creep_index_n : 0.0);
    showLaw(fibreK1_, fi, fi ? t.fibres->k1_pa : 0.0);
    showLaw(fibreK2_, fi, fi ? t.fibres->k2 : 0.0);
    fixedRegions_->setText(tr("%n ball(s)", "", int(s.organ.fixed_balls.size())));
    fixLigament_->setChecked(s.organ.fix_ligament);
    fixLigament_->setEnabled(s.organ.geometry == OrganGeometry::built_in_liver);
  });
}

double EditorTissuePanel::brushRadius_mm() const {
  return brushRadius_->value();
}

void EditorTissuePanel::showCost(const QString& text) {
  cost_->setText(text);
}

QString EditorTissuePanel::costText() const {
  return cost_->text();
}

}  // namespace liversim
