#include "scenario_document.h"

#include <QFileInfo>
#include <QUndoCommand>

namespace liversim {

// An edit as the scenario before and after it.
class ScenarioEditCommand : public QUndoCommand {
 public:
  ScenarioEditCommand(ScenarioDocument& document, const QString& text, Scenario before,
                      Scenario after, int mergeKey, int mergeRun)
      : QUndoCommand(text),
        document_(document),
        before_(std::move(before)),
        after_(std::move(after)),
        mergeKey_(mergeKey),
        mergeRun_(mergeRun) {}

  void undo() override { document_.apply(before_); }
  void redo() override { document_.apply(after_); }
  int id() const override { return mergeKey_ != 0 ? mergeKey_ : -1; }
  bool mergeWith(const QUndoCommand* other) override {
    const auto* next = static_cast<const ScenarioEditCommand*>(other);
    if (next->mergeRun_ != mergeRun_) return false;
    after_ = next->after_;
    return true;
  }

 private:
  ScenarioDocument& document_;
  Scenario before_, after_;
  int mergeKey_, mergeRun_;
};

bool sameOrganMesh(const OrganSpec& a, const OrganSpec& b) {
  return a.geometry == b.geometry && a.file == b.file && a.target_tet_count == b.target_tet_count &&
         a.metres_per_unit == b.metres_per_unit;
}

ScenarioDocument::ScenarioDocument(QObject* parent) : QObject(parent), scenario_(newScenario()) {}

Scenario ScenarioDocument::newScenario() {
  Scenario s;
  s.title = tr("New scenario").toStdString();
  LesionSpec lesion;
  lesion.name = "lesion 1";
  lesion.centre_mm = {-50.0, 10.0, 40.0};  // inside the right lobe of the built-in liver
  lesion.radii_mm = {12.0, 12.0, 12.0};
  s.lesions.push_back(lesion);
  s.task.kind = TaskKind::palpate_lesion;
  s.task.lesion = lesion.name;
  return s;
}

void ScenarioDocument::edit(const QString& text, const std::function<void(Scenario&)>& change,
                            int mergeKey) {
  Scenario after = scenario_;
  change(after);
  if (after == scenario_) return;  // nothing to undo
  undoStack_.push(
      new ScenarioEditCommand(*this, text, scenario_, std::move(after), mergeKey, mergeRun_));
}

std::vector<ScenarioError> ScenarioDocument::problems(const Scenario& scenario) {
  // What the file will say must read back as this scenario: the reader's checks (the parser's
  // ranges too), not only validate()'s.
  std::vector<ScenarioError> errors = validate(scenario);
  if (errors.empty()) errors = read_scenario(write_scenario(scenario)).errors;
  return errors;
}

QString scenarioErrorsText(const std::vector<ScenarioError>& errors) {
  QStringList lines;
  for (const ScenarioError& error : errors) lines << QString::fromStdString(error.text());
  return lines.join('\n');
}

std::filesystem::path ScenarioDocument::organFolder() const {
  return file_.isEmpty() ? std::filesystem::current_path()
                         : std::filesystem::path(file_.toStdString()).parent_path();
}

void ScenarioDocument::apply(const Scenario& scenario) {
  const bool organ = !sameOrganMesh(scenario.organ, scenario_.organ);
  scenario_ = scenario;
  if (organ) emit organChanged();
  emit changed();
}

std::vector<ScenarioError> ScenarioDocument::open(const QString& file) {
  const ScenarioReading reading = read_scenario_file(file.toStdString());
  if (!reading.scenario) return reading.errors;
  reset(*reading.scenario, QFileInfo(file).absoluteFilePath());
  return {};
}

void ScenarioDocument::reset(Scenario scenario, const QString& file) {
  undoStack_.clear();
  file_ = file;
  const bool organ = !sameOrganMesh(scenario.organ, scenario_.organ);
  scenario_ = std::move(scenario);
  ++mergeRun_;
  if (organ) emit organChanged();
  emit changed();
  emit fileChanged();
}

std::vector<ScenarioError> ScenarioDocument::saveAs(const QString& file) {
  // An organ file named relative to the old folder is named relative to the new one.
  Scenario saved = scenario_;
  std::string& organFile = saved.organ.file;
  if (!organFile.empty() && std::filesystem::path(organFile).is_relative()) {
    const std::filesystem::path from = std::filesystem::absolute(organFolder() / organFile);
    organFile =
        std::filesystem::relative(from, std::filesystem::absolute(file.toStdString()).parent_path())
            .generic_string();
  }
  if (std::vector<ScenarioError> errors = problems(saved); !errors.empty()) return errors;
  try {
    write_scenario_file(saved, file.toStdString());
  } catch (const std::exception& e) {
    return {ScenarioError{"", e.what()}};  // nothing changed: not the file, not the document
  }
  // The history's scenarios name the organ file relative to the old folder: it cannot be undone
  // into the new one.
  if (saved.organ.file != scenario_.organ.file) undoStack_.clear();
  scenario_ = std::move(saved);
  file_ = QFileInfo(file).absoluteFilePath();
  undoStack_.setClean();
  ++mergeRun_;
  emit fileChanged();
  return {};
}

}  // namespace liversim
