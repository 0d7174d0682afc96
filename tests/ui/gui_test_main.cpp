// main() of the GUI test programs: a QApplication (with VTK's OpenGL format) around GoogleTest.
#include "leak_check.h"
#include "vtk_viewport.h"

#include <gtest/gtest.h>
#include <QApplication>
#include <QDir>
#include <QSettings>

#include <iostream>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // Listing the tests (ctest discovery at build time) needs no display.
  if (GTEST_FLAG_GET(list_tests)) return RUN_ALL_TESTS();
  if (qEnvironmentVariableIsEmpty("DISPLAY")) {
    std::cerr << "FAIL: DISPLAY is not set. This GUI test needs an X server; run it under\n"
                 "  xvfb-run -a -s \"-screen 0 1280x1024x24\" ctest -L gui\n";
    return 1;
  }
  liversim::VtkViewport::setDefaultSurfaceFormat();
  QApplication app(argc, argv);
  // Settings of their own, never the user's: an INI file in a folder of this process.
  QApplication::setOrganizationName("LiverSimTests");
  QApplication::setApplicationName("LiverSimTests");
  QSettings::setDefaultFormat(QSettings::IniFormat);
  const QString settings_dir =
      QDir(QDir::tempPath())
          .filePath(QStringLiteral("liversim-gui-tests-%1").arg(app.applicationPid()));
  QSettings::setPath(QSettings::IniFormat, QSettings::UserScope, settings_dir);
  const int result = RUN_ALL_TESTS();
  liversim::checkLeaksWhileTheDisplayIsOpen();
  QDir(settings_dir).removeRecursively();
  return result;
}
