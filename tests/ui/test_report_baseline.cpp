// The instructor's report view (SessionReviewWindow) against a baseline picture
// (tests/baselines/instructor_report.png): one session of the small resection, written through the
// storage API into a fresh database (frames, events, metrics, a grade), opened in a window of a
// fixed size, in English, in UTC. Catches changes to the review's layout, tables and chart.
//
// The window is laid out and drawn but never put on the screen (Qt::WA_DontShowOnScreen): no
// window manager, focus or blinking cursor can change the picture, and it is drawn with the
// palette of an inactive window every time.
//
// Updating the baseline after an intended change: run the test, look at the picture it names, and
// copy it over tests/baselines/instructor_report.png.
#include "liversim/scenario/scenario.h"
#include "liversim/storage/sqlite_session_store.h"
#include "recorded_session.h"
#include "session_replay_window.h"
#include "session_review_window.h"
#include "translations.h"

#include <gtest/gtest.h>

#include <QByteArray>
#include <QChart>
#include <QChartView>
#include <QDir>
#include <QFile>
#include <QImage>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

namespace liversim {
namespace {

namespace fs = std::filesystem;

const QString kSmallScenario =
    QStringLiteral(LIVERSIM_TEST_DATA_DIR) + "/scenario-small-resection.json";
const fs::path kOutputDir = LIVERSIM_TEST_OUTPUT_DIR;
constexpr int kWindowWidth = 1100;
constexpr int kWindowHeight = 800;

// The same semantics as the rendering baselines' (tests/render): a pixel differs when any of its
// channels differs by more than 16 of 255 (6 %), which forgives the few levels by which another
// FreeType or Qt version anti-aliases a glyph's edge.
constexpr int kPixelThreshold = 16;
// The picture fails when more than 0.02 % of its pixels differ (176 of 1100 x 800): half of what a
// changed word does (the trainee's "Trainee" drawn as "Student" changes 359). Here the picture is
// the same to the pixel from run to run; the tolerance is for a few glyph edges drawn differently
// elsewhere.
constexpr double kMaxDifferingFraction = 0.0002;

// Sets the TZ variable for the test's lifetime: the review shows local times.
class ScopedTimeZone {
 public:
  explicit ScopedTimeZone(const char* zone) {
    if (const char* old = std::getenv("TZ")) old_ = old;
    setenv("TZ", zone, 1);
    tzset();
  }
  ~ScopedTimeZone() {
    if (old_)
      setenv("TZ", old_->c_str(), 1);
    else
      unsetenv("TZ");
    tzset();
  }
  ScopedTimeZone(const ScopedTimeZone&) = delete;
  ScopedTimeZone& operator=(const ScopedTimeZone&) = delete;

 private:
  std::optional<std::string> old_;
};

// One session of the scenario in `database`: 2 s of servo frames at 1 kHz (the force rising to
// 1.2 N and falling back), a grasp, a cut and a breach, the session's metrics and one grade.
std::int64_t writeSession(const QString& database, const std::string& scenario_text,
                          const std::string& title) {
  SqliteSessionStore store(database.toStdString());
  SessionStart start;
  start.trainee = "Trainee A";
  start.scenario_title = title;
  start.scenario_text = scenario_text;
  start.device = "Phantom Omni";
  start.started_unix_ms = 1'795'000'000'000;
  const std::int64_t session = store.begin_session(start);
  std::vector<ServoFrame> frames(2000);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const double t = 1e-3 * static_cast<double>(i);
    frames[i].time_s = 100.0 + t;
    // Never zero: the curve stays off the time axis, where the chart test looks for it.
    const double force_n = 0.2 + 1.0 * std::exp(-std::pow((t - 1.1) / 0.3, 2.0));
    frames[i].force_n = Eigen::Vector3d(0.0, -force_n, 0.0);
  }
  store.append_frames(session, frames);
  const std::vector<SessionEvent> events = {{100.4, SessionEventKind::grasp, ""},
                                            {101.1, SessionEventKind::cut, ""},
                                            {101.3, SessionEventKind::lesion_breach,
                                             "peripheral "
                                             "tumour"},
                                            {101.8, SessionEventKind::release, ""}};
  store.append_events(session, events);
  store.commit();
  store.end_session(session, 1'795'000'002'000, SessionServoFigures{.ticks = 2000});
  const std::vector<MetricValue> metrics = {
      {"task_time_s", 1.9},        {"path_length_mm", 84.2},  {"peak_force_n", 1.2},
      {"lesion_breached", 1.0},    {"lesion_margin_mm", 0.0}, {"plane_deviation_mm", 3.4},
      {"resected_volume_mm3", 0.0}};
  store.store_metrics(session, metrics);
  // Graded at the rubric's score: 2 of its 7 weights passed.
  store.set_password_cost_for_testing(kCheapPasswordCostForTesting);
  const Instructor rossi = store.add_instructor_account("Dr. Rossi", "report password", nullptr);
  store.store_grade(rossi, session,
                    {"Dr. Rossi", 1'795'000'600'000, 100.0 * 2.0 / 7.0, "fail",
                     "Breached the tumour: keep 10 mm from it."});
  return session;
}

// Pixels of `a` and `b` (same size) that differ by more than kPixelThreshold in any channel, and
// a picture of them: `a` faded, the differing pixels in red.
struct Comparison {
  long differing = 0;
  QImage difference;
};

Comparison compareImages(const QImage& a, const QImage& b) {
  Comparison result;
  result.difference = QImage(a.size(), QImage::Format_RGB32);
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const QRgb p = a.pixel(x, y), q = b.pixel(x, y);
      const bool differs = std::abs(qRed(p) - qRed(q)) > kPixelThreshold ||
                           std::abs(qGreen(p) - qGreen(q)) > kPixelThreshold ||
                           std::abs(qBlue(p) - qBlue(q)) > kPixelThreshold;
      result.differing += differs;
      const int faded = 192 + qGray(p) / 4;
      result.difference.setPixel(x, y, differs ? qRgb(255, 0, 0) : qRgb(faded, faded, faded));
    }
  return result;
}

// Whether a chart pixel is a series' (the theme's colours are saturated; the axes, grid and text
// are greys).
bool seriesPixel(QRgb p) {
  return std::max({qRed(p), qGreen(p), qBlue(p)}) - std::min({qRed(p), qGreen(p), qBlue(p)}) > 60;
}

TEST(InstructorReportBaseline, TheReviewOfASessionMatchesTheBaseline) {
  installTranslations(QStringLiteral("en"));
  const ScopedTimeZone utc("UTC");
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  QFile file(kSmallScenario);
  ASSERT_TRUE(file.open(QIODevice::ReadOnly));
  const std::string text = file.readAll().toStdString();
  const ScenarioReading reading = read_scenario(text);
  ASSERT_TRUE(reading.scenario);
  const QString database = folder.filePath("sessions.sqlite");
  const std::int64_t session = writeSession(database, text, reading.scenario->title);

  // Reviewed by the instructor who graded it, logged in.
  const std::optional<Instructor> rossi =
      SqliteSessionStore(database.toStdString()).log_in_instructor("Dr. Rossi", "report password");
  ASSERT_TRUE(rossi);
  SessionReviewWindow window(database, std::nullopt, rossi);
  window.setAttribute(Qt::WA_DontShowOnScreen);
  window.resize(kWindowWidth, kWindowHeight);
  window.show();
  ASSERT_TRUE(window.problem().isEmpty()) << window.problem().toStdString();
  ASSERT_EQ(window.listedSessionCount(), 1);
  ASSERT_TRUE(window.openSession(session));
  ASSERT_EQ(window.eventCount(), 4);
  QTest::qWait(50);  // the layout and the chart settle
  const QImage picture = window.grab().toImage().convertToFormat(QImage::Format_RGB32);
  ASSERT_EQ(picture.size(), QSize(kWindowWidth, kWindowHeight));

  // The chart is not blank: the force curve spans the whole time axis, so every column of the
  // plot area holds a pixel of a series (the curve, or an event's marker).
  auto* chart_view = window.findChild<QChartView*>("forceChart");
  ASSERT_NE(chart_view, nullptr);
  const QImage chart = chart_view->grab().toImage().convertToFormat(QImage::Format_RGB32);
  const QRect plot = chart_view->chart()->plotArea().toAlignedRect() & chart.rect();
  ASSERT_GT(plot.width(), 100) << "the chart has no room to plot";
  int columns_with_series = 0;
  for (int x = plot.left(); x <= plot.right(); ++x)
    for (int y = plot.top(); y <= plot.bottom(); ++y)
      if (seriesPixel(chart.pixel(x, y))) {
        ++columns_with_series;
        break;
      }
  // The curve's line is drawn anti-aliased from the plot's left edge to its right: the first and
  // last column may hold only a faint edge of it.
  EXPECT_GE(columns_with_series, plot.width() - 2)
      << "the force chart is blank or shows part of the session";

  fs::create_directories(kOutputDir);
  const fs::path baseline = fs::path(LIVERSIM_BASELINE_DIR) / "instructor_report.png";
  const fs::path output = kOutputDir / "instructor_report.png";
  ASSERT_TRUE(picture.save(QString::fromStdString(output.string())));
  ASSERT_TRUE(fs::exists(baseline))
      << "the baseline " << baseline << " is missing. The picture drawn now is\n  " << output
      << "\nlook at it and, if it is right, copy it there:\n  cp " << output << ' ' << baseline;
  const QImage expected =
      QImage(QString::fromStdString(baseline.string())).convertToFormat(QImage::Format_RGB32);
  ASSERT_EQ(expected.size(), picture.size())
      << baseline << " is " << expected.width() << "x" << expected.height() << "; " << output
      << " is " << picture.width() << "x" << picture.height();
  const Comparison comparison = compareImages(picture, expected);
  const double fraction =
      static_cast<double>(comparison.differing) / (picture.width() * picture.height());
  std::cout << "instructor report against the baseline: " << comparison.differing
            << " pixels differ by more than " << kPixelThreshold << " of 255 (" << fraction * 100
            << " %, limit " << kMaxDifferingFraction * 100 << " %)\n";
  if (fraction > kMaxDifferingFraction) {
    const fs::path diff = kOutputDir / "instructor_report_diff.png";
    comparison.difference.save(QString::fromStdString(diff.string()));
    ADD_FAILURE() << "the instructor's report no longer looks like the baseline: "
                  << comparison.differing << " pixels differ (limit " << kMaxDifferingFraction * 100
                  << " % of them)\n  drawn now:  " << output << "\n  baseline:   " << baseline
                  << "\n  difference: " << diff
                  << "\nif the change is intended, copy the picture drawn now over the baseline.";
    return;
  }
  fs::remove(output);  // passed: nothing to inspect
}

// A session of two devices (issue 43): the review plots each hand's force, says which events are
// the left hand's, and exports the left hand's frames beside the right's; a one-handed session
// shows and writes only its own.
TEST(InstructorReview, ATwoHandedSessionShowsAndExportsEachHand) {
  installTranslations(QStringLiteral("en"));
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QString database = folder.filePath("sessions.sqlite");
  testing::Recorded one_hand, two_hands;
  {
    SqliteSessionStore store(database.toStdString());
    one_hand = testing::record_session(store, "Trainee A", 300, 1);
    two_hands = testing::record_session(store, "Trainee B", 333, 2, 222);
  }
  SessionReviewWindow window(database, std::nullopt, std::nullopt);
  window.setAttribute(Qt::WA_DontShowOnScreen);
  window.show();
  ASSERT_TRUE(window.problem().isEmpty()) << window.problem().toStdString();
  const auto read = [](const QString& file) {
    std::ifstream in(file.toStdString());
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const auto lines = [](const std::string& text) {
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  };

  ASSERT_TRUE(window.openSession(two_hands.id));
  EXPECT_GT(window.forcePointCount(), 0);
  EXPECT_GT(window.leftForcePointCount(), 0);
  const QStringList left_events = window.eventLines().filter("(left hand)");
  ASSERT_EQ(left_events.size(), 2) << window.eventLines().join('\n').toStdString();
  EXPECT_TRUE(left_events[0].contains("tool_selected (left hand)  forceps"))
      << left_events[0].toStdString();
  EXPECT_TRUE(left_events[1].contains("grasp (left hand)")) << left_events[1].toStdString();
  const QString exported = folder.filePath("two-hands");
  ASSERT_TRUE(QDir().mkpath(exported));
  ASSERT_TRUE(window.exportCsv(exported)) << window.problem().toStdString();
  const QString base = exported + QString("/session-%1-").arg(two_hands.id);
  EXPECT_EQ(lines(read(base + "frames.csv")), two_hands.frames.size() + 1);
  EXPECT_EQ(lines(read(base + "left-frames.csv")), two_hands.left_frames.size() + 1);
  EXPECT_NE(read(base + "events.csv").find(",grasp,,left\n"), std::string::npos);
  {
    // The replay window plots each hand's recorded force (its scene is built on a worker, which
    // its closing waits for).
    SessionReplayWindow replay(database, two_hands.id);
    EXPECT_GT(replay.recordedForcePointCount(), 0);
    EXPECT_GT(replay.recordedLeftForcePointCount(), 0);
  }

  ASSERT_TRUE(window.openSession(one_hand.id));
  EXPECT_GT(window.forcePointCount(), 0);
  EXPECT_EQ(window.leftForcePointCount(), 0);
  EXPECT_TRUE(window.eventLines().filter("(left hand)").isEmpty());
  {
    SessionReplayWindow replay(database, one_hand.id);
    EXPECT_GT(replay.recordedForcePointCount(), 0);
    EXPECT_EQ(replay.recordedLeftForcePointCount(), 0);
  }
  const QString exported_one = folder.filePath("one-hand");
  ASSERT_TRUE(QDir().mkpath(exported_one));
  ASSERT_TRUE(window.exportCsv(exported_one)) << window.problem().toStdString();
  EXPECT_TRUE(QFile::exists(exported_one + QString("/session-%1-frames.csv").arg(one_hand.id)));
  EXPECT_FALSE(
      QFile::exists(exported_one + QString("/session-%1-left-frames.csv").arg(one_hand.id)));
}

}  // namespace
}  // namespace liversim
