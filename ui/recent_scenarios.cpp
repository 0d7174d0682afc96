#include "recent_scenarios.h"

#include "liversim/scenario/data_paths.h"

#include <QDir>
#include <QFileInfo>
#include <QSettings>

namespace liversim {
namespace {
constexpr const char* kKey = "scenarios/recent";
}

QStringList recentScenarioFiles() {
  return QSettings().value(kKey).toStringList();
}

void rememberScenarioFile(const QString& file) {
  const QString absolute = QFileInfo(file).absoluteFilePath();
  QStringList recent = recentScenarioFiles();
  recent.removeAll(absolute);
  recent.prepend(absolute);
  while (recent.size() > kRecentScenarioCount) recent.removeLast();
  QSettings().setValue(kKey, recent);
}

QString scenarioFolderToOpen() {
  const QStringList recent = recentScenarioFiles();
  if (!recent.isEmpty()) return QFileInfo(recent.front()).absolutePath();
  const QString shipped = QString::fromStdString(shipped_scenarios_folder().string());
  return QFileInfo(shipped).isDir() ? shipped : QDir::currentPath();
}

}  // namespace liversim
