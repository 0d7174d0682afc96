#include "session_reading.h"

#include <QCoreApplication>
#include <QProgressDialog>

#include <algorithm>

namespace liversim {

std::optional<std::vector<ServoFrame>> readSessionFrames(SessionStore& store, std::int64_t session,
                                                         QWidget* parent, int delayMs, Hand hand) {
  constexpr int kSteps = 1000;
  QProgressDialog dialog(
      (hand == Hand::left
           ? QCoreApplication::translate("SessionReading",
                                         "Reading the left hand's frames of session %1…")
           : QCoreApplication::translate("SessionReading", "Reading the frames of session %1…"))
          .arg(session),
      QCoreApplication::translate("SessionReading", "Cancel"), 0, kSteps, parent);
  dialog.setObjectName("sessionReadingProgress");
  dialog.setWindowTitle(QCoreApplication::translate("SessionReading", "Reading a session"));
  // Modal, setValue() processes events: the window repaints and Cancel can be pressed.
  dialog.setWindowModality(Qt::WindowModal);
  dialog.setMinimumDuration(delayMs);
  dialog.setAutoReset(false);
  dialog.setAutoClose(false);
  try {
    std::vector<ServoFrame> frames =
        store.frames(session, hand, [&](std::size_t read, std::size_t total) {
          const double fraction =
              total > 0 ? std::min(1.0, static_cast<double>(read) / static_cast<double>(total))
                        : 0.0;
          dialog.setValue(static_cast<int>(fraction * kSteps));
          return !dialog.wasCanceled();
        });
    return frames;
  } catch (const ReadingCancelled&) {
    return std::nullopt;
  }
}

QString sessionReadingCancelledText(std::int64_t session) {
  return QCoreApplication::translate("SessionReading",
                                     "The force trace of session %1 was not read: reading was "
                                     "cancelled. Open the session again to read it.")
      .arg(session);
}

}  // namespace liversim
