#include "session_replay_window.h"

#include "force_curve.h"
#include "render/liver_scene.h"
#include "session_reading.h"
#include "storage_messages.h"
#include "vtk_viewport.h"

#include "liversim/scenario/scenario.h"
#include "liversim/storage/sqlite_session_store.h"

#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>
#include <QChart>
#include <QChartView>
#include <QCheckBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineSeries>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QStyle>
#include <QVBoxLayout>
#include <QValueAxis>

#include <algorithm>
#include <cmath>

namespace liversim {

namespace {

// A frame's replay work at most, so that the window stays responsive while seeking.
constexpr int kTickBudgetMs = 25;
constexpr int kCyclesPerCall = 4;

}  // namespace

SessionReplayWindow::SessionReplayWindow(const QString& databaseFile, std::int64_t session,
                                         QWidget* parent)
    : SessionReplayWindow(nullptr, databaseFile, session, parent) {}

SessionReplayWindow::SessionReplayWindow(SessionStore& store, std::int64_t session, QWidget* parent)
    : SessionReplayWindow(&store, QString(), session, parent) {}

SessionReplayWindow::SessionReplayWindow(SessionStore* openStore, const QString& databaseFile,
                                         std::int64_t session, QWidget* parent)
    : QWidget(parent, Qt::Window), session_(session) {
  setObjectName("sessionReplay");
  setWindowTitle(tr("Replay of session %1").arg(session));

  viewport_ = new VtkViewport(this);
  viewport_->setObjectName("replayViewport");
  viewport_->setMinimumSize(480, 360);
  playButton_ = new QPushButton(this);
  playButton_->setObjectName("replayPlay");
  connect(playButton_, &QPushButton::clicked, this, [this] { playing_ ? pause() : play(); });
  slider_ = new QSlider(Qt::Horizontal, this);
  slider_->setObjectName("replaySeek");
  // Any change the user makes (a drag, a click on the groove, the keys) seeks; the replay's own
  // updates of the slider are made with its signals blocked.
  connect(slider_, &QSlider::valueChanged, this, [this](int ms) { seek(ms / 1000.0); });
  timeLabel_ = new QLabel(this);
  timeLabel_->setObjectName("replayTime");
  seeThrough_ = new QCheckBox(tr("See-through"), this);
  seeThrough_->setObjectName("replaySeeThrough");
  seeThrough_->setToolTip(
      tr("Show the liver semi-transparent, with the scenario's lesions inside"));
  connect(seeThrough_, &QCheckBox::toggled, this, [this](bool on) {
    if (!scene_) return;  // finishBuilding applies it
    scene_->set_opacity(on ? kSeeThroughOpacity : 1.0);
    viewport_->scheduleRender();
  });
  statusLabel_ = new QLabel(this);
  statusLabel_->setObjectName("replayStatus");
  statusLabel_->setWordWrap(true);

  recordedForce_ = new QLineSeries();
  recordedForce_->setName(tr("Recorded force on the tissue (N)"));
  replayedForce_ = new QLineSeries();
  replayedForce_->setName(tr("Replayed force on the tool (N)"));
  recordedLeftForce_ = new QLineSeries();
  recordedLeftForce_->setName(tr("Left hand, recorded (N)"));
  replayedLeftForce_ = new QLineSeries();
  replayedLeftForce_->setName(tr("Left hand, replayed (N)"));
  cursor_ = new QLineSeries();
  cursor_->setName(tr("Replayed time"));
  QChart* chart = force_chart(
      {recordedForce_, replayedForce_, recordedLeftForce_, replayedLeftForce_, cursor_});
  recordedLeftForce_->setVisible(false);
  replayedLeftForce_->setVisible(false);
  chart_ = new QChartView(chart, this);
  chart_->setObjectName("replayForceChart");
  chart_->setRenderHint(QPainter::Antialiasing);
  chart_->setMinimumHeight(200);

  auto* controls = new QHBoxLayout();
  controls->addWidget(playButton_);
  controls->addWidget(slider_, 1);
  controls->addWidget(timeLabel_);
  controls->addWidget(seeThrough_);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(viewport_, 3);
  layout->addLayout(controls);
  layout->addWidget(statusLabel_);
  layout->addWidget(chart_, 1);
  resize(900, 900);

  // What was recorded, read at once; the scene is built on a worker (meshing, the model).
  std::optional<ReplaySetup> setup;
  std::vector<SimulationInput> inputs;
  std::string scenario_text;
  try {
    std::unique_ptr<SqliteSessionStore> file;
    if (openStore == nullptr)
      file = std::make_unique<SqliteSessionStore>(std::filesystem::path(databaseFile.toStdString()),
                                                  SqliteSessionStore::Access::read_only);
    SessionStore& store = openStore != nullptr ? *openStore : *file;
    std::optional<double> scale;
    std::optional<LeftHandDevice> left_hand;
    for (const SessionSummary& summary : store.sessions())
      if (summary.id == session) {
        if (summary.mapping) scale = summary.mapping->scale;
        left_hand = summary.left_hand;
      }
    const std::optional<std::vector<ServoFrame>> read = readSessionFrames(store, session, parent);
    if (!read) throw ReadingCancelled();
    std::optional<std::vector<ServoFrame>> left_read;
    if (left_hand) {
      left_read =
          readSessionFrames(store, session, parent, kSessionReadingDialogDelayMs, Hand::left);
      if (!left_read) throw ReadingCancelled();
    }
    const std::vector<ServoFrame>& frames = *read;
    setup = store.replay_setup(session);
    inputs = store.inputs(session);
    scenario_text = store.scenario_text(session);
    // A session of free practice has no scenario, and so no lesions.
    if (const ScenarioReading reading = read_scenario(scenario_text); reading.scenario)
      lesions_ = visible_lesions(*reading.scenario);
    // A change of the model ends the session's input log: the replay stops there.
    for (const SessionEvent& event : store.events(session)) {
      const bool integrator = event.kind == SessionEventKind::integrator_changed;
      const bool gravity = event.kind == SessionEventKind::gravity_changed;
      if (!limitNote_.isEmpty() ||
          !(integrator || gravity || event.kind == SessionEventKind::material_changed))
        continue;
      const double at_s = event.time_s - (frames.empty() ? 0.0 : frames.front().time_s);
      limitNote_ = (integrator ? tr("The replay ends at %1 s, where the integrator was changed "
                                    "(to %2): what followed was not logged for replay.")
                    : gravity  ? tr("The replay ends at %1 s, where gravity was switched (to "
                                     "%2): what followed was not logged for replay.")
                               : tr("The replay ends at %1 s, where the tissue was changed (to "
                                     "%2): what followed was not logged for replay."))
                       .arg(at_s, 0, 'f', 2)
                       .arg(QString::fromStdString(event.detail));
    }
    t0_s_ = frames.empty() ? 0.0 : frames.front().time_s;
    const ForceCurve curve = force_curve(frames, scale ? 1.0 / *scale : 1.0, t0_s_);
    recordedForce_->replace(curve.points);
    largestForceN_ = std::max(curve.largest_n, 0.1);
    if (left_read) {
      twoHands_ = true;
      recordedForce_->setName(tr("Right hand, recorded (N)"));
      replayedForce_->setName(tr("Right hand, replayed (N)"));
      const ForceCurve left_curve = force_curve(*left_read, 1.0 / left_hand->mapping.scale, t0_s_);
      recordedLeftForce_->replace(left_curve.points);
      largestForceN_ = std::max(largestForceN_, left_curve.largest_n);
      recordedLeftForce_->setVisible(true);
      replayedLeftForce_->setVisible(true);
    }
  } catch (const StorageError& e) {
    problem_ = storageProblemText(tr("Session %1 cannot be read: %2").arg(session), e);
  } catch (const ReadingCancelled&) {
    problem_ = tr("Session %1 is not replayed: reading it was cancelled. Open the replay again "
                  "to read it.")
                   .arg(session);
  }
  if (problem_.isEmpty() && !setup)
    problem_ = tr("Session %1 was recorded without its simulation input (by a version before "
                  "replays, or as a replay itself): it cannot be replayed in the viewport.")
                   .arg(session);
  if (problem_.isEmpty() && inputs.empty())
    problem_ = tr("Session %1 has no simulation input stored (it ended before its first cycle "
                  "was saved).")
                   .arg(session);
  if (problem_.isEmpty()) {
    statusLabel_->setText(tr("Building the session's scene…"));
    builder_.start([this, setup = *setup, inputs = std::move(inputs),
                    scenario_text = std::move(scenario_text)]() mutable {
      std::shared_ptr<SessionReplay> replay;
      QString error;
      try {
        replay = std::make_shared<SessionReplay>(replay_scene(setup, scenario_text),
                                                 std::move(inputs), setup.loop_step_s);
      } catch (const std::exception& e) {
        error = QString::fromUtf8(e.what());
      }
      // Dropped if the window is gone (the destructor joins this thread first).
      QMetaObject::invokeMethod(
          this, [this, replay, error] { finishBuilding(replay, error); }, Qt::QueuedConnection);
    });
  }
  connect(&timer_, &QTimer::timeout, this, &SessionReplayWindow::tick);
  updateControls();
}

SessionReplayWindow::~SessionReplayWindow() {
  timer_.stop();
  if (builder_.started()) builder_.wait();
  if (scene_) viewport_->renderWindow()->RemoveRenderer(scene_->renderer());
}

void SessionReplayWindow::finishBuilding(std::shared_ptr<SessionReplay> replay,
                                         const QString& error) {
  builder_.wait();
  if (!replay) {
    problem_ = tr("Session %1 cannot be replayed: %2").arg(session_).arg(error);
    updateControls();
    return;
  }
  replay_ = std::move(replay);  // the worker is done with it
  scene_ = std::make_unique<LiverScene>(replay_->scene().mesh, replay_->scene().visual);
  scene_->set_tool_models(load_tool_models());
  if (!lesions_.empty()) scene_->show_lesions(lesions_);
  scene_->set_opacity(seeThrough_->isChecked() ? kSeeThroughOpacity : 1.0);
  viewport_->renderWindow()->AddRenderer(scene_->renderer());
  scene_->reset_camera(viewport_->height() > 0
                           ? static_cast<double>(viewport_->width()) / viewport_->height()
                           : 1.0);
  shownModel_ = replay_->simulation().snapshot().model;
  auto axes = chart_->chart()->axes();
  for (QAbstractAxis* axis : axes) {
    auto* value_axis = static_cast<QValueAxis*>(axis);
    if (axis->alignment() == Qt::AlignBottom)
      value_axis->setRange(0.0, std::max(durationS(), 1e-3));
    else
      value_axis->setRange(0.0, largestForceN_ * 1.1);
  }
  targetS_ = positionS();
  wall_.start();
  timer_.start(16);
  showSnapshot();
  updateControls();
  emit readyChanged(true);
}

double SessionReplayWindow::durationS() const {
  return replay_ ? replay_->end_s() - t0_s_ : 0.0;
}

double SessionReplayWindow::positionS() const {
  return replay_ ? replay_->time_s() - t0_s_ : 0.0;
}

bool SessionReplayWindow::seeking() const {
  return replay_ && seekPending_;
}

void SessionReplayWindow::setSeeThrough(bool on) {
  seeThrough_->setChecked(on);  // its toggled signal shows it
}

bool SessionReplayWindow::seeThrough() const {
  return seeThrough_->isChecked();
}

void SessionReplayWindow::play() {
  if (!replay_) return;
  if (positionS() >= durationS()) seek(0.0);  // played to the end: from the start again
  playing_ = true;
  wall_.restart();
  updateControls();
}

void SessionReplayWindow::pause() {
  playing_ = false;
  updateControls();
}

void SessionReplayWindow::seek(double seconds) {
  if (!replay_) return;
  targetS_ = std::clamp(seconds, 0.0, durationS());
  seekPending_ = true;
}

void SessionReplayWindow::tick() {
  if (!replay_) return;
  const double elapsed_s = wall_.restart() / 1000.0;
  if (playing_ && !seekPending_) targetS_ = std::min(targetS_ + elapsed_s, durationS());
  const std::size_t taken_before = replay_->taken();
  QElapsedTimer budget;
  budget.start();
  bool arrived = false;
  // The end is the last cycle's own time: t0 + (end − t0) can fall an ulp short of it, and the
  // last cycle would then not be taken (the replay stopped a cycle short, now and then).
  const double target_s = targetS_ >= durationS() ? replay_->end_s() : t0_s_ + targetS_;
  do {
    arrived = replay_->advance_to(target_s, kCyclesPerCall);
  } while (!arrived && budget.elapsed() < kTickBudgetMs);
  if (arrived) seekPending_ = false;
  // Playing slower than the session ran, the replay shows every cycle rather than skipping on.
  if (playing_ && !arrived && !seekPending_) targetS_ = positionS();
  if (playing_ && arrived && targetS_ >= durationS()) playing_ = false;
  if (replay_->taken() != taken_before) showSnapshot();  // paused: nothing to draw again
  updateControls();
}

void SessionReplayWindow::showSnapshot() {
  RealtimeSimulation& simulation = replay_->simulation();
  simulation.update_snapshot();
  const SimulationSnapshot& snapshot = simulation.snapshot();
  if (snapshot.model != shownModel_) {
    // A cut replaced the model, or a seek back started again from the uncut one.
    if (snapshot.topology_version == 0)
      scene_->show_uncut(snapshot.position_m);
    else
      scene_->show_cut_model(*snapshot.model, snapshot.position_m);
    shownModel_ = snapshot.model;
  }
  scene_->update_positions(snapshot.position_m);
  for (Hand hand : kHands) scene_->show_tool(hand, snapshot.hand(hand).tool);
  const double t = positionS();
  cursor_->replace({QPointF(t, 0.0), QPointF(t, largestForceN_ * 1.1)});
  // The replayed force, one point a frame; a seek back starts the curve again.
  const auto follow = [t](QLineSeries* series, double force_n) {
    if (series->count() > 0 && series->at(series->count() - 1).x() > t) series->clear();
    if (series->count() == 0 || series->at(series->count() - 1).x() < t) series->append(t, force_n);
  };
  follow(replayedForce_, snapshot.hand(Hand::right).force_n.norm());
  if (twoHands_) follow(replayedLeftForce_, snapshot.hand(Hand::left).force_n.norm());
  viewport_->scheduleRender();
}

void SessionReplayWindow::updateControls() {
  const bool can_play = replay_ != nullptr;
  playButton_->setEnabled(can_play);
  slider_->setEnabled(can_play);
  playButton_->setText(playing_ ? tr("Pause") : tr("Play"));
  playButton_->setIcon(
      style()->standardIcon(playing_ ? QStyle::SP_MediaPause : QStyle::SP_MediaPlay));
  {
    const QSignalBlocker blocker(slider_);
    slider_->setRange(0, static_cast<int>(std::lround(durationS() * 1000.0)));
    if (!seekPending_) slider_->setValue(static_cast<int>(std::lround(positionS() * 1000.0)));
  }
  timeLabel_->setText(tr("%1 / %2 s").arg(positionS(), 0, 'f', 2).arg(durationS(), 0, 'f', 2));
  statusLabel_->setText(statusText());
}

QString SessionReplayWindow::statusText() const {
  if (!problem_.isEmpty()) return problem_;
  if (!replay_) return tr("Building the session's scene…");
  QString text = seekPending_ ? tr("Seeking to %1 s…").arg(targetS_, 0, 'f', 2)
                 : playing_   ? tr("Playing.")
                              : tr("Paused.");
  if (!limitNote_.isEmpty()) text += ' ' + limitNote_;
  return text;
}

int SessionReplayWindow::recordedForcePointCount() const {
  return static_cast<int>(recordedForce_->count());
}

int SessionReplayWindow::replayedForcePointCount() const {
  return static_cast<int>(replayedForce_->count());
}

int SessionReplayWindow::recordedLeftForcePointCount() const {
  return static_cast<int>(recordedLeftForce_->count());
}

int SessionReplayWindow::replayedLeftForcePointCount() const {
  return static_cast<int>(replayedLeftForce_->count());
}

}  // namespace liversim
