#pragma once
// Measures of the engine's cost for the benchmarks (liversim-cli bench, docs/performance.md):
// the time of one internal-force evaluation, the rate of whole steps, and the memory a model and
// its state hold. Timing is wall-clock on the calling thread; tests never assert it.

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/state.h"
#include "liversim/meshing/default_scene.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace liversim {

// Heap bytes held by the model (every per-element and per-node array, by capacity).
std::size_t model_bytes(const SimModel& model);
// Heap bytes held by the state: positions, velocities, forces, scratch, viscous history and the
// integrator's arrays (the implicit schemes' sparse factorisation not included).
std::size_t state_bytes(const SimState& state);

struct ForceEvaluationTiming {
  int evaluations = 0;
  double wall_s = 0.0;
  double ns_per_tet = 0.0;  // per evaluation: wall / (evaluations · tets)
};
// Evaluates the internal forces at the state's positions (viscous regions advancing their history
// by step_s each time, as a central-difference step does) for at least min_wall_s, after one
// warm-up evaluation; the best of `repetitions` such runs (the least disturbed).
// `compute` is the build timed (another one: forces_variants.h).
ForceEvaluationTiming time_force_evaluations(
    const SimModel& model, SimState& state, double step_s, double min_wall_s, int repetitions = 3,
    InternalForcesFunction compute = &compute_internal_forces);

// The normal build against another build of the force loops on the same model and state: the
// normal build's compute_tissue_forces against `other`, the other build's.
struct BuildComparison {
  double normal_ns_per_tet = 0.0, other_ns_per_tet = 0.0;  // each build's best run
  // The median over the rounds of normal / other − 1, each round's two runs back to back: a
  // drift of the machine's speed touches both runs of a round alike.
  double relative_difference = 0.0;
};
// Alternates runs of the two builds `rounds` times, each on a copy of `state`.
BuildComparison compare_force_builds(const SimModel& model, const SimState& state,
                                     InternalForcesFunction other, double step_s, double min_wall_s,
                                     int rounds);

// What this machine itself allows on several threads: the same independent multiply-add chains
// (no memory traffic, nothing shared) on one thread and then split over `threads` threads.
struct ParallelCeiling {
  int threads = 1;
  double one_thread_s = 0.0, all_threads_s = 0.0;
  double speedup() const { return all_threads_s > 0.0 ? one_thread_s / all_threads_s : 0.0; }
};
// Best of `repetitions` of each.
ParallelCeiling measure_parallel_ceiling(int threads, int repetitions);

struct SteppingTiming {
  double simulated_s = 0.0;
  double wall_s = 0.0;
  StepReport steps;
  double steps_per_s() const { return wall_s > 0.0 ? steps.substeps / wall_s : 0.0; }
  double real_time_factor() const { return wall_s > 0.0 ? simulated_s / wall_s : 0.0; }
};
// Advances the state by `interval_s` at a time with the given inputs until at least min_wall_s of
// wall time has passed.
SteppingTiming time_stepping(const SimModel& model, SimState& state, const StepInputs& inputs,
                             double interval_s, double min_wall_s);

// The stepping benchmarks' load: the seed's 0.5 N pull, spread over the free surface within
// 20 mm of the anterior marked point (anterior_marked_node), as a tool's jaws would hold it.
std::vector<PointLoad> seed_pull_loads(const TetMesh& mesh, const SimModel& model);

// What a scene costs to simulate (the editor's "effects and their cost"): its model built, then
// stepped from rest in 1 ms intervals under seed_pull_loads for at least min_wall_s on `workers`
// (none: this thread). Throws what build_model throws.
SteppingTiming time_scene_under_pull(const SceneSetup& scene, double min_wall_s,
                                     std::shared_ptr<WorkerPool> workers = nullptr);

}  // namespace liversim
