#include "liversim/engine/model.h"
#include "liversim/engine/validation_message.h"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>

namespace liversim {

void build_node_incidence(SimModel& model) {
  const std::size_t tets = model.tet_count;
  model.node_slot_begin.assign(model.node_count + 1, 0);
  for (int c = 0; c < 4; ++c)
    for (std::size_t e = 0; e < tets; ++e) ++model.node_slot_begin[model.corner[c][e] + 1];
  for (std::size_t n = 0; n < model.node_count; ++n)
    model.node_slot_begin[n + 1] += model.node_slot_begin[n];
  model.node_slots.resize(4 * tets);
  model.node_slot_element.resize(4 * tets);
  std::vector<std::int32_t> fill(model.node_slot_begin.begin(), model.node_slot_begin.end() - 1);
  for (int c = 0; c < 4; ++c)
    for (std::size_t e = 0; e < tets; ++e) {
      const std::int32_t s = fill[model.corner[c][e]]++;
      model.node_slots[s] = static_cast<std::int32_t>(c * tets + e);
      model.node_slot_element[s] = static_cast<std::int32_t>(e);
    }
}

void validate_integrator(const IntegratorSettings& settings) {
  auto fail = [](const std::string& what, double value, const char* expected) {
    throw std::invalid_argument(out_of_range_message("integrator " + what, value, expected));
  };
  if (!std::isfinite(settings.step_s) || settings.step_s < 0.0)
    fail("step (s)", settings.step_s, "a finite value >= 0");
  const bool implicit =
      settings.kind == IntegratorKind::backward_euler || settings.kind == IntegratorKind::bdf2;
  if (implicit && settings.step_s == 0.0)
    fail("step (s)", settings.step_s, "a step > 0 for an implicit scheme");
  if (!std::isfinite(settings.tolerance_m) || settings.tolerance_m <= 0.0)
    fail("tolerance (m)", settings.tolerance_m, "a finite value > 0");
  if (!std::isfinite(settings.newton_tolerance_m) || settings.newton_tolerance_m <= 0.0)
    fail("Newton tolerance (m)", settings.newton_tolerance_m, "a finite value > 0");
  if (settings.max_newton_iterations < 1)
    fail("Newton iteration limit", settings.max_newton_iterations, "at least 1");
}

}  // namespace liversim
