#pragma once
// The scenario the instructor's editor works on: the scenario, the file it is saved in, and the
// undo history of its edits. Every edit goes through edit(), so every edit can be undone; saving
// validates first and refuses a scenario with errors.

#include "liversim/scenario/scenario.h"

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <filesystem>
#include <functional>
#include <vector>

namespace liversim {

class ScenarioDocument : public QObject {
  Q_OBJECT

 public:
  // A new scenario (no file): the defaults, a palpation task on one lesion.
  explicit ScenarioDocument(QObject* parent = nullptr);

  static Scenario newScenario();

  const Scenario& scenario() const { return scenario_; }
  // The file it was opened from or last saved to (absolute), or empty.
  const QString& file() const { return file_; }
  // Where the organ's file, when named relatively, is: the file's folder (no file: the current
  // folder).
  std::filesystem::path organFolder() const;
  QUndoStack* undoStack() { return &undoStack_; }
  bool isModified() const { return !undoStack_.isClean(); }

  // One undoable edit named `text` (shown in Edit ▸ Undo): `change` applied to the scenario.
  // Edits with the same non-zero merge key one after the other (a drag, typing in one field) are
  // one step; endMergeRun() starts a new step even for the same key (the next drag).
  void edit(const QString& text, const std::function<void(Scenario&)>& change, int mergeKey = 0);
  void endMergeRun() { ++mergeRun_; }

  // Replaces the document: a scenario read from `file` (empty: a new one), with no history.
  // Returns the errors of a file that cannot be read; the document is then unchanged.
  std::vector<ScenarioError> open(const QString& file);
  void reset(Scenario scenario, const QString& file);
  // Why `scenario` cannot be saved (or run): validate()'s errors and the reader's own on its JSON
  // text, so that what is saved always reads back. Empty: none.
  static std::vector<ScenarioError> problems(const Scenario& scenario);
  // Validates and writes to `file`. With errors nothing is written and they are returned; a write
  // that fails (a full disk, a folder that is not writable) is one error naming the file.
  std::vector<ScenarioError> saveAs(const QString& file);

 signals:
  // The scenario changed (an edit, undo, redo, open); organChanged too when the organ's shape or
  // element count did (the mesh must be rebuilt).
  void changed();
  void organChanged();
  void fileChanged();

 private:
  friend class ScenarioEditCommand;
  void apply(const Scenario& scenario);

  Scenario scenario_;
  QString file_;
  QUndoStack undoStack_;
  int mergeRun_ = 0;
};

// The errors, one per line, as the workstation and the editor show them.
QString scenarioErrorsText(const std::vector<ScenarioError>& errors);

// Whether two organs are meshed alike (the same geometry, file, unit and element count); fixed
// regions and the ligament do not change the mesh.
bool sameOrganMesh(const OrganSpec& a, const OrganSpec& b);

}  // namespace liversim
