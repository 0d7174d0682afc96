#include "recent_scenarios.h"

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

}  // namespace liversim
