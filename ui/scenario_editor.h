#pragma once
// The instructor's scenario editor: the organ seen through (lesions inside it), with the lesions
// placed, moved and resized by mouse on it, the planned resection plane drawn across it, fixed
// regions painted on its surface and the fibre direction shown; panels for every parameter with
// units, ranges and tooltips; the effects with what they cost, measured; "Try it" runs the
// scenario in the workstation. Every edit can be undone; saving validates. The panels are
// EditorLesionPanel, EditorTaskPanel, EditorTissuePanel, EditorOrganPanel and EditorGradingPanel;
// the editor places them in its docks and keeps the view, the lesion selected, the files and the
// cost measurement.

#include "scenario_document.h"

#include "liversim/meshing/default_scene.h"

#include <QMainWindow>
#include <QPoint>

#include <atomic>
#include <memory>
#include <optional>
#include "liversim/engine/background_job.h"

class QAction;
class QActionGroup;
class QDockWidget;
class QMenu;

namespace liversim {

class EditorGradingPanel;
class EditorLesionPanel;
class EditorOrganPanel;
class EditorTaskPanel;
class EditorTissuePanel;
class LiverScene;
class ScenarioOverlay;
class VtkViewport;

class ScenarioEditor : public QMainWindow {
  Q_OBJECT

 public:
  // What a left press on the organ does (a press on a lesion always takes the lesion).
  enum class Mode {
    view,            // turns the view
    placeLesion,     // puts a new lesion under the surface there
    drawPlane,       // drags the planned resection plane's trace across the view
    paintFixed,      // paints fixed regions (ligament attachments) on the surface
    pickGraspPoint,  // the next click sets a retraction's grasp point, then back to view
  };

  // A new scenario (ScenarioDocument::newScenario).
  explicit ScenarioEditor(QWidget* parent = nullptr);
  ~ScenarioEditor() override;

  ScenarioDocument& document() { return document_; }
  VtkViewport* viewport() const { return viewport_; }
  LiverScene* scene() const { return scene_.get(); }  // null while the organ cannot be built
  const ScenarioOverlay* overlay() const { return overlay_.get(); }
  QString organProblem() const { return organProblem_; }

  void setMode(Mode mode);
  Mode mode() const { return mode_; }
  int selectedLesion() const { return selectedLesion_; }  // -1: none
  void selectLesion(int index);

  // File actions. openFile refuses a file with errors (shown, document unchanged). save and
  // saveAs validate first: a scenario with errors is not written, they are shown (the box
  // "saveErrorsBox") and false returned. Both ask first when there are unsaved changes.
  bool openFile(const QString& file);
  bool save();  // to its file, or asks where
  bool saveAs(const QString& file);
  void newScenario();
  // With unsaved changes, asks (the box "unsavedChangesBox": save, discard or cancel); true when
  // the document may be replaced or closed.
  bool maybeSave();

  // The effects' cost: steps per second of the scenario as it is now, measured on a worker (the
  // model built and stepped under a pull for half a second). Remeasured after every change of
  // the effects, the tissue, the lesions or the organ.
  QString costText() const;
  int costMeasurementCount() const { return costMeasurements_; }
  std::optional<double> stepsPerSecond() const { return stepsPerSecond_; }

 signals:
  // "Try it": run this scenario in the workstation (`file`: where it is saved, or empty).
  void tryScenario(const Scenario& scenario, const QString& file);
  void costMeasured();

 protected:
  void closeEvent(QCloseEvent* event) override;
  void showEvent(QShowEvent* event) override;

 private:
  void buildActions();
  QDockWidget* addDock(const QString& title, const char* name, QWidget* panel);
  void fitCamera();     // the whole organ in the view
  void rebuildOrgan();  // the organ's mesh, after organChanged
  void showDocument();  // panels and overlay from the document
  void showOverlay();
  void updateTitle();
  void showErrors(const QString& title, const char* boxName,
                  const std::vector<ScenarioError>& errors);
  void updateRecentMenu();
  void tryIt();

  // Mouse on the viewport (VTK display coordinates).
  bool pressAt(QPoint display, Qt::MouseButton button, Qt::KeyboardModifiers modifiers);
  void moveTo(QPoint display);
  void releaseAt(QPoint display);
  int lesionAt(QPoint display) const;  // -1: none
  Eigen::Vector3d viewDirection() const;
  // From the view's left to its right (not normalised); none while no organ is shown.
  std::optional<Eigen::Vector3d> screenHorizontal() const;
  void paintAt(QPoint display);

  // A new lesion, named "lesion N", centred at `point_m`, or with depth_mm > 0 that much deeper
  // than its radius along the view; it is selected.
  void addLesion(const QString& text, const Eigen::Vector3d& point_m, double depth_mm);

  void measureCost();  // (again) after the current measurement
  void finishCostMeasurement(std::optional<double> stepsPerSecond, double realTimeFactor,
                             int tetCount, QString problem);

  ScenarioDocument document_;
  VtkViewport* viewport_ = nullptr;
  std::optional<SceneSetup> organ_;                          // the organ's mesh as shown
  Eigen::Vector3d organCentre_m_ = Eigen::Vector3d::Zero();  // the mean of its nodes
  std::unique_ptr<LiverScene> scene_;
  std::unique_ptr<ScenarioOverlay> overlay_;
  QString organProblem_;
  Mode mode_ = Mode::view;
  int selectedLesion_ = -1;
  bool shown_ = false;

  // The drag the mouse is doing.
  enum class Drag { none, moveLesion, resizeLesion, plane, paint };
  Drag drag_ = Drag::none;
  QPoint pressAt_;
  LesionSpec lesionAtPress_;
  Eigen::Vector3d dragOffset_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d planeStart_m_ = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> lastPaint_m_;

  QActionGroup* modes_ = nullptr;
  QAction* viewAction_ = nullptr;
  QAction* placeLesionAction_ = nullptr;
  QAction* drawPlaneAction_ = nullptr;
  QAction* paintFixedAction_ = nullptr;
  QMenu* recentMenu_ = nullptr;

  EditorLesionPanel* lesionPanel_ = nullptr;
  EditorTaskPanel* taskPanel_ = nullptr;
  EditorTissuePanel* tissuePanel_ = nullptr;  // shows the cost
  EditorOrganPanel* organPanel_ = nullptr;
  EditorGradingPanel* gradingPanel_ = nullptr;

  // The cost measurement on its worker.
  BackgroundJob costWorker_;
  bool costBusy_ = false;
  bool costAgain_ = false;                // the scenario changed during the measurement
  std::optional<Scenario> costScenario_;  // measured, or being measured
  int costMeasurements_ = 0;
  std::optional<double> stepsPerSecond_;
  std::optional<double> previousStepsPerSecond_;
  std::shared_ptr<std::atomic<bool>> alive_ = std::make_shared<std::atomic<bool>>(true);
};

}  // namespace liversim
