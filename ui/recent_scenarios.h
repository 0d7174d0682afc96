#pragma once
// The scenario files opened or saved lately, newest first, kept in the settings: one list for the
// workstation's File menu and the editor's.

#include <QStringList>

namespace liversim {

inline constexpr int kRecentScenarioCount = 8;

QStringList recentScenarioFiles();
// Puts `file` (made absolute) first, dropping its older place and the oldest beyond the count.
void rememberScenarioFile(const QString& file);
// Where an Open dialog starts: the folder of the newest recent file, else the shipped scenarios
// (data_paths.h), else the current folder.
QString scenarioFolderToOpen();

}  // namespace liversim
