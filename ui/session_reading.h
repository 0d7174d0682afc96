#pragma once
// Reading a recorded session's frames in the workstation: a long session (ten minutes at 1 kHz
// are 600 000 frames) shows a progress dialog with Cancel once reading takes longer than
// kSessionReadingDialogDelayMs. The dialog is window-modal and keeps the interface responsive
// while it reads on the GUI thread, chunk by chunk.

#include "liversim/sessions/session_store.h"

#include <QString>

#include <cstdint>
#include <optional>
#include <vector>

class QWidget;

namespace liversim {

inline constexpr int kSessionReadingDialogDelayMs = 500;

// The session's frames of the device in `hand`; nullopt when the user cancelled. Throws
// StorageError as frames() does. `delayMs`: how long reading goes on before the dialog appears
// (tests show it at once).
std::optional<std::vector<ServoFrame>> readSessionFrames(SessionStore& store, std::int64_t session,
                                                         QWidget* parent,
                                                         int delayMs = kSessionReadingDialogDelayMs,
                                                         Hand hand = Hand::right);

// What a window says in place of a trace whose reading was cancelled.
QString sessionReadingCancelledText(std::int64_t session);

}  // namespace liversim
