#include "liversim/sessions/session_export.h"

#include "liversim/scenario/scenario.h"

#include <iomanip>

namespace liversim {

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void write_frames_csv(std::span<const ServoFrame> frames, std::ostream& out) {
  out << std::setprecision(17)
      << "time_s,x_mm,y_mm,z_mm,vx_mm_per_s,vy_mm_per_s,vz_mm_per_s,fx_n,fy_n,fz_n,buttons\n";
  for (const ServoFrame& f : frames) {
    out << f.time_s;
    for (int k = 0; k < 3; ++k) out << ',' << f.sample.position_mm[k];
    for (int k = 0; k < 3; ++k) out << ',' << f.sample.velocity_mm_per_s[k];
    for (int k = 0; k < 3; ++k) out << ',' << f.force_n[k];
    out << ',' << f.sample.buttons << '\n';
  }
}

void write_events_csv(std::span<const SessionEvent> events, std::ostream& out) {
  out << std::setprecision(17) << "time_s,kind,detail,hand\n";
  for (const SessionEvent& e : events)
    out << e.time_s << ',' << session_event_name(e.kind) << ',' << csv_field(e.detail) << ','
        << hand_name(e.hand) << '\n';
}

void write_metrics_csv(std::span<const MetricValue> metrics, const RubricResult& rubric,
                       std::ostream& out) {
  out << std::setprecision(17) << "metric,value,unit,criterion,threshold,weight,passed\n";
  for (const MetricValue& m : metrics) {
    const MetricInfo* info = find_metric(m.name);
    out << csv_field(m.name) << ',' << m.value << ','
        << csv_field(info ? std::string(info->unit) : std::string());
    const CriterionResult* graded = nullptr;
    for (const CriterionResult& r : rubric.criteria)
      if (r.criterion.metric == m.name) graded = &r;
    if (graded)
      out << ',' << (graded->criterion.rule == PassRule::at_most ? "at_most" : "at_least") << ','
          << graded->criterion.threshold << ',' << graded->criterion.weight << ','
          << (graded->passed ? 1 : 0);
    else
      out << ",,,,";
    out << '\n';
  }
  // Criteria whose metric the session lacks fail; they are listed too.
  for (const CriterionResult& r : rubric.criteria)
    if (!r.value)
      out << csv_field(r.criterion.metric) << ",,,"
          << (r.criterion.rule == PassRule::at_most ? "at_most" : "at_least") << ','
          << r.criterion.threshold << ',' << r.criterion.weight << ",0\n";
  out << "score_percent,";
  if (rubric.score_percent) out << *rubric.score_percent;
  out << ",%,,,,\n";
}

}  // namespace liversim
