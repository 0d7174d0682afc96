#include "instructor_login_dialog.h"

#include "liversim/storage/password_hash.h"

#include <QDialogButtonBox>
#include <QFormLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>

namespace liversim {

QLabel* newFormErrorLabel(const QString& objectName, QWidget* parent) {
  auto* label = new QLabel(parent);
  label->setObjectName(objectName);
  label->setWordWrap(true);
  label->setStyleSheet("color: #b00020;");
  label->hide();
  return label;
}

void layOutForm(QDialog& dialog, QLabel* intro, QFormLayout* form, QLabel* error,
                QDialogButtonBox* buttons, const std::function<void()>& request) {
  QObject::connect(buttons, &QDialogButtonBox::accepted, &dialog, request);
  QObject::connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  auto* layout = new QVBoxLayout(&dialog);
  layout->addWidget(intro);
  layout->addLayout(form);
  layout->addWidget(error);
  layout->addWidget(buttons);
}

InstructorLoginDialog::InstructorLoginDialog(Purpose purpose, QWidget* parent)
    : QDialog(parent), purpose_(purpose) {
  setObjectName("instructorLoginDialog");
  const bool creating = purpose != Purpose::log_in;
  setWindowTitle(purpose == Purpose::log_in                 ? tr("Instructor Log-in")
                 : purpose == Purpose::create_first_account ? tr("First Instructor Account")
                                                            : tr("Add an Instructor Account"));
  auto* intro = new QLabel(
      purpose == Purpose::log_in
          ? tr("Instructor mode changes the tissue, authors scenarios and grades sessions. Log in "
               "with your instructor account.")
      : purpose == Purpose::create_first_account
          ? tr("This workstation has no instructor account yet. Set up the first one: its name "
               "and a password of at least %1 characters. Further accounts can then be added only "
               "by an instructor who has logged in.")
                .arg(kMinimumPasswordLength)
          : tr("A new instructor account: its name and a password of at least %1 characters.")
                .arg(kMinimumPasswordLength),
      this);
  intro->setWordWrap(true);
  name_ = new QLineEdit(this);
  name_->setObjectName("instructorName");
  password_ = new QLineEdit(this);
  password_->setObjectName("instructorPassword");
  password_->setEchoMode(QLineEdit::Password);
  repeated_ = new QLineEdit(this);
  repeated_->setObjectName("instructorPasswordRepeated");
  repeated_->setEchoMode(QLineEdit::Password);
  error_ = newFormErrorLabel("instructorLoginError", this);

  auto* form = new QFormLayout;
  form->addRow(tr("Name:"), name_);
  form->addRow(tr("Password:"), password_);
  form->addRow(tr("Password again:"), repeated_);
  form->setRowVisible(repeated_, creating);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  ok_ = buttons->button(QDialogButtonBox::Ok);
  ok_->setText(creating ? tr("Create Account") : tr("Log In"));
  layOutForm(*this, intro, form, error_, buttons, [this] { request(); });
}

void InstructorLoginDialog::submit(const QString& name, const QString& password,
                                   const QString& repeated) {
  name_->setText(name);
  password_->setText(password);
  repeated_->setText(repeated);
  request();
}

void InstructorLoginDialog::request() {
  const QString name = name_->text().trimmed();
  if (name.isEmpty()) return showError(tr("Enter the instructor's name."));
  if (password_->text().isEmpty()) return showError(tr("Enter the password."));
  if (purpose_ != Purpose::log_in && password_->text() != repeated_->text())
    return showError(tr("The two passwords differ: type the same password twice."));
  error_->hide();
  emit requested(name, password_->text());
}

void InstructorLoginDialog::showError(const QString& message) {
  error_->setText(message);
  error_->show();
  password_->clear();
  repeated_->clear();
  password_->setFocus();
}

QString InstructorLoginDialog::errorText() const {
  return error_->isHidden() ? QString() : error_->text();
}

}  // namespace liversim
