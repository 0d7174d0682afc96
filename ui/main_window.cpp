#include "main_window.h"

#include "accuracy_panel.h"
#include "accuracy_study_dialog.h"
#include "calibration_dialog.h"
#include "device_control.h"
#include "device_panel.h"
#include "material_panel.h"
#include "panel_scroll_area.h"
#include "recent_scenarios.h"
#include "scenario_document.h"
#include "scenario_editor.h"
#include "scenario_panel.h"
#include "session_reading.h"
#include "session_review_window.h"
#include "simulation_status.h"
#include "storage_messages.h"
#include "tool_panel.h"
#include "training_centre_control.h"
#include "translations.h"
#include "vtk_viewport.h"

#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>
#include <QAction>
#include <QActionGroup>
#include <QCloseEvent>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QGuiApplication>
#include <QInputDialog>
#include <QKeySequence>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QProgressBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QStatusBar>
#include <QStyle>
#include <QToolBar>

#include <algorithm>
#include <exception>

namespace liversim {
namespace {

// A form's request answered: it closes when `attempt` succeeds, else shows why not.
template <typename Form, typename Attempt>
void answerForm(Form& form, Attempt attempt) {
  QString why;
  if (attempt(&why))
    form.accept();
  else
    form.showError(why);
}

QString qstring(const std::string& text) {
  return QString::fromStdString(text);
}

}  // namespace

MainWindow::MainWindow(SceneSetup setup, std::optional<OpenedScenario> scenario, QWidget* parent)
    : QMainWindow(parent), toolModels_(load_tool_models()) {
  station_ =
      std::make_unique<Workstation>(std::move(setup), std::move(scenario), stationListener());
  mouseControl_ = std::make_unique<MouseToolControl>(
      *station_, [this]() -> LiverScene& { return *scene_; },
      [this] { return deviceAxesFromView(); });
  ambientOcclusion_ = QSettings().value("view/ambient_occlusion", false).toBool();
  showNewScene();

  viewport_ = new VtkViewport(this);
  viewport_->setObjectName("liverViewport");
  viewport_->renderWindow()->AddRenderer(scene_->renderer());
  viewport_->setPressFilter(
      [this](QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers) {
        return mouseControl_->press(pos, button, modifiers, toolPanel_->tool());
      });
  // While the mouse holds a tool, the wheel pushes it in along its shaft or draws it back.
  viewport_->setWheelFilter([this](int notches) {
    return mouseControl_->pushIn(notches * MouseToolControl::kWheelPushM);
  });
  connect(viewport_, &VtkViewport::mouseMovedTo, this, [this](QPoint pos, Qt::MouseButtons) {
    mouseControl_->move(pos, QGuiApplication::keyboardModifiers());
  });
  connect(viewport_, &VtkViewport::mouseReleasedAt, this,
          [this](QPoint, Qt::MouseButton button) { mouseControl_->release(button); });
  connect(viewport_, &QOpenGLWidget::frameSwapped, this, [this] { ++framesInWindow_; });
  setCentralWidget(viewport_);

  scenarioPanel_ = new ScenarioPanel(this);
  scenarioPanel_->setObjectName("scenarioPanel");
  QDockWidget* scenarioDock = addPanelDock(tr("Scenario"), "scenarioDock", scenarioPanel_);

  accuracyPanel_ = new AccuracyPanel(this);
  accuracyPanel_->setObjectName("accuracyPanel");
  accuracyPanel_->setSettings(station_->integrator());
  connect(accuracyPanel_, &AccuracyPanel::applyRequested, this,
          [this](const IntegratorSettings& settings) { applyIntegratorSettings(settings); });
  connect(accuracyPanel_, &AccuracyPanel::studyRequested, this, [this] { openAccuracyStudy(); });
  QDockWidget* accuracyDock = addPanelDock(tr("Accuracy"), "accuracyDock", accuracyPanel_);

  materialPanel_ = new MaterialPanel(this);
  materialPanel_->setObjectName("materialPanel");
  connect(materialPanel_, &MaterialPanel::tissueRequested, this, [this](const TissueSpec& tissue) {
    if (!applyTissue(tissue) && instructor_)
      materialPanel_->showError(
          tr("a scene or an integrator change is being built; enter the "
             "value again after it."));
  });
  connect(materialPanel_, &MaterialPanel::gravityRequested, this, [this](bool on) {
    if (!applyGravity(on))
      materialPanel_->showError(
          tr("a scene or another change of the model is being built; "
             "switch gravity again after it."));
  });
  QDockWidget* materialDock = addPanelDock(tr("Material"), "materialDock", materialPanel_);

  toolPanel_ = new ToolPanel(this);
  toolPanel_->setObjectName("toolPanel");
  QDockWidget* toolDock = addPanelDock(tr("Tool"), "toolDock", toolPanel_);
  connect(toolPanel_, &ToolPanel::toolChanged, this, [this] {
    if (station_->mouse()) {
      if (mouseControl_->tool()) mouseControl_->endTool();  // the next press puts the new one down
      return;
    }
    station_->device_tool_changed();
    station_->record_tool_choice();
  });

  devicePanel_ = new DevicePanel(this);
  devicePanel_->setObjectName("devicePanel");
  QDockWidget* deviceDock = addPanelDock(tr("Device"), "deviceDock", devicePanel_);
  // Five docks stacked on the right leave each a sliver on a 1280 × 800 screen, their fields
  // clipped; two groups of tabs give each panel half the height: the scenario with the settings
  // of its model (Accuracy, Material) above, the tool with the device that moves it below. The
  // task and the force on the tool, what a trainee watches while working, are in front. The tabs
  // are above their panels, where one looks for them (below, the lower group's would sit at the
  // status bar). Each panel can still be dragged out, floated or closed.
  setTabPosition(Qt::AllDockWidgetAreas, QTabWidget::North);
  tabifyDockWidget(scenarioDock, accuracyDock);
  tabifyDockWidget(accuracyDock, materialDock);
  tabifyDockWidget(toolDock, deviceDock);
  scenarioDock->raise();
  toolDock->raise();

  DeviceControl::Context devices;
  devices.window = this;
  devices.panel = devicePanel_;
  devices.tools = toolPanel_;
  devices.viewAxes = [this] { return deviceAxesFromView(); };
  devices.showMessage = [this](const QString& text) { statusBar()->showMessage(text); };
  devices.replayableSessions = [this] { return replayableSessions(); };
  devices.sessionsProblem = [this] { return sessionsProblem_; };
  devices_ = new DeviceControl(*station_, *mouseControl_, std::move(devices));

  if (const auto& opened = station_->scenario(); opened && !opened->file.empty())
    rememberScenarioFile(QString::fromStdString(opened->file.string()));
  buildMenus();
  showScenarioDetails();
  setSeeThrough(QSettings().value("view/see_through", false).toBool());
  applyMode(false);  // every start is a trainee's: instructor mode needs a log-in

  statusLabel_ = new QLabel(this);
  statusLabel_->setObjectName("simulationStatus");
  statusBar()->addPermanentWidget(statusLabel_, 1);
  buildProgress_ = new QProgressBar(this);
  buildProgress_->setObjectName("buildProgress");
  buildProgress_->setMaximumWidth(200);
  buildProgress_->hide();
  statusBar()->addPermanentWidget(buildProgress_);
  cancelBuild_ = new QPushButton(tr("Cancel"), this);
  cancelBuild_->setObjectName("cancelBuild");
  cancelBuild_->setToolTip(tr("Stop building the scene; the scene that is running goes on"));
  cancelBuild_->hide();
  connect(cancelBuild_, &QPushButton::clicked, this, &MainWindow::cancelSceneBuild);
  statusBar()->addPermanentWidget(cancelBuild_);
  trainingCentreControl_ = new TrainingCentreControl(*station_, this);
  statusBar()->addPermanentWidget(trainingCentreControl_->statusLabel());
  if (toolModels_.problem.empty())
    statusBar()->showMessage(
        tr("Drag the liver with the left mouse button; drag the background to "
           "turn the view, wheel to zoom."));
  else
    statusBar()->showMessage(tr("The tool models could not be read, so the tools are drawn as "
                                "simple shapes: %1")
                                 .arg(qstring(toolModels_.problem)));
  resize(1200, 800);
  restoreLayout();

  frameTimer_.setTimerType(Qt::PreciseTimer);
  connect(&frameTimer_, &QTimer::timeout, this, &MainWindow::showNewestSnapshot);
  frameTimer_.start(16);
  connect(&statusTimer_, &QTimer::timeout, this, &MainWindow::updateStatus);
  statusTimer_.start(500);
  frameWindow_.start();
  devices_->useLastDevice();
}

MainWindow::~MainWindow() {
  frameTimer_.stop();
  // The station ends a session under way and stores its metrics; nothing is shown any more.
  station_.reset();
}

StationListener MainWindow::stationListener() {
  StationListener listener;
  listener.scene_build_progress = [this](const MeshingProgress& p) { showSceneBuildProgress(p); };
  listener.scene_leaving = [this] { mouseControl_->letGo(); };
  listener.scene_opened = [this](const SceneOpening& opening) { sceneOpened(opening); };
  listener.model_changed = [this](const ModelChangeOutcome& outcome) { modelChanged(outcome); };
  listener.scene_restarted = [this] {
    if (scene_ && shownTopology_ != 0)
      scene_->show_uncut(station_->simulation().snapshot().position_m);
    shownTopology_ = 0;
  };
  listener.session_metrics_stored = [this](const SessionMetricsOutcome& outcome) {
    sessionMetricsDone(outcome);
  };
  listener.recording_refused = [this](const StorageError& e) {
    showStorageProblem(storageProblemText(tr("Sessions are not recorded: %1"), e));
  };
  listener.session_not_saved = [this](const std::string& error) {
    showStorageProblem(tr("The session was not saved whole: %1").arg(qstring(error)));
  };
  listener.recording_stopped = [this](const StorageError& failure) {
    // Said when it happens: the session is no longer being saved (what was committed stays).
    showStorageProblem(storageProblemText(
        tr("Recording stopped: this session is no longer being saved (what was saved before "
           "is kept). %1"),
        failure));
    devicePanel_->showStatus(sessionsProblem_, true);
    emit recordingStopped(sessionsProblem_);
  };
  listener.device_stopped = [this](DeviceChoice choice, const std::string& device,
                                   const std::string& fault) {
    devices_->deviceStopped(choice, device, fault);
  };
  listener.device_tool = [this] {
    return devices_ ? devices_->deviceTool() : std::optional<DeviceToolSettings>();
  };
  listener.left_device_tool = [this] {
    return devices_ ? devices_->leftDeviceTool() : std::optional<DeviceToolSettings>();
  };
  listener.trainee = [this] { return traineeName().toStdString(); };
  return listener;
}

void MainWindow::showStorageProblem(const QString& text) {
  sessionsProblem_ = text;
  statusBar()->showMessage(text);
}

QDockWidget* MainWindow::addPanelDock(const QString& title, const char* name, QWidget* panel) {
  auto* dock = new QDockWidget(title, this);
  dock->setObjectName(name);
  dock->setWidget(new PanelScrollArea(panel, dock));
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable |
                    QDockWidget::DockWidgetClosable);
  addDockWidget(Qt::RightDockWidgetArea, dock);
  return dock;
}

void MainWindow::restoreLayout() {
  QSettings settings;
  restoreGeometry(settings.value("window/geometry").toByteArray());
  restoreState(settings.value("window/state").toByteArray(), kLayoutVersion);
}

void MainWindow::closeEvent(QCloseEvent* event) {
  QSettings settings;
  settings.setValue("window/geometry", saveGeometry());
  settings.setValue("window/state", saveState(kLayoutVersion));
  QMainWindow::closeEvent(event);
}

// --- Instructors --------------------------------------------------------------------------------

void MainWindow::setInstructorMode(bool on) {
  if (on && !instructor_) {  // the mode follows a log-in
    applyMode(false);
    openInstructorLogin(InstructorLoginDialog::Purpose::log_in);
    return;
  }
  if (!on) logOutInstructor();
  applyMode(on);
}

void MainWindow::applyMode(bool instructor) {
  instructorMode_ = instructor;
  materialPanel_->setEditable(instructor);
  materialPanel_->setGravityEditable(instructor || !station_->scenario());
  if (instructorModeAction_ != nullptr) instructorModeAction_->setChecked(instructor);
  if (scenarioEditorAction_ != nullptr) scenarioEditorAction_->setVisible(instructor);
  if (reviewSessionsAction_ != nullptr) reviewSessionsAction_->setVisible(instructor);
  if (addInstructorAction_ != nullptr) addInstructorAction_->setVisible(instructor);
}

bool MainWindow::logInInstructor(const QString& name, const QString& password, QString* why) {
  const auto refuse = [&](const QString& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  SessionStore* sessions = station_->sessions();
  if (!sessions)
    return refuse(tr("Instructor accounts are kept in the sessions database, which cannot be "
                     "used: %1")
                      .arg(sessionsProblem_.isEmpty() ? tr("there is none") : sessionsProblem_));
  try {
    if (!sessions->has_instructor_accounts())
      instructor_ =
          sessions->add_instructor_account(name.toStdString(), password.toStdString(), nullptr);
    else
      instructor_ = sessions->log_in_instructor(name.toStdString(), password.toStdString());
  } catch (const StorageError& e) {
    return refuse(storageProblemText(tr("Cannot log in: %1"), e));
  } catch (const std::exception& e) {  // a password that breaks the rule, a name taken
    return refuse(tr("Cannot set up the account: %1").arg(QString::fromUtf8(e.what())));
  }
  if (!instructor_) return refuse(tr("Wrong name or password."));
  applyMode(true);
  statusBar()->showMessage(tr("Logged in as %1 (instructor).").arg(qstring(instructor_->name())));
  return true;
}

bool MainWindow::addInstructorAccount(const QString& name, const QString& password, QString* why) {
  const auto refuse = [&](const QString& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (!station_->sessions() || !instructor_)
    return refuse(tr("Only an instructor who has logged in can add instructor accounts."));
  try {
    station_->sessions()->add_instructor_account(name.toStdString(), password.toStdString(),
                                                 &*instructor_);
  } catch (const StorageError& e) {
    return refuse(storageProblemText(tr("The account was not added: %1"), e));
  } catch (const std::exception& e) {
    return refuse(tr("The account was not added: %1").arg(QString::fromUtf8(e.what())));
  }
  statusBar()->showMessage(tr("Instructor account %1 added.").arg(name));
  return true;
}

void MainWindow::logOutInstructor() {
  instructor_.reset();
  if (review_) review_->close();  // it grades as the instructor who logged in
  applyMode(false);
}

InstructorLoginDialog* MainWindow::openInstructorLogin(InstructorLoginDialog::Purpose purpose) {
  if (purpose == InstructorLoginDialog::Purpose::log_in && station_->sessions()) {
    try {
      if (!station_->sessions()->has_instructor_accounts())
        purpose = InstructorLoginDialog::Purpose::create_first_account;
    } catch (const StorageError&) {
      // logInInstructor says what is wrong with the database when the form is sent
    }
  }
  if (loginDialog_) loginDialog_->close();
  auto* dialog = new InstructorLoginDialog(purpose, this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  connect(dialog, &InstructorLoginDialog::requested, this,
          [this, dialog](const QString& name, const QString& password) {
            answerForm(*dialog, [&](QString* why) {
              return dialog->purpose() == InstructorLoginDialog::Purpose::add_account
                         ? addInstructorAccount(name, password, why)
                         : logInInstructor(name, password, why);
            });
          });
  loginDialog_ = dialog;
  dialog->open();
  return dialog;
}

// --- The scene ---------------------------------------------------------------------------------

void MainWindow::showNewScene() {
  const SceneSetup& setup = station_->setup();
  auto scene = std::make_unique<LiverScene>(setup.mesh, setup.visual);
  scene->set_tool_models(toolModels_);
  scene->set_opacity(seeThrough_ ? kSeeThroughOpacity : 1.0);
  scene->set_ambient_occlusion(ambientOcclusion_);
  if (viewport_) {
    if (scene_) viewport_->renderWindow()->RemoveRenderer(scene_->renderer());
    viewport_->renderWindow()->AddRenderer(scene->renderer());
  }
  scene_ = std::move(scene);
  shownTopology_ = 0;
}

bool MainWindow::openScenario(const QString& file) {
  if (station_->busy_building()) return false;
  auto read = read_scenario_to_run(file.toStdString());
  if (auto* errors = std::get_if<std::vector<ScenarioError>>(&read)) {
    refuseScenario(file, scenarioErrorsText(*errors));
    return true;
  }
  auto& opened = std::get<OpenedScenario>(read);
  const QString folder = QString::fromStdString(opened.file.parent_path().string());
  buildScenario(std::move(opened), folder);
  return true;
}

bool MainWindow::tryScenario(const Scenario& scenario, const QString& file) {
  if (station_->busy_building()) return false;
  const QString folder = file.isEmpty() ? QDir::currentPath() : QFileInfo(file).absolutePath();
  buildScenario({scenario, file.toStdString(), write_scenario(scenario)}, folder);
  return true;
}

void MainWindow::buildScenario(OpenedScenario opened, const QString& folder) {
  const QString name = scenarioName(opened);
  station_->open_scenario(std::move(opened), folder.toStdString());
  accuracyPanel_->setBusy(true);
  statusBar()->showMessage(tr("Building the scene of %1…").arg(name));
  // Until meshing reports its attempts, the bar only says that work goes on.
  buildProgress_->setRange(0, 0);
  buildProgress_->show();
  cancelBuild_->setEnabled(true);
  cancelBuild_->show();
  buildProgress_->setProperty("scenarioName", name);
}

void MainWindow::showSceneBuildProgress(const MeshingProgress& p) {
  const QString name = buildProgress_->property("scenarioName").toString();
  const QString text =
      p.tet_count == 0 ? tr("Building the scene of %1: meshing the organ, attempt %2 of at most %3 "
                            "(elements of %4 mm)…")
                             .arg(name)
                             .arg(p.attempt)
                             .arg(p.max_attempts)
                             .arg(p.element_size_mm, 0, 'f', 1)
                       : tr("Building the scene of %1: attempt %2 made %3 elements…")
                             .arg(name)
                             .arg(p.attempt)
                             .arg(p.tet_count);
  // Before and after each attempt: done attempts of at most max_attempts.
  buildProgress_->setRange(0, p.max_attempts);
  buildProgress_->setValue(p.attempt - (p.tet_count == 0 ? 1 : 0));
  statusBar()->showMessage(text);
}

void MainWindow::sceneOpened(const SceneOpening& opening) {
  accuracyPanel_->setBusy(false);
  buildProgress_->hide();
  cancelBuild_->hide();
  const QString name = buildProgress_->property("scenarioName").toString();
  switch (opening.result) {
    case SceneOpening::Result::cancelled:  // asked for: not an error
      statusBar()->showMessage(
          tr("Opening %1 was cancelled; the scene that was running goes on.").arg(name));
      emit scenarioOpenFinished(false);
      return;
    case SceneOpening::Result::refused:
      return refuseScenario(name, qstring(opening.error));
    case SceneOpening::Result::opened:
      break;
  }
  showNewScene();
  accuracyPanel_->setSettings(station_->integrator());
  showScenarioDetails();
  if (!scenario()->file.empty()) {
    rememberScenarioFile(QString::fromStdString(scenario()->file.string()));
    updateRecentMenu();
  }
  statusBar()->showMessage(tr("Opened %1.").arg(name));
  viewport_->scheduleRender();
  emit scenarioOpenFinished(true);
}

QString MainWindow::scenarioName(const OpenedScenario& opened) {
  return opened.file.empty()
             ? tr("“%1” (from the editor, not saved)").arg(qstring(opened.scenario.title))
             : QString::fromStdString(opened.file.filename().string());
}

void MainWindow::refuseScenario(const QString& file, const QString& why) {
  const QString text =
      tr("Cannot open the scenario %1:\n%2\nThe scene that was running goes on.").arg(file, why);
  scenarioPanel_->showProblem(text);
  statusBar()->showMessage(tr("Cannot open the scenario %1.").arg(QFileInfo(file).fileName()));
  // Window-modal but not blocking, so that the simulation and the caller go on.
  auto* box = new QMessageBox(QMessageBox::Warning, tr("Cannot open the scenario"), text,
                              QMessageBox::Ok, this);
  box->setObjectName("scenarioErrorBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
  emit scenarioOpenFinished(false);
}

void MainWindow::cancelSceneBuild() {
  if (!station_->opening_scenario()) return;
  station_->cancel_scene_build();
  cancelBuild_->setEnabled(false);
  statusBar()->showMessage(tr("Cancelling…"));
}

void MainWindow::showScenarioDetails() {
  const auto& opened = scenario();
  const QString name =
      opened ? qstring(opened->scenario.title)
             : tr("free practice, %1 elements").arg(station_->setup().mesh.tet_count());
  setWindowTitle(tr("LiverSim — %1").arg(name));
  scene_->show_lesions(opened ? visible_lesions(opened->scenario) : std::vector<LesionShape>{});
  scenarioPanel_->showScenario(opened ? &opened->scenario : nullptr,
                               opened ? QString::fromStdString(opened->file.string()) : QString());
  // Free practice offers what a scenario does by default: every tool.
  toolPanel_->setAvailableTools(opened ? opened->scenario.tools : Scenario{}.tools);
  if (devices_) devices_->setLeftHandTools(opened ? opened->scenario.tools : Scenario{}.tools);
  const Scenario described = station_->described_scenario();
  materialPanel_->showTissue(described.parenchyma, described.effects);
  materialPanel_->setGravityEditable(instructorMode_ || !opened);
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->setObjectName("fileMenu");
  QAction* open = file->addAction(tr("&Open Scenario…"), this, [this] {
    const QString chosen =
        QFileDialog::getOpenFileName(this, tr("Open a scenario"), scenarioFolderToOpen(),
                                     tr("LiverSim scenarios (*.json);;All files (*)"));
    if (!chosen.isEmpty()) openScenarioFromMenu(chosen);
  });
  open->setObjectName("openScenarioAction");
  open->setShortcut(QKeySequence::Open);
  recentMenu_ = file->addMenu(tr("Open &Recent"));
  recentMenu_->setObjectName("recentScenariosMenu");
  updateRecentMenu();
  QAction* editor =
      file->addAction(tr("Scenario &Editor…"), this, [this] { openScenarioEditor(); });
  editor->setObjectName("scenarioEditorAction");
  editor->setToolTip(tr("Instructors: author the scenario shown, or a new one"));
  editor->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_E));
  scenarioEditorAction_ = editor;
  file->addSeparator();
  QAction* quit = file->addAction(tr("&Quit"), this, &QWidget::close);
  quit->setObjectName("quitAction");
  quit->setShortcut(QKeySequence::Quit);

  QMenu* view = menuBar()->addMenu(tr("&View"));
  view->setObjectName("viewMenu");
  seeThroughAction_ = view->addAction(tr("&See-through Liver"), this,
                                      [this](bool checked) { setSeeThrough(checked); });
  seeThroughAction_->setObjectName("seeThroughAction");
  seeThroughAction_->setCheckable(true);
  seeThroughAction_->setShortcut(QKeySequence(Qt::Key_T));
  seeThroughAction_->setToolTip(tr("Show the liver translucent, with the lesions inside it"));
  ambientOcclusionAction_ = view->addAction(tr("&Ambient Occlusion"), this, [this](bool checked) {
    ambientOcclusion_ = checked;
    scene_->set_ambient_occlusion(checked);
    QSettings().setValue("view/ambient_occlusion", checked);
    viewport_->update();
  });
  ambientOcclusionAction_->setObjectName("ambientOcclusionAction");
  ambientOcclusionAction_->setCheckable(true);
  ambientOcclusionAction_->setToolTip(
      tr("Darken creases and cut edges by their ambient occlusion (costs frame rate: "
         "docs/rendering-performance.md)"));
  ambientOcclusion_ = QSettings().value("view/ambient_occlusion", false).toBool();
  ambientOcclusionAction_->setChecked(ambientOcclusion_);
  scene_->set_ambient_occlusion(ambientOcclusion_);
  view->addSeparator();
  panelsMenu_ = view->addMenu(tr("&Panels"));
  panelsMenu_->setObjectName("panelsMenu");
  for (QDockWidget* dock : findChildren<QDockWidget*>())
    panelsMenu_->addAction(dock->toggleViewAction());

  QMenu* session = menuBar()->addMenu(tr("&Session"));
  session->setObjectName("sessionMenu");
  QAction* mark =
      session->addAction(tr("&Mark the Lesion Here"), this, [this] { markLesionUnderTool(); });
  mark->setObjectName("markLesionAction");
  mark->setShortcut(QKeySequence(Qt::Key_M));
  QAction* removeSpecimen = session->addAction(tr("Remove &Specimen"), this, [this] {
    const int bodies = station_->take_out_specimens();
    statusBar()->showMessage(bodies == 0
                                 ? tr("There is no specimen to remove: no piece has been cut free.")
                                 : tr("Took %n specimen(s) out of the field.", nullptr, bodies));
  });
  removeSpecimen->setObjectName("removeSpecimenAction");
  removeSpecimen->setToolTip(
      tr("Take the pieces cut free out of the field; they are kept as the session's specimen"));
  QAction* review =
      session->addAction(tr("&Review Sessions…"), this, [this] { openSessionReview(); });
  review->setObjectName("reviewSessionsAction");
  review->setToolTip(tr("Instructors: review and grade every trainee's sessions"));
  reviewSessionsAction_ = review;
  QAction* serverReview = session->addAction(tr("Review Sessions on the Ser&ver…"), this, [this] {
    auto* login = new InstructorLoginDialog(InstructorLoginDialog::Purpose::log_in, this);
    login->setObjectName("serverLogin");
    login->setWindowTitle(tr("Log in to the training centre's server"));
    login->setAttribute(Qt::WA_DeleteOnClose);
    connect(login, &InstructorLoginDialog::requested, this,
            [this, login](const QString& name, const QString& password) {
              answerForm(*login, [&](QString* why) {
                return openServerReview(name, password, why) != nullptr;
              });
            });
    login->show();
  });
  serverReview->setObjectName("serverReviewAction");
  serverReview->setToolTip(
      tr("Instructors: review and grade the sessions of every workstation on the training "
         "centre's server"));
  QAction* history =
      session->addAction(tr("My &Sessions…"), this, [this] { openTraineeHistory(); });
  history->setObjectName("traineeHistoryAction");
  mark->setToolTip(
      tr("Palpation: mark the point of the liver under the tool as where the lesion "
         "is (graded at the session's end)"));

  QMenu* settings = menuBar()->addMenu(tr("Se&ttings"));
  settings->setObjectName("settingsMenu");
  instructorModeAction_ =
      settings->addAction(tr("&Instructor Mode"), this, [this](bool on) { setInstructorMode(on); });
  instructorModeAction_->setObjectName("instructorModeAction");
  instructorModeAction_->setCheckable(true);
  instructorModeAction_->setShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_I));
  instructorModeAction_->setToolTip(
      tr("Instructor mode, after a log-in: change the tissue, author scenarios, review and "
         "grade every trainee's sessions"));
  addInstructorAction_ = settings->addAction(tr("&Add Instructor Account…"), this, [this] {
    openInstructorLogin(InstructorLoginDialog::Purpose::add_account);
  });
  addInstructorAction_->setObjectName("addInstructorAction");
  addInstructorAction_->setVisible(instructorMode_);
  QAction* centre = settings->addAction(tr("&Training Centre Server…"), this,
                                        [this] { openTrainingCentreSettings(); });
  centre->setObjectName("trainingCentreAction");
  centre->setToolTip(
      tr("Upload finished sessions to the training centre's server and pull its scenarios"));
  settings->addSeparator();
  QMenu* language = settings->addMenu(tr("&Language"));
  language->setObjectName("languageMenu");
  auto* languages = new QActionGroup(language);
  const QString chosen = languageSetting();
  const auto addLanguage = [&](const QString& code, const QString& name) {
    QAction* action = language->addAction(name);
    action->setObjectName("language_" + (code.isEmpty() ? QStringLiteral("system") : code));
    action->setCheckable(true);
    action->setChecked(code == chosen);
    languages->addAction(action);
    connect(action, &QAction::triggered, this, [this, code] {
      setLanguageSetting(code);
      statusBar()->showMessage(tr("LiverSim will use this language when it starts again."));
    });
  };
  addLanguage({}, tr("The System's Language"));
  for (const QString& code : availableLanguages()) addLanguage(code, languageName(code));

  // The actions of every session in reach, each with its shortcut in its tooltip.
  toolBar_ = addToolBar(tr("Main Toolbar"));
  toolBar_->setObjectName("mainToolBar");
  toolBar_->setToolButtonStyle(Qt::ToolButtonTextBesideIcon);
  open->setIcon(style()->standardIcon(QStyle::SP_DialogOpenButton));
  for (QAction* action : {open, editor}) toolBar_->addAction(action);
  toolBar_->addSeparator();
  toolBar_->addAction(seeThroughAction_);
  toolBar_->addSeparator();
  for (QAction* action : {mark, history, review}) toolBar_->addAction(action);
  toolBar_->addSeparator();
  toolBar_->addAction(instructorModeAction_);
  static const QRegularExpression mnemonic(QStringLiteral(R"(\(&\w\)|&)"));
  for (QAction* action : toolBar_->actions()) {
    // A button shows no mnemonic, neither "&" nor a translation's "(&O)".
    action->setIconText(action->text().remove(mnemonic));
    // An action without a tooltip of its own shows its text: the button's, then.
    QString tip = action->toolTip();
    if (tip == QString(action->text()).remove('&')) tip = action->iconText();
    if (!action->shortcut().isEmpty())
      tip = tr("%1 (%2)").arg(tip, action->shortcut().toString(QKeySequence::NativeText));
    action->setToolTip(tip);
  }
  panelsMenu_->addAction(toolBar_->toggleViewAction());
}

void MainWindow::setSeeThrough(bool on) {
  seeThrough_ = on;
  scene_->set_opacity(on ? kSeeThroughOpacity : 1.0);
  if (seeThroughAction_ != nullptr) seeThroughAction_->setChecked(on);
  QSettings().setValue("view/see_through", on);
  viewport_->update();
}

ScenarioEditor* MainWindow::openScenarioEditor() {
  if (!instructor_) {  // the action is hidden in trainee mode; this holds for any caller
    statusBar()->showMessage(
        tr("Authoring scenarios is for instructors: log in first (Settings ▸ Instructor Mode)."));
    return nullptr;
  }
  if (!editor_) {
    editor_ = new ScenarioEditor(this);
    editor_->setWindowFlag(Qt::Window);
    editor_->setAttribute(Qt::WA_DeleteOnClose);
    // The scenario running here, to start from (a tried one keeps its editor's document).
    if (scenario() && !scenario()->file.empty())
      editor_->document().reset(scenario()->scenario,
                                QString::fromStdString(scenario()->file.string()));
    connect(editor_, &ScenarioEditor::tryScenario, this,
            [this](const Scenario& scenario, const QString& file) {
              if (!tryScenario(scenario, file))
                statusBar()->showMessage(
                    tr("A scene is still being built; try the scenario after it."));
              raise();
              activateWindow();
            });
  }
  editor_->show();
  editor_->raise();
  return editor_;
}

void MainWindow::openScenarioFromMenu(const QString& file) {
  if (!openScenario(file))
    statusBar()->showMessage(tr("A scene is still being built; open the scenario after it."));
}

void MainWindow::updateRecentMenu() {
  recentMenu_->clear();
  const QStringList recent = recentScenarioFiles();
  for (const QString& file : recent) {
    QAction* action = recentMenu_->addAction(QFileInfo(file).fileName(), this,
                                             [this, file] { openScenarioFromMenu(file); });
    action->setToolTip(file);
    action->setData(file);
  }
  recentMenu_->setEnabled(!recent.isEmpty());
}

// --- Live changes of the model -----------------------------------------------------------------

bool MainWindow::applyIntegratorSettings(const IntegratorSettings& settings) {
  if (!station_->change_integrator(settings)) return false;
  accuracyPanel_->setBusy(true);
  return true;
}

bool MainWindow::applyTissue(const TissueSpec& tissue) {
  if (!instructor_) {  // the panel is read-only in trainee mode; this holds for any caller
    materialPanel_->showError(
        tr("Changing the tissue is for instructors: log in first "
           "(Settings ▸ Instructor Mode)."));
    return false;
  }
  if (!station_->change_tissue(tissue)) return false;
  materialPanel_->setBusy(true);
  return true;
}

bool MainWindow::applyGravity(bool on) {
  if (station_->scenario() && !instructorMode_) {  // the scenario's: for instructors to change
    materialPanel_->showError(
        tr("Gravity is the scenario's: an instructor can switch it (Settings ▸ Instructor Mode)."));
    return true;  // said why
  }
  if (!station_->change_gravity(on)) return false;
  materialPanel_->setSwitchingGravity();
  return true;
}

void MainWindow::modelChanged(const ModelChangeOutcome& outcome) {
  if (outcome.kind == ModelChangeOutcome::Kind::gravity) {
    if (!outcome.applied)
      materialPanel_->showError(outcome.cut_meanwhile
                                    ? tr("The liver was cut while gravity was switched; switch it "
                                         "again.")
                                    : qstring(outcome.error));
    else
      materialPanel_->showTissue(station_->described_scenario().parenchyma,
                                 station_->described_scenario().effects);
    emit gravityChangeFinished(outcome.applied);
    return;
  }
  const bool integrator = outcome.kind == ModelChangeOutcome::Kind::integrator;
  if (!outcome.applied) {
    const QString why = !outcome.cut_meanwhile ? qstring(outcome.error)
                        : integrator
                            ? tr("The liver was cut while the integrator changed; apply it again.")
                            : tr("The liver was cut while the tissue changed; enter it again.");
    if (integrator) {
      accuracyPanel_->setBusy(false);
      accuracyPanel_->showError(why);
      emit integratorChangeFinished(false);
    } else {
      materialPanel_->showError(why);
      emit tissueChangeFinished(false);
    }
    return;
  }
  if (integrator) {
    accuracyPanel_->setBusy(false);
    accuracyPanel_->setSettings(station_->integrator());
    emit integratorChangeFinished(true);
    return;
  }
  const Scenario described = station_->described_scenario();
  materialPanel_->showTissue(described.parenchyma, described.effects);
  emit tissueChangeFinished(true);
}

AccuracyStudyDialog* MainWindow::openAccuracyStudy() {
  if (!accuracyStudy_) {
    accuracyStudy_ = new AccuracyStudyDialog(this);
    connect(accuracyStudy_, &AccuracyStudyDialog::settingChosen, this,
            [this](const IntegratorSettings& chosen) {
              // The study sets the scheme and its step or tolerance; Newton's settings stay.
              IntegratorSettings settings = station_->integrator();
              settings.kind = chosen.kind;
              settings.step_s = chosen.step_s;
              settings.tolerance_m = chosen.tolerance_m;
              if (!applyIntegratorSettings(settings))
                statusBar()->showMessage(
                    tr("Not applied: a model is being built. Try again when it is done."));
            });
  }
  accuracyStudy_->show();
  accuracyStudy_->raise();
  return accuracyStudy_;
}

// --- Display -----------------------------------------------------------------------------------

void MainWindow::showNewestSnapshot() {
  const StationFrame frame = station_->frame();
  if (!frame.new_snapshot) return;
  const SimulationSnapshot& snapshot = station_->simulation().snapshot();
  if (snapshot.topology_version != shownTopology_ && snapshot.model) {
    scene_->show_cut_model(*snapshot.model, snapshot.position_m);
    shownTopology_ = snapshot.topology_version;
  }
  scene_->update_positions(snapshot.position_m);
  // The device's (or the mouse's) hand: the Tool panel shows its force and its blade.
  const HandSnapshot& held = snapshot.hand(Hand::right);
  for (Hand hand : kHands) scene_->show_tool(hand, snapshot.hand(hand).tool);  // where it has them
  if (mouseControl_->tool() || (servo() && held.tool))
    toolPanel_->showForce(snapshot.time_s, held.force_n, held.grasping);
  else if (const auto pull = mouseControl_->grabForce_n(snapshot.position_m))
    toolPanel_->showForce(snapshot.time_s, *pull, true);
  else
    toolPanel_->showForce(snapshot.time_s, Eigen::Vector3d::Zero(), false);
  const bool scalpel = held.tool && held.tool->kind == ToolKind::scalpel;
  toolPanel_->showBlade(scalpel ? std::optional(held.blade_edge_in_tissue_m) : std::nullopt,
                        held.blade_cutting);
  viewport_->scheduleRender();
}

void MainWindow::updateStatus() {
  if (servo()) {
    const ServoStats stats = servo()->stats();
    devicePanel_->showServoStats(&stats);
  }
  SimulationStatus status;
  const double window_s = frameWindow_.restart() / 1000.0;
  status.framesPerSecond = window_s > 0 ? framesInWindow_ / window_s : 0.0;
  framesInWindow_ = 0;
  status.stats = station_->simulation().stats();
  const SimulationSnapshot& snapshot = station_->simulation().snapshot();
  if (const auto pull = mouseControl_->grabForce_n(snapshot.position_m))
    status.pullingForce_n = pull->norm();
  status.resectedVolume_m3 = snapshot.resected_volume_m3;
  status.freeBodies = snapshot.free_bodies;
  status.specimensTakenOut = snapshot.specimens_taken_out;
  statusLabel_->setText(simulationStatusText(status));
}

// --- Devices -----------------------------------------------------------------------------------

Eigen::Quaterniond MainWindow::deviceAxesFromView() const {
  double direction[3], up[3];
  vtkCamera* camera = scene_->renderer()->GetActiveCamera();
  camera->GetDirectionOfProjection(direction);
  camera->GetViewUp(up);
  return device_axes_from_view(-Eigen::Vector3d(direction[0], direction[1], direction[2]),
                               Eigen::Vector3d(up[0], up[1], up[2]));
}

bool MainWindow::useLeftHandOmni() {
  return devices_->useLeftOmni();
}

bool MainWindow::useLeftHandDevice(const QString& trajectoryFile) {
  if (trajectoryFile.isEmpty()) {
    devices_->clearLeftDevice();
    return true;
  }
  return devices_->useLeftDevice(trajectoryFile);
}

bool MainWindow::useDevice(DeviceChoice device, const QString& trajectoryFile) {
  return devices_->useDevice(device, trajectoryFile);
}

CalibrationDialog* MainWindow::openCalibration() {
  return devices_->openCalibration();
}

const HapticPreferences& MainWindow::hapticPreferences() const {
  return devices_->preferences();
}

// --- Sessions ----------------------------------------------------------------------------------

bool MainWindow::setSessionsDatabase(const QString& file) {
  if (instructor_) logOutInstructor();  // an account is of one database
  sessionsProblem_.clear();
  if (const std::optional<StorageError> problem = station_->open_sessions(file.toStdString())) {
    showStorageProblem(storageProblemText(tr("Sessions are not recorded: %1"), *problem));
    trainingCentreControl_->showStatus();
    return false;
  }
  trainingCentreControl_->startAtLaunch();
  return true;
}

QString MainWindow::traineeName() const {
  return QSettings()
      .value("sessions/trainee", qEnvironmentVariable("USER", tr("Trainee")))
      .toString();
}

bool MainWindow::markLesionUnderTool() {
  if (!station_->recording_session() || !servo()) {
    statusBar()->showMessage(
        station_->sessions()
            ? tr("Marks are kept with a recorded session: put a tool on the liver first.")
            : tr("Marks are kept with a recorded session, and there is no sessions database."));
    return false;
  }
  const std::optional<Eigen::Vector3d> rest_m = station_->mark_lesion_under_tool();
  if (!rest_m) {
    statusBar()->showMessage(tr("Hold a tool over the place to mark."));
    return false;
  }
  statusBar()->showMessage(tr("Marked the lesion at (%1, %2, %3) mm.")
                               .arg(rest_m->x() * 1e3, 0, 'f', 0)
                               .arg(rest_m->y() * 1e3, 0, 'f', 0)
                               .arg(rest_m->z() * 1e3, 0, 'f', 0));
  return true;
}

void MainWindow::sessionMetricsDone(const SessionMetricsOutcome& outcome) {
  if (outcome.storage_problem)
    showStorageProblem(storageProblemText(tr("The session's metrics were not stored: %1"),
                                          *outcome.storage_problem));
  else if (!outcome.stored)
    showStorageProblem(
        tr("The session's metrics were not stored: %1").arg(qstring(outcome.problem)));
  else
    scenarioPanel_->showSessionResult(outcome.rubric, outcome.metrics);
  emit sessionMetricsStored(outcome.session, outcome.stored);
}

SessionReviewWindow* MainWindow::openSessionReview() {
  if (!instructor_) {
    statusBar()->showMessage(
        tr("Reviewing every trainee's sessions is for instructors: log in first (Settings ▸ "
           "Instructor Mode)."));
    return nullptr;
  }
  return showSessionsWindow(review_, std::nullopt);
}

SessionReviewWindow* MainWindow::openTraineeHistory() {
  return showSessionsWindow(history_, traineeName());
}

SessionReviewWindow* MainWindow::showSessionsWindow(QPointer<SessionReviewWindow>& window,
                                                    const std::optional<QString>& trainee) {
  if (!station_->sessions()) {
    statusBar()->showMessage(sessionsProblem_.isEmpty() ? tr("There is no sessions database.")
                                                        : sessionsProblem_);
    return nullptr;
  }
  if (!window) {
    // The instructor logged in grades; a trainee's history takes no grader.
    window = new SessionReviewWindow(QString::fromStdString(station_->sessions_file().string()),
                                     trainee, instructor_, this);
    window->setAttribute(Qt::WA_DeleteOnClose);
  } else {
    window->refresh();
  }
  window->show();
  window->raise();
  return window;
}

std::vector<SessionSummary> MainWindow::replayableSessions() {
  // A trainee replays their own sessions only.
  SessionStore& sessions = *station_->sessions();
  return instructor_ ? sessions.sessions()
                     : sessions.sessions_of_trainee(traineeName().toStdString());
}

bool MainWindow::replaySession(std::int64_t session) {
  return devices_->replaySession(session);
}

// --- The training centre -----------------------------------------------------------------------

bool MainWindow::connectTrainingCentre(const TrainingCentreSetting& setting,
                                       const QString& password, QString* why) {
  return trainingCentreControl_->connect(setting, password, why);
}

QString MainWindow::trainingCentreStatusText() const {
  return trainingCentreControl_->statusText();
}

QString MainWindow::pulledScenarioFolder() const {
  return QString::fromStdString(station_->pulled_scenario_folder().string());
}

TrainingCentreDialog* MainWindow::openTrainingCentreSettings() {
  return trainingCentreControl_->openSettings();
}

SessionReviewWindow* MainWindow::openServerReview(const QString& instructor,
                                                  const QString& password, QString* why) {
  return trainingCentreControl_->openServerReview(instructor, password, why);
}

}  // namespace liversim
