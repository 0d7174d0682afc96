#pragma once
// A storage error as the workstation says it: what went wrong (the store's own message, which
// names the file) and what the user can do about it.

#include "liversim/sessions/session_store.h"

#include <QString>

namespace liversim {

// The advice for a kind of storage problem; empty when there is none to give.
QString storageAdvice(StorageProblem problem);
// "what went wrong" then, on a new line, the advice.
QString storageProblemText(const QString& what, const StorageError& error);

}  // namespace liversim
