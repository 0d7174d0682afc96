// liversim: the workstation. Builds the default scene and opens the main window.
#include "main_window.h"
#include "vtk_viewport.h"

#include "liversim/core/default_scene.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QMessageBox>

#include <exception>

int main(int argc, char** argv) {
  liversim::VtkViewport::setDefaultSurfaceFormat();  // before QApplication, for every GL context
  QApplication app(argc, argv);
  QApplication::setApplicationName("LiverSim");
  QApplication::setOrganizationName("LiverSim");
  QApplication::setApplicationVersion(LIVERSIM_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription(
      QApplication::translate("main", "Real-time finite-element liver surgery simulator"));
  parser.addHelpOption();
  parser.addVersionOption();
  QCommandLineOption tets("tets", QApplication::translate("main", "Element count of the liver."),
                          "count", QString::number(liversim::kDefaultLiverTetCount));
  parser.addOption(tets);
  parser.process(app);

  bool ok = false;
  const int tet_count = parser.value(tets).toInt(&ok);
  if (!ok || tet_count < 100 || tet_count > 2'000'000) {
    qCritical("liversim: --tets must be a whole number from 100 to 2000000, not '%s'",
              qPrintable(parser.value(tets)));
    return 2;
  }
  try {
    liversim::MainWindow window(liversim::default_scene(tet_count));
    window.show();
    return QApplication::exec();
  } catch (const std::exception& e) {
    QMessageBox::critical(nullptr, QApplication::translate("main", "LiverSim cannot start"),
                          QString::fromUtf8(e.what()));
    return 1;
  }
}
