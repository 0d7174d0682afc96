// The interface in Simplified Chinese: every string the main window shows (its menus, panels,
// status bar and tooltips) is translated. The same walk over the English window finds English
// everywhere, so the check can fail.
#include "device_panel.h"
#include "main_window.h"
#include "translations.h"
#include "wait_limits.h"

#include "liversim/meshing/default_scene.h"

#include <gtest/gtest.h>
#include <QAbstractButton>
#include <QAbstractSpinBox>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QGroupBox>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QRegularExpression>
#include <QSettings>
#include <QSpinBox>
#include <QStatusBar>
#include <QTest>
#include <QTextDocumentFragment>

#include <memory>
#include <string>
#include <vector>

namespace liversim {
namespace {

constexpr int kTetCount = 1500;

struct ShownText {
  QString where;  // the widget or action showing it
  QString text;
};

QString nameOf(const QObject* object) {
  const QString name = object->objectName();
  return QString::fromLatin1(object->metaObject()->className()) +
         (name.isEmpty() ? QString() : " " + name);
}

void add(std::vector<ShownText>& out, const QObject* object, const QString& what, QString text) {
  if (Qt::mightBeRichText(text)) text = QTextDocumentFragment::fromHtml(text).toPlainText();
  if (!text.trimmed().isEmpty()) out.push_back({nameOf(object) + " " + what, text});
}

void addMenu(std::vector<ShownText>& out, const QMenu* menu) {
  add(out, menu, "title", menu->title());
  for (const QAction* action : menu->actions()) {
    if (action->isSeparator()) continue;
    if (action->menu() != nullptr) {
      addMenu(out, action->menu());
      continue;
    }
    add(out, action, "text", action->text());
    if (action->toolTip() != QString(action->text()).remove('&'))
      add(out, action, "tooltip", action->toolTip());
  }
}

// What the window shows, or shows on hover, or in its menus.
std::vector<ShownText> shownTexts(const MainWindow& window) {
  std::vector<ShownText> out;
  add(out, &window, "title", window.windowTitle());
  for (const QAction* action : window.menuBar()->actions())
    if (action->menu() != nullptr) addMenu(out, action->menu());
  add(out, window.statusBar(), "message", window.statusBar()->currentMessage());
  for (const QWidget* widget : window.findChildren<QWidget*>()) {
    if (!widget->isVisibleTo(&window) || qobject_cast<const QMenu*>(widget) != nullptr) continue;
    add(out, widget, "tooltip", widget->toolTip());
    if (const auto* label = qobject_cast<const QLabel*>(widget))
      add(out, label, "text", label->text());
    if (const auto* button = qobject_cast<const QAbstractButton*>(widget))
      add(out, button, "text", button->text());
    if (const auto* box = qobject_cast<const QGroupBox*>(widget))
      add(out, box, "title", box->title());
    if (const auto* dock = qobject_cast<const QDockWidget*>(widget))
      add(out, dock, "title", dock->windowTitle());
    if (const auto* combo = qobject_cast<const QComboBox*>(widget))
      for (int i = 0; i < combo->count(); ++i)
        add(out, combo, QStringLiteral("item %1").arg(i), combo->itemText(i));
    if (const auto* spin = qobject_cast<const QDoubleSpinBox*>(widget)) {
      add(out, spin, "prefix", spin->prefix());
      add(out, spin, "suffix", spin->suffix());
    }
    if (const auto* spin = qobject_cast<const QSpinBox*>(widget)) {
      add(out, spin, "prefix", spin->prefix());
      add(out, spin, "suffix", spin->suffix());
    }
    if (const auto* spin = qobject_cast<const QAbstractSpinBox*>(widget))
      add(out, spin, "special value", spin->specialValueText());
  }
  return out;
}

// What may stay in Latin letters in a Chinese interface: names (of the product, devices,
// methods, file formats), units, the symbols of the tissue's parameters (E, n, k1, J...) and of
// gravity's acceleration (g), key names
// and shortcuts "（Ctrl+O）", mnemonics "(&F)", file names in docs/, numbers.
QString withoutNamesAndUnits(QString text) {
  static const QRegularExpression allowed(QStringLiteral(
      // “Left Device”, “Default Device”: the names Omnis have in Touch Setup (Geomagic's
      // configuration tool), which the user types there.
      R"(\(&[A-Z]\)|LiverSim|Phantom Omni|Geomagic Touch|OpenHaptics|Touch Setup|libHD\.so|)"
      R"(SQLite|JSON|“Left Device”|“Default Device”|)"
      R"(CSV|PDF|RK4|BDF2|Dormand|Prince|Gmsh|English|Shift|Ctrl|p99|)"
      R"(（((Ctrl|Shift|Alt)\+)*[A-Z]）|docs/[\w.-]+\.md|kg/m³|m/s²|J/m²|)"
      R"([-+]?\d+(\.\d+)?(e[-+]?\d+)?|)"
      R"(\b(N|mm|m|s|ms|µm|nm|pm|mL|Pa|kPa|Hz|x|y|z|E|E1|E2|n|k1|k2|g|J)\b)"));
  return text.remove(allowed);
}

bool hasLatinLetters(const QString& text) {
  static const QRegularExpression latin(QStringLiteral("[A-Za-z]"));
  return text.contains(latin);
}

class MainWindowLanguage : public ::testing::Test {
 protected:
  void SetUp() override { QSettings().clear(); }
  void TearDown() override {
    window_.reset();
    installTranslations(QStringLiteral("en"));
  }

  std::vector<ShownText> showWindowIn(const QString& language) {
    EXPECT_EQ(installTranslations(language), language);
    window_ = std::make_unique<MainWindow>(default_scene(kTetCount));
    window_->show();
    EXPECT_TRUE(QTest::qWaitForWindowExposed(window_.get()));
    // The status line is written every 500 ms, the device panel's servo line once the servo has
    // run (its figures replace the line said before it starts).
    auto* status = window_->findChild<QLabel*>("simulationStatus");
    const QString notRunning = window_->devicePanel()->servoText();
    EXPECT_TRUE(status != nullptr);
    EXPECT_TRUE(QTest::qWaitFor(
        [&] {
          return status != nullptr && !status->text().isEmpty() &&
                 window_->devicePanel()->servoText() != notRunning;
        },
        test::waitLimitMs(30'000)))
        << "the status line or the servo's figures never came";
    return shownTexts(*window_);
  }

  std::unique_ptr<MainWindow> window_;
};

TEST_F(MainWindowLanguage, NoVisibleStringIsLeftInEnglishInTheChineseInterface) {
  const std::vector<ShownText> shown = showWindowIn(QStringLiteral("zh_CN"));
  ASSERT_GT(shown.size(), 50u) << "the walk found too little to mean anything";
  EXPECT_EQ(window_->menuBar()->actions().front()->text(), QStringLiteral("文件(&F)"));
  std::string untranslated;
  int count = 0;
  for (const ShownText& item : shown) {
    if (!hasLatinLetters(withoutNamesAndUnits(item.text))) continue;
    ++count;
    untranslated += "  " + item.where.toStdString() + ": \"" + item.text.toStdString() + "\"\n";
  }
  EXPECT_EQ(count, 0) << "shown in English in the Chinese interface:\n" << untranslated;
  // For a look at the layout in Chinese (a CJK font is needed: fonts-wqy-microhei).
  window_->grab().save(QDir(LIVERSIM_TEST_OUTPUT_DIR).filePath("main_window_zh_CN.png"));
}

TEST_F(MainWindowLanguage, TheEnglishInterfaceIsEnglishAndCountsItsPlurals) {
  const std::vector<ShownText> shown = showWindowIn(QStringLiteral("en"));
  int english = 0;
  for (const ShownText& item : shown) english += hasLatinLetters(withoutNamesAndUnits(item.text));
  // Nearly everything: the walk does see the strings the Chinese test checks.
  EXPECT_GT(english, static_cast<int>(shown.size()) * 8 / 10);
  EXPECT_EQ(window_->menuBar()->actions().front()->text(), QStringLiteral("&File"));
  EXPECT_EQ(QCoreApplication::translate("liversim::ScenarioPanel", "%n lesion(s)", nullptr, 1),
            QStringLiteral("1 lesion"));
  EXPECT_EQ(QCoreApplication::translate("liversim::ScenarioPanel", "%n lesion(s)", nullptr, 3),
            QStringLiteral("3 lesions"));
}

TEST(InterfaceLanguage, FollowsTheSystemUnlessTheSettingsNameOne) {
  QSettings().clear();
  EXPECT_TRUE(languageSetting().isEmpty());
  setLanguageSetting(QStringLiteral("zh_CN"));
  EXPECT_EQ(languageSetting(), QStringLiteral("zh_CN"));
  setLanguageSetting({});
  EXPECT_TRUE(languageSetting().isEmpty());
  // Traditional Chinese is not shipped: English, not Simplified Chinese.
  EXPECT_EQ(installTranslations(QStringLiteral("zh_TW")), QStringLiteral("en"));
  EXPECT_EQ(installTranslations(QStringLiteral("zh_SG")), QStringLiteral("zh_CN"));
  EXPECT_EQ(QCoreApplication::translate("liversim::MainWindow", "&File"),
            QStringLiteral("文件(&F)"));
  EXPECT_EQ(installTranslations(QStringLiteral("de_DE")), QStringLiteral("en"));
  EXPECT_EQ(QCoreApplication::translate("liversim::MainWindow", "&File"), QStringLiteral("&File"));
}

}  // namespace
}  // namespace liversim
