// liversim: the workstation. Builds the default scene (or a scenario's) and opens the main window.
#include "main_window.h"
#include "vtk_viewport.h"

#include "liversim/core/default_scene.h"
#include "liversim/core/scenario.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QDir>
#include <QMessageBox>
#include <QStandardPaths>
#include <QTimer>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>

namespace {

struct Options {
  int tet_count = liversim::kDefaultLiverTetCount;
  std::optional<double> quit_after_s;  // close this long after the window is shown (unattended)
  std::optional<liversim::Scenario> scenario;  // validated
  std::string scenario_file;
  std::string scenario_text;  // its exact content
  QString sessions_database;  // empty: sessions.sqlite in the user's data directory
};

// Parsed under a plain QCoreApplication, so --help, --version and bad options work without a
// display. Exits the process for --help, --version and errors, as QCommandLineParser does.
Options parse_options(int argc, char** argv) {
  QCoreApplication app(argc, argv);
  QCoreApplication::setApplicationName("liversim");
  QCoreApplication::setApplicationVersion(LIVERSIM_VERSION);
  QCommandLineParser parser;
  parser.setApplicationDescription(
      QCoreApplication::translate("main",
                                  "LiverSim: real-time finite-element liver surgery "
                                  "training workstation"));
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption tets(
      "tets", QCoreApplication::translate("main", "Element count of the liver (100 to 2000000)."),
      "count", QString::number(liversim::kDefaultLiverTetCount));
  parser.addOption(tets);
  const QCommandLineOption quit_after(
      "quit-after",
      QCoreApplication::translate("main",
                                  "Close the application this many seconds after the main window "
                                  "is shown (for unattended runs)."),
      "seconds");
  parser.addOption(quit_after);
  const QCommandLineOption scenario(
      "scenario",
      QCoreApplication::translate("main",
                                  "Run this scenario file (JSON, docs/scenario-format.md) instead "
                                  "of free practice on the built-in liver."),
      "file");
  parser.addOption(scenario);
  const QCommandLineOption database(
      "database",
      QCoreApplication::translate("main",
                                  "Record sessions to this SQLite file (default: sessions.sqlite "
                                  "in the user's data directory)."),
      "file");
  parser.addOption(database);
  parser.process(app);

  Options options;
  bool ok = false;
  options.tet_count = parser.value(tets).toInt(&ok);
  if (!ok || options.tet_count < 100 || options.tet_count > 2'000'000) {
    std::cerr << "liversim: --tets must be a whole number from 100 to 2000000, not '"
              << parser.value(tets).toStdString() << "'\n";
    std::exit(2);
  }
  if (parser.isSet(quit_after)) {
    const double seconds = parser.value(quit_after).toDouble(&ok);
    // At most a day, so the delay fits QTimer's int milliseconds.
    if (!ok || !std::isfinite(seconds) || seconds <= 0.0 || seconds > 86'400.0) {
      std::cerr << "liversim: --quit-after must be a number of seconds above 0 and at most "
                   "86400, not '"
                << parser.value(quit_after).toStdString() << "'\n";
      std::exit(2);
    }
    options.quit_after_s = seconds;
  }
  if (parser.isSet(scenario)) {
    if (parser.isSet(tets)) {
      std::cerr << "liversim: --tets and --scenario cannot go together: the scenario sets the "
                   "element count (organ.target_tet_count)\n";
      std::exit(2);
    }
    options.scenario_file = parser.value(scenario).toStdString();
    liversim::ScenarioReading reading = liversim::read_scenario_file(options.scenario_file);
    if (!reading.scenario) {
      std::cerr << "liversim: cannot open the scenario " << options.scenario_file << ":\n";
      for (const auto& error : reading.errors) std::cerr << "  " << error.text() << '\n';
      std::exit(2);
    }
    options.scenario = std::move(reading.scenario);
    // The exact text, which recorded sessions store with the scenario.
    std::ifstream in(options.scenario_file, std::ios::binary);
    options.scenario_text.assign(std::istreambuf_iterator<char>(in), {});
  }
  if (parser.isSet(database)) options.sessions_database = parser.value(database);
  return options;
}

bool has_display() {
  for (const char* variable : {"DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"}) {
    const char* value = std::getenv(variable);
    if (value != nullptr && *value != '\0') return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  Options options = parse_options(argc, argv);
  if (!has_display()) {
    std::cerr << "liversim: no display found (DISPLAY and WAYLAND_DISPLAY are unset). Run it on a "
                 "desktop, or try the headless demo: xvfb-run -a liversim-cli demo\n";
    return 2;
  }
  // The scene before the window: a scenario whose mesh cannot be built is refused here.
  std::optional<liversim::SceneSetup> setup;
  std::optional<liversim::OpenedScenario> opened;
  try {
    if (options.scenario) {
      const std::filesystem::path file = std::filesystem::absolute(options.scenario_file);
      setup = liversim::build_scene(*options.scenario, file.parent_path());
      opened = liversim::OpenedScenario{std::move(*options.scenario),
                                        QString::fromStdString(file.string()),
                                        std::move(options.scenario_text)};
    } else {
      setup = liversim::default_scene(options.tet_count);
    }
  } catch (const std::exception& e) {
    std::cerr << "liversim: cannot build the scene"
              << (options.scenario_file.empty() ? std::string() : " of " + options.scenario_file)
              << ": " << e.what() << '\n';
    return 2;
  }
  liversim::VtkViewport::setDefaultSurfaceFormat();  // before QApplication, for every GL context
  QApplication app(argc, argv);
  QApplication::setApplicationName("LiverSim");
  QApplication::setOrganizationName("LiverSim");
  QApplication::setApplicationVersion(LIVERSIM_VERSION);
  try {
    liversim::MainWindow window(std::move(*setup), std::move(opened));
    QString database = options.sessions_database;
    if (database.isEmpty()) {
      const QString folder = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
      QDir().mkpath(folder);  // if it cannot be made, opening the file below says so
      database = folder + "/sessions.sqlite";
    }
    if (!window.setSessionsDatabase(database))
      std::cerr << "liversim: " << window.sessionsProblem().toStdString() << '\n';
    window.show();
    if (options.quit_after_s)
      QTimer::singleShot(static_cast<int>(std::lround(*options.quit_after_s * 1e3)), &app,
                         &QApplication::quit);
    return QApplication::exec();
  } catch (const std::exception& e) {
    QMessageBox::critical(nullptr, QApplication::translate("main", "LiverSim cannot start"),
                          QString::fromUtf8(e.what()));
    return 1;
  }
}
