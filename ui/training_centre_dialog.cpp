#include "training_centre_dialog.h"

#include "instructor_login_dialog.h"

#include "liversim/storage/server_settings.h"

#include <QCheckBox>
#include <QDialogButtonBox>
#include <QFormLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSettings>
#include <QVBoxLayout>

#include <stdexcept>

namespace liversim {

TrainingCentreSetting trainingCentreSetting() {
  QSettings settings;
  return {settings.value("training_centre/server_url").toString(),
          settings.value("training_centre/password_from_libpq", false).toBool()};
}

void setTrainingCentreSetting(const TrainingCentreSetting& setting) {
  QSettings settings;
  settings.setValue("training_centre/server_url", setting.serverUrl);
  settings.setValue("training_centre/password_from_libpq", setting.passwordFromLibpq);
}

TrainingCentreDialog::TrainingCentreDialog(const TrainingCentreSetting& setting, QWidget* parent)
    : QDialog(parent) {
  setObjectName("trainingCentreDialog");
  setWindowTitle(tr("Training Centre Server"));
  auto* intro = new QLabel(
      tr("Finished sessions are uploaded to the training centre's server, and its published "
         "scenarios pulled, in the background. Recording never waits for the server. The "
         "password is not saved."),
      this);
  intro->setWordWrap(true);
  url_ = new QLineEdit(setting.serverUrl, this);
  url_->setObjectName("serverUrl");
  url_->setPlaceholderText("postgresql://ws-01@server:5432/liversim?sslmode=verify-full");
  password_ = new QLineEdit(this);
  password_->setObjectName("serverPassword");
  password_->setEchoMode(QLineEdit::Password);
  fromLibpq_ = new QCheckBox(tr("The password is in ~/.pgpass, or a client certificate is used "
                                "(connect at every start)"),
                             this);
  fromLibpq_->setObjectName("passwordFromLibpq");
  fromLibpq_->setChecked(setting.passwordFromLibpq);
  connect(fromLibpq_, &QCheckBox::toggled, password_, &QWidget::setDisabled);
  password_->setDisabled(setting.passwordFromLibpq);
  error_ = newFormErrorLabel("trainingCentreError", this);
  auto* form = new QFormLayout;
  form->addRow(tr("Server:"), url_);
  form->addRow(tr("Password:"), password_);
  form->addRow(QString(), fromLibpq_);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Cancel, this);
  QPushButton* connectButton = buttons->addButton(tr("Connect"), QDialogButtonBox::AcceptRole);
  connectButton->setObjectName("connectTrainingCentre");
  layOutForm(*this, intro, form, error_, buttons, [this] { request(); });
  resize(560, sizeHint().height());
}

void TrainingCentreDialog::submit(const QString& url, const QString& password,
                                  bool passwordFromLibpq) {
  url_->setText(url);
  password_->setText(password);
  fromLibpq_->setChecked(passwordFromLibpq);
  request();
}

void TrainingCentreDialog::showError(const QString& message) {
  error_->setText(message);
  error_->setVisible(!message.isEmpty());
}

QString TrainingCentreDialog::errorText() const {
  return error_->text();
}

void TrainingCentreDialog::request() {
  const QString url = url_->text().trimmed();
  if (!url.isEmpty()) {
    try {
      parse_server_url(url.toStdString());
    } catch (const std::invalid_argument& e) {
      showError(QString::fromStdString(e.what()));  // names the problem, never a password
      return;
    }
  }
  showError({});
  emit requested({url, fromLibpq_->isChecked()},
                 fromLibpq_->isChecked() ? QString() : password_->text());
}

}  // namespace liversim
