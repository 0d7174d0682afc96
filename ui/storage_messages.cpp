#include "storage_messages.h"

#include <QCoreApplication>

namespace liversim {
namespace {

QString tr(const char* text) {
  return QCoreApplication::translate("StorageMessages", text);
}

}  // namespace

QString storageAdvice(StorageProblem problem) {
  switch (problem) {
    case StorageProblem::unreachable:
      return tr(
          "Check that the folder exists and can be written and that its disk is mounted, "
          "or start LiverSim with another file (liversim --database FILE).");
    case StorageProblem::read_only:
      return tr(
          "Make the file and its folder writable, or start LiverSim with another file "
          "(liversim --database FILE). The sessions already saved in it are kept.");
    case StorageProblem::disk_full:
      return tr(
          "Free space on the disk, then start a new session. The sessions already saved "
          "are kept.");
    case StorageProblem::damaged:
      return tr(
          "Keep a copy of the file and restore it from a backup (sqlite3's .recover "
          "command can rescue what is left), or start LiverSim with a new file "
          "(liversim --database FILE).");
    case StorageProblem::not_a_database:
      return tr(
          "Choose a LiverSim sessions database, or a new file name "
          "(liversim --database FILE).");
    case StorageProblem::newer_version:
      return tr(
          "Open it with the newer LiverSim that wrote it, or start this one with another "
          "file (liversim --database FILE).");
    case StorageProblem::deleted:
      return tr(
          "Start LiverSim again to make a new sessions database there, or restore the file "
          "from a backup. Until then, sessions are not recorded.");
    case StorageProblem::refused:
      return tr(
          "Check the login name and password in the training centre settings, or ask the "
          "server's administrator for the permission. Sessions keep being recorded on this "
          "workstation.");
    case StorageProblem::other:
      break;
  }
  return {};
}

QString storageProblemText(const QString& what, const StorageError& error) {
  const QString advice = storageAdvice(error.problem());
  const QString text = what.arg(QString::fromUtf8(error.what()));
  return advice.isEmpty() ? text : text + '\n' + advice;
}

}  // namespace liversim
