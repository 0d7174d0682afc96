// liversim: the workstation. Builds the default scene and opens the main window.
#include "main_window.h"
#include "vtk_viewport.h"

#include "liversim/core/default_scene.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QMessageBox>
#include <QTimer>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <optional>

namespace {

struct Options {
  int tet_count = liversim::kDefaultLiverTetCount;
  std::optional<double> quit_after_s;  // close this long after the window is shown (unattended)
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
  const Options options = parse_options(argc, argv);
  if (!has_display()) {
    std::cerr << "liversim: no display found (DISPLAY and WAYLAND_DISPLAY are unset). Run it on a "
                 "desktop, or try the headless demo: xvfb-run -a liversim-cli demo\n";
    return 2;
  }
  liversim::VtkViewport::setDefaultSurfaceFormat();  // before QApplication, for every GL context
  QApplication app(argc, argv);
  QApplication::setApplicationName("LiverSim");
  QApplication::setOrganizationName("LiverSim");
  QApplication::setApplicationVersion(LIVERSIM_VERSION);
  try {
    liversim::MainWindow window(liversim::default_scene(options.tet_count));
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
