// liversim: the workstation. Builds the default scene (or a scenario's) and opens the main window.
#include "device_panel.h"
#include "leak_check.h"
#include "main_window.h"
#include "translations.h"
#include "vtk_viewport.h"

#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QDir>
#include <QIcon>
#include <QMessageBox>
#include <QSocketNotifier>
#include <QStandardPaths>
#include <QTimer>

#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

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
  QString trajectory_file;    // the scripted device's trajectory, driving the tool from the start
  QString language;           // empty: the setting, else the system's
};

// Parsed under a plain QCoreApplication, so --help, --version and bad options work without a
// display. Exits the process for --help, --version and errors, as QCommandLineParser does.
// --language X or --language=X, if given: the help is printed in it.
QString language_argument(const QStringList& arguments) {
  for (qsizetype i = 1; i < arguments.size(); ++i) {
    if (arguments[i] == QLatin1String("--language") && i + 1 < arguments.size())
      return arguments[i + 1];
    if (arguments[i].startsWith(QLatin1String("--language=")))
      return arguments[i].mid(QStringLiteral("--language=").size());
  }
  return {};
}

// The names QSettings and the data folders go by.
void name_application() {
  QCoreApplication::setApplicationName("LiverSim");
  QCoreApplication::setOrganizationName("LiverSim");
  QCoreApplication::setApplicationVersion(LIVERSIM_VERSION);
}

Options parse_options(int argc, char** argv) {
  QCoreApplication app(argc, argv);
  name_application();
  QString language = language_argument(QCoreApplication::arguments());
  if (language.isEmpty()) language = liversim::languageSetting();
  liversim::installTranslations(language);
  QCoreApplication::setApplicationName("liversim");  // what --version prints
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
  const QCommandLineOption trajectory(
      "trajectory",
      QCoreApplication::translate(
          "main",
          "Drive the tool from the start with the scripted device playing this trajectory file "
          "(a line per point: time_s x_mm y_mm z_mm [buttons]); its session is recorded."),
      "file");
  parser.addOption(trajectory);
  const QCommandLineOption language_option(
      "language",
      QCoreApplication::translate("main",
                                  "Interface language: en or zh_CN (default: the one chosen in "
                                  "Settings, else the system's)."),
      "code");
  parser.addOption(language_option);
  parser.addPositionalArgument(
      "scenario-file",
      QCoreApplication::translate("main", "A scenario file to run, as with --scenario."),
      "[scenario-file]");
  parser.process(app);
  const QStringList positional = parser.positionalArguments();
  if (positional.size() > 1 || (positional.size() == 1 && parser.isSet(scenario))) {
    std::cerr << "liversim: give one scenario file, either with --scenario or alone\n";
    std::exit(2);
  }

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
  if (parser.isSet(scenario) || !positional.isEmpty()) {
    if (parser.isSet(tets)) {
      std::cerr << "liversim: --tets and --scenario cannot go together: the scenario sets the "
                   "element count (organ.target_tet_count)\n";
      std::exit(2);
    }
    options.scenario_file =
        (positional.isEmpty() ? parser.value(scenario) : positional.front()).toStdString();
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
  if (parser.isSet(trajectory)) options.trajectory_file = parser.value(trajectory);
  if (parser.isSet(language_option)) {
    options.language = parser.value(language_option);
    if (!liversim::availableLanguages().contains(options.language)) {
      std::cerr << "liversim: --language must be one of "
                << liversim::availableLanguages().join(", ").toStdString() << ", not '"
                << options.language.toStdString() << "'\n";
      std::exit(2);
    }
  }
  return options;
}

// SIGTERM (a logout, a shutdown, `kill`) and SIGINT (Ctrl+C in its terminal) close the
// workstation as --quit-after does, so the session under way ends complete instead of being left
// for the next start to close as incomplete. The handler only writes a byte (async-signal-safe);
// the event loop reads it and quits.
int stop_signal_socket = -1;

void on_stop_signal(int signal) {
  const char byte = static_cast<char>(signal);
  [[maybe_unused]] const ssize_t written = ::write(stop_signal_socket, &byte, 1);
}

void quit_on_stop_signals(QApplication& app) {
  int sockets[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) return;  // left default
  stop_signal_socket = sockets[0];
  auto* notifier = new QSocketNotifier(sockets[1], QSocketNotifier::Read, &app);
  QObject::connect(notifier, &QSocketNotifier::activated, &app, [fd = sockets[1]] {
    char signal = 0;
    if (::read(fd, &signal, 1) == 1)
      std::cerr << "liversim: " << (signal == SIGINT ? "SIGINT" : "SIGTERM")
                << ": closing the workstation as its window's close does" << std::endl;
    QApplication::quit();
  });
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
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
      opened = liversim::OpenedScenario{std::move(*options.scenario), file,
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
  name_application();
  QApplication::setDesktopFileName("org.liversim.LiverSim");
  QApplication::setWindowIcon(QIcon(":/icons/liversim.svg"));
  quit_on_stop_signals(app);
  // The viewport is a QOpenGLWidget, which Qt's offscreen and minimal platforms do not support
  // (they create a context, but no surface for the widget): said here, rather than VTK crashing
  // on the missing surface.
  if (const QString platform = QGuiApplication::platformName();
      platform == QLatin1String("offscreen") || platform == QLatin1String("minimal")) {
    std::cerr << "liversim: Qt's '" << platform.toStdString()
              << "' platform cannot show the 3D view (no OpenGL widget). Run it on a desktop or "
                 "under xvfb-run -a.\n";
    return 2;
  }
  liversim::installTranslations(options.language.isEmpty() ? liversim::languageSetting()
                                                           : options.language);
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
    // Also in the terminal's log, for whoever looks after the workstation.
    QObject::connect(&window, &liversim::MainWindow::recordingStopped, [](const QString& message) {
      std::cerr << "liversim: " << message.toStdString() << std::endl;
    });
    window.show();
    if (!options.trajectory_file.isEmpty() &&
        !window.useDevice(liversim::DeviceChoice::scripted, options.trajectory_file)) {
      std::cerr << "liversim: cannot play the trajectory " << options.trajectory_file.toStdString()
                << ": " << window.devicePanel()->statusText().toStdString() << '\n';
      return 2;
    }
    if (options.quit_after_s)
      QTimer::singleShot(static_cast<int>(std::lround(*options.quit_after_s * 1e3)), &app,
                         &QApplication::quit);
    const int result = QApplication::exec();
    liversim::checkLeaksWhileTheDisplayIsOpen();
    return result;
  } catch (const std::exception& e) {
    QMessageBox::critical(
        nullptr, QApplication::translate("main", "LiverSim cannot start"),
        QApplication::translate("main",
                                "The main window could not be opened: %1\n\nStart LiverSim from a "
                                "terminal to see its messages; liversim --help lists its options "
                                "(a smaller liver: --tets N; another scenario: --scenario FILE).")
            .arg(QString::fromUtf8(e.what())));
    return 1;
  }
}
