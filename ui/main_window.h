#pragma once
// The workstation's main window: the liver viewport in the middle, the scenario, the accuracy
// setting (time integrator and step), the tissue, the tool and the device beside it, live
// statistics in the status bar. The station itself (scene, simulation, devices, recording, the
// training centre's link) is a Workstation (core/station) that the window drives and shows; the
// window keeps the docks, menus, status text, the mouse, dialogs, settings and translations.

#include "haptic_preferences.h"
#include "instructor_login_dialog.h"
#include "mouse_tool_control.h"
#include "render/liver_scene.h"
#include "training_centre_dialog.h"

#include "liversim/meshing/default_scene.h"
#include "liversim/station/workstation.h"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QPointer>
#include <QTimer>

#include <cstdint>
#include <memory>
#include <optional>

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
class DeviceControl;
class DevicePanel;
class MaterialPanel;
class ScenarioEditor;
class ScenarioPanel;
class SessionReviewWindow;
class ToolPanel;
class TrainingCentreControl;
class VtkViewport;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  // The scene to run, and the scenario it was built from (none: free practice).
  explicit MainWindow(SceneSetup setup, std::optional<OpenedScenario> scenario = std::nullopt,
                      QWidget* parent = nullptr);
  ~MainWindow() override;

  Workstation& station() { return *station_; }
  VtkViewport* viewport() const { return viewport_; }
  LiverScene& scene() { return *scene_; }
  RealtimeSimulation& simulation() { return station_->simulation(); }
  const Grab* activeGrab() const { return mouseControl_->grab(); }
  // The tool the mouse holds in the scene, if any (tools other than the hand).
  const std::optional<Tool>& heldTool() const { return mouseControl_->tool(); }
  AccuracyPanel* accuracyPanel() const { return accuracyPanel_; }
  MaterialPanel* materialPanel() const { return materialPanel_; }
  ScenarioPanel* scenarioPanel() const { return scenarioPanel_; }
  ToolPanel* toolPanel() const { return toolPanel_; }
  DevicePanel* devicePanel() const { return devicePanel_; }
  QToolBar* mainToolBar() const { return toolBar_; }
  // See-through: the liver translucent, its visible lesions inside it (View menu, T; remembered).
  void setSeeThrough(bool on);
  bool seeThrough() const { return seeThrough_; }

  // The Accuracy panel's integrator setting, built on the station's worker while the liver runs
  // on, then run from where the liver is (integratorChangeFinished tells whether it was applied;
  // the panel says why not). False, doing nothing, while a model is being built.
  bool applyIntegratorSettings(const IntegratorSettings& settings);
  bool changingIntegrator() const { return station_->changing_integrator(); }
  // The accuracy study (Accuracy panel's "Compare Integrators…"): a run's setting chosen there is
  // applied here.
  AccuracyStudyDialog* openAccuracyStudy();
  // The Material panel's tissue for the parenchyma, applied as an integrator change is
  // (tissueChangeFinished); instructors only. False while a scene or an integrator change is
  // being built.
  bool applyTissue(const TissueSpec& tissue);
  bool changingTissue() const { return station_->changing_tissue(); }
  // The Material panel's gravity switch, applied as a tissue change is (gravityChangeFinished):
  // anyone in free practice, instructors in a scenario. False while a model is being built.
  bool applyGravity(bool on);

  // Instructor mode: the Material panel edits the tissue, and the scenario editor and the review
  // and grading of every trainee's sessions are offered. Every start is in trainee mode; turning
  // it on asks for an instructor's log-in (or sets up the first account of a database without
  // one). Turning it off logs out.
  void setInstructorMode(bool on);
  bool instructorMode() const { return instructorMode_; }
  // False, with the reason in `why`, for a wrong name or password, a password too short for a new
  // account, or without a database.
  bool logInInstructor(const QString& name, const QString& password, QString* why = nullptr);
  void logOutInstructor();
  const std::optional<Instructor>& instructor() const { return instructor_; }
  bool addInstructorAccount(const QString& name, const QString& password, QString* why = nullptr);
  InstructorLoginDialog* openInstructorLogin(InstructorLoginDialog::Purpose purpose);

  // Opens a scenario file: a bad file is refused with its errors in the Scenario panel and a
  // message box, the running scene staying; otherwise its scene is built by the station and runs
  // in place of the current one (scenarioOpenFinished). False, doing nothing, while a model is
  // being built.
  bool openScenario(const QString& file);
  // Runs a scenario from the instructor's editor ("Try it"): `file` is where it is saved (its
  // organ file is named relative to that folder), or empty.
  bool tryScenario(const Scenario& scenario, const QString& file);
  // The status bar's Cancel: the running scene goes on; scenarioOpenFinished(false) follows.
  void cancelSceneBuild();
  ScenarioEditor* openScenarioEditor();
  const std::optional<OpenedScenario>& scenario() const { return station_->scenario(); }

  // The device that moves the tool (Device panel): the mouse, the Phantom Omni (looked for at
  // start in libHD.so or LIVERSIM_OPENHAPTICS_LIBRARY), a scripted trajectory file or a replay.
  // False, saying why in the panel, when it cannot be used; the device in use then stays.
  bool useDevice(DeviceChoice device, const QString& trajectoryFile = {});
  // The left hand's device (Device panel, "Left hand"): a scripted trajectory file played beside
  // the device in use (empty: none). False, saying why in the panel, when it cannot be played.
  bool useLeftHandDevice(const QString& trajectoryFile);
  // A second Omni in the left hand (Touch Setup's "Left Device"), as the panel's entry chooses it.
  bool useLeftHandOmni();
  DeviceChoice device() const { return station_->device(); }
  ServoLoop* servo() const { return station_->servo(); }
  const HapticPreferences& hapticPreferences() const;
  CalibrationDialog* openCalibration();

  // Sessions (docs/session-storage.md): false, with the reason in sessionsProblem() and the status
  // bar, when the database cannot be opened: the workstation then runs without recording.
  bool setSessionsDatabase(const QString& file);
  QString sessionsProblem() const { return sessionsProblem_; }
  // Plays a recorded session's device input through the servo (a replay is not recorded). False,
  // saying why in the Device panel, when it cannot be loaded or is not the user's to replay.
  bool replaySession(std::int64_t session);
  std::optional<std::int64_t> recordingSession() const { return station_->recording_session(); }
  SessionReviewWindow* openSessionReview();
  SessionReviewWindow* openTraineeHistory();
  QString traineeName() const;
  // Palpation: the point of the liver under the tool as the trainee's mark of the lesion.
  bool markLesionUnderTool();

  // The training centre (docs/training-centre.md; Settings ▸ Training Centre Server…): the
  // server's address is saved (never the password); an empty address stops the link.
  bool connectTrainingCentre(const TrainingCentreSetting& setting, const QString& password,
                             QString* why = nullptr);
  TrainingCentreSync* trainingCentre() const { return station_->training_centre(); }
  QString trainingCentreStatusText() const;
  QString pulledScenarioFolder() const;
  TrainingCentreDialog* openTrainingCentreSettings();
  SessionReviewWindow* openServerReview(const QString& instructor, const QString& password,
                                        QString* why = nullptr);

 signals:
  void sessionMetricsStored(qint64 session, bool stored);
  void recordingStopped(const QString& message);
  void integratorChangeFinished(bool applied);
  void tissueChangeFinished(bool applied);
  void gravityChangeFinished(bool applied);
  void scenarioOpenFinished(bool opened);

 protected:
  void closeEvent(QCloseEvent* event) override;  // remembers the window's layout

 private:
  StationListener stationListener();
  // The station's reports.
  void showSceneBuildProgress(const MeshingProgress& progress);
  void sceneOpened(const SceneOpening& opening);
  void modelChanged(const ModelChangeOutcome& outcome);
  void sessionMetricsDone(const SessionMetricsOutcome& outcome);
  void showStorageProblem(const QString& text);

  void applyMode(bool instructor);
  std::vector<SessionSummary> replayableSessions();
  QDockWidget* addPanelDock(const QString& title, const char* name, QWidget* panel);
  void restoreLayout();
  // 2: the panels in scroll areas, tabbed in two groups (a saved layout of five stacked docks
  // would squeeze them again).
  static constexpr int kLayoutVersion = 2;
  // The picture of the station's scene, new (at start and when a scenario opened).
  void showNewScene();
  void showScenarioDetails();
  void buildScenario(OpenedScenario opened, const QString& folder);
  static QString scenarioName(const OpenedScenario& opened);
  void refuseScenario(const QString& file, const QString& why);
  void buildMenus();
  void openScenarioFromMenu(const QString& file);
  void updateRecentMenu();
  Eigen::Quaterniond deviceAxesFromView() const;
  void showNewestSnapshot();
  void updateStatus();
  SessionReviewWindow* showSessionsWindow(QPointer<SessionReviewWindow>& window,
                                          const std::optional<QString>& trainee);

  std::unique_ptr<Workstation> station_;
  std::unique_ptr<LiverScene> scene_;
  std::unique_ptr<MouseToolControl> mouseControl_;
  ToolModels toolModels_;            // read once; every scene draws its tools with them
  std::uint64_t shownTopology_ = 0;  // the cut the picture shows
  bool seeThrough_ = false;
  bool ambientOcclusion_ = false;  // View menu, remembered; off by default (its frame-rate cost)
  QAction* seeThroughAction_ = nullptr;
  QAction* ambientOcclusionAction_ = nullptr;

  VtkViewport* viewport_ = nullptr;
  AccuracyPanel* accuracyPanel_ = nullptr;
  MaterialPanel* materialPanel_ = nullptr;
  ToolPanel* toolPanel_ = nullptr;
  DevicePanel* devicePanel_ = nullptr;
  ScenarioPanel* scenarioPanel_ = nullptr;
  QToolBar* toolBar_ = nullptr;
  QMenu* panelsMenu_ = nullptr;
  QMenu* recentMenu_ = nullptr;
  QAction* instructorModeAction_ = nullptr;
  QAction* scenarioEditorAction_ = nullptr;
  QAction* reviewSessionsAction_ = nullptr;
  QAction* addInstructorAction_ = nullptr;
  QLabel* statusLabel_ = nullptr;
  QProgressBar* buildProgress_ = nullptr;  // while a scene is built, with cancelBuild_
  QPushButton* cancelBuild_ = nullptr;
  QTimer frameTimer_;
  QTimer statusTimer_;
  int framesInWindow_ = 0;
  QElapsedTimer frameWindow_;

  bool instructorMode_ = false;
  std::optional<Instructor> instructor_;  // who logged in, in instructor mode
  QPointer<InstructorLoginDialog> loginDialog_;
  QPointer<AccuracyStudyDialog> accuracyStudy_;
  QPointer<ScenarioEditor> editor_;
  QPointer<SessionReviewWindow> review_;
  QPointer<SessionReviewWindow> history_;

  DeviceControl* devices_ = nullptr;
  TrainingCentreControl* trainingCentreControl_ = nullptr;
  QString sessionsProblem_;
};

}  // namespace liversim
