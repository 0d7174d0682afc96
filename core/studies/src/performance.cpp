#include "liversim/studies/performance.h"
#include "liversim/engine/model_building.h"

#include "liversim/engine/integrator.h"
#include "liversim/studies/seed_experiments.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <thread>
#include <vector>

namespace liversim {
namespace {

template <typename T>
std::size_t bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
std::size_t bytes(const NodeArray& a) {
  return bytes(a.x) + bytes(a.y) + bytes(a.z);
}
template <typename T, std::size_t N>
std::size_t bytes(const std::array<T, N>& arrays) {
  std::size_t total = 0;
  for (const T& a : arrays) total += bytes(a);
  return total;
}
template <typename T>
std::size_t bytes(const std::vector<std::vector<T>>& v) {
  std::size_t total = v.capacity() * sizeof(std::vector<T>);
  for (const auto& inner : v) total += bytes(inner);
  return total;
}
std::size_t bytes(const std::vector<NodeArray>& v) {
  std::size_t total = v.capacity() * sizeof(NodeArray);
  for (const NodeArray& a : v) total += bytes(a);
  return total;
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

std::size_t model_bytes(const SimModel& m) {
  return bytes(m.corner) + bytes(m.dm_inverse) + bytes(m.rest_volume_m3) +
         bytes(m.shear_modulus_pa) + bytes(m.lame_lambda_pa) + bytes(m.mooney_rivlin_c2_pa) +
         bytes(m.region) + bytes(m.regions) + bytes(m.fibre_parameters) + bytes(m.fibre_direction) +
         bytes(m.viscous_parameters) + bytes(m.rest_position_m) + bytes(m.lumped_mass_kg) +
         bytes(m.inverse_mass_per_kg) + bytes(m.is_fixed) + bytes(m.node_slot_begin) +
         bytes(m.node_slots) + bytes(m.node_slot_element);
}

std::size_t state_bytes(const SimState& s) {
  const ForceScratch& f = s.force_scratch;
  const IntegratorScratch& i = s.integrator;
  return bytes(s.position_m) + bytes(s.velocity_m_per_s) + bytes(s.force_n) +
         bytes(f.corner_force_n) + bytes(f.element_volume_ratio) +
         bytes(f.nodal_lambda_pressure_pa) + bytes(f.chunk_seen) + bytes(f.chunk_dissipated_j) +
         bytes(f.region_constants) + bytes(f.needs_general) + bytes(s.spring_damping_per_s) +
         s.viscous_history.capacity_bytes() + bytes(s.viscous_step) + bytes(i.start_position_m) +
         bytes(i.start_velocity_m_per_s) + bytes(i.stage_position_m) +
         bytes(i.stage_velocity_m_per_s) + bytes(i.position_rate) + bytes(i.velocity_rate) +
         bytes(i.start_arm) + bytes(i.stage_arm) + bytes(i.elastic_stress) + bytes(i.arm_rate) +
         bytes(i.external_force_n) + bytes(i.previous_external_force_n) +
         bytes(i.velocity_history) + bytes(i.previous_position_m) +
         bytes(i.previous_velocity_m_per_s) + bytes(i.predicted_position_m) +
         bytes(i.predicted_velocity_m_per_s) + bytes(i.previous_arm) + bytes(i.predicted_arm) +
         bytes(i.keep_by_region) + bytes(i.elastic_weight_by_region);
}

ForceEvaluationTiming time_force_evaluations(const SimModel& model, SimState& state, double step_s,
                                             double min_wall_s, int repetitions,
                                             InternalForcesFunction compute) {
  compute(model, state, step_s);  // warm-up: caches, first-touch pages
  ForceEvaluationTiming best;
  best.ns_per_tet = std::numeric_limits<double>::infinity();
  for (int r = 0; r < std::max(1, repetitions); ++r) {
    ForceEvaluationTiming run;
    const Clock::time_point start = Clock::now();
    do {
      compute(model, state, step_s);
      ++run.evaluations;
      run.wall_s = seconds_since(start);
    } while (run.wall_s < min_wall_s);
    run.ns_per_tet = 1e9 * run.wall_s /
                     (static_cast<double>(run.evaluations) * static_cast<double>(model.tet_count));
    if (run.ns_per_tet < best.ns_per_tet) best = run;
  }
  return best;
}

BuildComparison compare_force_builds(const SimModel& model, const SimState& state,
                                     InternalForcesFunction other, double step_s, double min_wall_s,
                                     int rounds) {
  BuildComparison best{std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity(), 0.0};
  std::vector<double> ratios;
  for (int r = 0; r < std::max(1, rounds); ++r) {
    SimState a = state, b = state;
    // Alternate which build goes first, so that neither always runs on a warmer machine.
    const bool normal_first = r % 2 == 0;
    double normal = 0.0, variant = 0.0;
    for (int turn = 0; turn < 2; ++turn) {
      if ((turn == 0) == normal_first)
        normal = time_force_evaluations(model, a, step_s, min_wall_s, 1, &compute_tissue_forces)
                     .ns_per_tet;
      else
        variant = time_force_evaluations(model, b, step_s, min_wall_s, 1, other).ns_per_tet;
    }
    best.normal_ns_per_tet = std::min(best.normal_ns_per_tet, normal);
    best.other_ns_per_tet = std::min(best.other_ns_per_tet, variant);
    ratios.push_back(normal / variant - 1.0);
  }
  std::sort(ratios.begin(), ratios.end());
  const std::size_t n = ratios.size();
  best.relative_difference = n % 2 == 1 ? ratios[n / 2] : 0.5 * (ratios[n / 2 - 1] + ratios[n / 2]);
  return best;
}

namespace {

// 16 independent multiply-add chains: enough in flight that the floating-point units' throughput,
// not the latency of one chain, bounds them (as in the element loops).
double multiply_add_chains(long iterations) {
  double chain[16];
  for (int k = 0; k < 16; ++k) chain[k] = 0.01 * k;
  for (long i = 0; i < iterations; ++i)
    for (double& c : chain) c = c * 0.999999 + 1e-7;
  double sum = 0.0;
  for (double c : chain) sum += c;
  return sum;
}

double time_chains(int threads, long iterations_per_thread) {
  std::vector<std::thread> workers;
  std::vector<double> results(static_cast<std::size_t>(threads));
  const Clock::time_point start = Clock::now();
  for (int t = 1; t < threads; ++t)
    workers.emplace_back([&, t] { results[t] = multiply_add_chains(iterations_per_thread); });
  results[0] = multiply_add_chains(iterations_per_thread);
  for (std::thread& worker : workers) worker.join();
  const double wall_s = seconds_since(start);
  volatile double sink = results[0];  // keep the work
  (void)sink;
  return wall_s;
}

}  // namespace

ParallelCeiling measure_parallel_ceiling(int threads, int repetitions) {
  constexpr long kIterations = 20'000'000;  // ~0.2 s on one thread
  ParallelCeiling ceiling;
  ceiling.threads = std::max(1, threads);
  ceiling.one_thread_s = ceiling.all_threads_s = std::numeric_limits<double>::infinity();
  for (int r = 0; r < std::max(1, repetitions); ++r) {
    ceiling.one_thread_s = std::min(ceiling.one_thread_s, time_chains(1, kIterations));
    ceiling.all_threads_s = std::min(ceiling.all_threads_s,
                                     time_chains(ceiling.threads, kIterations / ceiling.threads));
  }
  return ceiling;
}

SteppingTiming time_stepping(const SimModel& model, SimState& state, const StepInputs& inputs,
                             double interval_s, double min_wall_s) {
  SteppingTiming timing;
  const Clock::time_point start = Clock::now();
  do {
    accumulate(timing.steps, advance(model, state, inputs, interval_s));
    timing.simulated_s += interval_s;
    timing.wall_s = seconds_since(start);
  } while (timing.wall_s < min_wall_s);
  return timing;
}

std::vector<PointLoad> seed_pull_loads(const TetMesh& mesh, const SimModel& model) {
  std::vector<PointLoad> pull;
  spread_load(make_load_patch(mesh, model, anterior_marked_node(mesh), 0.02),
              kSeedPullDirection * 0.5, pull);
  return pull;
}

SteppingTiming time_scene_under_pull(const SceneSetup& scene, double min_wall_s,
                                     std::shared_ptr<WorkerPool> workers) {
  const SimModel model = build_model(scene.mesh, scene.model_options);
  SimState state = make_rest_state(model, std::move(workers));
  const std::vector<PointLoad> pull = seed_pull_loads(scene.mesh, model);
  constexpr double kInterval_s = 1e-3;
  advance(model, state, {pull, {}}, kInterval_s);  // warm-up: first factorisation, caches
  return time_stepping(model, state, {pull, {}}, kInterval_s, min_wall_s);
}

}  // namespace liversim
