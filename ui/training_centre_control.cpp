#include "training_centre_control.h"

#include "session_review_window.h"

#include "liversim/storage/postgres_session_store.h"

#include <QDateTime>
#include <QLabel>

namespace liversim {

TrainingCentreControl::TrainingCentreControl(Workstation& station, QWidget* window)
    : QObject(window), station_(station), window_(window), label_(new QLabel(window)) {
  label_->setObjectName("trainingCentreStatus");
  label_->hide();
  QObject::connect(&timer_, &QTimer::timeout, this, [this] {
    if (station_.training_centre()) showStatus();
  });
  timer_.start(1000);
}

void TrainingCentreControl::startAtLaunch() {
  if (!station_.training_centre())
    if (const TrainingCentreSetting setting = trainingCentreSetting();
        !setting.serverUrl.isEmpty() && setting.passwordFromLibpq)
      connect(setting, {});
  showStatus();
}

bool TrainingCentreControl::connect(const TrainingCentreSetting& setting, const QString& password,
                                    QString* why) {
  const auto refuse = [&](const QString& reason) {
    if (why) *why = reason;
    return false;
  };
  if (setting.serverUrl.isEmpty()) {
    station_.disconnect_training_centre();
    setTrainingCentreSetting(setting);
    showStatus();
    return true;
  }
  ServerSettings server;
  try {
    server = parse_server_url(setting.serverUrl.toStdString());
  } catch (const std::invalid_argument& e) {
    return refuse(QString::fromStdString(e.what()));
  }
  if (!station_.sessions()) return refuse(tr("There is no sessions database to upload from."));
  // A wrong log-in is said here, at once; a server out of reach is not: the link retries.
  if (const auto refused = station_.connect_training_centre(server, password.toStdString()))
    return refuse(QString::fromStdString(*refused));
  setTrainingCentreSetting(setting);
  showStatus();
  return true;
}

QString TrainingCentreControl::statusText() const {
  TrainingCentreSync* link = station_.training_centre();
  if (!link)
    return trainingCentreSetting().serverUrl.isEmpty()
               ? QString()
               : tr("Training centre: not connected (Settings ▸ Training Centre Server…)");
  const TrainingCentreStatus status = link->status();
  const QString server = QString::fromStdString(server_name(link->server()));
  if (status.runs == 0) return tr("Training centre: connecting to %1…").arg(server);
  if (!status.last_run_ok())
    return tr("Training centre: %1 not reached, %n session(s) waiting", nullptr, status.waiting)
        .arg(server);
  return tr("Training centre: up to date at %1, %n session(s) uploaded", nullptr, status.uploaded)
      .arg(QDateTime::fromMSecsSinceEpoch(status.last_ok_unix_ms).toString("HH:mm"));
}

void TrainingCentreControl::showStatus() {
  const QString text = statusText();
  label_->setText(text);
  label_->setVisible(!text.isEmpty());
  TrainingCentreSync* link = station_.training_centre();
  const std::optional<std::string> problem = link ? link->status().problem : std::nullopt;
  label_->setToolTip(problem ? QString::fromStdString(*problem) : QString());
}

TrainingCentreDialog* TrainingCentreControl::openSettings() {
  auto* dialog = new TrainingCentreDialog(trainingCentreSetting(), window_);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  QObject::connect(dialog, &TrainingCentreDialog::requested, this,
                   [this, dialog](const TrainingCentreSetting& setting, const QString& password) {
                     QString why;
                     if (connect(setting, password, &why))
                       dialog->accept();
                     else
                       dialog->showError(why);
                   });
  dialog->show();
  return dialog;
}

SessionReviewWindow* TrainingCentreControl::openServerReview(const QString& instructor,
                                                             const QString& password,
                                                             QString* why) {
  const auto refuse = [&](const QString& reason) -> SessionReviewWindow* {
    if (why) *why = reason;
    return nullptr;
  };
  const TrainingCentreSetting setting = trainingCentreSetting();
  if (setting.serverUrl.isEmpty())
    return refuse(tr("No training centre server is set (Settings ▸ Training Centre Server…)."));
  try {
    // The instructor's own login on the server, at the same server and database.
    ServerSettings server = parse_server_url(setting.serverUrl.toStdString());
    server.user = instructor.toStdString();
    auto store = std::make_unique<PostgresSessionStore>(server, password.toStdString());
    std::optional<Instructor> grader =
        store->log_in_instructor(instructor.toStdString(), password.toStdString());
    if (!grader) return refuse(tr("%1 is not an instructor on the server.").arg(instructor));
    if (serverReview_) serverReview_->close();
    serverReview_ = new SessionReviewWindow(
        std::move(store), QString::fromStdString(server_name(server)), grader, window_);
    serverReview_->setAttribute(Qt::WA_DeleteOnClose);
    serverReview_->show();
    return serverReview_;
  } catch (const std::exception& e) {  // StorageError, a malformed address
    return refuse(QString::fromStdString(e.what()));
  }
}

}  // namespace liversim
