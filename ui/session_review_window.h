#pragma once
// The instructor's review of recorded sessions: the sessions listed and filtered (trainee,
// scenario, date, score), and one session opened: its metrics against the scenario's rubric with
// the overall score, the force on the device over time with the session's events, and a grade
// and comment saved to the database (docs/session-storage.md).

#include "liversim/sessions/grading.h"
#include "liversim/sessions/session_store.h"
#include "session_reading.h"

#include <QPointer>
#include <QString>
#include <QStringList>
#include <QWidget>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

class QChartView;
class QLabel;
class QLineEdit;
class QLineSeries;
class QListWidget;
class QPlainTextEdit;
class QPushButton;
class QScatterSeries;
class QTableWidget;

namespace liversim {

class SessionReplayWindow;

class SessionReviewWindow : public QWidget {
  Q_OBJECT

 public:
  // Opens its own connection to the database file (the recorder keeps writing through the
  // workstation's); a file it cannot open is said in the window, which then lists nothing.
  // With `trainee`, the trainee's own history: only that trainee's sessions (the store lists no
  // others), and no grading. Otherwise every session, graded by `grader`, the instructor who
  // logged in (without one, nothing can be graded).
  explicit SessionReviewWindow(const QString& databaseFile,
                               const std::optional<QString>& trainee = std::nullopt,
                               const std::optional<Instructor>& grader = std::nullopt,
                               QWidget* parent = nullptr);
  // Every session of a store already open (the training centre's server, named `source` in the
  // title), graded by `grader` (an instructor logged in on that store).
  SessionReviewWindow(std::unique_ptr<SessionStore> store, const QString& source,
                      const std::optional<Instructor>& grader, QWidget* parent = nullptr);
  ~SessionReviewWindow() override;

  QString problem() const { return problem_; }
  // Re-reads the sessions (and their scores) from the database.
  void refresh();
  // Shows only sessions whose trainee or scenario title contains the text (any case).
  void setFilter(const QString& text);
  int listedSessionCount() const;
  // Opens a session in the lower half; false when it is not listed.
  bool openSession(std::int64_t session);
  std::optional<std::int64_t> openedSession() const { return opened_; }
  // Whether the opened session's frames were read: a long session shows a progress dialog whose
  // Cancel leaves the trace and events out (opening the session again reads them).
  bool traceRead() const { return traceRead_; }
  // How long reading goes on before its progress dialog appears (session_reading.h).
  void setReadingDialogDelayMs(int delayMs) { readingDialogDelayMs_ = delayMs; }

  // What the opened session shows.
  const RubricResult& rubricResult() const { return rubric_; }
  QString scoreText() const;
  int forcePointCount() const;  // points of the force curve (downsampled: peaks kept)
  // Points of the left hand's force curve: 0 for a one-handed session.
  int leftForcePointCount() const;
  int eventCount() const;
  QStringList eventLines() const;  // as listed: time, kind, detail
  QString gradesText() const;      // the grades saved so far, oldest first

  // The grade form (graded by the instructor who logged in); saveGrade stores it (with the
  // rubric's score) and shows it under the earlier ones. False, saying why, for a trainee, without
  // an instructor or a grade, or when the database refuses.
  void setGradeForm(const QString& grade, const QString& comment);
  bool saveGrade();

  // The opened session as CSV files in `folder` (session-N-frames.csv, -events.csv,
  // -metrics.csv, and -left-frames.csv for a two-handed session: docs/session-storage.md), and as a
  // printable PDF report (its summary, metrics against the rubric, force plot, events and grades).
  // False, saying why in problem(), when a file cannot be written; nothing is left half-written
  // under the final name.
  bool exportCsv(const QString& folder);
  bool exportPdf(const QString& file);
  // The opened session played back in a viewport (its own window, session_replay_window.h);
  // null when no session is open.
  SessionReplayWindow* openReplay();

 private:
  struct OpenedStore {
    std::unique_ptr<SessionStore> store;
    QString problem;  // why there is none
  };
  static OpenedStore openFile(const QString& databaseFile);
  SessionReviewWindow(OpenedStore opened, const QString& source, const QString& databaseFile,
                      const std::optional<QString>& trainee,
                      const std::optional<Instructor>& grader, QWidget* parent);
  void showSessions();
  void setProblem(const QString& problem);
  void showOpenedSession();

  std::unique_ptr<SessionStore> store_;
  QString problem_;
  std::vector<SessionSummary> sessions_;
  std::vector<std::optional<double>> scores_;  // per session of sessions_
  QString filter_;
  std::optional<QString> trainee_;
  std::optional<Instructor> grader_;
  std::optional<std::int64_t> opened_;
  bool traceRead_ = false;
  int readingDialogDelayMs_ = kSessionReadingDialogDelayMs;
  std::vector<RubricCriterion> openedRubric_;
  RubricResult rubric_;

  QLabel* problemLabel_ = nullptr;
  QLineEdit* filterEdit_ = nullptr;
  QTableWidget* sessionTable_ = nullptr;
  QLabel* scoreLabel_ = nullptr;
  QTableWidget* metricTable_ = nullptr;
  QChartView* forceChart_ = nullptr;
  QLineSeries* forceSeries_ = nullptr;
  QLineSeries* leftForceSeries_ = nullptr;  // shown for a two-handed session
  QScatterSeries* eventSeries_ = nullptr;
  QListWidget* eventList_ = nullptr;
  QLineEdit* instructorEdit_ = nullptr;
  QLineEdit* gradeEdit_ = nullptr;
  QPlainTextEdit* commentEdit_ = nullptr;
  QPushButton* saveButton_ = nullptr;
  QPushButton* csvButton_ = nullptr;
  QPushButton* pdfButton_ = nullptr;
  QPushButton* replayButton_ = nullptr;
  QString databaseFile_;  // empty: the store is not a file (replays read store_)
  QPointer<SessionReplayWindow> replayWindow_;
  QLabel* gradesLabel_ = nullptr;
};

}  // namespace liversim
