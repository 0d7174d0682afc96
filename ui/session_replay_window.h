#pragma once
// A recorded session played back in a viewport: its scene built again and its simulation input
// replayed cycle by cycle on the session's timeline (core/session_replay.h), so the liver goes
// through the states the trainee saw, cuts included. Play, pause and seek (a seek back replays
// from the start); the session's recorded force is plotted with a cursor at the replayed time,
// and the replayed force on the tool beside it. The liver can be seen through, with the lesions
// of the session's scenario inside it.

#include "liversim/sessions/session_replay.h"
#include "liversim/sessions/session_store.h"

#include <QElapsedTimer>
#include <QString>
#include <QTimer>
#include <QWidget>

#include <cstdint>
#include <memory>
#include <vector>
#include "liversim/engine/background_job.h"

class QCheckBox;
class QChartView;
class QLabel;
class QLineSeries;
class QPushButton;
class QSlider;

namespace liversim {

class LiverScene;
class VtkViewport;
struct LesionShape;

class SessionReplayWindow : public QWidget {
  Q_OBJECT

 public:
  // Reads the session from the database file (its own connection) and builds its scene on a
  // worker; ready() when it can play. A session that cannot be replayed says why in problem().
  SessionReplayWindow(const QString& databaseFile, std::int64_t session, QWidget* parent = nullptr);
  // The same from a store already open (the training centre's server), read at once.
  SessionReplayWindow(SessionStore& store, std::int64_t session, QWidget* parent = nullptr);
  ~SessionReplayWindow() override;

 private:
  // `store` null: opens the file read-only.
  SessionReplayWindow(SessionStore* store, const QString& databaseFile, std::int64_t session,
                      QWidget* parent);

 public:
  std::int64_t session() const { return session_; }
  bool ready() const { return replay_ != nullptr; }
  QString problem() const { return problem_; }
  QString statusText() const;

  // The timeline, in seconds from the session's first frame.
  double durationS() const;
  double positionS() const;  // of the cycle last replayed
  bool playing() const { return playing_; }
  // Seeking: the replay has not yet caught up with the time asked for.
  bool seeking() const;

  void play();
  void pause();
  void seek(double seconds);

  // See-through: the liver at kSeeThroughOpacity, its scenario's visible lesions inside.
  void setSeeThrough(bool on);
  bool seeThrough() const;

  SessionReplay* replay() const { return replay_.get(); }
  VtkViewport* viewport() const { return viewport_; }
  const LiverScene* scene() const { return scene_.get(); }  // null until ready()
  int recordedForcePointCount() const;
  int replayedForcePointCount() const;
  // The left hand's curves, in a two-handed session (0 points otherwise).
  int recordedLeftForcePointCount() const;
  int replayedLeftForcePointCount() const;

 signals:
  void readyChanged(bool ready);

 private:
  void finishBuilding(std::shared_ptr<SessionReplay> replay, const QString& error);
  void tick();          // advances toward the target within a frame's budget, then shows it
  void showSnapshot();  // the replayed cycle: liver, cut, tool, cursor, force
  void updateControls();

  std::int64_t session_;
  std::shared_ptr<SessionReplay> replay_;
  QString problem_;
  QString limitNote_;     // what the replay does not cover (an integrator change)
  double t0_s_ = 0.0;     // servo time of the session's first frame
  double targetS_ = 0.0;  // where the replay is going, from t0
  bool playing_ = false;
  bool seekPending_ = false;                    // a seek the replay has not caught up with yet
  std::shared_ptr<const SimModel> shownModel_;  // the model the scene shows
  std::unique_ptr<LiverScene> scene_;
  std::vector<LesionShape> lesions_;  // the scenario's visible ones
  VtkViewport* viewport_ = nullptr;
  QCheckBox* seeThrough_ = nullptr;
  QPushButton* playButton_ = nullptr;
  QSlider* slider_ = nullptr;
  QLabel* timeLabel_ = nullptr;
  QLabel* statusLabel_ = nullptr;
  QChartView* chart_ = nullptr;
  QLineSeries* recordedForce_ = nullptr;
  QLineSeries* replayedForce_ = nullptr;
  QLineSeries* recordedLeftForce_ = nullptr;  // shown for a two-handed session
  QLineSeries* replayedLeftForce_ = nullptr;
  bool twoHands_ = false;
  QLineSeries* cursor_ = nullptr;
  double largestForceN_ = 0.1;
  QTimer timer_;
  QElapsedTimer wall_;
  BackgroundJob builder_;
};

}  // namespace liversim
