#pragma once
// Instructor mode asks for an instructor's name and password (their account is in the sessions
// database, the password kept only as an Argon2id hash). On a workstation without accounts it
// sets up the first one instead, with the password typed twice. Adding a further account (an
// instructor logged in) uses the same form.

#include <QDialog>

#include <functional>

class QDialogButtonBox;
class QFormLayout;
class QLabel;
class QLineEdit;
class QPushButton;

namespace liversim {

// The red line a form shows its refusal in (hidden until there is one).
QLabel* newFormErrorLabel(const QString& objectName, QWidget* parent);
// A form dialog's layout, top to bottom: what it is for, the fields, the refusal, the buttons.
// The buttons' accepted() asks `request`; rejected() closes.
void layOutForm(QDialog& dialog, QLabel* intro, QFormLayout* form, QLabel* error,
                QDialogButtonBox* buttons, const std::function<void()>& request);

class InstructorLoginDialog : public QDialog {
  Q_OBJECT

 public:
  enum class Purpose { log_in, create_first_account, add_account };
  explicit InstructorLoginDialog(Purpose purpose, QWidget* parent = nullptr);

  Purpose purpose() const { return purpose_; }
  // Fills the form and asks for it as the OK button does (tests, and scripted set-ups).
  void submit(const QString& name, const QString& password, const QString& repeated = {});
  // Why the last request was refused (shown in the dialog, which stays open).
  void showError(const QString& message);
  QString errorText() const;

 signals:
  // The form, when it is complete and both passwords agree; whoever handles it answers with
  // accept() or showError().
  void requested(const QString& name, const QString& password);

 private:
  void request();

  Purpose purpose_;
  QLineEdit* name_ = nullptr;
  QLineEdit* password_ = nullptr;
  QLineEdit* repeated_ = nullptr;
  QLabel* error_ = nullptr;
  QPushButton* ok_ = nullptr;
};

}  // namespace liversim
