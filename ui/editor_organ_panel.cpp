#include "editor_organ_panel.h"

#include "accuracy_panel.h"

#include "liversim/meshing/surface_import.h"

#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>

namespace liversim {

EditorOrganPanel::EditorOrganPanel(ScenarioDocument& scenarioDocument, QWidget* parent)
    : EditorPanel(scenarioDocument, parent) {
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  organGeometry_ = new QComboBox;
  organGeometry_->setObjectName("organGeometry");
  organGeometry_->addItem(tr("Built-in liver"), int(OrganGeometry::built_in_liver));
  organGeometry_->addItem(tr("Surface model (OBJ, STL, PLY, glTF, FBX, 3DS)"),
                          int(OrganGeometry::surface_file));
  organGeometry_->addItem(tr("Tetrahedral mesh (.inp, .msh)"), int(OrganGeometry::tet_mesh_file));
  form->addRow(tr("Organ"), organGeometry_);
  connect(organGeometry_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing()) return;
    const auto geometry = OrganGeometry(organGeometry_->itemData(index).toInt());
    document().edit(tr("Change the organ"), [&](Scenario& s) {
      // Fields of another geometry are not written: back to their defaults.
      OrganSpec& o = s.organ;
      const OrganSpec defaults;
      o.geometry = geometry;
      if (geometry == OrganGeometry::built_in_liver) o.file.clear();
      if (geometry != OrganGeometry::tet_mesh_file) o.fixed_node_set.clear();
      if (geometry != OrganGeometry::surface_file) o.metres_per_unit = defaults.metres_per_unit;
      if (geometry != OrganGeometry::built_in_liver) o.fix_ligament = defaults.fix_ligament;
      if (geometry == OrganGeometry::tet_mesh_file) o.target_tet_count = defaults.target_tet_count;
    });
  });
  organFile_ = new QLineEdit;
  organFile_->setObjectName("organFile");
  organFile_->setToolTip(tr("The organ's file: relative to the scenario's folder, or absolute"));
  auto* choose = new QPushButton(tr("Choose…"));
  choose->setObjectName("chooseOrganFileButton");
  auto* fileRow = new QHBoxLayout;
  fileRow->addWidget(organFile_, 1);
  fileRow->addWidget(choose);
  form->addRow(tr("File"), fileRow);
  const auto setFile = [this](const QString& file) {
    document().edit(tr("Choose the organ's file"),
                    [&](Scenario& s) { s.organ.file = file.toStdString(); });
  };
  connect(organFile_, &QLineEdit::editingFinished, this,
          [this, setFile] { setFile(organFile_->text()); });
  connect(choose, &QPushButton::clicked, this, [this, setFile] {
    const bool surface = document().scenario().organ.geometry == OrganGeometry::surface_file;
    QStringList patterns;
    if (surface)
      for (const std::string& extension : surface_file_extensions())
        patterns << "*" + QString::fromStdString(extension);
    else
      patterns << "*.inp"
               << "*.msh";
    const QString folder = QString::fromStdString(document().organFolder().string());
    const QString chosen =
        QFileDialog::getOpenFileName(window(), tr("The organ's file"), folder,
                                     tr("Organ files (%1);;All files (*)").arg(patterns.join(' ')));
    if (chosen.isEmpty()) return;
    // Named relative to the scenario's folder when it is saved, so the two move together.
    setFile(document().file().isEmpty() ? chosen : QDir(folder).relativeFilePath(chosen));
  });
  lengthUnit_ = new QComboBox;
  lengthUnit_->setObjectName("organLengthUnit");
  for (const LengthUnit& unit : kLengthUnits)
    lengthUnit_->addItem(QString::fromUtf8(unit.name.data(), int(unit.name.size())), unit.metres);
  lengthUnit_->setToolTip(tr("The unit of the surface model's lengths (never guessed)"));
  form->addRow(tr("Length unit"), lengthUnit_);
  connect(lengthUnit_, &QComboBox::currentIndexChanged, this, [this](int index) {
    if (refreshing()) return;
    const double metres = lengthUnit_->itemData(index).toDouble();
    document().edit(tr("Change the organ's unit"),
                    [&](Scenario& s) { s.organ.metres_per_unit = metres; });
  });
  targetTetCount_ = new QSpinBox;
  targetTetCount_->setObjectName("targetTetCount");
  targetTetCount_->setRange(1000, 50000);
  targetTetCount_->setSingleStep(500);
  targetTetCount_->setKeyboardTracking(false);
  targetTetCount_->setToolTip(
      tr("Elements of the organ's mesh: 1000 to 50000 (more is more accurate and slower: see "
         "the cost in Tissue and effects)"));
  form->addRow(tr("Elements"), targetTetCount_);
  connect(targetTetCount_, &QSpinBox::valueChanged, this, [this](int count) {
    if (!refreshing())
      document().edit(
          tr("Change the element count"), [&](Scenario& s) { s.organ.target_tet_count = count; },
          kTargetTetCount);
  });
  fixedNodeSet_ = new QLineEdit;
  fixedNodeSet_->setObjectName("fixedNodeSet");
  fixedNodeSet_->setToolTip(tr("A node set of the mesh file held fixed (empty: none)"));
  form->addRow(tr("Fixed node set"), fixedNodeSet_);
  connect(fixedNodeSet_, &QLineEdit::editingFinished, this, [this] {
    const std::string set = fixedNodeSet_->text().toStdString();
    document().edit(tr("Change the fixed node set"),
                    [&](Scenario& s) { s.organ.fixed_node_set = set; });
  });
  organStatus_ = new QLabel;
  organStatus_->setObjectName("organStatus");
  organStatus_->setWordWrap(true);
  form->addRow(QString(), organStatus_);
  layout->addLayout(form);

  accuracy_ = new AccuracyPanel;
  accuracy_->setObjectName("accuracyPanel");
  connect(
      accuracy_, &AccuracyPanel::applyRequested, this, [this](const IntegratorSettings& settings) {
        document().edit(tr("Change the integrator"), [&](Scenario& s) { s.integrator = settings; });
      });
  layout->addWidget(accuracy_);
  layout->addStretch(1);
}

void EditorOrganPanel::refresh() {
  const Scenario& s = document().scenario();
  fillFields([&] {
    const OrganSpec& o = s.organ;
    organGeometry_->setCurrentIndex(organGeometry_->findData(int(o.geometry)));
    organFile_->setText(QString::fromStdString(o.file));
    organFile_->setEnabled(o.geometry != OrganGeometry::built_in_liver);
    lengthUnit_->setCurrentIndex(lengthUnit_->findData(o.metres_per_unit));
    lengthUnit_->setEnabled(o.geometry == OrganGeometry::surface_file);
    targetTetCount_->setValue(o.target_tet_count);
    targetTetCount_->setEnabled(o.geometry != OrganGeometry::tet_mesh_file);
    fixedNodeSet_->setText(QString::fromStdString(o.fixed_node_set));
    fixedNodeSet_->setEnabled(o.geometry == OrganGeometry::tet_mesh_file);
    accuracy_->setSettings(s.integrator);
  });
}

void EditorOrganPanel::showStatus(const QString& text) {
  organStatus_->setText(text);
}

}  // namespace liversim
