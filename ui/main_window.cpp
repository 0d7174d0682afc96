#include "main_window.h"

#include "accuracy_panel.h"
#include "accuracy_study_dialog.h"
#include "calibration_dialog.h"
#include "device_panel.h"
#include "instructor_login_dialog.h"
#include "material_panel.h"
#include "recent_scenarios.h"
#include "render/liver_scene.h"
#include "scenario_document.h"
#include "scenario_editor.h"
#include "scenario_panel.h"
#include "tool_panel.h"
#include "translations.h"
#include "vtk_viewport.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/surface.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/openhaptics_device.h"
#include "liversim/interaction/cutting.h"
#include "liversim/sessions/outcome_metrics.h"
#include "liversim/sessions/session_recording.h"
#include "liversim/sessions/session_replay.h"
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"
#include "session_reading.h"
#include "session_review_window.h"
#include "storage_messages.h"

#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>
#include <QAction>
#include <QActionGroup>
#include <QCloseEvent>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QFile>
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
#include <atomic>
#include <cmath>
#include <exception>
#include <sstream>
#include <string_view>

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

// A positive number with two or three significant digits and no exponent: 0.81, 2.6, 15, 480.
QString formatAmount(double value) {
  const double size = std::abs(value);
  return QString::number(value, 'f', size < 1.0 ? 2 : size < 10.0 ? 1 : 0);
}

// A tissue as a session event's detail (the database's, in English): the parenchyma's parameters
// of the effects simulated.
std::string describe_tissue(const TissueSpec& tissue, const EffectsSpec& effects) {
  std::ostringstream text;
  text << "E " << tissue.elastic.youngs_modulus_pa << " Pa, nu " << tissue.elastic.poisson_ratio
       << ", density " << tissue.elastic.density_kg_per_m3 << " kg/m3";
  if (effects.viscoelastic && tissue.viscoelastic)
    text << ", E1 " << tissue.viscoelastic->e1_pa << " Pa, eta1 " << tissue.viscoelastic->eta1_pa_s
         << " Pa s";
  if (effects.viscoplastic && tissue.viscoplastic)
    text << ", yield limit " << tissue.viscoplastic->yield_limit_pa << " Pa, eta2 "
         << tissue.viscoplastic->eta2_pa_s_pow_n << " Pa s^n, n "
         << tissue.viscoplastic->creep_index_n;
  if (effects.fibres && tissue.fibres)
    text << ", k1 " << tissue.fibres->k1_pa << " Pa, k2 " << tissue.fibres->k2;
  return text.str();
}

}  // namespace

MainWindow::MainWindow(SceneSetup setup, std::optional<OpenedScenario> scenario, QWidget* parent)
    : QMainWindow(parent), toolModels_(load_tool_models()), scenario_(std::move(scenario)) {
  auto model = std::make_shared<const SimModel>(build_model(setup.mesh, setup.model_options));
  installScene(std::move(setup), std::move(model));

  viewport_ = new VtkViewport(this);
  viewport_->setObjectName("liverViewport");
  viewport_->renderWindow()->AddRenderer(scene_->renderer());
  viewport_->setPressFilter(
      [this](QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers) {
        return beginGrab(pos, button, modifiers);
      });
  connect(viewport_, &VtkViewport::mouseMovedTo, this, [this](QPoint pos, Qt::MouseButtons) {
    if (grab_) moveGrab(pos);
    if (tool_) moveTool(pos);
  });
  connect(viewport_, &VtkViewport::mouseReleasedAt, this, [this](QPoint, Qt::MouseButton button) {
    if (grab_ && button == Qt::LeftButton) endGrab();
    if (tool_ && button == Qt::LeftButton) endTool();
  });
  connect(viewport_, &QOpenGLWidget::frameSwapped, this, [this] { ++framesInWindow_; });
  setCentralWidget(viewport_);

  scenarioPanel_ = new ScenarioPanel(this);
  scenarioPanel_->setObjectName("scenarioPanel");
  addPanelDock(tr("Scenario"), "scenarioDock", scenarioPanel_);

  accuracyPanel_ = new AccuracyPanel(this);
  accuracyPanel_->setObjectName("accuracyPanel");
  accuracyPanel_->setSettings(setup_.model_options.integrator);
  connect(accuracyPanel_, &AccuracyPanel::applyRequested, this,
          [this](const IntegratorSettings& settings) { applyIntegratorSettings(settings); });
  connect(accuracyPanel_, &AccuracyPanel::studyRequested, this, [this] { openAccuracyStudy(); });
  addPanelDock(tr("Accuracy"), "accuracyDock", accuracyPanel_);

  materialPanel_ = new MaterialPanel(this);
  materialPanel_->setObjectName("materialPanel");
  connect(materialPanel_, &MaterialPanel::tissueRequested, this, [this](const TissueSpec& tissue) {
    if (!applyTissue(tissue))
      materialPanel_->showError(
          tr("a scene or an integrator change is being built; enter the "
             "value again after it."));
  });
  addPanelDock(tr("Material"), "materialDock", materialPanel_);

  toolPanel_ = new ToolPanel(this);
  toolPanel_->setObjectName("toolPanel");
  addPanelDock(tr("Tool"), "toolDock", toolPanel_);
  connect(toolPanel_, &ToolPanel::toolChanged, this, [this] {
    if (mouse_) {
      if (tool_) endTool();  // the mouse puts the new one down with its next press
      return;
    }
    if (servo_) simulation_->set_device_tool(deviceToolSettings());
    recordToolChoice();
  });

  devicePanel_ = new DevicePanel(this);
  devicePanel_->setObjectName("devicePanel");
  addPanelDock(tr("Device"), "deviceDock", devicePanel_);
  {
    QSettings settings;
    haptics_ = load_haptic_preferences(settings);
  }
  openOmni();
  connect(devicePanel_, &DevicePanel::deviceChosen, this, [this](DeviceChoice device) {
    if (device == DeviceChoice::replay) return chooseSessionToReplay();
    if (device != DeviceChoice::scripted) return void(useDevice(device));
    const QString file =
        QFileDialog::getOpenFileName(this, tr("Trajectory to play"), haptics_.trajectory_file,
                                     tr("Trajectories (*.txt *.trajectory);;All files (*)"));
    if (file.isEmpty())
      devicePanel_->showDevice(haptics_.device);  // cancelled: the device in use stays
    else
      useDevice(device, file);
  });
  connect(devicePanel_, &DevicePanel::calibrateRequested, this, [this] { openCalibration(); });

  if (scenario_) rememberScenarioFile(scenario_->file);
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
  trainingCentreLabel_ = new QLabel(this);
  trainingCentreLabel_->setObjectName("trainingCentreStatus");
  trainingCentreLabel_->hide();
  statusBar()->addPermanentWidget(trainingCentreLabel_);
  // The link's status changes on its thread; the rest changes here and is shown at once.
  connect(&trainingCentreTimer_, &QTimer::timeout, this, [this] {
    if (trainingCentre_) showTrainingCentreStatus();
  });
  trainingCentreTimer_.start(1000);
  // A session's upload waits for its metrics: the link is asked to run once they are stored.
  connect(this, &MainWindow::sessionMetricsStored, this, [this] {
    if (trainingCentre_) trainingCentre_->run_soon();
  });
  if (toolModels_.problem.empty())
    statusBar()->showMessage(
        tr("Drag the liver with the left mouse button; drag the background to "
           "turn the view, wheel to zoom."));
  else
    statusBar()->showMessage(tr("The tool models could not be read, so the tools are drawn as "
                                "simple shapes: %1")
                                 .arg(QString::fromStdString(toolModels_.problem)));
  resize(1200, 800);
  restoreLayout();

  frameTimer_.setTimerType(Qt::PreciseTimer);
  connect(&frameTimer_, &QTimer::timeout, this, &MainWindow::showNewestSnapshot);
  frameTimer_.start(16);
  connect(&statusTimer_, &QTimer::timeout, this, &MainWindow::updateStatus);
  statusTimer_.start(500);
  frameWindow_.start();
  simulation_->start();
  // The device of the last session: the Omni if it is there again (a script is played on
  // request only); otherwise the mouse.
  const DeviceChoice last = haptics_.device;
  haptics_.device = DeviceChoice::mouse;
  useDevice(DeviceChoice::mouse);
  if (last == DeviceChoice::openhaptics && !useDevice(DeviceChoice::openhaptics)) {
    HapticPreferences remembered = haptics_;  // tried again at the next start
    remembered.device = last;
    QSettings settings;
    save_haptic_preferences(settings, remembered);
  }
}

QDockWidget* MainWindow::addPanelDock(const QString& title, const char* name, QWidget* panel) {
  auto* dock = new QDockWidget(title, this);
  dock->setObjectName(name);
  dock->setWidget(panel);
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
  if (!sessions_)
    return refuse(tr("Instructor accounts are kept in the sessions database, which cannot be "
                     "used: %1")
                      .arg(sessionsProblem_.isEmpty() ? tr("there is none") : sessionsProblem_));
  try {
    if (!sessions_->has_instructor_accounts())
      instructor_ =
          sessions_->add_instructor_account(name.toStdString(), password.toStdString(), nullptr);
    else
      instructor_ = sessions_->log_in_instructor(name.toStdString(), password.toStdString());
  } catch (const StorageError& e) {
    return refuse(storageProblemText(tr("Cannot log in: %1"), e));
  } catch (const std::exception& e) {  // a password that breaks the rule, a name taken
    return refuse(tr("Cannot set up the account: %1").arg(QString::fromUtf8(e.what())));
  }
  if (!instructor_) return refuse(tr("Wrong name or password."));
  applyMode(true);
  statusBar()->showMessage(
      tr("Logged in as %1 (instructor).").arg(QString::fromStdString(instructor_->name())));
  return true;
}

bool MainWindow::addInstructorAccount(const QString& name, const QString& password, QString* why) {
  const auto refuse = [&](const QString& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (!sessions_ || !instructor_)
    return refuse(tr("Only an instructor who has logged in can add instructor accounts."));
  try {
    sessions_->add_instructor_account(name.toStdString(), password.toStdString(), &*instructor_);
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
  if (purpose == InstructorLoginDialog::Purpose::log_in && sessions_) {
    try {
      if (!sessions_->has_instructor_accounts())
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

void MainWindow::installScene(SceneSetup setup, std::shared_ptr<const SimModel> model) {
  // The visual surface's triangles are the physics boundary's (its vertex i is node nodes[i]).
  auto simulation = make_scene_simulation(model, setup.visual.surface);
  auto scene = std::make_unique<LiverScene>(setup.mesh, setup.visual);
  scene->set_tool_models(toolModels_);
  scene->set_opacity(seeThrough_ ? kSeeThroughOpacity : 1.0);
  scene->set_ambient_occlusion(ambientOcclusion_);
  if (simulation_) {
    // The hand and the mouse's tool let go of the old liver; a device stays attached.
    if (grab_) endGrab();
    if (tool_) endTool();
    simulation_->stop();
  }
  if (viewport_) {
    if (scene_) viewport_->renderWindow()->RemoveRenderer(scene_->renderer());
    viewport_->renderWindow()->AddRenderer(scene->renderer());
  }
  simulation_ = std::move(simulation);
  scene_ = std::move(scene);
  setup_ = std::move(setup);
  sceneModel_ = std::move(model);
  shownTopology_ = 0;
  tissueChangedInFreePractice_ = false;
}

void MainWindow::restartFromRest() {
  simulation_->stop();
  // An integrator changed on a cut liver: the scene's model with it, built now.
  if (sceneModel_->integrator != setup_.model_options.integrator)
    sceneModel_ = std::make_shared<const SimModel>(build_model(setup_.mesh, setup_.model_options));
  simulation_ = make_scene_simulation(sceneModel_, setup_.visual.surface);
  if (grab_) simulation_->set_springs(springs_);
  attachDevice();
  if (shownTopology_ != 0) {
    scene_->show_uncut(simulation_->snapshot().position_m);
    shownTopology_ = 0;
  }
  simulation_->log_inputs(true);
  simulation_->start();
}

bool MainWindow::openScenario(const QString& file) {
  if (busyBuilding()) return false;
  // The exact text is what a recorded session refers to, so it is read once, here.
  QFile in(file);
  ScenarioReading reading;
  std::string text;
  if (in.open(QIODevice::ReadOnly)) {
    text = in.readAll().toStdString();
    reading = read_scenario(text);
  } else {
    reading = read_scenario_file(file.toStdString());  // names why it cannot be read
  }
  if (!reading.scenario) {
    refuseScenario(file, scenarioErrorsText(reading.errors));
    return true;
  }
  const QString absolute = QFileInfo(file).absoluteFilePath();
  buildScenario({*reading.scenario, absolute, std::move(text)}, QFileInfo(absolute).absolutePath());
  return true;
}

bool MainWindow::tryScenario(const Scenario& scenario, const QString& file) {
  if (busyBuilding()) return false;
  const QString folder = file.isEmpty() ? QDir::currentPath() : QFileInfo(file).absolutePath();
  buildScenario({scenario, file, write_scenario(scenario)}, folder);
  return true;
}

void MainWindow::buildScenario(OpenedScenario opened, const QString& folder) {
  if (modelBuilder_.joinable()) modelBuilder_.join();  // the last one has reported back
  openingScenario_ = true;
  accuracyPanel_->setBusy(true);
  statusBar()->showMessage(tr("Building the scene of %1…").arg(scenarioName(opened)));
  // Until meshing reports its attempts, the bar only says that work goes on.
  buildProgress_->setRange(0, 0);
  buildProgress_->show();
  cancelBuild_->setEnabled(true);
  cancelBuild_->show();
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  buildCancelled_ = cancelled;
  modelBuilder_ = std::thread([this, opened = std::move(opened), folder, cancelled] {
    std::shared_ptr<SceneSetup> setup;
    std::shared_ptr<const SimModel> model;
    QString error;
    try {
      // A surface model is meshed first: each attempt at its element count is shown.
      const auto progress = [this, name = scenarioName(opened),
                             cancelled](const MeshingProgress& p) {
        const QString text =
            p.tet_count == 0
                ? tr("Building the scene of %1: meshing the organ, attempt %2 of at most %3 "
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
        const int done = p.attempt - (p.tet_count == 0 ? 1 : 0);
        QMetaObject::invokeMethod(
            this,
            [this, text, done, max = p.max_attempts] {
              if (buildCancelled_ && *buildCancelled_) return;
              buildProgress_->setRange(0, max);
              buildProgress_->setValue(done);
              statusBar()->showMessage(text);
            },
            Qt::QueuedConnection);
        return !*cancelled;
      };
      setup = std::make_shared<SceneSetup>(
          build_scene(opened.scenario, std::filesystem::path(folder.toStdString()), progress));
      model = std::make_shared<const SimModel>(build_model(setup->mesh, setup->model_options));
    } catch (const std::exception& e) {
      error = QString::fromUtf8(e.what());
    }
    // As in applyIntegratorSettings: dropped if the window is gone.
    QMetaObject::invokeMethod(
        this,
        [this, opened, setup, model, error] { finishScenarioOpen(opened, setup, model, error); },
        Qt::QueuedConnection);
  });
}

void MainWindow::finishScenarioOpen(const OpenedScenario& opened, std::shared_ptr<SceneSetup> setup,
                                    std::shared_ptr<const SimModel> model, const QString& error) {
  modelBuilder_.join();  // it ends right after posting this
  openingScenario_ = false;
  accuracyPanel_->setBusy(false);
  buildProgress_->hide();
  cancelBuild_->hide();
  const bool cancelled = buildCancelled_ && *buildCancelled_;
  buildCancelled_.reset();
  if (cancelled) {  // asked for: not an error, and whatever was built is dropped
    statusBar()->showMessage(tr("Opening %1 was cancelled; the scene that was running goes on.")
                                 .arg(scenarioName(opened)));
    emit scenarioOpenFinished(false);
    return;
  }
  if (!model) return refuseScenario(scenarioName(opened), error);
  // The device stays; its session was of the old scene: it ends (with the old scene's outcome)
  // and another begins on the new one.
  const bool recording = recorder_ != nullptr;
  endRecording();
  try {
    installScene(std::move(*setup), std::move(model));
  } catch (const std::exception& e) {
    simulation_->start();  // nothing was replaced: the old scene goes on
    if (recording) beginRecording();
    return refuseScenario(scenarioName(opened), QString::fromUtf8(e.what()));
  }
  scenario_ = opened;
  attachDevice();
  simulation_->start();
  if (recording) beginRecording();
  accuracyPanel_->setSettings(setup_.model_options.integrator);
  showScenarioDetails();
  if (!opened.file.isEmpty()) {
    rememberScenarioFile(opened.file);
    updateRecentMenu();
  }
  statusBar()->showMessage(tr("Opened %1.").arg(scenarioName(opened)));
  viewport_->scheduleRender();
  emit scenarioOpenFinished(true);
}

QString MainWindow::scenarioName(const OpenedScenario& opened) {
  return opened.file.isEmpty() ? tr("“%1” (from the editor, not saved)")
                                     .arg(QString::fromStdString(opened.scenario.title))
                               : QFileInfo(opened.file).fileName();
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
  if (!buildCancelled_) return;
  *buildCancelled_ = true;
  cancelBuild_->setEnabled(false);
  statusBar()->showMessage(tr("Cancelling…"));
}

void MainWindow::showScenarioDetails() {
  const QString name = scenario_ ? QString::fromStdString(scenario_->scenario.title)
                                 : tr("free practice, %1 elements").arg(setup_.mesh.tet_count());
  setWindowTitle(tr("LiverSim — %1").arg(name));
  scene_->show_lesions(scenario_ ? visible_lesions(scenario_->scenario)
                                 : std::vector<LesionShape>{});
  scenarioPanel_->showScenario(scenario_ ? &scenario_->scenario : nullptr,
                               scenario_ ? scenario_->file : QString());
  // Free practice offers what a scenario does by default: every tool.
  toolPanel_->setAvailableTools(scenario_ ? scenario_->scenario.tools : Scenario{}.tools);
  const Scenario described = describedScenario();
  materialPanel_->showTissue(described.parenchyma, described.effects);
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
    if (scenario_ && !scenario_->file.isEmpty())
      editor_->document().reset(scenario_->scenario, scenario_->file);
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

MainWindow::~MainWindow() {
  if (modelBuilder_.joinable()) modelBuilder_.join();
  simulation_->stop();
  detachDevice();  // the servo's last command is a zero force; a session ends (its metrics start)
  if (metricsWorker_.joinable()) metricsWorker_.join();
}

bool MainWindow::applyIntegratorSettings(const IntegratorSettings& settings) {
  if (busyBuilding()) return false;
  changingIntegrator_ = true;
  accuracyPanel_->setBusy(true);
  ModelOptions options = setup_.model_options;
  options.integrator = settings;
  // A cut liver is not the scene's mesh any more: its model is taken as it is.
  std::shared_ptr<const SimModel> cut =
      shownTopology_ > 0 ? simulation_->snapshot().model : nullptr;
  startModelChange({settings, std::nullopt}, [this, options = std::move(options), settings, cut] {
    ModelChangeBuilt built;
    if (cut) {
      validate_integrator(settings);
      auto changed = std::make_shared<SimModel>(*cut);
      changed->integrator = settings;
      changed->stable_time_step_s = stable_time_step_s(*changed, StepInputs{});
      built.model = std::move(changed);
    } else {
      // build_model checks the settings first, so a bad entry is refused at once.
      built.model = std::make_shared<const SimModel>(build_model(setup_.mesh, options));
      built.rest_model = built.model;
    }
    return built;
  });
  return true;
}

bool MainWindow::applyTissue(const TissueSpec& tissue) {
  if (changingTissue_) {  // the newest entry is applied after the one being applied
    pendingTissue_ = tissue;
    return true;
  }
  if (busyBuilding()) return false;
  if (!instructor_) {  // the panel is read-only in trainee mode; this holds for any caller
    materialPanel_->showError(
        tr("Changing the tissue is for instructors: log in first "
           "(Settings ▸ Instructor Mode)."));
    return false;
  }
  Scenario described = describedScenario();
  described.parenchyma = tissue;
  std::vector<RegionMaterial> regions = region_materials(described);
  changingTissue_ = true;
  materialPanel_->setBusy(true);
  // The model running (cut or not) and the scene's uncut one, which a restart from rest runs.
  std::shared_ptr<const SimModel> running = simulation_->snapshot().model;
  std::shared_ptr<const SimModel> rest = sceneModel_;
  startModelChange({std::nullopt, tissue}, [regions = std::move(regions), running, rest] {
    const auto changed = [&](const SimModel& model) {
      auto copy = std::make_shared<SimModel>(model);
      set_region_materials(*copy, regions);
      return copy;
    };
    ModelChangeBuilt built;
    built.model = changed(*running);
    built.rest_model = running == rest ? built.model : changed(*rest);
    return built;
  });
  return true;
}

bool MainWindow::busyBuilding() const {
  return changingIntegrator_ || changingTissue_ || openingScenario_;
}

Scenario MainWindow::describedScenario() const {
  if (scenario_) return scenario_->scenario;
  // Free practice: the built-in liver's parenchyma (region 0), the effects its model has.
  const ModelOptions& options = setup_.model_options;
  const RegionMaterial& parenchyma = options.regions.at(0);
  Scenario s;
  s.lesions.clear();
  s.parenchyma.elastic = parenchyma.tissue;
  s.parenchyma.viscoelastic = parenchyma.viscoelastic;
  s.parenchyma.viscoplastic = parenchyma.viscoplastic;
  if (parenchyma.fibres && !options.fibre_field.first_family.empty()) {
    const Eigen::Vector3d& d = options.fibre_field.first_family.front();
    s.parenchyma.fibres =
        FibreSpec{parenchyma.fibres->k1_pa, parenchyma.fibres->k2, {d.x(), d.y(), d.z()}};
  }
  s.effects = {options.average_nodal_pressure, parenchyma.viscoelastic.has_value(),
               parenchyma.viscoplastic.has_value(), s.parenchyma.fibres.has_value()};
  return s;
}

void MainWindow::startModelChange(ModelChange change, std::function<ModelChangeBuilt()> build) {
  if (modelBuilder_.joinable()) modelBuilder_.join();  // the last one has reported back
  modelBuilder_ = std::thread([this, change = std::move(change), build = std::move(build)] {
    ModelChangeBuilt built;
    QString error;
    try {
      built = build();
    } catch (const std::exception& e) {
      error = QString::fromUtf8(e.what());
    }
    // Runs on the GUI thread; dropped if the window is gone (its destructor joins this thread
    // first, and a QObject discards the events posted to it when it is destroyed).
    QMetaObject::invokeMethod(
        this, [this, change, built, error] { finishModelChange(change, built, error); },
        Qt::QueuedConnection);
  });
}

void MainWindow::finishModelChange(const ModelChange& change, const ModelChangeBuilt& built,
                                   const QString& error) {
  modelBuilder_.join();  // it ends right after posting this
  const auto refuse = [&](const QString& why) {
    if (change.integrator) {
      changingIntegrator_ = false;
      accuracyPanel_->setBusy(false);
      accuracyPanel_->showError(why);
      emit integratorChangeFinished(false);
    } else {
      changingTissue_ = false;
      materialPanel_->showError(why);
      emit tissueChangeFinished(false);
      applyPendingTissue();
    }
  };
  if (!built.model) return refuse(error);

  // Carry the liver's motion over: the same mesh, so the same node order. The new scheme starts
  // its own history (a multistep scheme its first step, an adaptive one its step size).
  simulation_->stop();
  const SimState& old = simulation_->state();
  if (old.position_m.size() != built.model->node_count) {  // a cut came in while it was built
    simulation_->start();
    return refuse(change.integrator
                      ? tr("The liver was cut while the integrator changed; apply it again.")
                      : tr("The liver was cut while the tissue changed; enter it again."));
  }
  // A recorded session's input log ends here: a replay does not follow a change of the model.
  if (recorder_) {
    simulation_->log_inputs(false);
    recorder_->record_inputs(simulation_->take_input_log());
  }
  const std::shared_ptr<const SimModel>& model = built.model;
  SimState state = make_rest_state(*model, shared_worker_pool());
  state.position_m = old.position_m;
  state.velocity_m_per_s = old.velocity_m_per_s;
  state.max_speed_m_per_s = old.max_speed_m_per_s;  // the node-travel limit of the first step
  if (state.viscous_history.size() == old.viscous_history.size())
    state.viscous_history = old.viscous_history;
  state.energy = old.energy;  // the books go on (the guard bounds kinetic energy by them)
  state.time_s = old.time_s;
  state.step_count = old.step_count;
  // The same mesh: a session's damage and lift tracking go on in the new simulation.
  std::optional<OutcomeTracking> outcome = simulation_->outcome();
  try {
    auto replacement = std::make_unique<RealtimeSimulation>(model, std::move(state));
    simulation_ = std::move(replacement);
    if (outcome) simulation_->track_outcome(std::move(*outcome));
  } catch (const std::exception& e) {
    if (recorder_) simulation_->log_inputs(true);  // the old one's log goes on
    simulation_->start();                          // the old one goes on where it stopped
    return refuse(QString::fromUtf8(e.what()));
  }
  if (grab_) simulation_->set_springs(springs_);
  simulation_->enable_tools(scene_->surface());
  simulation_->enable_cutting();
  attachDevice();
  simulation_->start();
  // Built from the scene's mesh (not a cut one): a restart from rest can use it.
  if (built.rest_model &&
      (built.rest_model != built.model ||
       (shownTopology_ == 0 && built.model->node_count == setup_.mesh.node_count())))
    sceneModel_ = built.rest_model;
  if (change.integrator) {
    const IntegratorSettings& settings = *change.integrator;
    if (recorder_)
      recorder_->record_event({servo_->now_s(), SessionEventKind::integrator_changed,
                               std::string(integrator_name(settings.kind))});
    setup_.model_options.integrator = settings;
    changingIntegrator_ = false;
    accuracyPanel_->setBusy(false);
    accuracyPanel_->setSettings(settings);
    emit integratorChangeFinished(true);
    return;
  }
  const TissueSpec& tissue = *change.tissue;
  const EffectsSpec effects = describedScenario().effects;  // a tissue change keeps them
  if (recorder_)
    recorder_->record_event(
        {servo_->now_s(), SessionEventKind::material_changed, describe_tissue(tissue, effects)});
  setup_.model_options.regions = model->regions;
  if (scenario_) {
    // Sessions recorded from now on store the scenario as it runs, so that they replay with it.
    scenario_->scenario.parenchyma = tissue;
    scenario_->text = write_scenario(scenario_->scenario);
  } else {
    tissueChangedInFreePractice_ = true;
  }
  changingTissue_ = false;
  materialPanel_->showTissue(tissue, effects);
  emit tissueChangeFinished(true);
  applyPendingTissue();
}

void MainWindow::applyPendingTissue() {
  if (!pendingTissue_) return;
  const TissueSpec next = *pendingTissue_;
  pendingTissue_.reset();
  applyTissue(next);
}

bool MainWindow::beginGrab(QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers) {
  // While the tissue is held, other buttons must not move the camera under the handle.
  if (grab_ || tool_) return true;
  if (button != Qt::LeftButton || modifiers != Qt::NoModifier) return false;
  if (const auto kind = toolPanel_->tool()) {
    if (!mouse_) return false;  // a device holds the tool: the mouse turns the view
    return beginTool(*kind, pos);
  }
  const auto hit = scene_->pick(pos.x(), pos.y());
  if (!hit) return false;  // background: the camera takes the drag
  grab_ = grab_surface(scene_->surface(), simulation_->snapshot().position_m,
                       simulation_->snapshot().model->lumped_mass_kg, hit->point_m, kGrabRadiusM,
                       kGrabStiffnessNPerM);
  handle_m_ = hit->point_m;
  scene_->show_grab_marker(handle_m_);
  grab_springs(*grab_, handle_m_, springs_);
  simulation_->set_springs(springs_);
  return true;
}

void MainWindow::moveGrab(QPoint pos) {
  handle_m_ = scene_->display_to_world(pos.x(), pos.y(), handle_m_);
  scene_->show_grab_marker(handle_m_);
  grab_springs(*grab_, handle_m_, springs_);
  simulation_->set_springs(springs_);
}

void MainWindow::endGrab() {
  grab_.reset();
  simulation_->clear_springs();
  scene_->show_grab_marker(std::nullopt);
}

Eigen::Quaterniond MainWindow::toolOrientationFromView() const {
  return tool_orientation_from_view(deviceAxesFromView());
}

// The mouse is a device like the others (ManualDevice, through the servo, recorded): a press puts
// the tool on the liver where the mouse is, its shaft toward the viewer and tilted up by 35° (as a
// laparoscopic instrument comes in through a port, and so that it shows), with the action button
// down: the probe's ball on the surface, the forceps' jaws closed on it, the blade's tip touching
// it and armed. Device millimetres are scene millimetres (kMouseMapping).
bool MainWindow::beginTool(ToolKind kind, QPoint pos) {
  const auto hit = scene_->pick(pos.x(), pos.y());
  if (!hit) return false;  // background: the camera takes the drag
  Tool tool;
  tool.kind = kind;
  tool.jaw_opening = 0.0;
  tool.pose.orientation = toolOrientationFromView();
  const Eigen::Vector3d shaft = tool.pose.orientation * Eigen::Vector3d::UnitZ();
  switch (kind) {
    case ToolKind::probe:
      tool.pose.origin_m = hit->point_m + tool.geometry.probe_tip_radius_m * shaft;
      break;
    case ToolKind::forceps:
      tool.pose.origin_m = hit->point_m - (forceps_grasp_point_m(tool) - tool.pose.origin_m);
      break;
    case ToolKind::scalpel:
      // The blade goes in where you press, its heel just above the surface so that drawing it
      // along keeps the edge through the tissue's top: it cuts once the tissue gives way.
      tool.pose.origin_m = hit->point_m + 0.004 * shaft;
      break;
  }
  tool_ = tool;
  toolPoint_m_ = hit->point_m;
  mouse_->place(tool.pose.origin_m * 1e3, kMouseActionButton);
  // After the placement, so that the frames of the tool's interval are all where it is put. A
  // session of the mouse begins when it first takes a tool to the liver (and restarts the
  // simulation from rest: the device tool is set on the simulation that runs after).
  if (!recorder_)
    beginRecording();
  else
    recordToolChoice();
  simulation_->set_device_tool(deviceToolSettings(), servo_->now_s());
  return true;
}

// Dragging moves the tool in the view plane; with Shift, up and down the screen move it along its
// shaft (down pushes it in).
void MainWindow::moveTool(QPoint pos) {
  const Eigen::Vector3d point = scene_->display_to_world(pos.x(), pos.y(), toolPoint_m_);
  Eigen::Vector3d move = point - toolPoint_m_;
  if (QGuiApplication::keyboardModifiers() & Qt::ShiftModifier) {
    const Eigen::Vector2d from = scene_->world_to_display(toolPoint_m_);
    const double up = pos.y() > from.y() ? 1.0 : -1.0;  // display y grows upward
    const Eigen::Vector3d shaft = tool_->pose.orientation * Eigen::Vector3d::UnitZ();
    move = up * move.norm() * shaft;
  }
  tool_->pose.origin_m += move;
  toolPoint_m_ += move;
  mouse_->set(tool_->pose.origin_m * 1e3, kMouseActionButton);
}

// The release lets go (the action button up) and takes the tool out of the scene; the device's
// point is lifted along the shaft, so that a replay of the session's device input, which keeps
// the tool in the scene, does not leave it resting on the liver.
void MainWindow::endTool() {
  const Eigen::Vector3d shaft = tool_->pose.orientation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d lifted_m = tool_->pose.origin_m + kMouseLiftM * shaft;
  tool_.reset();
  recordToolChoice();  // before the lift, which is no motion of the tool in use
  mouse_->place(lifted_m * 1e3, 0);
  simulation_->set_device_tool(std::nullopt);  // the forceps let go as they leave
}

void MainWindow::showTool(const std::optional<Tool>& tool) {
  scene_->show_tool(tool);
  viewport_->scheduleRender();
}

void MainWindow::showNewestSnapshot() {
  if (recorder_) {
    recorder_->record_inputs(simulation_->take_input_log());
    // Said when it happens, not at the session's end: the trainee is told the session is no
    // longer being saved (what was committed before stays).
    if (!recordingFailureShown_) {
      if (const std::optional<StorageError> failure = recorder_->failure()) {
        recordingFailureShown_ = true;
        sessionsProblem_ = storageProblemText(
            tr("Recording stopped: this session is no longer being saved (what was saved before "
               "is kept). %1"),
            *failure);
        statusBar()->showMessage(sessionsProblem_);
        devicePanel_->showStatus(sessionsProblem_, true);
        emit recordingStopped(sessionsProblem_);
      }
    }
  }
  if (simulation_->update_snapshot()) {
    const SimulationSnapshot& snapshot = simulation_->snapshot();
    const bool cut = snapshot.topology_version != shownTopology_ && snapshot.model;
    recordSimulationEvents(snapshot, cut);
    if (cut) {
      scene_->show_cut_model(*snapshot.model, snapshot.position_m);
      shownTopology_ = snapshot.topology_version;
    }
    scene_->update_positions(snapshot.position_m);
    showTool(snapshot.tool);  // where the simulation has it
    if (tool_ || (servo_ && snapshot.tool))
      toolPanel_->showForce(snapshot.time_s, snapshot.tool_force_n, snapshot.tool_grasping);
    else if (grab_)
      toolPanel_->showForce(snapshot.time_s,
                            grab_reaction_force_n(*grab_, handle_m_, snapshot.position_m), true);
    else
      toolPanel_->showForce(snapshot.time_s, Eigen::Vector3d::Zero(), false);
    viewport_->scheduleRender();
  }
}

void MainWindow::updateStatus() {
  checkDevice();
  const double window_s = frameWindow_.restart() / 1000.0;
  framesPerSecond_ = window_s > 0 ? framesInWindow_ / window_s : 0.0;
  framesInWindow_ = 0;
  const RealtimeStats stats = simulation_->stats();
  QString text = tr("%1 fps | %2 steps/s | real-time factor %3 | step %4 ms")
                     .arg(framesPerSecond_, 0, 'f', 0)
                     .arg(stats.steps_per_second, 0, 'f', 0)
                     .arg(stats.real_time_factor, 0, 'f', 2)
                     .arg(stats.step_s * 1e3, 0, 'f', 3);
  if (stats.behind) text += tr(" | slower than real time");
  text += tr(" | ") + accuracyStatus(stats);
  // The step guards: what went wrong and what the simulation did about it.
  if (stats.halted)
    text = tr("Simulation halted: %1; every retry with shorter steps failed. Apply a setting in "
              "the Accuracy panel (another integrator or a shorter step) to go on from the last "
              "good state. | ")
               .arg(healthProblemText(stats.last_problem)) +
           text;
  else if (stats.rollbacks > 0 || stats.rejected_inputs > 0)
    text += tr(" | recovered %1 times, refused %2 inputs (last: %3)")
                .arg(stats.rollbacks)
                .arg(stats.rejected_inputs)
                .arg(healthProblemText(stats.last_problem));
  if (stats.energy_created)
    text +=
        tr(" | energy books: the scheme is creating energy (choose a shorter step or an "
           "implicit scheme)");
  if (grab_) {
    const Eigen::Vector3d force =
        grab_reaction_force_n(*grab_, handle_m_, simulation_->snapshot().position_m);
    text += tr(" | pulling %1 N").arg(force.norm(), 0, 'f', 2);
  }
  if (const double resected_m3 = simulation_->snapshot().resected_volume_m3; resected_m3 > 0.0)
    text += tr(" | resected %1 mL").arg(resected_m3 * 1e6, 0, 'f', 1);
  statusLabel_->setText(text);
}

QString MainWindow::healthProblemText(HealthProblem problem) {
  switch (problem) {
    case HealthProblem::none:
      return tr("no problem");
    case HealthProblem::non_finite_input:
      return tr("a tool input was not a number");
    case HealthProblem::non_finite_position:
      return tr("a node position became not a number");
    case HealthProblem::non_finite_velocity:
      return tr("a node velocity became not a number");
    case HealthProblem::runaway_speed:
      return tr("a node moved implausibly fast");
    case HealthProblem::runaway_energy:
      return tr("a node gained more energy than the tools put in");
    case HealthProblem::solver_failed:
      return tr("an implicit step did not converge");
  }
  return tr("unknown problem");
}

// The error estimate for the status bar, in the unit that suits it: "≈ 2.1 µm". Below a picometre
// it is round-off, not a number worth reading.
QString MainWindow::formatError(double error_m) {
  if (std::isnan(error_m)) return tr("n/a");
  const double size = std::abs(error_m);
  if (size < 1e-12) return tr("< 1 pm");
  if (size < 1e-9) return tr("≈ %1 pm").arg(formatAmount(error_m * 1e12));
  if (size < 1e-6) return tr("≈ %1 nm").arg(formatAmount(error_m * 1e9));
  if (size < 1e-3) return tr("≈ %1 µm").arg(formatAmount(error_m * 1e6));
  return tr("≈ %1 mm").arg(formatAmount(error_m * 1e3));
}

QString MainWindow::accuracyStatus(const RealtimeStats& stats) const {
  QString text = tr("%1 · error %2")
                     .arg(AccuracyPanel::integratorName(stats.integrator),
                          formatError(stats.error_estimate_m));
  if (stats.wall_s_per_simulated_s > 0.0) {
    // Both are per millisecond of simulated time: the scale of a step.
    text += tr(" · %1 ms wall per ms simulated · %2 force evaluations per ms simulated")
                .arg(formatAmount(stats.wall_s_per_simulated_s),
                     formatAmount(stats.force_evaluations_per_simulated_s * 1e-3));
  }
  if (stats.stability_limited) text += tr(" · stability-limited");
  return text;
}

Eigen::Quaterniond MainWindow::deviceAxesFromView() const {
  double direction[3], up[3];
  vtkCamera* camera = scene_->renderer()->GetActiveCamera();
  camera->GetDirectionOfProjection(direction);
  camera->GetViewUp(up);
  return device_axes_from_view(-Eigen::Vector3d(direction[0], direction[1], direction[2]),
                               Eigen::Vector3d(up[0], up[1], up[2]));
}

Eigen::Vector3d MainWindow::deviceHome_m() const {
  return device_home_m(simulation_->snapshot().position_m, deviceAxesFromView());
}

std::optional<DeviceToolSettings> MainWindow::deviceToolSettings() const {
  DeviceToolSettings settings;
  if (mouse_) {
    if (!tool_) return std::nullopt;  // the mouse holds a tool only while pressed
    settings.kind = tool_->kind;
    settings.orientation = tool_->pose.orientation;
    settings.action_buttons = kMouseActionButton;
    return settings;
  }
  const auto kind = toolPanel_->tool();
  if (!kind) return std::nullopt;  // the hand: the device holds nothing
  settings.kind = *kind;
  settings.orientation = toolOrientationFromView();
  settings.action_buttons = haptics_.action_buttons;
  return settings;
}

void MainWindow::attachDevice() {
  if (!servo_) return;
  simulation_->set_haptic_servo(servo_.get());
  simulation_->set_device_tool(deviceToolSettings());
}

void MainWindow::detachDevice() {
  if (!simulation_->running()) {
    simulation_->set_haptic_servo(nullptr);
    simulation_->set_device_tool(std::nullopt);
  }
  if (servo_) servo_->stop();  // the last command is a zero force; its last frames are logged
  endRecording();
  servo_.reset();
  mouse_ = nullptr;
  ownDevice_.reset();
}

bool MainWindow::setSessionsDatabase(const QString& file) {
  endRecording();
  if (instructor_) logOutInstructor();  // an account is of one database
  sessions_.reset();
  sessionsProblem_.clear();
  try {
    sessions_ = std::make_unique<SqliteSessionStore>(std::filesystem::path(file.toStdString()));
    sessionsFile_ = file;
  } catch (const StorageError& e) {
    sessionsProblem_ = storageProblemText(tr("Sessions are not recorded: %1"), e);
    statusBar()->showMessage(sessionsProblem_);
    trainingCentre_.reset();
    return false;
  }
  if (servo_) beginRecording();
  startTrainingCentreAtLaunch();
  return true;
}

void MainWindow::startTrainingCentreAtLaunch() {
  if (trainingCentre_) {  // the same server and log-in, from the new file
    TrainingCentreLink link = trainingCentre_->link();
    trainingCentre_.reset();
    link.sessions_database = sessionsFile_.toStdString();
    link.scenario_folder = pulledScenarioFolder().toStdString();
    trainingCentre_ = std::make_unique<TrainingCentreSync>(std::move(link));
  } else if (const TrainingCentreSetting setting = trainingCentreSetting();
             !setting.serverUrl.isEmpty() && setting.passwordFromLibpq) {
    connectTrainingCentre(setting, {});
  }
  showTrainingCentreStatus();
}

bool MainWindow::connectTrainingCentre(const TrainingCentreSetting& setting,
                                       const QString& password, QString* why) {
  const auto refuse = [&](const QString& reason) {
    if (why) *why = reason;
    return false;
  };
  if (setting.serverUrl.isEmpty()) {
    trainingCentre_.reset();
    setTrainingCentreSetting(setting);
    showTrainingCentreStatus();
    return true;
  }
  ServerSettings server;
  try {
    server = parse_server_url(setting.serverUrl.toStdString());
  } catch (const std::invalid_argument& e) {
    return refuse(QString::fromStdString(e.what()));
  }
  if (!sessions_) return refuse(tr("There is no sessions database to upload from."));
  // A wrong log-in is said here, at once; a server out of reach is not: the link retries.
  try {
    PostgresSessionStore{server, password.toStdString()};
  } catch (const StorageError& e) {
    if (e.problem() == StorageProblem::refused || e.problem() == StorageProblem::not_a_database ||
        e.problem() == StorageProblem::newer_version)
      return refuse(QString::fromStdString(e.what()));
  }
  setTrainingCentreSetting(setting);
  TrainingCentreLink link;
  link.server = server;
  link.password = password.toStdString();
  link.sessions_database = sessionsFile_.toStdString();
  link.scenario_folder = pulledScenarioFolder().toStdString();
  trainingCentre_.reset();  // the old link's run ends first
  trainingCentre_ = std::make_unique<TrainingCentreSync>(std::move(link));
  showTrainingCentreStatus();
  return true;
}

QString MainWindow::pulledScenarioFolder() const {
  if (sessionsFile_.isEmpty()) return {};
  return QFileInfo(sessionsFile_).absolutePath() + "/training-centre-scenarios";
}

QString MainWindow::trainingCentreStatusText() const {
  if (!trainingCentre_)
    return trainingCentreSetting().serverUrl.isEmpty()
               ? QString()
               : tr("Training centre: not connected (Settings ▸ Training Centre Server…)");
  const TrainingCentreStatus status = trainingCentre_->status();
  const QString server = QString::fromStdString(server_name(trainingCentre_->server()));
  if (status.runs == 0) return tr("Training centre: connecting to %1…").arg(server);
  if (!status.last_run_ok())
    return tr("Training centre: %1 not reached, %n session(s) waiting", nullptr, status.waiting)
        .arg(server);
  return tr("Training centre: up to date at %1, %n session(s) uploaded", nullptr, status.uploaded)
      .arg(QDateTime::fromMSecsSinceEpoch(status.last_ok_unix_ms).toString("HH:mm"));
}

void MainWindow::showTrainingCentreStatus() {
  const QString text = trainingCentreStatusText();
  trainingCentreLabel_->setText(text);
  trainingCentreLabel_->setVisible(!text.isEmpty());
  const std::optional<std::string> problem =
      trainingCentre_ ? trainingCentre_->status().problem : std::nullopt;
  trainingCentreLabel_->setToolTip(problem ? QString::fromStdString(*problem) : QString());
}

TrainingCentreDialog* MainWindow::openTrainingCentreSettings() {
  auto* dialog = new TrainingCentreDialog(trainingCentreSetting(), this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  connect(dialog, &TrainingCentreDialog::requested, this,
          [this, dialog](const TrainingCentreSetting& setting, const QString& password) {
            answerForm(*dialog,
                       [&](QString* why) { return connectTrainingCentre(setting, password, why); });
          });
  dialog->show();
  return dialog;
}

SessionReviewWindow* MainWindow::openServerReview(const QString& instructor,
                                                  const QString& password, QString* why) {
  const auto refuse = [&](const QString& reason) -> SessionReviewWindow* {
    if (why) *why = reason;
    return nullptr;
  };
  const TrainingCentreSetting setting = trainingCentreSetting();
  if (setting.serverUrl.isEmpty())
    return refuse(tr("No training centre server is set (Settings ▸ Training Centre Server…)."));
  try {
    // The instructor's own login on the server, at the same server and database.
    ServerSettings server = parse_server_url(setting.serverUrl.toStdString());
    server.user = instructor.toStdString();
    auto store = std::make_unique<PostgresSessionStore>(server, password.toStdString());
    std::optional<Instructor> grader =
        store->log_in_instructor(instructor.toStdString(), password.toStdString());
    if (!grader) return refuse(tr("%1 is not an instructor on the server.").arg(instructor));
    if (serverReview_) serverReview_->close();
    serverReview_ = new SessionReviewWindow(
        std::move(store), QString::fromStdString(server_name(server)), grader, this);
    serverReview_->setAttribute(Qt::WA_DeleteOnClose);
    serverReview_->show();
    return serverReview_;
  } catch (const std::exception& e) {  // StorageError, a malformed address
    return refuse(QString::fromStdString(e.what()));
  }
}

std::optional<std::int64_t> MainWindow::recordingSession() const {
  if (!recorder_) return std::nullopt;
  return recorder_->session();
}

bool MainWindow::replaySession(std::int64_t session) {
  auto refuse = [&](const QString& why) {
    devicePanel_->showStatus(why, true);
    devicePanel_->showDevice(haptics_.device);
    return false;
  };
  if (!sessions_)
    return refuse(sessionsProblem_.isEmpty() ? tr("There is no sessions database.")
                                             : sessionsProblem_);
  std::vector<ServoFrame> frames;
  try {
    const std::vector<SessionSummary> replayable = replayableSessions();
    if (std::none_of(replayable.begin(), replayable.end(),
                     [&](const SessionSummary& s) { return s.id == session; }))
      return refuse(tr("Session %1 is not yours to replay: trainees replay their own sessions "
                       "(an instructor may replay any).")
                        .arg(session));
    std::optional<std::vector<ServoFrame>> read = readSessionFrames(*sessions_, session, this);
    if (!read)
      return refuse(tr("Session %1 is not replayed: reading it was cancelled.").arg(session));
    frames = std::move(*read);
    // Mapped as it was recorded (sessions before schema 2 kept no mapping: today's).
    replayMapping_ = haptics_.mapping;
    for (const SessionSummary& summary : sessions_->sessions())
      if (summary.id == session && summary.mapping) replayMapping_ = *summary.mapping;
  } catch (const StorageError& e) {
    return refuse(storageProblemText(tr("Cannot replay session %1: %2").arg(session), e));
  }
  if (frames.empty()) return refuse(tr("Session %1 has no device input to replay.").arg(session));
  replayPoints_ = trajectory_of_frames(frames);
  replayName_ = tr("Replay of session %1").arg(session);
  return useDevice(DeviceChoice::replay);
}

std::vector<SessionSummary> MainWindow::replayableSessions() {
  // A trainee replays their own sessions only.
  return instructor_ ? sessions_->sessions()
                     : sessions_->sessions_of_trainee(traineeName().toStdString());
}

void MainWindow::chooseSessionToReplay() {
  std::vector<SessionSummary> sessions;
  try {
    if (sessions_) sessions = replayableSessions();
  } catch (const StorageError& e) {
    sessionsProblem_ = storageProblemText(QStringLiteral("%1"), e);
  }
  QStringList items;
  for (auto it = sessions.rbegin(); it != sessions.rend(); ++it)
    if (it->frame_count > 0)
      items << tr("%1: %2, %3, %4 (%5)")
                   .arg(it->id)
                   .arg(QString::fromStdString(it->trainee),
                        QString::fromStdString(it->scenario_title),
                        QDateTime::fromMSecsSinceEpoch(it->started_unix_ms)
                            .toString("yyyy-MM-dd hh:mm"),
                        QString::fromUtf8(session_status_name(it->status).data()));
  if (items.isEmpty()) {
    devicePanel_->showStatus(
        sessions_ ? tr("No recorded session has device input to replay.") : sessionsProblem_, true);
    devicePanel_->showDevice(haptics_.device);
    return;
  }
  bool ok = false;
  const QString item =
      QInputDialog::getItem(this, tr("Replay a session"), tr("Session:"), items, 0, false, &ok);
  if (!ok) return devicePanel_->showDevice(haptics_.device);  // cancelled
  replaySession(item.section(':', 0, 0).toLongLong());
}

void MainWindow::beginRecording() {
  // A replay is not a new session: its input is already recorded. The mouse's session begins
  // with its first press.
  if (!sessions_ || !servo_ || recorder_ || haptics_.device == DeviceChoice::replay) return;
  if (mouse_ && !tool_) return;
  SessionStart start;
  start.trainee = traineeName().toStdString();
  if (scenario_) {
    start.scenario_title = scenario_->scenario.title;
    start.scenario_text = scenario_->text;
  } else {
    // Free practice has no file: the text names the scene it ran.
    start.scenario_title = tr("Free practice").toStdString();
    start.scenario_text = free_practice_text(setup_.mesh.tet_count());
    if (tissueChangedInFreePractice_) {
      const Scenario described = describedScenario();
      start.scenario_text +=
          ", tissue changed: " + describe_tissue(described.parenchyma, described.effects);
    }
  }
  start.device = ownDevice_ ? ownDevice_->name() : omni_ ? omni_->name() : "haptic device";
  start.started_unix_ms = QDateTime::currentMSecsSinceEpoch();
  start.mapping = servo_->mapping();
  ReplaySetup replay;
  replay.integrator = setup_.model_options.integrator;
  if (scenario_)  // as tryScenario: an unsaved scenario's organ file is named from here
    replay.scenario_folder = (scenario_->file.isEmpty() ? QDir::currentPath()
                                                        : QFileInfo(scenario_->file).absolutePath())
                                 .toStdString();
  else
    replay.built_in_liver_tets = setup_.built_in_liver_tets;
  // Free practice stores only its element count: a tissue changed in it cannot be built again.
  if (scenario_ || (setup_.built_in_liver_tets && !tissueChangedInFreePractice_))
    start.replay = replay;
  ServoLoop* servo = servo_.get();
  droppedBeforeRecording_ = skip_earlier_servo_frames(*servo);
  recordingFailureShown_ = false;
  try {
    recorder_ = std::make_unique<SessionRecorder>(
        *sessions_, start, [servo](ServoFrame& frame) { return servo->next_logged_frame(frame); });
  } catch (const StorageError& e) {
    sessionsProblem_ = storageProblemText(tr("Sessions are not recorded: %1"), e);
    statusBar()->showMessage(sessionsProblem_);
    return;
  }
  recordToolChoice();
  // The session starts from rest, its simulation's input logged, so that it can be replayed.
  restartFromRest();
  // Damage, lift and resection need the simulation: tracked while the session runs.
  const Scenario* running = scenario_ ? &scenario_->scenario : nullptr;
  track_session_outcome(*simulation_, running);
  eventWatch_.emplace(running);
}

void MainWindow::recordSimulationEvents(const SimulationSnapshot& snapshot, bool cut) {
  if (!recorder_ || !servo_ || !eventWatch_) return;
  std::vector<SessionEvent> events;
  eventWatch_->observe(servo_->now_s(), snapshot, simulation_->stats(), cut, events);
  for (const SessionEvent& event : events) recorder_->record_event(event);
}

QString MainWindow::traineeName() const {
  return QSettings()
      .value("sessions/trainee", qEnvironmentVariable("USER", tr("Trainee")))
      .toString();
}

AccuracyStudyDialog* MainWindow::openAccuracyStudy() {
  if (!accuracyStudy_) {
    accuracyStudy_ = new AccuracyStudyDialog(this);
    connect(accuracyStudy_, &AccuracyStudyDialog::settingChosen, this,
            [this](const IntegratorSettings& chosen) {
              // The study sets the scheme and its step or tolerance; Newton's settings stay.
              IntegratorSettings settings = setup_.model_options.integrator;
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
  if (!sessions_) {
    statusBar()->showMessage(sessionsProblem_.isEmpty() ? tr("There is no sessions database.")
                                                        : sessionsProblem_);
    return nullptr;
  }
  if (!window) {
    // The instructor logged in grades; a trainee's history takes no grader.
    window = new SessionReviewWindow(sessionsFile_, trainee, instructor_, this);
    window->setAttribute(Qt::WA_DeleteOnClose);
  } else {
    window->refresh();
  }
  window->show();
  window->raise();
  return window;
}

QString MainWindow::sessionResultText(const RubricResult& rubric,
                                      const std::vector<MetricValue>& metrics) {
  if (!rubric.score_percent) {
    for (const MetricValue& m : metrics)
      if (m.name == "peak_force_n")
        return tr("Last session: peak force %1 N (free practice: no rubric).")
            .arg(m.value, 0, 'f', 2);
    return tr("Last session stored (no rubric).");
  }
  QStringList missed;
  for (const CriterionResult& r : rubric.criteria)
    if (!r.passed)
      missed << QString("%1 %2 %3 (%4)")
                    .arg(QString::fromStdString(r.criterion.metric),
                         r.criterion.rule == PassRule::at_most ? "≤" : "≥",
                         QString::number(r.criterion.threshold),
                         r.value ? tr("was %1").arg(r.value.value(), 0, 'g', 3) : tr("not done"));
  QString text = tr("Last session: score %1 %").arg(*rubric.score_percent, 0, 'f', 0);
  text += missed.isEmpty() ? tr(", every criterion passed.")
                           : tr(". Not passed: %1.").arg(missed.join("; "));
  return text;
}

bool MainWindow::markLesionUnderTool() {
  if (!recorder_ || !servo_) {
    statusBar()->showMessage(
        sessions_ ? tr("Marks are kept with a recorded session: put a tool on the liver first.")
                  : tr("Marks are kept with a recorded session, and there is no sessions "
                       "database."));
    return false;
  }
  const SimulationSnapshot& snapshot = simulation_->snapshot();
  if (!snapshot.tool || !snapshot.model) {
    statusBar()->showMessage(tr("Hold a tool over the place to mark."));
    return false;
  }
  const Eigen::Vector3d rest_m =
      rest_point_nearest(*snapshot.model, snapshot.position_m, snapshot.tool->pose.origin_m);
  recorder_->record_event({servo_->now_s(), SessionEventKind::lesion_marked, mark_detail(rest_m)});
  statusBar()->showMessage(tr("Marked the lesion at (%1, %2, %3) mm.")
                               .arg(rest_m.x() * 1e3, 0, 'f', 0)
                               .arg(rest_m.y() * 1e3, 0, 'f', 0)
                               .arg(rest_m.z() * 1e3, 0, 'f', 0));
  return true;
}

void MainWindow::recordToolChoice() {
  if (!recorder_ || !servo_) return;
  // The mouse holds a tool while pressed; a device, the Tool panel's.
  const auto tool =
      mouse_ ? (tool_ ? std::optional(tool_->kind) : std::nullopt) : toolPanel_->tool();
  // The hand holds no tool (tool_intervals reads any other name as none).
  recorder_->record_event({servo_->now_s(), SessionEventKind::tool_selected,
                           tool ? std::string(tool_name(*tool)) : "hand"});
}

void MainWindow::endRecording() {
  if (!recorder_) return;
  if (simulation_) {
    simulation_->log_inputs(false);
    recorder_->record_inputs(simulation_->take_input_log());
  }
  const ServoStats stats = servo_ ? servo_->stats() : ServoStats{};
  const std::uint64_t dropped = servo_ ? servo_->dropped_log_frames() - droppedBeforeRecording_ : 0;
  const std::int64_t session = recorder_->session();
  eventWatch_.reset();
  std::optional<OutcomeTracking> outcome;
  if (simulation_) {
    outcome = simulation_->outcome();
    simulation_->stop_tracking_outcome();
  }
  if (!recorder_->finish(QDateTime::currentMSecsSinceEpoch(), servo_figures(stats, dropped))) {
    sessionsProblem_ =
        tr("The session was not saved whole: %1").arg(QString::fromStdString(recorder_->error()));
    statusBar()->showMessage(sessionsProblem_);
    recorder_.reset();
    return;
  }
  recorder_.reset();
  computeSessionMetrics(session, std::move(outcome), servo_->mapping());
}

void MainWindow::computeSessionMetrics(std::int64_t session, std::optional<OutcomeTracking> outcome,
                                       const WorkspaceMapping& mapping) {
  // The metrics of its trace, from what was stored, and of its simulation
  // (docs/session-metrics.md): a long session is hundreds of megabytes of frames, so they are
  // read and computed on a worker with its own connection, off the UI thread.
  if (metricsWorker_.joinable()) metricsWorker_.join();  // one at a time
  ++pendingMetrics_;
  std::optional<Scenario> scenario;
  if (scenario_) scenario = scenario_->scenario;
  metricsWorker_ = std::thread([this, file = sessionsFile_.toStdString(), session,
                                outcome = std::move(outcome), scenario = std::move(scenario),
                                mapping] {
    std::vector<MetricValue> values;
    QString problem;
    try {
      SqliteSessionStore store{std::filesystem::path(file)};
      values =
          store_session_metrics(store, session, outcome, scenario ? &*scenario : nullptr, mapping);
    } catch (const StorageError& e) {
      problem = storageProblemText(tr("The session's metrics were not stored: %1"), e);
    } catch (const std::exception& e) {
      problem = tr("The session's metrics were not stored: %1").arg(QString::fromUtf8(e.what()));
    }
    const QString result =
        problem.isEmpty()
            ? sessionResultText(
                  scenario ? grade_against_rubric(scenario->rubric, values) : RubricResult{},
                  values)
            : QString();
    // Dropped if the window is gone (it joins this thread first).
    QMetaObject::invokeMethod(
        this,
        [this, session, problem, result] {
          --pendingMetrics_;
          if (!problem.isEmpty()) {
            sessionsProblem_ = problem;
            statusBar()->showMessage(problem);
          } else {
            scenarioPanel_->showResult(result);
          }
          emit sessionMetricsStored(session, problem.isEmpty());
        },
        Qt::QueuedConnection);
  });
}

void MainWindow::openOmni() {
  const QByteArray library = qgetenv("LIVERSIM_OPENHAPTICS_LIBRARY");
  OpenHapticsOpening omni =
      open_openhaptics_device(library.isEmpty() ? "libHD.so" : library.toStdString());
  omni_ = std::move(omni.device);
  omniProblem_ = QString::fromStdString(omni.problem);
  devicePanel_->setOpenHapticsProblem(omniProblem_);
}

void MainWindow::saveHapticPreferences() {
  QSettings settings;
  save_haptic_preferences(settings, haptics_);
}

bool MainWindow::useDevice(DeviceChoice choice, const QString& trajectoryFile) {
  auto refuse = [&](const QString& why) {
    devicePanel_->showStatus(why, true);
    devicePanel_->showDevice(haptics_.device);
    return false;
  };
  HapticDevice* device = nullptr;
  std::unique_ptr<HapticDevice> owned;  // the devices the window makes: all but the Omni
  QString file = trajectoryFile.isEmpty() ? haptics_.trajectory_file : trajectoryFile;
  switch (choice) {
    case DeviceChoice::mouse:
      owned = std::make_unique<ManualDevice>();
      device = owned.get();
      break;
    case DeviceChoice::openhaptics:
      if (!omni_) openOmni();
      if (!omni_) return refuse(tr("The Phantom Omni is not available: %1").arg(omniProblem_));
      device = omni_.get();
      break;
    case DeviceChoice::replay:
      if (replayPoints_.empty()) return refuse(tr("Choose a recorded session to replay."));
      owned = std::make_unique<TrajectoryDevice>(replayName_.toStdString(), replayPoints_);
      device = owned.get();
      break;
    case DeviceChoice::scripted:
      if (file.isEmpty()) return refuse(tr("Choose a trajectory file to play."));
      try {
        owned = std::make_unique<TrajectoryDevice>(
            tr("Scripted: %1").arg(QFileInfo(file).fileName()).toStdString(),
            load_trajectory(file.toStdString()));
      } catch (const std::exception& e) {
        return refuse(tr("Cannot play the trajectory: %1").arg(QString::fromUtf8(e.what())));
      }
      device = owned.get();
      break;
  }
  const bool mouse = choice == DeviceChoice::mouse;
  if (!mouse && !haptics_.mapping_set) {
    // First use: the device's axes the screen's, its origin just in front of the liver.
    haptics_.mapping = first_use_mapping(simulation_->snapshot().position_m, deviceAxesFromView());
    haptics_.mapping_set = true;
  }
  std::unique_ptr<ServoLoop> servo;
  {
    ServoLoop::Options options;
    // A replay maps as its session did; the mouse's millimetres are the scene's.
    options.mapping = mouse                            ? kMouseMapping
                      : choice == DeviceChoice::replay ? replayMapping_
                                                       : haptics_.mapping;
    try {
      servo = std::make_unique<ServoLoop>(*device, options);
    } catch (const std::exception& e) {
      return refuse(tr("Cannot run the device: %1").arg(QString::fromUtf8(e.what())));
    }
  }
  // The mouse lets go of what it held; the device's tool appears with its first frame.
  if (tool_) endTool();
  simulation_->stop();
  detachDevice();
  servo_ = std::move(servo);
  ownDevice_ = std::move(owned);
  mouse_ = mouse ? static_cast<ManualDevice*>(ownDevice_.get()) : nullptr;
  haptics_.device = choice;
  if (choice == DeviceChoice::scripted) haptics_.trajectory_file = file;
  attachDevice();
  simulation_->start();
  servo_->start();
  if (!mouse) beginRecording();  // the mouse's begins with its first press
  saveHapticPreferences();
  devicePanel_->showDevice(choice);
  devicePanel_->setCalibrationAvailable(!mouse);
  devicePanel_->showServoStats(nullptr);
  devicePanel_->showStatus(mouse ? tr("The mouse moves the tool: press on the liver to put the "
                                      "tool chosen in the Tool panel there.")
                                 : tr("%1 moves the tool chosen in the Tool panel.")
                                       .arg(QString::fromStdString(device->name())));
  return true;
}

void MainWindow::checkDevice() {
  if (!servo_) return;
  const ServoStats stats = servo_->stats();
  devicePanel_->showServoStats(&stats);
  const std::string fault = servo_->device_fault();
  if (fault.empty()) return;
  if (recorder_) recorder_->record_event({servo_->now_s(), SessionEventKind::device_fault, fault});
  // A vanished or broken device: its force is off already; the mouse takes over.
  const bool omni = haptics_.device == DeviceChoice::openhaptics;
  const QString name = omni ? QString::fromStdString(omni_->name()) : tr("The device");
  const QString why = tr("%1 stopped: %2. The mouse moves the tool now; choose the device again "
                         "once it is back.")
                          .arg(name, QString::fromStdString(fault));
  useDevice(DeviceChoice::mouse);
  if (omni) {
    // Its fault sticks: choosing it again opens it anew.
    omni_.reset();
    omniProblem_ = QString::fromStdString(fault);
    devicePanel_->setOpenHapticsProblem(omniProblem_);
  }
  devicePanel_->showStatus(why, true);
  statusBar()->showMessage(why);
}

CalibrationDialog* MainWindow::openCalibration() {
  if (calibration_) {
    calibration_->raise();
    return calibration_;
  }
  CalibrationDialog::Context context;
  context.device_name = haptics_.device == DeviceChoice::openhaptics && omni_
                            ? QString::fromStdString(omni_->name())
                        : haptics_.device == DeviceChoice::scripted ? tr("the scripted device")
                                                                    : tr("the device");
  if (auto* omni = dynamic_cast<OpenHapticsDevice*>(
          haptics_.device == DeviceChoice::openhaptics ? omni_.get() : nullptr))
    context.calibration = omni->calibration_ok()
                              ? tr("calibrated")
                              : tr("not calibrated: put the stylus in its inkwell (or move it "
                                   "through its whole range), then open this dialog again");
  context.view_rotation = deviceAxesFromView();
  context.home_m = deviceHome_m();
  context.device_position_mm = [this]() -> std::optional<Eigen::Vector3d> {
    const auto& sample = simulation_->snapshot().device_sample;
    return sample ? std::optional<Eigen::Vector3d>(sample->position_mm) : std::nullopt;
  };
  HapticPreferences shown = haptics_;
  if (!shown.mapping_set) shown.mapping.rotation = context.view_rotation;
  calibration_ = new CalibrationDialog(shown, std::move(context), this);
  calibration_->setAttribute(Qt::WA_DeleteOnClose);
  connect(calibration_, &QDialog::accepted, this, [this] {
    haptics_.mapping = calibration_->mapping();
    haptics_.action_buttons = calibration_->actionButtons();
    haptics_.mapping_set = true;
    saveHapticPreferences();
    if (servo_) useDevice(haptics_.device);  // the servo takes the new mapping
  });
  calibration_->show();
  return calibration_;
}

}  // namespace liversim
