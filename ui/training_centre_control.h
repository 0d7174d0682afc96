#pragma once
// The training centre as the workstation's user sets it up and follows it
// (docs/training-centre.md): the server's address saved in the settings (never the password), the
// station's background link started from it, its status in the status bar, and an instructor's
// review of the sessions on the server.

#include "training_centre_dialog.h"

#include "liversim/station/workstation.h"

#include <QObject>
#include <QPointer>
#include <QTimer>

class QLabel;

namespace liversim {

class SessionReviewWindow;

class TrainingCentreControl : public QObject {
  Q_OBJECT

 public:
  // `window`: the dialogs' parent; the status label is made for its status bar.
  TrainingCentreControl(Workstation& station, QWidget* window);
  QLabel* statusLabel() const { return label_; }

  // With a sessions database newly opened: a link already running follows it; a saved server
  // whose password libpq finds is connected to at once.
  void startAtLaunch();
  // Saves the address and starts the link; an empty address stops it. False, with why, for an
  // address that is none, a wrong log-in or without a sessions database (a server out of reach is
  // not refused: the link retries).
  bool connect(const TrainingCentreSetting& setting, const QString& password,
               QString* why = nullptr);
  QString statusText() const;
  void showStatus();
  TrainingCentreDialog* openSettings();
  // The review of every session on the server, as an instructor's own server login; null, saying
  // why, without a server set or when it refuses the log-in.
  SessionReviewWindow* openServerReview(const QString& instructor, const QString& password,
                                        QString* why = nullptr);

 private:
  Workstation& station_;
  QWidget* window_;
  QLabel* label_;
  QTimer timer_;  // the label follows the link's status, which changes on its thread
  QPointer<SessionReviewWindow> serverReview_;
};

}  // namespace liversim
