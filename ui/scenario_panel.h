#pragma once
// The scenario the trainee is running, read-only: its title and description, the task with its
// time limit, the tools it allows and the effects it simulates, and the file it came from. Without
// a scenario it says the window is in free practice and how to open one.

#include "liversim/scenario/scenario.h"
#include "liversim/sessions/grading.h"

#include <QWidget>

#include <optional>

class QLabel;

namespace liversim {

class ScenarioPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ScenarioPanel(QWidget* parent = nullptr);

  // The scenario in the window and its file, or none (free practice on the built-in liver).
  void showScenario(const Scenario* scenario, const QString& file);
  // A scenario that could not be opened: why, in red, under what is still running.
  void showProblem(const QString& text);

  // The trainee's result of the session just ended (its score and criteria); empty hides it.
  void showResult(const QString& text);
  void showSessionResult(const RubricResult& rubric, const std::vector<MetricValue>& metrics);

  QString taskText() const;
  QString problemText() const;
  QString resultText() const;

 private:
  QLabel* title_ = nullptr;
  QLabel* description_ = nullptr;
  QLabel* task_ = nullptr;
  QLabel* setup_ = nullptr;
  QLabel* file_ = nullptr;
  QLabel* problem_ = nullptr;
  QLabel* result_ = nullptr;
};

// What the task asks, for the trainee: its instructions, or a sentence made from its fields.
QString describeTask(const TaskSpec& task);

}  // namespace liversim
