#include "stability_runner.h"

#include <cmath>
#include <limits>

namespace liversim::detail {

BookedRun::BookedRun(const SimModel& model_in, std::string variant)
    : model(model_in),
      state(make_rest_state(model_in)),
      checkpoint_(make_checkpoint(model_in)),
      start_(std::chrono::steady_clock::now()) {
  run_.variant = std::move(variant);
  run_.integrator = std::string(integrator_name(model.integrator.kind));
  open_books();
}

void BookedRun::open_books(const StepInputs& inputs) {
  open_energy_books(model, state, inputs);
  last_balance_ = energy_balance(model, state, inputs);
}

bool BookedRun::advance(const StepInputs& inputs, double interval_s, int intervals) {
  GuardOptions options = guard;
  options.check_energy = true;
  for (int i = 0; i < intervals; ++i) {
    const GuardedReport report =
        guarded_advance(model, state, inputs, interval_s, checkpoint_, options);
    ++run_.intervals;
    run_.simulated_s += interval_s;
    run_.rollbacks += report.rollbacks;
    run_.rejected_inputs += report.inputs_rejected ? 1 : 0;
    accumulate(run_.steps, report.steps);
    if (report.problem != HealthProblem::none)
      run_.last_problem = std::string(health_problem_text(report.problem));
    if (report.gave_up) {
      run_.gave_up = true;
      run_.gave_up_at_s = state.time_s;
      return false;
    }
    last_balance_ = *report.energy;
    const double created = -last_balance_.dissipated_j();
    const double supplied = last_balance_.supplied_j();
    const double error = supplied > 0.0    ? created / supplied
                         : created > 1e-12 ? std::numeric_limits<double>::infinity()
                                           : 0.0;
    run_.energy_error = std::max(run_.energy_error, error);
    run_.max_displacement_m =
        std::max(run_.max_displacement_m, max_displacement_m(model, state.position_m));
  }
  return true;
}

void BookedRun::check(std::string what, double value, double limit, bool at_most) {
  run_.checks.push_back({std::move(what), value, limit, at_most});
}

StabilityRun BookedRun::finish(double displacement_bound_m, double energy_tolerance) {
  bool finite = true;
  for (std::size_t n = 0; n < model.node_count; ++n)
    finite =
        finite && state.position_m.at(n).allFinite() && state.velocity_m_per_s.at(n).allFinite();
  check("state finite (1 = yes)", finite ? 1.0 : 0.0, 1.0, false);
  check("guard gave up (1 = yes)", run_.gave_up ? 1.0 : 0.0, 0.0);
  check("energy created / energy supplied", run_.energy_error, energy_tolerance);
  check("largest displacement (m)", run_.max_displacement_m, displacement_bound_m);
  run_.energy_supplied_j = last_balance_.supplied_j();
  run_.energy_held_j = last_balance_.held_j();
  run_.viscous_dissipated_j = last_balance_.viscous_dissipated_j;
  run_.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return run_;
}

double max_displacement_m(const SimModel& model, const NodeArray& position) {
  double largest_sq = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n)
    largest_sq = std::max(largest_sq, (position.at(n) - model.rest_position_m.at(n)).squaredNorm());
  return std::sqrt(largest_sq);
}

}  // namespace liversim::detail
