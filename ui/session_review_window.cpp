#include "session_review_window.h"

#include "force_curve.h"
#include "session_reading.h"
#include "session_replay_window.h"
#include "storage_messages.h"

#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_export.h"
#include "liversim/storage/sqlite_session_store.h"

#include <QBuffer>
#include <QChart>
#include <QChartView>
#include <QDateTime>
#include <QDir>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QListWidget>
#include <QPdfWriter>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSaveFile>
#include <QScatterSeries>
#include <QSignalBlocker>
#include <QSplitter>
#include <QTableWidget>
#include <QTextDocument>
#include <QVBoxLayout>
#include <QValueAxis>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace liversim {

namespace {

std::vector<RubricCriterion> rubric_of(SessionStore& store, std::int64_t session) {
  const ScenarioReading reading = read_scenario(store.scenario_text(session));
  return reading.scenario ? reading.scenario->rubric : std::vector<RubricCriterion>{};
}

QString number(double value) {
  return QString::number(value, 'g', 4);
}

QTableWidgetItem* cell(const QString& text) {
  auto* item = new QTableWidgetItem(text);
  item->setFlags(item->flags() & ~Qt::ItemIsEditable);
  return item;
}

}  // namespace

SessionReviewWindow::OpenedStore SessionReviewWindow::openFile(const QString& databaseFile) {
  try {
    return {std::make_unique<SqliteSessionStore>(std::filesystem::path(databaseFile.toStdString())),
            {}};
  } catch (const StorageError& e) {
    return {nullptr, storageProblemText(tr("The sessions cannot be read: %1"), e)};
  }
}

SessionReviewWindow::SessionReviewWindow(const QString& databaseFile,
                                         const std::optional<QString>& trainee,
                                         const std::optional<Instructor>& grader, QWidget* parent)
    : SessionReviewWindow(openFile(databaseFile), databaseFile, databaseFile, trainee, grader,
                          parent) {}

SessionReviewWindow::SessionReviewWindow(std::unique_ptr<SessionStore> store, const QString& source,
                                         const std::optional<Instructor>& grader, QWidget* parent)
    : SessionReviewWindow(OpenedStore{std::move(store), {}}, source, QString(), std::nullopt,
                          grader, parent) {}

SessionReviewWindow::SessionReviewWindow(OpenedStore opened, const QString& source,
                                         const QString& databaseFile,
                                         const std::optional<QString>& trainee,
                                         const std::optional<Instructor>& grader, QWidget* parent)
    : QWidget(parent, Qt::Window),
      store_(std::move(opened.store)),
      problem_(opened.problem),
      trainee_(trainee),
      grader_(trainee ? std::nullopt : grader),
      databaseFile_(databaseFile) {
  setObjectName(trainee ? "traineeHistoryWindow" : "sessionReviewWindow");
  setWindowTitle(trainee ? tr("Sessions of %1").arg(*trainee) : tr("Sessions — %1").arg(source));
  problemLabel_ = new QLabel(this);
  problemLabel_->setObjectName("reviewProblem");
  problemLabel_->setWordWrap(true);
  problemLabel_->setStyleSheet("color: #b00020");
  filterEdit_ = new QLineEdit(this);
  filterEdit_->setObjectName("sessionFilter");
  filterEdit_->setPlaceholderText(tr("Filter by trainee or scenario"));
  connect(filterEdit_, &QLineEdit::textChanged, this, &SessionReviewWindow::setFilter);

  sessionTable_ = new QTableWidget(0, 6, this);
  sessionTable_->setObjectName("sessionTable");
  sessionTable_->setHorizontalHeaderLabels(
      {tr("Session"), tr("Trainee"), tr("Scenario"), tr("Started"), tr("Status"), tr("Score")});
  sessionTable_->setSelectionBehavior(QAbstractItemView::SelectRows);
  sessionTable_->setSelectionMode(QAbstractItemView::SingleSelection);
  sessionTable_->setSortingEnabled(true);
  sessionTable_->horizontalHeader()->setStretchLastSection(true);
  connect(sessionTable_, &QTableWidget::itemSelectionChanged, this, [this] {
    const auto rows = sessionTable_->selectionModel()->selectedRows();
    if (!rows.isEmpty())
      openSession(sessionTable_->item(rows.front().row(), 0)->data(Qt::UserRole).toLongLong());
  });

  scoreLabel_ = new QLabel(tr("Open a session to see it against its rubric."), this);
  scoreLabel_->setObjectName("sessionScore");
  metricTable_ = new QTableWidget(0, 4, this);
  metricTable_->setObjectName("metricTable");
  metricTable_->setHorizontalHeaderLabels(
      {tr("Metric"), tr("Value"), tr("Criterion (weight)"), tr("Passed")});
  metricTable_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  metricTable_->verticalHeader()->hide();

  forceSeries_ = new QLineSeries();
  forceSeries_->setName(tr("Force on the device (N)"));
  leftForceSeries_ = new QLineSeries();
  leftForceSeries_->setName(tr("Left hand (N)"));
  eventSeries_ = new QScatterSeries();
  eventSeries_->setName(tr("Events"));
  eventSeries_->setMarkerSize(8.0);
  QChart* chart = force_chart({forceSeries_, leftForceSeries_, eventSeries_});
  leftForceSeries_->setVisible(false);
  forceChart_ = new QChartView(chart, this);
  forceChart_->setObjectName("forceChart");
  forceChart_->setRenderHint(QPainter::Antialiasing);
  forceChart_->setMinimumHeight(220);
  eventList_ = new QListWidget(this);
  eventList_->setObjectName("eventList");

  instructorEdit_ = new QLineEdit(this);
  instructorEdit_->setObjectName("gradeInstructor");
  instructorEdit_->setReadOnly(true);  // who logged in grades
  instructorEdit_->setText(grader_ ? QString::fromStdString(grader_->name())
                                   : tr("(log in as an instructor to grade)"));
  gradeEdit_ = new QLineEdit(this);
  gradeEdit_->setObjectName("gradeText");
  gradeEdit_->setPlaceholderText(tr("e.g. pass, fail, B+"));
  commentEdit_ = new QPlainTextEdit(this);
  commentEdit_->setObjectName("gradeComment");
  commentEdit_->setMaximumHeight(80);
  saveButton_ = new QPushButton(tr("Save Grade"), this);
  saveButton_->setObjectName("saveGrade");
  connect(saveButton_, &QPushButton::clicked, this, &SessionReviewWindow::saveGrade);
  gradesLabel_ = new QLabel(this);
  gradesLabel_->setObjectName("savedGrades");
  gradesLabel_->setWordWrap(true);
  gradesLabel_->setTextFormat(Qt::PlainText);
  csvButton_ = new QPushButton(tr("Export CSV…"), this);
  csvButton_->setObjectName("exportCsv");
  connect(csvButton_, &QPushButton::clicked, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, tr("Export the session to"));
    if (!folder.isEmpty()) exportCsv(folder);
  });
  pdfButton_ = new QPushButton(tr("Save Report as PDF…"), this);
  pdfButton_->setObjectName("exportPdf");
  connect(pdfButton_, &QPushButton::clicked, this, [this] {
    const QString file = QFileDialog::getSaveFileName(this, tr("Save the report"), QString(),
                                                      tr("PDF documents (*.pdf)"));
    if (!file.isEmpty()) exportPdf(file);
  });
  auto* form = new QFormLayout();
  form->addRow(tr("Instructor:"), instructorEdit_);
  form->addRow(tr("Grade:"), gradeEdit_);
  form->addRow(tr("Comment:"), commentEdit_);
  form->addRow(QString(), saveButton_);
  form->addRow(tr("Saved grades:"), gradesLabel_);
  replayButton_ = new QPushButton(tr("Replay in the Viewport…"), this);
  replayButton_->setObjectName("replaySession");
  replayButton_->setToolTip(
      tr("Play the session back in a viewport from its recorded input, "
         "with its force plotted in step"));
  connect(replayButton_, &QPushButton::clicked, this, [this] { openReplay(); });
  auto* exports = new QHBoxLayout();
  exports->addWidget(replayButton_);
  exports->addWidget(csvButton_);
  exports->addWidget(pdfButton_);
  form->addRow(tr("Export:"), exports);
  if (trainee) {  // a trainee sees the grades, and gives none
    for (QWidget* field :
         {static_cast<QWidget*>(instructorEdit_), static_cast<QWidget*>(gradeEdit_),
          static_cast<QWidget*>(commentEdit_), static_cast<QWidget*>(saveButton_)})
      form->setRowVisible(field, false);
  }

  auto* top = new QWidget(this);
  auto* top_layout = new QVBoxLayout(top);
  top_layout->addWidget(problemLabel_);
  top_layout->addWidget(filterEdit_);
  top_layout->addWidget(sessionTable_);
  auto* detail = new QWidget(this);
  auto* detail_layout = new QHBoxLayout(detail);
  auto* left = new QVBoxLayout();
  left->addWidget(scoreLabel_);
  left->addWidget(metricTable_);
  left->addLayout(form);
  auto* right = new QVBoxLayout();
  right->addWidget(forceChart_, 3);
  right->addWidget(eventList_, 1);
  detail_layout->addLayout(left, 1);
  detail_layout->addLayout(right, 2);
  auto* splitter = new QSplitter(Qt::Vertical, this);
  splitter->addWidget(top);
  splitter->addWidget(detail);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(splitter);
  resize(1100, 800);

  refresh();
}

SessionReviewWindow::~SessionReviewWindow() = default;

void SessionReviewWindow::refresh() {
  sessions_.clear();
  scores_.clear();
  if (store_) {
    try {
      sessions_ =
          trainee_ ? store_->sessions_of_trainee(trainee_->toStdString()) : store_->sessions();
      for (const SessionSummary& s : sessions_)
        scores_.push_back(
            grade_against_rubric(rubric_of(*store_, s.id), store_->metrics(s.id)).score_percent);
    } catch (const StorageError& e) {
      problem_ = storageProblemText(tr("The sessions cannot be read: %1"), e);
      sessions_.clear();
      scores_.clear();
    }
  }
  setProblem(problem_);
  showSessions();
}

void SessionReviewWindow::setProblem(const QString& problem) {
  problem_ = problem;
  problemLabel_->setText(problem_);
  problemLabel_->setVisible(!problem_.isEmpty());
}

void SessionReviewWindow::setFilter(const QString& text) {
  filter_ = text;
  if (filterEdit_->text() != text) filterEdit_->setText(text);
  showSessions();
}

void SessionReviewWindow::showSessions() {
  sessionTable_->setSortingEnabled(false);
  sessionTable_->setRowCount(0);
  for (std::size_t i = 0; i < sessions_.size(); ++i) {
    const SessionSummary& s = sessions_[i];
    const QString trainee = QString::fromStdString(s.trainee);
    const QString scenario = QString::fromStdString(s.scenario_title);
    if (!filter_.isEmpty() && !trainee.contains(filter_, Qt::CaseInsensitive) &&
        !scenario.contains(filter_, Qt::CaseInsensitive))
      continue;
    const int row = sessionTable_->rowCount();
    sessionTable_->insertRow(row);
    auto* id = cell(QString::number(s.id));
    id->setData(Qt::UserRole, static_cast<qlonglong>(s.id));
    sessionTable_->setItem(row, 0, id);
    sessionTable_->setItem(row, 1, cell(trainee));
    sessionTable_->setItem(row, 2, cell(scenario));
    sessionTable_->setItem(
        row, 3,
        cell(QDateTime::fromMSecsSinceEpoch(s.started_unix_ms).toString("yyyy-MM-dd hh:mm")));
    sessionTable_->setItem(
        row, 4,
        cell(QString::fromUtf8(session_status_name(s.status).data(),
                               static_cast<int>(session_status_name(s.status).size()))));
    sessionTable_->setItem(row, 5,
                           cell(scores_[i] ? QString::number(*scores_[i], 'f', 0) + " %" : "–"));
  }
  sessionTable_->setSortingEnabled(true);
}

int SessionReviewWindow::listedSessionCount() const {
  return sessionTable_->rowCount();
}

bool SessionReviewWindow::openSession(std::int64_t session) {
  for (int row = 0; row < sessionTable_->rowCount(); ++row)
    if (sessionTable_->item(row, 0)->data(Qt::UserRole).toLongLong() == session) {
      if (opened_ == session) {
        if (!traceRead_) showOpenedSession();  // its reading was cancelled: read it now
        return true;
      }
      opened_ = session;
      {
        const QSignalBlocker opening(sessionTable_);  // the selection opens nothing more
        sessionTable_->selectRow(row);
      }
      showOpenedSession();
      return true;
    }
  return false;
}

void SessionReviewWindow::showOpenedSession() {
  forceSeries_->clear();
  leftForceSeries_->clear();
  leftForceSeries_->setVisible(false);
  eventSeries_->clear();
  eventList_->clear();
  metricTable_->setRowCount(0);
  rubric_ = {};
  traceRead_ = false;
  if (!opened_ || !store_) return;
  try {
    const std::vector<MetricValue> metrics = store_->metrics(*opened_);
    openedRubric_ = rubric_of(*store_, *opened_);
    rubric_ = grade_against_rubric(openedRubric_, metrics);
    scoreLabel_->setText(scoreText());
    // The rubric's criteria first (passed or not), then the other metrics measured.
    for (const CriterionResult& r : rubric_.criteria) {
      const int row = metricTable_->rowCount();
      metricTable_->insertRow(row);
      const MetricInfo* info = find_metric(r.criterion.metric);
      const QString unit =
          info ? QString::fromUtf8(info->unit.data(), static_cast<int>(info->unit.size()))
               : QString();
      metricTable_->setItem(row, 0, cell(QString::fromStdString(r.criterion.metric)));
      metricTable_->setItem(row, 1,
                            cell(r.value ? number(*r.value) + " " + unit : tr("not measured")));
      metricTable_->setItem(row, 2,
                            cell((r.criterion.rule == PassRule::at_most ? "≤ " : "≥ ") +
                                 number(r.criterion.threshold) + " " + unit + " (" +
                                 number(r.criterion.weight) + ")"));
      metricTable_->setItem(row, 3, cell(r.passed ? tr("yes") : tr("no")));
    }
    for (const MetricValue& m : metrics) {
      const bool graded = std::any_of(openedRubric_.begin(), openedRubric_.end(),
                                      [&](const RubricCriterion& c) { return c.metric == m.name; });
      if (graded) continue;
      const int row = metricTable_->rowCount();
      metricTable_->insertRow(row);
      metricTable_->setItem(row, 0, cell(QString::fromStdString(m.name)));
      metricTable_->setItem(row, 1, cell(number(m.value)));
      metricTable_->setItem(row, 2, cell(tr("not graded")));
      metricTable_->setItem(row, 3, cell(QString()));
    }

    // The force on the tissue (the device's over the mapping's scale; the device's own for
    // sessions recorded without their mapping), each bucket of frames as its largest force.
    std::optional<double> scale;
    std::optional<LeftHandDevice> left_hand;
    for (const SessionSummary& summary : sessions_)
      if (summary.id == *opened_) {
        if (summary.mapping) scale = summary.mapping->scale;
        left_hand = summary.left_hand;
      }
    forceSeries_->setName(left_hand ? tr("Right hand (N)")
                          : scale   ? tr("Force on the tissue (N)")
                                    : tr("Force on the device (N)"));
    const double force_factor = scale ? 1.0 / *scale : 1.0;
    std::optional<std::vector<ServoFrame>> read =
        readSessionFrames(*store_, *opened_, this, readingDialogDelayMs_);
    // A two-handed session's left hand, on the same clock and axes.
    std::optional<std::vector<ServoFrame>> left_read;
    if (read && left_hand) {
      left_read = readSessionFrames(*store_, *opened_, this, readingDialogDelayMs_, Hand::left);
      if (!left_read) read.reset();
    }
    traceRead_ = read.has_value();
    forceChart_->chart()->setTitle(read ? QString() : sessionReadingCancelledText(*opened_));
    const std::vector<ServoFrame> frames = read.value_or(std::vector<ServoFrame>{});
    const double t0 = frames.empty() ? 0.0 : frames.front().time_s;
    const ForceCurve curve = force_curve(frames, force_factor, t0);
    double largest = curve.largest_n;
    forceSeries_->replace(curve.points);
    if (left_read) {
      const ForceCurve left_curve = force_curve(*left_read, 1.0 / left_hand->mapping.scale, t0);
      largest = std::max(largest, left_curve.largest_n);
      leftForceSeries_->replace(left_curve.points);
      leftForceSeries_->setVisible(true);
    }
    // Event times are from the first frame: without the frames they are not listed either.
    const std::vector<SessionEvent> events =
        read ? store_->events(*opened_) : std::vector<SessionEvent>{};
    for (const SessionEvent& e : events) {
      const std::string_view kind = session_event_name(e.kind);
      // A mark's detail is kept at full precision; shown to the tenth of a millimetre.
      QString detail = QString::fromStdString(e.detail);
      const std::vector<Eigen::Vector3d> mark = lesion_marks(std::span(&e, 1));
      if (!mark.empty())
        detail = tr("at (%1, %2, %3) mm")
                     .arg(mark[0].x() * 1e3, 0, 'f', 1)
                     .arg(mark[0].y() * 1e3, 0, 'f', 1)
                     .arg(mark[0].z() * 1e3, 0, 'f', 1);
      // In a two-handed session, the left hand's events say so.
      const QString what = QString::fromUtf8(kind.data(), static_cast<int>(kind.size())) +
                           (left_hand && e.hand == Hand::left ? tr(" (left hand)") : QString());
      eventList_->addItem(
          QString("%1 s  %2  %3").arg(e.time_s - t0, 0, 'f', 3).arg(what).arg(detail));
      eventSeries_->append(e.time_s - t0, 0.0);
    }
    const double end_s = frames.empty() ? 1.0 : std::max(frames.back().time_s - t0, 1e-3);
    auto axes = forceChart_->chart()->axes();
    for (QAbstractAxis* axis : axes) {
      auto* value_axis = static_cast<QValueAxis*>(axis);
      if (axis->alignment() == Qt::AlignBottom)
        value_axis->setRange(0.0, end_s);
      else
        value_axis->setRange(0.0, std::max(largest * 1.1, 0.1));
    }
    std::vector<SessionGrade> grades = store_->grades(*opened_);
    QStringList lines;
    for (const SessionGrade& g : grades)
      lines
          << tr("%1, %2: %3%4 — %5")
                 .arg(QString::fromStdString(g.instructor),
                      QDateTime::fromMSecsSinceEpoch(g.graded_unix_ms).toString("yyyy-MM-dd hh:mm"),
                      QString::fromStdString(g.grade),
                      g.score_percent ? tr(" (score %1 %)").arg(*g.score_percent, 0, 'f', 0)
                                      : QString(),
                      QString::fromStdString(g.comment));
    gradesLabel_->setText(lines.isEmpty() ? tr("none yet") : lines.join('\n'));
  } catch (const StorageError& e) {
    scoreLabel_->setText(storageProblemText(tr("Session %1 cannot be read: %2").arg(*opened_), e));
  }
}

SessionReplayWindow* SessionReviewWindow::openReplay() {
  if (!opened_) return nullptr;
  if (replayWindow_) replayWindow_->close();  // one replay at a time: each holds a whole model
  replayWindow_ = databaseFile_.isEmpty() ? new SessionReplayWindow(*store_, *opened_, this)
                                          : new SessionReplayWindow(databaseFile_, *opened_, this);
  replayWindow_->setAttribute(Qt::WA_DeleteOnClose);
  replayWindow_->show();
  return replayWindow_;
}

QString SessionReviewWindow::scoreText() const {
  if (!opened_) return {};
  if (!rubric_.score_percent) return tr("Session %1: its scenario has no rubric.").arg(*opened_);
  int passed = 0;
  for (const CriterionResult& r : rubric_.criteria) passed += r.passed ? 1 : 0;
  return tr("Session %1: score %2 % (%3 of %4 criteria passed)")
      .arg(*opened_)
      .arg(*rubric_.score_percent, 0, 'f', 0)
      .arg(passed)
      .arg(rubric_.criteria.size());
}

int SessionReviewWindow::forcePointCount() const {
  return static_cast<int>(forceSeries_->count());
}

int SessionReviewWindow::leftForcePointCount() const {
  return static_cast<int>(leftForceSeries_->count());
}

int SessionReviewWindow::eventCount() const {
  return eventList_->count();
}

QStringList SessionReviewWindow::eventLines() const {
  QStringList lines;
  for (int i = 0; i < eventList_->count(); ++i) lines << eventList_->item(i)->text();
  return lines;
}

QString SessionReviewWindow::gradesText() const {
  return gradesLabel_->text();
}

void SessionReviewWindow::setGradeForm(const QString& grade, const QString& comment) {
  gradeEdit_->setText(grade);
  commentEdit_->setPlainText(comment);
}

bool SessionReviewWindow::saveGrade() {
  if (!opened_ || !store_) return false;
  if (trainee_) {
    gradesLabel_->setText(tr("Trainees cannot grade sessions."));
    return false;
  }
  if (!grader_) {
    gradesLabel_->setText(
        tr("Log in as an instructor to grade sessions (Settings ▸ Instructor "
           "Mode)."));
    return false;
  }
  const QString grade = gradeEdit_->text().trimmed();
  if (grade.isEmpty()) {
    gradesLabel_->setText(tr("Enter the grade first (e.g. pass, fail, B+)."));
    return false;
  }
  SessionGrade entry;
  entry.instructor = grader_->name();
  entry.graded_unix_ms = QDateTime::currentMSecsSinceEpoch();
  entry.score_percent = rubric_.score_percent;
  entry.grade = grade.toStdString();
  entry.comment = commentEdit_->toPlainText().toStdString();
  try {
    store_->store_grade(*grader_, *opened_, entry);
  } catch (const AccessDenied& e) {
    gradesLabel_->setText(tr("The grade was not saved: %1").arg(QString::fromUtf8(e.what())));
    return false;
  } catch (const StorageError& e) {
    gradesLabel_->setText(storageProblemText(tr("The grade was not saved: %1"), e));
    return false;
  }
  gradeEdit_->clear();
  commentEdit_->clear();
  showOpenedSession();
  return true;
}

namespace {

// Writes through a temporary file committed over `file` only when everything was written.
bool write_whole(const QString& file, const std::string& bytes, QString& problem) {
  QSaveFile out(file);
  if (!out.open(QIODevice::WriteOnly) ||
      out.write(bytes.data(), static_cast<qint64>(bytes.size())) !=
          static_cast<qint64>(bytes.size()) ||
      !out.commit()) {
    problem = QObject::tr("%1 could not be written: %2").arg(file, out.errorString());
    return false;
  }
  return true;
}

}  // namespace

bool SessionReviewWindow::exportCsv(const QString& folder) {
  if (!opened_ || !store_) return false;
  const QString base = QDir(folder).filePath(QString("session-%1-").arg(*opened_));
  QString problem;
  try {
    std::ostringstream frames, events, metrics;
    const std::optional<std::vector<ServoFrame>> read =
        readSessionFrames(*store_, *opened_, this, readingDialogDelayMs_);
    if (!read) {
      setProblem(tr("Nothing was exported: reading session %1 was cancelled.").arg(*opened_));
      return false;
    }
    bool two_hands = false;
    for (const SessionSummary& s : sessions_)
      if (s.id == *opened_) two_hands = s.left_hand.has_value();
    std::optional<std::vector<ServoFrame>> left_read;
    if (two_hands) {
      left_read = readSessionFrames(*store_, *opened_, this, readingDialogDelayMs_, Hand::left);
      if (!left_read) {
        setProblem(tr("Nothing was exported: reading session %1 was cancelled.").arg(*opened_));
        return false;
      }
    }
    std::ostringstream left_frames;
    write_frames_csv(*read, frames);
    if (left_read) write_frames_csv(*left_read, left_frames);
    write_events_csv(store_->events(*opened_), events);
    write_metrics_csv(store_->metrics(*opened_), rubric_, metrics);
    const bool written =
        write_whole(base + "frames.csv", frames.str(), problem) &&
        (!left_read || write_whole(base + "left-frames.csv", left_frames.str(), problem)) &&
        write_whole(base + "events.csv", events.str(), problem) &&
        write_whole(base + "metrics.csv", metrics.str(), problem);
    setProblem(written ? QString() : problem);
    return written;
  } catch (const StorageError& e) {
    setProblem(storageProblemText(tr("Session %1 cannot be read: %2").arg(*opened_), e));
    return false;
  }
}

bool SessionReviewWindow::exportPdf(const QString& file) {
  if (!opened_) return false;
  const SessionSummary* summary = nullptr;
  for (const SessionSummary& s : sessions_)
    if (s.id == *opened_) summary = &s;
  if (summary == nullptr) return false;
  auto escaped = [](const QString& text) { return text.toHtmlEscaped(); };
  QString html;
  html += "<h1>" + escaped(tr("LiverSim session %1").arg(*opened_)) + "</h1>";
  html +=
      "<p>" + escaped(tr("Trainee: %1").arg(QString::fromStdString(summary->trainee))) + "<br>" +
      escaped(tr("Scenario: %1").arg(QString::fromStdString(summary->scenario_title))) + "<br>" +
      escaped(tr("Started: %1")
                  .arg(QDateTime::fromMSecsSinceEpoch(summary->started_unix_ms)
                           .toString("yyyy-MM-dd hh:mm"))) +
      "<br><b>" + escaped(scoreText()) + "</b></p>";
  html += "<table border=1 cellpadding=3 cellspacing=0><tr>";
  for (int c = 0; c < metricTable_->columnCount(); ++c)
    html += "<th>" + escaped(metricTable_->horizontalHeaderItem(c)->text()) + "</th>";
  html += "</tr>";
  for (int r = 0; r < metricTable_->rowCount(); ++r) {
    html += "<tr>";
    for (int c = 0; c < metricTable_->columnCount(); ++c)
      html += "<td>" + escaped(metricTable_->item(r, c) ? metricTable_->item(r, c)->text() : "") +
              "</td>";
    html += "</tr>";
  }
  html += "</table>";
  html += "<h2>" + escaped(tr("Force on the device")) + "</h2><img src=\"chart:force\" width=640>";
  html += "<h2>" + escaped(tr("Events")) + "</h2><p>";
  for (int i = 0; i < eventList_->count(); ++i)
    html += escaped(eventList_->item(i)->text()) + "<br>";
  html += "</p><h2>" + escaped(tr("Grades")) + "</h2><p>" +
          escaped(gradesLabel_->text()).replace('\n', "<br>") + "</p>";

  QTextDocument document;
  const QImage chart = forceChart_->grab().toImage();
  document.addResource(QTextDocument::ImageResource, QUrl("chart:force"), chart);
  document.setHtml(html);
  QByteArray bytes;
  {
    QBuffer buffer(&bytes);
    buffer.open(QIODevice::WriteOnly);
    QPdfWriter pdf(&buffer);
    pdf.setPageSize(QPageSize(QPageSize::A4));
    pdf.setTitle(tr("LiverSim session %1").arg(*opened_));
    pdf.setCreator("LiverSim");
    document.print(&pdf);
  }
  QString problem;
  const bool written = write_whole(file, bytes.toStdString(), problem);
  setProblem(written ? QString() : problem);
  return written;
}

}  // namespace liversim
