#pragma once
// Settings ▸ Training Centre Server…: the PostgreSQL server this workstation uploads its finished
// sessions to and pulls published scenarios from (docs/training-centre.md). The server's address
// (postgresql://LOGIN@HOST:PORT/DATABASE?sslmode=...) is kept in the settings; the password never
// is: it is asked here and held in memory while the workstation runs, or libpq finds it
// (~/.pgpass, a client certificate) when the workstation should connect unattended.

#include <QDialog>

class QCheckBox;
class QLabel;
class QLineEdit;

namespace liversim {

// The settings kept: the server's address and whether libpq finds the password itself.
struct TrainingCentreSetting {
  QString serverUrl;  // empty: no training centre
  bool passwordFromLibpq = false;
};
TrainingCentreSetting trainingCentreSetting();
void setTrainingCentreSetting(const TrainingCentreSetting& setting);

class TrainingCentreDialog : public QDialog {
  Q_OBJECT

 public:
  explicit TrainingCentreDialog(const TrainingCentreSetting& setting, QWidget* parent = nullptr);

  // Fills the form and asks for it as the Connect button does (tests, scripted set-ups).
  void submit(const QString& url, const QString& password, bool passwordFromLibpq = false);
  void showError(const QString& message);
  QString errorText() const;

 signals:
  // Connect: an address that reads as one (parse_server_url); whoever handles it answers with
  // accept() or showError(). An empty address: stop using a training centre.
  void requested(const TrainingCentreSetting& setting, const QString& password);

 private:
  void request();

  QLineEdit* url_ = nullptr;
  QLineEdit* password_ = nullptr;
  QCheckBox* fromLibpq_ = nullptr;
  QLabel* error_ = nullptr;
};

}  // namespace liversim
