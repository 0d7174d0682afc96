#pragma once
// The workstation's main window: the liver viewport in the middle, the scenario, the accuracy
// setting (time integrator and step), the tool and the device beside it, live statistics in the
// status bar. The simulation runs on its own thread; the viewport renders from its newest snapshot.

#include "haptic_preferences.h"
#include "instructor_login_dialog.h"
#include "render/liver_scene.h"
#include "training_centre_dialog.h"

#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/haptic_device.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/interaction/grab.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/grading.h"
#include "liversim/sessions/session_recorder.h"
#include "liversim/sessions/session_recording.h"
#include "liversim/simulation/realtime_simulation.h"
#include "liversim/storage/training_centre_sync.h"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QPointer>
#include <QStringList>
#include <QTimer>

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>

class QDockWidget;
class QLabel;
class QMenu;
class QProgressBar;
class QPushButton;
class QToolBar;

namespace liversim {

class AccuracyPanel;
class AccuracyStudyDialog;
class CalibrationDialog;
class DevicePanel;
class LiverScene;
class MaterialPanel;
class ScenarioEditor;
class ScenarioPanel;
class SessionReviewWindow;
class ToolPanel;
class VtkViewport;

// A scenario as the window runs it, the file it came from (none: tried from the editor unsaved)
// and the exact text it was read from, which a recorded session stores.
struct OpenedScenario {
  Scenario scenario;
  QString file;
  std::string text;
};

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  // The scene to run, and the scenario it was built from (none: free practice).
  explicit MainWindow(SceneSetup setup, std::optional<OpenedScenario> scenario = std::nullopt,
                      QWidget* parent = nullptr);
  ~MainWindow() override;

  VtkViewport* viewport() const { return viewport_; }
  LiverScene& scene() { return *scene_; }
  RealtimeSimulation& simulation() { return *simulation_; }
  const Grab* activeGrab() const { return grab_ ? &*grab_ : nullptr; }
  AccuracyPanel* accuracyPanel() const { return accuracyPanel_; }
  // See-through: the liver translucent, its visible lesions inside it (View menu, T; remembered).
  void setSeeThrough(bool on);
  bool seeThrough() const { return seeThrough_; }
  ToolPanel* toolPanel() const { return toolPanel_; }
  // The tool the mouse holds in the scene, if any (tools other than the hand).
  const std::optional<Tool>& heldTool() const { return tool_; }

  // Rebuilds the model with these integrator settings on a worker thread (the simulation runs on
  // meanwhile; a large mesh takes seconds), then restarts the simulation from the liver's current
  // positions and velocities. When the settings are invalid the panel shows why and the running
  // simulation stays. integratorChangeFinished tells which. Returns false, and does nothing, while
  // an earlier change is still being built.
  bool applyIntegratorSettings(const IntegratorSettings& settings);
  bool changingIntegrator() const { return changingIntegrator_; }
  // The accuracy study (Accuracy panel's "Compare Integrators…"): each integrator's error and
  // cost measured on the built-in liver; a run's setting chosen there is applied here.
  AccuracyStudyDialog* openAccuracyStudy();

  // The Material panel's tissue for the parenchyma (a scenario's lesions follow as its file
  // describes), applied as an integrator change is: built on a worker, then the liver runs on
  // from where it is, cut or not. An entry made while one is applied is applied after it (only
  // the newest). tissueChangeFinished tells whether it was applied; a bad value is refused in
  // the panel and the tissue in use stays. A scenario's sessions recorded afterwards store the
  // scenario with this tissue. False while a scene or an integrator change is being built.
  bool applyTissue(const TissueSpec& tissue);
  bool changingTissue() const { return changingTissue_; }
  MaterialPanel* materialPanel() const { return materialPanel_; }

  // Instructor mode: the Material panel edits the tissue, and the scenario editor and the review
  // and grading of every trainee's sessions are offered. Trainee mode shows the tissue read-only
  // and offers the trainee's own sessions only. Every start is in trainee mode; turning
  // instructor mode on (Settings menu, toolbar) asks for an instructor's log-in, or sets up the
  // first account of a database without one. Turning it off logs out.
  void setInstructorMode(bool on);
  bool instructorMode() const { return instructorMode_; }
  // Logs in with an instructor account of the sessions database (on a database without accounts,
  // creates the first one with this name and password) and turns instructor mode on. False, with
  // the reason in `why`, for a wrong name or password, a password too short for a new account, or
  // without a database.
  bool logInInstructor(const QString& name, const QString& password, QString* why = nullptr);
  void logOutInstructor();
  const std::optional<Instructor>& instructor() const { return instructor_; }
  // A further account, added by the instructor logged in (Settings ▸ Add Instructor Account…).
  bool addInstructorAccount(const QString& name, const QString& password, QString* why = nullptr);
  // The log-in form (or the first account's, or a further account's), not modal-blocking.
  InstructorLoginDialog* openInstructorLogin(InstructorLoginDialog::Purpose purpose);
  QToolBar* mainToolBar() const { return toolBar_; }

  // Opens a scenario file. It is read and validated at once: a bad file is refused with its
  // errors (field, value, what is expected) in the Scenario panel and a message box, and the
  // running scene stays. Otherwise its scene is built on a worker thread (meshing takes seconds)
  // and then runs in place of the current one; a scene that cannot be built is refused the same
  // way. scenarioOpenFinished tells which. Returns false, and does nothing, while a model is being
  // built.
  bool openScenario(const QString& file);
  // Runs a scenario from the instructor's editor ("Try it") as openScenario() runs a file's:
  // `file` is where it is saved (its organ file is named relative to that folder), or empty.
  bool tryScenario(const Scenario& scenario, const QString& file);
  // Stops building the scene being opened (the status bar's Cancel): meshing stops at its next
  // attempt and anything already built is dropped; the running scene goes on and
  // scenarioOpenFinished(false) follows, without an error.
  void cancelSceneBuild();
  // The instructor's scenario editor (File menu), on the scenario shown if it has a file, else
  // on a new one; its "Try it" runs here.
  ScenarioEditor* openScenarioEditor();
  const std::optional<OpenedScenario>& scenario() const { return scenario_; }
  ScenarioPanel* scenarioPanel() const { return scenarioPanel_; }

  // Haptic devices (Device panel). Each drives the tool through the 1 kHz servo: the mouse puts
  // the Tool panel's tool on the liver where it presses and moves it while held (its session is
  // recorded from its first press); the others hold the tool chosen in the Tool panel (the
  // hand: none) all the time. The
  // Phantom Omni is looked for at start, in the OpenHaptics runtime libHD.so (or the library
  // named by LIVERSIM_OPENHAPTICS_LIBRARY). Returns false, saying why in the panel, when the
  // device cannot be used; the device in use then stays.
  bool useDevice(DeviceChoice device, const QString& trajectoryFile = {});
  DeviceChoice device() const { return haptics_.device; }
  DevicePanel* devicePanel() const { return devicePanel_; }
  ServoLoop* servo() const { return servo_.get(); }
  const HapticPreferences& hapticPreferences() const { return haptics_; }
  // Opens the calibration dialog for the device in use (not modal); accepting it saves and uses
  // the new mapping.
  CalibrationDialog* openCalibration();

  // Sessions (docs/session-storage.md): while a device drives the tool through the servo, its
  // frames and events are recorded to the sessions database, one session per device and scene
  // (the mouse's from its first press on the liver).
  // Opens (or creates) the database; false, with the reason in sessionsProblem() and the status
  // bar, when it cannot: the workstation then runs without recording.
  bool setSessionsDatabase(const QString& file);
  QString sessionsProblem() const { return sessionsProblem_; }
  // Plays a recorded session's device input through the servo at its original rate (a replay is
  // not itself recorded). False, saying why in the Device panel, when it cannot be loaded.
  bool replaySession(std::int64_t session);
  // The session being recorded, if any.
  std::optional<std::int64_t> recordingSession() const;
  // The instructor's review of the sessions database's sessions (Session menu), in its own
  // window; null without a database.
  SessionReviewWindow* openSessionReview();
  // The trainee's own sessions (Session menu): the same window, only the trainee's sessions
  // (the trainee name recorded with sessions), without grading.
  SessionReviewWindow* openTraineeHistory();
  QString traineeName() const;
  // Palpation: records the rest point of the liver under the tool as the trainee's mark of the
  // lesion (a lesion_marked event; Session menu, M). False, saying why in the status bar, when
  // no session is recorded or no tool is in the scene.
  bool markLesionUnderTool();

  // The training centre (docs/training-centre.md; Settings ▸ Training Centre Server…): finished
  // sessions uploaded and published scenarios pulled (to pulledScenarioFolder()) in the
  // background, on the link's own thread and connection, so recording never waits for the
  // server; the status bar says how it stands. Connecting saves the server's address (never the
  // password, held in memory only) and starts the link; an empty address stops it. False, with
  // the reason, for an address that is none or without a sessions database. At start, a saved
  // server whose password libpq finds is connected to at once; otherwise the status bar asks for
  // the log-in.
  bool connectTrainingCentre(const TrainingCentreSetting& setting, const QString& password,
                             QString* why = nullptr);
  TrainingCentreSync* trainingCentre() const { return trainingCentre_.get(); }
  QString trainingCentreStatusText() const;
  QString pulledScenarioFolder() const;
  TrainingCentreDialog* openTrainingCentreSettings();
  // The review of every session on the training centre's server, as an instructor's own server
  // login; grades saved there reach the workstations with their next run. Null, saying why,
  // without a server set or when it refuses the log-in.
  SessionReviewWindow* openServerReview(const QString& instructor, const QString& password,
                                        QString* why = nullptr);

  // Spring stiffness of a mouse grab and the radius of tissue it holds.
  static constexpr double kGrabStiffnessNPerM = 300.0;
  static constexpr double kGrabRadiusM = 0.02;

 signals:
  // A recorded session's metrics were computed and stored (or not: stored false, the reason in
  // sessionsProblem()), after its end, on a worker.
  void sessionMetricsStored(qint64 session, bool stored);
  // The session under way is no longer being saved (a full disk, a deleted or read-only file):
  // what is said to the trainee, with what to do.
  void recordingStopped(const QString& message);
  void integratorChangeFinished(bool applied);
  void tissueChangeFinished(bool applied);
  void scenarioOpenFinished(bool opened);

 protected:
  void closeEvent(QCloseEvent* event) override;  // remembers the window's layout

 private:
  void applyMode(bool instructor);
  // The sessions the user may replay: all for an instructor, a trainee's own otherwise.
  std::vector<SessionSummary> replayableSessions();
  // A panel docked on the right, movable, floatable and closable (View ▸ Panels).
  QDockWidget* addPanelDock(const QString& title, const char* name, QWidget* panel);
  // The window's size, docks and toolbar as the user left them (saveState).
  void restoreLayout();
  static constexpr int kLayoutVersion = 1;
  // Runs `model` of `setup` from rest, in place of the scene shown (if any): a new simulation,
  // liver picture and tool interaction; the device in use stays attached.
  void installScene(SceneSetup setup, std::shared_ptr<const SimModel> model);
  // The scene shown starts again from rest, uncut, logging its input (a recorded session starts
  // so: its replay starts from the same state).
  void restartFromRest();
  void buildScenario(OpenedScenario opened, const QString& folder);  // on modelBuilder_
  static QString scenarioName(const OpenedScenario& opened);         // for messages
  void finishScenarioOpen(const OpenedScenario& opened, std::shared_ptr<SceneSetup> setup,
                          std::shared_ptr<const SimModel> model, const QString& error);
  void refuseScenario(const QString& file, const QString& why);
  void showScenarioDetails();  // title, panel and allowed tools of scenario_
  void buildMenus();
  void openScenarioFromMenu(const QString& file);  // says so when a scene is still being built
  void updateRecentMenu();
  bool beginGrab(QPoint vtkDisplayPos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers);
  void moveGrab(QPoint vtkDisplayPos);
  void endGrab();
  bool beginTool(ToolKind kind, QPoint vtkDisplayPos);
  void moveTool(QPoint vtkDisplayPos);
  void endTool();
  void showTool(const std::optional<Tool>& tool);
  // The shaft's direction for a tool put on the liver: toward the viewer, tilted up by 35°.
  Eigen::Quaterniond toolOrientationFromView() const;
  // Device axes (x right, y up, z toward the user) → scene, for the current view.
  Eigen::Quaterniond deviceAxesFromView() const;
  // Just in front of the liver, seen from the camera: where a centred stylus puts the tool.
  Eigen::Vector3d deviceHome_m() const;
  std::optional<DeviceToolSettings> deviceToolSettings() const;
  void attachDevice();  // the servo and the device's tool to the (stopped) simulation
  void detachDevice();  // stops the servo; the simulation must be stopped
  void checkDevice();   // servo statistics and faults, with the status
  void saveHapticPreferences();
  void chooseSessionToReplay();  // asks which recorded session, then replaySession()
  void beginRecording();         // a session of servo_ on the scene now shown
  void endRecording();           // (detachDevice stops servo_ first: its last frames are kept)
  void recordToolChoice();       // the Tool panel's tool as a session event
  void openOmni();               // looks for the Phantom Omni: omni_, or why not in omniProblem_
  // A change of the running model, built on modelBuilder_, then run on from the liver's state:
  // an integrator setting (Accuracy panel) or a tissue (Material panel).
  struct ModelChange {
    std::optional<IntegratorSettings> integrator;
    std::optional<TissueSpec> tissue;
  };
  struct ModelChangeBuilt {
    std::shared_ptr<const SimModel> model;       // to run now
    std::shared_ptr<const SimModel> rest_model;  // the scene's uncut model with the change
  };
  void startModelChange(ModelChange change, std::function<ModelChangeBuilt()> build);
  void finishModelChange(const ModelChange& change, const ModelChangeBuilt& built,
                         const QString& error);
  void applyPendingTissue();
  bool busyBuilding() const;  // a scene, an integrator or a tissue
  // The scenario running, or free practice's tissue and effects as a scenario without lesions.
  Scenario describedScenario() const;
  void showNewestSnapshot();
  void updateStatus();
  QString accuracyStatus(const RealtimeStats& stats) const;
  static QString healthProblemText(HealthProblem problem);
  static QString formatError(double error_m);

  SceneSetup setup_;
  ToolModels toolModels_;  // read once; every scene draws its tools with them
  bool seeThrough_ = false;
  QAction* seeThroughAction_ = nullptr;
  bool ambientOcclusion_ = false;  // View menu, remembered; off by default (its frame-rate cost)
  QAction* ambientOcclusionAction_ = nullptr;
  std::shared_ptr<const SimModel> sceneModel_;  // setup_'s model, uncut, with the integrator in use
  std::unique_ptr<RealtimeSimulation> simulation_;
  std::unique_ptr<LiverScene> scene_;
  VtkViewport* viewport_ = nullptr;
  AccuracyPanel* accuracyPanel_ = nullptr;
  QPointer<AccuracyStudyDialog> accuracyStudy_;
  std::optional<Instructor> instructor_;  // who logged in, in instructor mode
  bool recordingFailureShown_ = false;    // the recorder's storage failure, said once
  QPointer<InstructorLoginDialog> loginDialog_;
  QAction* addInstructorAction_ = nullptr;
  ToolPanel* toolPanel_ = nullptr;
  DevicePanel* devicePanel_ = nullptr;
  ScenarioPanel* scenarioPanel_ = nullptr;
  MaterialPanel* materialPanel_ = nullptr;
  QToolBar* toolBar_ = nullptr;
  QMenu* panelsMenu_ = nullptr;
  QAction* instructorModeAction_ = nullptr;
  QAction* scenarioEditorAction_ = nullptr;
  QAction* reviewSessionsAction_ = nullptr;
  bool instructorMode_ = false;
  QMenu* recentMenu_ = nullptr;
  QPointer<CalibrationDialog> calibration_;
  QLabel* statusLabel_ = nullptr;
  QLabel* trainingCentreLabel_ = nullptr;  // shown while a server is set
  std::unique_ptr<TrainingCentreSync> trainingCentre_;
  QTimer trainingCentreTimer_;  // the label follows the link's status
  QPointer<SessionReviewWindow> serverReview_;
  void showTrainingCentreStatus();
  void startTrainingCentreAtLaunch();
  QProgressBar* buildProgress_ = nullptr;  // while a scene is built, with cancelBuild_
  QPushButton* cancelBuild_ = nullptr;
  std::shared_ptr<std::atomic<bool>> buildCancelled_;  // of the build under way
  QTimer frameTimer_;
  QTimer statusTimer_;

  std::optional<Grab> grab_;
  Eigen::Vector3d handle_m_ = Eigen::Vector3d::Zero();
  std::vector<NodeSpring> springs_;

  std::optional<Tool> tool_;
  Eigen::Vector3d toolPoint_m_ = Eigen::Vector3d::Zero();  // where the mouse holds the tool

  std::uint64_t shownTopology_ = 0;  // the cut the scene shows (SimulationSnapshot)

  int framesInWindow_ = 0;
  QElapsedTimer frameWindow_;
  double framesPerSecond_ = 0.0;

  HapticPreferences haptics_;
  std::unique_ptr<HapticDevice> omni_;  // opened at start when its runtime and device are there
  QString omniProblem_;                 // why not, otherwise
  std::unique_ptr<HapticDevice> ownDevice_;  // the mouse, a script or a replay (not the Omni)
  ManualDevice* mouse_ = nullptr;            // ownDevice_, while the mouse is the device
  std::unique_ptr<ServoLoop> servo_;         // runs for the device in use, the mouse too
  // The mouse: its millimetres are the scene's; its action button is held while pressed; its
  // release lifts the tool this far up its shaft.
  static inline const WorkspaceMapping kMouseMapping{};
  static constexpr std::uint32_t kMouseActionButton = 1;
  static constexpr double kMouseLiftM = 0.03;
  std::uint64_t droppedBeforeRecording_ = 0;  // servo log frames dropped before the session

  std::optional<OpenedScenario> scenario_;

  std::unique_ptr<SessionStore> sessions_;
  QString sessionsFile_;
  // While recording: the events the display frames show, the lesions a cut has breached too.
  std::optional<SessionEventWatch> eventWatch_;
  std::thread metricsWorker_;
  int pendingMetrics_ = 0;
  void computeSessionMetrics(std::int64_t session, std::optional<OutcomeTracking> outcome,
                             const WorkspaceMapping& mapping);
  void recordSimulationEvents(const SimulationSnapshot& snapshot, bool cut);
  SessionReviewWindow* showSessionsWindow(QPointer<SessionReviewWindow>& window,
                                          const std::optional<QString>& trainee);
  // The trainee's summary of a session just ended, for the Scenario panel.
  static QString sessionResultText(const RubricResult& rubric,
                                   const std::vector<MetricValue>& metrics);
  QPointer<ScenarioEditor> editor_;
  QPointer<SessionReviewWindow> review_;
  QPointer<SessionReviewWindow> history_;
  QString sessionsProblem_;
  std::unique_ptr<SessionRecorder> recorder_;  // while servo_ runs and sessions_ is open
  std::vector<TrajectoryPoint> replayPoints_;  // of the session replaySession() loaded
  WorkspaceMapping replayMapping_;             // and the mapping it was recorded with
  QString replayName_;

  // Builds the model of an integrator change (reading setup_.mesh, which changes only when no
  // model is being built) or the scene of a scenario being opened.
  std::thread modelBuilder_;
  bool changingIntegrator_ = false;
  bool changingTissue_ = false;
  std::optional<TissueSpec> pendingTissue_;
  bool tissueChangedInFreePractice_ = false;  // its sessions cannot be replayed then
  bool openingScenario_ = false;
};

}  // namespace liversim
