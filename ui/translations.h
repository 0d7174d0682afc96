#pragma once
// The interface language: English (the source) or Simplified Chinese, from the .ts files of
// translations/ built into the program. It follows the system unless the settings name one; a
// change takes effect at the next start (the windows are built in one language).

#include <QString>
#include <QStringList>

namespace liversim {

// Language codes LiverSim ships: "en", "zh_CN".
QStringList availableLanguages();
// The language's own name for itself ("English", "简体中文").
QString languageName(const QString& language);
// The language chosen in the settings; empty: the system's.
QString languageSetting();
void setLanguageSetting(const QString& language);  // empty: the system's
// Installs LiverSim's and Qt's own translations for `language` (empty: the system's locale) in
// the application, in place of any installed before. Returns the language in use: one of
// availableLanguages(), English when the wanted one is not shipped.
QString installTranslations(const QString& language);

}  // namespace liversim
