#pragma once
// "What accuracy costs in time", in the workstation: runs the accuracy study (accuracy_study.h)
// on a worker for the integrators chosen, with a progress bar and Cancel, and shows each run's
// error against the reference beside its cost per simulated second, the best trade-offs marked.
// A run's setting can be put to use on the running liver. `liversim-cli study accuracy` runs the
// full grid and writes docs/accuracy-study.md.

#include "liversim/studies/accuracy_study.h"

#include <QDialog>

#include <atomic>
#include <optional>
#include "liversim/engine/background_job.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QTableWidget;

namespace liversim {

class AccuracyStudyDialog : public QDialog {
  Q_OBJECT

 public:
  explicit AccuracyStudyDialog(QWidget* parent = nullptr);
  ~AccuracyStudyDialog() override;

  // The study the fields ask for: the built-in liver of that size, the effect set, the checked
  // integrators at the study's steps (1, 0.5, 0.25 ms) and tolerances, over the duration.
  AccuracyStudyOptions requestedOptions() const;

  // Starts the study on a worker; false (and the reason shown) if one is running or nothing is
  // checked. finished() follows, or cancelled() after cancel().
  bool start();
  void cancel();
  // Until finish() has taken the worker's result and joined it.
  bool running() const { return worker_.started(); }

  const std::optional<AccuracyStudyResult>& result() const { return result_; }
  // The status line: progress, the outcome, or what went wrong.
  QString statusText() const;

  // Writes the result as accuracy-study.csv does; false with the reason in the status line.
  bool saveCsv(const QString& path);

 signals:
  void finished();
  void cancelled();
  void failed(const QString& message);
  // "Use This Setting" on a run: its integrator and step (or tolerance).
  void settingChosen(const liversim::IntegratorSettings& settings);

 private:
  void showProgress(const StudyProgressReport& report);
  void finish(std::optional<AccuracyStudyResult> result, const QString& error, bool wasCancelled);
  void fillTable();
  void setRunning(bool running);
  void setStatus(const QString& text, bool isError);

  QSpinBox* tetCount_ = nullptr;
  QComboBox* effects_ = nullptr;
  std::vector<std::pair<IntegratorKind, QCheckBox*>> integrators_;
  QSpinBox* durationMs_ = nullptr;
  QPushButton* run_ = nullptr;
  QPushButton* cancel_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QLabel* status_ = nullptr;
  QTableWidget* table_ = nullptr;
  QPushButton* useSetting_ = nullptr;
  QPushButton* saveCsv_ = nullptr;

  AccuracyStudyOptions runOptions_;
  std::optional<AccuracyStudyResult> result_;
  std::atomic<bool> cancelRequested_{false};
  // Last: joined first when the dialog goes, while the object its reports are posted to lives.
  BackgroundJob worker_;
};

}  // namespace liversim
