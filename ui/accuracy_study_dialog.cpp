#include "accuracy_study_dialog.h"

#include "accuracy_panel.h"

#include "liversim/meshing/liver_geometry.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QTableWidget>
#include <QVBoxLayout>

#include <fstream>
#include <memory>

namespace liversim {
namespace {

enum Column {
  kIntegratorColumn,
  kSettingColumn,
  kMeanStepColumn,
  kLargestErrorColumn,
  kLoadPointErrorColumn,
  kCostColumn,
  kRealTimeColumn,
  kBestColumn,
  kColumnCount
};

constexpr double kMicrometresPerMetre = 1e6;
constexpr double kMsPerSecond = 1e3;
constexpr int kProgressSteps = 1000;

QString effectsName(StudyEffects effects) {
  switch (effects) {
    case StudyEffects::elastic:
      return AccuracyStudyDialog::tr("Elastic (neo-Hookean)");
    case StudyEffects::viscoelastic:
      return AccuracyStudyDialog::tr("Viscoelastic");
    case StudyEffects::viscoplastic:
      return AccuracyStudyDialog::tr("Viscoelastic and viscoplastic");
    case StudyEffects::fibres:
      return AccuracyStudyDialog::tr("Elastic with fibres");
  }
  return {};
}

QTableWidgetItem* readOnlyItem(const QString& text) {
  auto* item = new QTableWidgetItem(text);
  item->setFlags(Qt::ItemIsSelectable | Qt::ItemIsEnabled);
  return item;
}

}  // namespace

AccuracyStudyDialog::AccuracyStudyDialog(QWidget* parent) : QDialog(parent) {
  setWindowTitle(tr("Accuracy Study: What Accuracy Costs in Time"));
  setObjectName("accuracyStudyDialog");

  const AccuracyStudyOptions defaults;
  tetCount_ = new QSpinBox(this);
  tetCount_->setObjectName("studyTetCount");
  tetCount_->setRange(200, 50000);
  tetCount_->setSingleStep(500);
  tetCount_->setValue(kDefaultLiverTetCount);
  tetCount_->setSuffix(tr(" tetrahedra"));
  tetCount_->setToolTip(tr("Size of the built-in liver the study runs on (about this many)."));

  effects_ = new QComboBox(this);
  effects_->setObjectName("studyEffects");
  for (StudyEffects effects : kAllStudyEffects)
    effects_->addItem(effectsName(effects), static_cast<int>(effects));
  effects_->setToolTip(
      tr("The tissue laws simulated (docs/accuracy-study.md gives the parameters)."));

  auto* integratorRow = new QHBoxLayout;
  for (IntegratorKind kind : kAllIntegrators) {
    auto* box = new QCheckBox(AccuracyPanel::integratorName(kind), this);
    box->setObjectName(QStringLiteral("studyIntegrator_%1").arg(static_cast<int>(kind)));
    box->setChecked(true);
    integrators_.emplace_back(kind, box);
    integratorRow->addWidget(box);
  }

  durationMs_ = new QSpinBox(this);
  durationMs_->setObjectName("studyDurationMs");
  durationMs_->setRange(1, 1000);  // whole load intervals of the largest step, 1 ms
  durationMs_->setValue(static_cast<int>(defaults.duration_s * kMsPerSecond));
  durationMs_->setSuffix(tr(" ms"));
  durationMs_->setToolTip(
      tr("Simulated time of each run: the liver is pulled at its marked point, the force rising "
         "smoothly to %1 N.")
          .arg(defaults.peak_force_n));

  auto* settingsNote = new QLabel(
      tr("Fixed-step schemes run at 1, 0.5 and 0.25 ms; Dormand–Prince at tolerances 0.1, 0.001 "
         "and 0.00001 µm. Errors are against Runge–Kutta 4 at 1/64 of the smallest step."),
      this);
  settingsNote->setWordWrap(true);

  run_ = new QPushButton(tr("&Run Study"), this);
  run_->setObjectName("runStudy");
  cancel_ = new QPushButton(tr("Cancel"), this);
  cancel_->setObjectName("cancelStudy");
  cancel_->setEnabled(false);
  progress_ = new QProgressBar(this);
  progress_->setObjectName("studyProgress");
  progress_->setRange(0, kProgressSteps);
  progress_->setValue(0);
  status_ = new QLabel(tr("Choose the runs and press Run Study."), this);
  status_->setObjectName("studyStatus");
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);

  table_ = new QTableWidget(0, kColumnCount, this);
  table_->setObjectName("studyResults");
  table_->setHorizontalHeaderLabels({tr("Integrator"), tr("Setting"), tr("Mean step (ms)"),
                                     tr("Largest error (µm)"), tr("Error at the load (µm)"),
                                     tr("Cost (s per simulated s)"), tr("Against real time"),
                                     tr("Best trade-off")});
  table_->horizontalHeaderItem(kLargestErrorColumn)
      ->setToolTip(tr("Largest distance of any node from the reference at the end."));
  table_->horizontalHeaderItem(kCostColumn)
      ->setToolTip(tr("Wall time of the steps per simulated second, on one thread of this "
                      "machine: below 1 runs faster than real time."));
  table_->horizontalHeaderItem(kBestColumn)
      ->setToolTip(tr("No other run is both more accurate and cheaper."));
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  table_->verticalHeader()->hide();

  useSetting_ = new QPushButton(tr("&Use This Setting"), this);
  useSetting_->setObjectName("useStudySetting");
  useSetting_->setToolTip(
      tr("Advance the running liver with the selected run's integrator and "
         "step."));
  useSetting_->setEnabled(false);
  saveCsv_ = new QPushButton(tr("&Save as CSV…"), this);
  saveCsv_->setObjectName("saveStudyCsv");
  saveCsv_->setEnabled(false);
  auto* close = new QDialogButtonBox(QDialogButtonBox::Close, this);

  auto* form = new QFormLayout;
  form->addRow(tr("Liver:"), tetCount_);
  form->addRow(tr("Tissue:"), effects_);
  form->addRow(tr("Integrators:"), integratorRow);
  form->addRow(tr("Duration:"), durationMs_);
  auto* runRow = new QHBoxLayout;
  runRow->addWidget(run_);
  runRow->addWidget(cancel_);
  runRow->addWidget(progress_, 1);
  auto* resultRow = new QHBoxLayout;
  resultRow->addWidget(useSetting_);
  resultRow->addWidget(saveCsv_);
  resultRow->addStretch(1);
  resultRow->addWidget(close);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form);
  layout->addWidget(settingsNote);
  layout->addLayout(runRow);
  layout->addWidget(status_);
  layout->addWidget(table_, 1);
  layout->addLayout(resultRow);
  resize(900, 560);

  connect(run_, &QPushButton::clicked, this, [this] { start(); });
  connect(cancel_, &QPushButton::clicked, this, [this] { cancel(); });
  connect(close, &QDialogButtonBox::rejected, this, &QDialog::reject);
  connect(table_, &QTableWidget::itemSelectionChanged, this,
          [this] { useSetting_->setEnabled(!table_->selectedItems().isEmpty()); });
  connect(useSetting_, &QPushButton::clicked, this, [this] {
    const int row = table_->currentRow();
    if (!result_ || row < 0 || row >= static_cast<int>(result_->rows.size())) return;
    const AccuracyStudyRow& run = result_->rows[static_cast<std::size_t>(row)];
    IntegratorSettings settings;
    settings.kind = run.integrator;
    settings.step_s = run.step_s;
    if (run.integrator == IntegratorKind::dopri5) settings.tolerance_m = run.tolerance_m;
    emit settingChosen(settings);
  });
  connect(saveCsv_, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save the study"),
                                                      "accuracy-study.csv", tr("CSV (*.csv)"));
    if (!path.isEmpty()) saveCsv(path);
  });
  // Closing the dialog stops a study under way: nobody would see its result.
  connect(this, &QDialog::finished, this, [this] { cancel(); });
}

AccuracyStudyDialog::~AccuracyStudyDialog() {
  cancelRequested_ = true;
  if (worker_.started()) worker_.wait();
}

AccuracyStudyOptions AccuracyStudyDialog::requestedOptions() const {
  AccuracyStudyOptions options;
  options.tet_counts = {tetCount_->value()};
  options.effects = {static_cast<StudyEffects>(effects_->currentData().toInt())};
  options.integrators.clear();
  for (const auto& [kind, box] : integrators_)
    if (box->isChecked()) options.integrators.push_back(kind);
  options.duration_s = durationMs_->value() / kMsPerSecond;
  return options;
}

bool AccuracyStudyDialog::start() {
  if (running()) {
    setStatus(tr("A study is running: wait for it or cancel it first."), true);
    return false;
  }
  const AccuracyStudyOptions options = requestedOptions();
  if (options.integrators.empty()) {
    setStatus(tr("Check at least one integrator to study."), true);
    return false;
  }
  runOptions_ = options;
  result_.reset();
  fillTable();
  cancelRequested_ = false;
  setRunning(true);
  setStatus(tr("Starting…"), false);
  worker_.start([this, options] {
    auto result = std::make_shared<std::optional<AccuracyStudyResult>>();
    QString error;
    bool wasCancelled = false;
    try {
      *result = run_accuracy_study(options, [this](const StudyProgressReport& report) {
        QMetaObject::invokeMethod(
            this, [this, report] { showProgress(report); }, Qt::QueuedConnection);
        return !cancelRequested_.load();
      });
    } catch (const StudyCancelled&) {
      wasCancelled = true;
    } catch (const std::exception& e) {
      error = QString::fromUtf8(e.what());
    }
    // The last thing the worker does; dropped if the dialog is gone (it joins this thread).
    QMetaObject::invokeMethod(
        this,
        [this, result, error, wasCancelled] { finish(std::move(*result), error, wasCancelled); },
        Qt::QueuedConnection);
  });
  return true;
}

void AccuracyStudyDialog::cancel() {
  if (!running()) return;
  cancelRequested_ = true;
  cancel_->setEnabled(false);
  setStatus(tr("Cancelling…"), false);
}

QString AccuracyStudyDialog::statusText() const {
  return status_->text();
}

bool AccuracyStudyDialog::saveCsv(const QString& path) {
  if (!result_) {
    setStatus(tr("There is no result to save yet: run the study first."), true);
    return false;
  }
  std::ofstream csv(path.toStdString());
  if (csv) write_accuracy_study_csv(csv, runOptions_, *result_);
  csv.close();
  if (!csv) {
    setStatus(tr("Could not write %1: check that its folder exists and is writable, and that "
                 "the disk has space.")
                  .arg(QDir::toNativeSeparators(path)),
              true);
    return false;
  }
  setStatus(tr("Saved %1.").arg(QDir::toNativeSeparators(path)), false);
  return true;
}

void AccuracyStudyDialog::showProgress(const StudyProgressReport& report) {
  if (cancelRequested_) return;  // a report posted before the cancel
  const double runs = report.runs_done + report.fraction_of_run;
  progress_->setValue(
      report.runs_total > 0 ? static_cast<int>(runs / report.runs_total * kProgressSteps) : 0);
  setStatus(tr("Run %1 of %2: %3")
                .arg(std::min(report.runs_done + 1, report.runs_total))
                .arg(report.runs_total)
                .arg(QString::fromStdString(report.running)),
            false);
}

void AccuracyStudyDialog::finish(std::optional<AccuracyStudyResult> result, const QString& error,
                                 bool wasCancelled) {
  worker_.wait();  // its last act was to post this
  setRunning(false);
  if (wasCancelled) {
    progress_->setValue(0);
    setStatus(tr("Cancelled: no result was kept."), false);
    emit cancelled();
    return;
  }
  if (!result) {
    progress_->setValue(0);
    setStatus(tr("The study stopped: %1").arg(error), true);
    emit failed(error);
    return;
  }
  result_ = std::move(result);
  progress_->setValue(kProgressSteps);
  fillTable();
  setStatus(tr("Done: %n run(s). Select one and press Use This Setting to advance the running "
               "liver with it.",
               nullptr, static_cast<int>(result_->rows.size())),
            false);
  emit finished();
}

void AccuracyStudyDialog::fillTable() {
  table_->clearContents();
  table_->setRowCount(result_ ? static_cast<int>(result_->rows.size()) : 0);
  saveCsv_->setEnabled(result_.has_value());
  useSetting_->setEnabled(false);
  if (!result_) return;
  std::vector<const AccuracyStudyRow*> runs;
  for (const AccuracyStudyRow& row : result_->rows) runs.push_back(&row);
  const std::vector<bool> best = pareto_front(runs);
  for (int r = 0; r < table_->rowCount(); ++r) {
    const AccuracyStudyRow& row = result_->rows[static_cast<std::size_t>(r)];
    const bool adaptive = row.integrator == IntegratorKind::dopri5;
    const QString setting =
        adaptive ? tr("tolerance %1 µm").arg(row.tolerance_m * kMicrometresPerMetre, 0, 'g', 3)
                 : tr("step %1 ms").arg(row.step_s * kMsPerSecond, 0, 'g', 3);
    const double cost = row.wall_per_simulated_s(runOptions_);
    const QString realTime = cost <= 1.0 ? tr("%1× faster").arg(1.0 / cost, 0, 'f', 1)
                                         : tr("%1× slower").arg(cost, 0, 'f', 1);
    QString meanStep = QString::number(row.mean_step_s(runOptions_) * kMsPerSecond, 'g', 3);
    if (row.steps.stability_limited_steps > 0) meanStep += tr(" (stability-limited)");
    table_->setItem(r, kIntegratorColumn,
                    readOnlyItem(AccuracyPanel::integratorName(row.integrator)));
    table_->setItem(r, kSettingColumn, readOnlyItem(setting));
    table_->setItem(r, kMeanStepColumn, readOnlyItem(meanStep));
    table_->setItem(
        r, kLargestErrorColumn,
        readOnlyItem(QString::number(row.max_node_error_m * kMicrometresPerMetre, 'g', 3)));
    table_->setItem(
        r, kLoadPointErrorColumn,
        readOnlyItem(QString::number(row.marked_point_error_m * kMicrometresPerMetre, 'g', 3)));
    table_->setItem(r, kCostColumn, readOnlyItem(QString::number(cost, 'g', 3)));
    table_->setItem(r, kRealTimeColumn, readOnlyItem(realTime));
    table_->setItem(r, kBestColumn,
                    readOnlyItem(best[static_cast<std::size_t>(r)] ? tr("yes") : QString()));
  }
}

void AccuracyStudyDialog::setRunning(bool running) {
  run_->setEnabled(!running);
  cancel_->setEnabled(running);
  for (QWidget* field : std::initializer_list<QWidget*>{tetCount_, effects_, durationMs_})
    field->setEnabled(!running);
  for (const auto& entry : integrators_) entry.second->setEnabled(!running);
  if (running) progress_->setValue(0);
}

void AccuracyStudyDialog::setStatus(const QString& text, bool isError) {
  status_->setText(text);
  status_->setStyleSheet(isError ? QStringLiteral("color: #b00020;") : QString());
}

}  // namespace liversim
