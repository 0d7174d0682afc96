#include "translations.h"

#include <QCoreApplication>
#include <QLibraryInfo>
#include <QLocale>
#include <QSettings>
#include <QTranslator>

#include <memory>

namespace liversim {
namespace {

constexpr const char* kKey = "interface/language";

// Installed translators, replaced by the next installTranslations(). Not children of the
// application: the workstation parses its options under an application of its own first.
std::unique_ptr<QTranslator> ownTranslator;
std::unique_ptr<QTranslator> qtTranslator;

void remove(std::unique_ptr<QTranslator>& translator) {
  if (!translator) return;
  if (QCoreApplication::instance() != nullptr) QCoreApplication::removeTranslator(translator.get());
  translator.reset();
}

}  // namespace

QStringList availableLanguages() {
  return {QStringLiteral("en"), QStringLiteral("zh_CN")};
}

QString languageName(const QString& language) {
  if (language == QLatin1String("zh_CN")) return QStringLiteral("简体中文");
  return QStringLiteral("English");
}

QString languageSetting() {
  return QSettings().value(kKey).toString();
}

void setLanguageSetting(const QString& language) {
  QSettings settings;
  if (language.isEmpty())
    settings.remove(kKey);
  else
    settings.setValue(kKey, language);
}

QString installTranslations(const QString& language) {
  remove(ownTranslator);
  remove(qtTranslator);
  const QLocale locale = language.isEmpty() ? QLocale::system() : QLocale(language);
  // Simplified Chinese for zh_CN, zh_SG and zh_Hans; English for everything else.
  const bool chinese = locale.language() == QLocale::Chinese &&
                       locale.script() != QLocale::TraditionalChineseScript &&
                       locale.territory() != QLocale::Taiwan &&
                       locale.territory() != QLocale::HongKong;
  const QString chosen = chinese ? QStringLiteral("zh_CN") : QStringLiteral("en");
  // English needs its file for plural forms only ("%n lesion(s)": "1 lesion", "2 lesions").
  ownTranslator = std::make_unique<QTranslator>();
  if (!ownTranslator->load(QStringLiteral(":/i18n/liversim_") + chosen)) {
    remove(ownTranslator);
    return QStringLiteral("en");
  }
  QCoreApplication::installTranslator(ownTranslator.get());
  // Qt's own strings (standard buttons, file dialogs), from Debian's qt6-translations-l10n.
  qtTranslator = std::make_unique<QTranslator>();
  if (chinese && qtTranslator->load(QStringLiteral("qtbase_") + chosen,
                                    QLibraryInfo::path(QLibraryInfo::TranslationsPath)))
    QCoreApplication::installTranslator(qtTranslator.get());
  else
    remove(qtTranslator);
  return chosen;
}

}  // namespace liversim
