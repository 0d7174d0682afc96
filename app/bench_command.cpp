#include "bench_command.h"

#include "cli_commands.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"
#include "liversim/studies/accuracy_study.h"
#include "liversim/studies/forces_variants.h"
#include "liversim/studies/performance.h"
#include "liversim/studies/seed_experiments.h"

#include <CLI/CLI.hpp>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

extern char** environ;

namespace liversim::cli {
namespace {

// Runs per force measurement and per step measurement; the best is kept (the others were
// disturbed).
constexpr int kRepetitions = 5;
constexpr int kSteppingRepetitions = 3;
// The effect-off comparison: many short back-to-back pairs (compare_force_builds).
constexpr int kEffectOffRounds = 41;
constexpr double kEffectOffRunS = 0.05;  // or --min-time, if shorter

struct BenchOptions {
  std::vector<int> tet_counts{std::begin(kSeedMeshSizes), std::end(kSeedMeshSizes)};
  std::vector<int> stepping_tet_counts{kDefaultLiverTetCount, 10583};
  int threads = 0;  // of the second column of the thread tables; 0: the engine's default
  double min_time_s = 0.3;
  std::filesystem::path output_dir = "docs";
  // The seed's Table 1 beside ours: simulated seconds per case.
  double table1_simulated_s = TimingSettings{}.simulated_s;
  // The workstation's peak resident memory; default: `liversim` beside this executable.
  std::optional<std::filesystem::path> workstation;
  int workstation_tets = 10583;
  double workstation_seconds = 10.0;
  // Internal: only evaluate the forces of one effect-off case on one build, for a count of the
  // instructions under callgrind (see count_instructions).
  std::optional<int> effect_off_case;
  bool without_effect = false;
  int evaluations = 20;
};

// Issue 6's target for the workstation with the 10583-tet liver.
constexpr double kWorkstationTargetMb = 600.0;

// ---- The workstation's peak resident memory -----------------------------------------------------

// `liversim` in the directory of the running executable (/proc/self/exe); empty when unknown.
std::filesystem::path default_workstation() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return {};
  return self.parent_path() / "liversim";
}

bool has_display() {
  for (const char* variable : {"DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"}) {
    const char* value = std::getenv(variable);
    if (value != nullptr && *value != '\0') return true;
  }
  return false;
}

struct WorkstationMemory {
  std::string command;            // as run
  std::optional<double> peak_mb;  // ru_maxrss of the child; only when it exited with status 0
  std::string outcome;            // one sentence when there is no figure
};

// A value with `decimals` digits after the point, never in exponent notation.
std::string fixed(double value, int decimals = 1) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

// How a waited-for child ended, in words.
std::string exit_description(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    const char* name = strsignal(signal);
    return "was killed by signal " + std::to_string(signal) +
           (name != nullptr ? " (" + std::string(name) + ")" : std::string());
  }
  return "ended with wait status " + std::to_string(status);
}

// Runs `workstation --tets N --quit-after S` as a child (on Qt's offscreen platform when there is
// no display, where the workstation says it cannot show its 3D view and exits: run the bench
// under xvfb-run to measure it) and takes its peak resident set (wait4's ru_maxrss, KiB). A child still running long after it should
// have quit is killed, and reported as such.
WorkstationMemory measure_workstation(const std::filesystem::path& workstation, int tets,
                                      double seconds) {
  const std::vector<std::string> arguments{workstation.string(), "--tets", std::to_string(tets),
                                           "--quit-after", number(seconds)};
  WorkstationMemory result;
  for (const std::string& argument : arguments)
    result.command += (result.command.empty() ? "" : " ") + argument;
  if (workstation.empty() || access(workstation.c_str(), X_OK) != 0) {
    result.outcome = "workstation not built: not measured (no executable " +
                     (workstation.empty() ? std::string("found") : "at " + workstation.string()) +
                     ")";
    return result;
  }
  const bool offscreen = !has_display();
  if (offscreen) result.command = "QT_QPA_PLATFORM=offscreen " + result.command;

  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  std::vector<char*> environment;
  for (char** variable = environ; *variable != nullptr; ++variable)
    if (!offscreen || std::strncmp(*variable, "QT_QPA_PLATFORM=", 16) != 0)
      environment.push_back(*variable);
  std::string offscreen_variable = "QT_QPA_PLATFORM=offscreen";
  if (offscreen) environment.push_back(offscreen_variable.data());
  environment.push_back(nullptr);

  pid_t child = 0;
  const int spawn_error =
      posix_spawn(&child, workstation.c_str(), nullptr, nullptr, argv.data(), environment.data());
  if (spawn_error != 0) {
    result.outcome = "could not start " + workstation.string() + ": " + std::strerror(spawn_error) +
                     "; not measured";
    return result;
  }
  // Building the liver and opening the window come before the quit timer starts: allow for them.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds + 300.0);
  int status = 0;
  rusage usage{};
  bool killed_by_bench = false;
  for (;;) {
    const pid_t waited = wait4(child, &status, WNOHANG, &usage);
    if (waited == child) break;
    if (waited < 0 && errno != EINTR) {
      result.outcome = std::string("waiting for the workstation failed: ") + std::strerror(errno) +
                       "; not measured";
      return result;
    }
    if (!killed_by_bench && std::chrono::steady_clock::now() > deadline) {
      kill(child, SIGKILL);
      killed_by_bench = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (killed_by_bench) {
    result.outcome = "the workstation was still running " + number(seconds + 300.0) +
                     " s after it started, so the bench killed it (it " + exit_description(status) +
                     "); not measured";
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    result.peak_mb = static_cast<double>(usage.ru_maxrss) * 1024.0 / 1e6;
  } else {
    result.outcome = "the workstation " + exit_description(status) + "; not measured";
  }
  return result;
}

// ---- The seed's Table 1 beside ours -------------------------------------------------------------

struct Table1Row {
  int requested_tets = 0;
  const SeedTable1Row* seed = nullptr;
  TimingCase central_difference, rk4;
};

// Our deformation time at each size: the seed's pull (F = 0.75 N, frames of Δt = 2 ms, the seed's
// step requested), with the default integrator and with the seed's RK4.
std::vector<Table1Row> run_table1(const std::vector<int>& tet_counts, double simulated_s,
                                  std::shared_ptr<WorkerPool> workers) {
  TimingSettings settings;
  settings.workers = std::move(workers);
  settings.simulated_s = simulated_s;
  std::vector<Table1Row> rows;
  for (int tets : tet_counts) {
    Table1Row row;
    row.requested_tets = tets;
    for (const SeedTable1Row& seed : kSeedTable1)
      if (seed.tets == tets) row.seed = &seed;
    for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::rk4}) {
      IntegratorSettings integrator;
      integrator.kind = kind;
      integrator.step_s = settings.frame_s;  // the seed's 2 ms requested; split when unstable
      const ExperimentScene built = build_scene(tets, integrator);
      TimingCase timing = run_timing_case(built.scene.mesh, built.model, settings);
      std::cout << "Table 1, " << tets << " tets, " << integrator_name(kind) << ": "
                << fixed(timing.deformation_wall_s * 1e3) << " ms for " << number(simulated_s)
                << " s simulated (" << timing.steps.substeps << " steps), real-time factor "
                << format(timing.real_time_factor(settings)) << std::endl;
      (kind == IntegratorKind::rk4 ? row.rk4 : row.central_difference) = timing;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string table1_markdown(const std::vector<Table1Row>& rows, double simulated_s) {
  TimingSettings settings;
  settings.simulated_s = simulated_s;
  std::ostringstream md;
  md << "| tets (seed) | tets (ours) | ours, central difference (ms) | real-time factor | steps | "
        "ours, RK4 (ms) | real-time factor | steps | seed deform | [3] deform | [14] deform | "
        "ours cut | seed cut | [3] cut | [14] cut |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n";
  for (const Table1Row& row : rows) {
    const TimingCase &cd = row.central_difference, &rk4 = row.rk4;
    md << "| " << row.requested_tets << " | " << cd.tet_count << " | "
       << fixed(cd.deformation_wall_s * 1e3) << " | " << format(cd.real_time_factor(settings))
       << " | " << cd.steps.substeps << " | " << fixed(rk4.deformation_wall_s * 1e3) << " | "
       << format(rk4.real_time_factor(settings)) << " | " << rk4.steps.substeps << " | ";
    if (row.seed)
      md << number(row.seed->seed_deform_ms) << " | " << number(row.seed->conical_spring_deform_ms)
         << " | " << number(row.seed->implicit_fem_deform_ms) << " | see cutting-performance.md | "
         << number(row.seed->seed_cut_ms) << " | " << number(row.seed->conical_spring_cut_ms)
         << " | " << number(row.seed->implicit_fem_cut_ms) << " |\n";
    else
      md << "- | - | - | see cutting-performance.md | - | - | - |\n";
  }
  return md.str();
}

// The effect sets of the force benchmark: the default scene's tissue (E = 3500 Pa, ν = 0.49)
// with the accuracy study's laws (accuracy_study.h), with and without average nodal pressure.
struct EffectSet {
  const char* name;
  bool average_nodal_pressure;
  std::vector<StudyEffects> laws;
};
const std::vector<EffectSet>& effect_sets() {
  static const std::vector<EffectSet> sets{
      {"Neo-Hookean", false, {StudyEffects::elastic}},
      {"+ near-incompressibility (ANP)", true, {StudyEffects::elastic}},
      {"ANP + viscoelastic", true, {StudyEffects::viscoelastic}},
      {"ANP + viscoplastic", true, {StudyEffects::viscoplastic}},
      {"ANP + fibres", true, {StudyEffects::fibres}},
      {"full: ANP + viscoplastic + fibres",
       true,
       {StudyEffects::viscoplastic, StudyEffects::fibres}},
  };
  return sets;
}

SimModel model_for(const SceneSetup& scene, const EffectSet& set) {
  ModelOptions options = scene.model_options;
  options.average_nodal_pressure = set.average_nodal_pressure;
  for (StudyEffects laws : set.laws) apply_study_effects(laws, options);
  return build_model(scene.mesh, options);
}

// One force evaluation's cost per effect set, size and thread count.
struct ForceRow {
  const EffectSet* set;
  std::vector<std::vector<double>> ns_per_tet;  // [size][thread count]
};

// The scene of "what an effect that is off costs": the full model with that effect left off.
struct EffectOffCase {
  const char* effect;
  const char* scene;
  bool average_nodal_pressure;
  std::vector<StudyEffects> laws;
  unsigned without;
};
const std::vector<EffectOffCase>& effect_off_cases() {
  static const std::vector<EffectOffCase> cases{
      // The control: the normal build against itself, the same way (its difference is the
      // measurement's own spread on this machine).
      {"none (the normal build against itself)",
       "full: ANP + viscoplastic + fibres",
       true,
       {StudyEffects::viscoplastic, StudyEffects::fibres},
       0},
      {"fibres", "ANP + viscoplastic", true, {StudyEffects::viscoplastic}, kWithoutFibres},
      {"viscous tissue", "ANP + fibres", true, {StudyEffects::fibres}, kWithoutViscous},
      {"average nodal pressure",
       "viscoplastic + fibres",
       false,
       {StudyEffects::viscoplastic, StudyEffects::fibres},
       kWithoutAverageNodalPressure},
      {"Mooney–Rivlin term",
       "full: ANP + viscoplastic + fibres",
       true,
       {StudyEffects::viscoplastic, StudyEffects::fibres},
       kWithoutMooneyRivlin},
      // Gravity is off in every scene above; its build leaves out the weight and the support.
      {"gravity",
       "full: ANP + viscoplastic + fibres",
       true,
       {StudyEffects::viscoplastic, StudyEffects::fibres},
       kWithoutGravity},
  };
  return cases;
}

SimModel effect_off_model(const SceneSetup& scene, const EffectOffCase& c) {
  return model_for(scene, EffectSet{c.scene, c.average_nodal_pressure, c.laws});
}

// compute_tissue_forces of the build without `effect` (0: the normal build).
InternalForcesFunction build_without(unsigned effect) {
  if (effect == 0) return &compute_tissue_forces;
  for (const ForcesVariant& variant : forces_variants())
    if (variant.without == effect) return variant.compute_tissue_forces;
  throw std::logic_error("no build without that effect");
}

// The child of count_instructions: `evaluations` force evaluations of one effect-off case on
// one build, on one thread, and nothing else worth counting.
int evaluate_effect_off_case(const BenchOptions& o) {
  const std::vector<EffectOffCase>& cases = effect_off_cases();
  if (*o.effect_off_case < 0 || *o.effect_off_case >= static_cast<int>(cases.size()))
    throw std::invalid_argument("--effect-off-case must be below " + std::to_string(cases.size()));
  const EffectOffCase& c = cases[static_cast<std::size_t>(*o.effect_off_case)];
  const SimModel model = effect_off_model(default_scene(o.tet_counts.front()), c);
  SimState state = make_rest_state(model, make_worker_pool(1));
  const InternalForcesFunction compute = build_without(o.without_effect ? c.without : 0);
  for (int i = 0; i < o.evaluations; ++i) compute(model, state, 1e-3);
  return 0;
}

std::string shell_quoted(const std::string& text) {
  std::string quoted = "'";
  for (char ch : text) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return quoted + "'";
}

// Instructions per tetrahedron per force evaluation of one effect-off case on one build, counted
// by callgrind (valgrind) in a child: unlike time, the same from run to run whatever else the
// machine does. Only the force loops are counted (--toggle-collect). Empty when valgrind is
// missing or the child fails; `command` is what was run.
constexpr int kCountedEvaluations = 20;
std::optional<double> count_instructions(std::size_t case_index, bool without_effect, int tets,
                                         int tet_count, std::string& command) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error || std::system("command -v valgrind > /dev/null 2>&1") != 0) return std::nullopt;
  command =
      "LIVERSIM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=/dev/null "
      "--toggle-collect='liversim::*compute_tissue_forces*' " +
      shell_quoted(self.string()) + " bench --tets " + std::to_string(tets) +
      " --effect-off-case " + std::to_string(case_index) +
      (without_effect ? " --without-effect" : "") + " --evaluations " +
      std::to_string(kCountedEvaluations);
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return std::nullopt;
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  if (pclose(pipe) != 0) return std::nullopt;
  const std::size_t at = output.rfind("Collected : ");
  if (at == std::string::npos) return std::nullopt;
  const double collected = std::strtod(output.c_str() + at + 12, nullptr);
  return collected / (static_cast<double>(kCountedEvaluations) * tet_count);
}

std::shared_ptr<WorkerPool> pool_of(int threads) {
  return threads == default_engine_threads() ? shared_worker_pool() : make_worker_pool(threads);
}

std::string thread_label(int threads) {
  return threads == 1 ? "one thread" : std::to_string(threads) + " threads";
}

int run_bench(const BenchOptions& o) {
  const int threads = o.threads > 0 ? o.threads : default_engine_threads();
  std::filesystem::create_directories(o.output_dir);
  std::vector<int> thread_counts{1};
  if (threads > 1) thread_counts.push_back(threads);
  std::vector<std::shared_ptr<WorkerPool>> pools;
  for (int count : thread_counts) pools.push_back(pool_of(count));

  // ---- Force evaluations per effect set, size and thread count; memory at the largest size.
  std::vector<SceneSetup> scenes;
  for (int tets : o.tet_counts) scenes.push_back(default_scene(tets));
  std::vector<ForceRow> force_rows;
  std::ostringstream memory;
  memory << "| effects | tets | model (B/tet) | state (B/tet) | total (B/tet) |\n"
            "|---|---:|---:|---:|---:|\n";
  double full_total_bytes = 0.0;
  for (const EffectSet& set : effect_sets()) {
    ForceRow row{&set, {}};
    for (const SceneSetup& scene : scenes) {
      const SimModel model = model_for(scene, set);
      std::vector<double> per_threads;
      for (std::size_t t = 0; t < thread_counts.size(); ++t) {
        SimState state = make_rest_state(model, pools[t]);
        const ForceEvaluationTiming timing =
            time_force_evaluations(model, state, 1e-3, o.min_time_s, kRepetitions);
        std::cout << set.name << ", " << model.tet_count << " tets, "
                  << thread_label(thread_counts[t]) << ": " << format(timing.ns_per_tet)
                  << " ns/tet (" << timing.evaluations << " evaluations)" << std::endl;
        per_threads.push_back(timing.ns_per_tet);
        if (&scene == &scenes.back() && t == 0) {
          const double tets = static_cast<double>(model.tet_count);
          const double m = model_bytes(model) / tets, s = state_bytes(state) / tets;
          memory << "| " << set.name << " | " << model.tet_count << " | " << format(m, 4) << " | "
                 << format(s, 4) << " | " << format(m + s, 4) << " |\n";
          full_total_bytes = m + s;  // the last set is the full model
        }
      }
      row.ns_per_tet.push_back(per_threads);
    }
    force_rows.push_back(row);
  }
  auto force_table = [&](auto cell) {
    std::ostringstream table;
    table << "| effects |";
    for (int tets : o.tet_counts) table << " " << tets << " |";
    table << "\n|---|";
    for (std::size_t i = 0; i < o.tet_counts.size(); ++i) table << "---:|";
    table << "\n";
    for (const ForceRow& row : force_rows) {
      table << "| " << row.set->name << " |";
      for (const auto& per_threads : row.ns_per_tet) table << " " << cell(per_threads) << " |";
      table << "\n";
    }
    return table.str();
  };
  const ParallelCeiling ceiling = measure_parallel_ceiling(threads, 3);
  std::cout << "this machine on " << threads << " threads: " << format(ceiling.speedup(), 3)
            << "x (independent multiply-add chains)" << std::endl;

  // ---- What an effect that is off costs: the normal build against one without the effect.
  const SceneSetup& default_size = scenes.front();
  std::ostringstream effect_off;
  effect_off << "| effect left off | scene | normal build (ns/tet) | build without it (ns/tet) | "
                "difference of the bests | median of the paired differences | instructions per "
                "tet, normal build | instructions per tet, build without it | difference in "
                "instructions |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  double worst_difference = -std::numeric_limits<double>::infinity(), control_difference = 0.0;
  // Over the rows with an effect; unset when any row could not be counted.
  double worst_instruction_difference = -std::numeric_limits<double>::infinity();
  bool instructions_counted = true;
  std::string counting_command;
  const double effect_off_run_s = std::min(o.min_time_s, kEffectOffRunS);
  for (std::size_t i = 0; i < effect_off_cases().size(); ++i) {
    const EffectOffCase& c = effect_off_cases()[i];
    const SimModel model = effect_off_model(default_size, c);
    const SimState state = make_rest_state(model);
    const BuildComparison comparison = compare_force_builds(
        model, state, build_without(c.without), 1e-3, effect_off_run_s, kEffectOffRounds);
    const double difference = comparison.normal_ns_per_tet / comparison.other_ns_per_tet - 1.0;
    if (c.without == 0)
      control_difference = difference;
    else
      worst_difference = std::max(worst_difference, difference);
    std::cout << c.effect << " off: " << format(comparison.normal_ns_per_tet) << " ns/tet against "
              << format(comparison.other_ns_per_tet) << " without it" << std::endl;
    effect_off << "| " << c.effect << " | " << c.scene << " | "
               << format(comparison.normal_ns_per_tet) << " | "
               << format(comparison.other_ns_per_tet) << " | " << fixed(100.0 * difference)
               << " % | " << fixed(100.0 * comparison.relative_difference) << " % | ";
    if (c.without == 0) {  // the same build twice: nothing to count apart
      effect_off << "– | – | – |\n";
      continue;
    }
    std::string command;
    const std::optional<double> normal =
        count_instructions(i, false, o.tet_counts.front(), model.tet_count, command);
    const std::optional<double> without =
        count_instructions(i, true, o.tet_counts.front(), model.tet_count, command);
    if (normal && without) {
      const double instruction_difference = *normal / *without - 1.0;
      worst_instruction_difference = std::max(worst_instruction_difference, instruction_difference);
      counting_command = command;
      std::cout << "  instructions per tet: " << format(*normal, 6) << " against "
                << format(*without, 6) << std::endl;
      effect_off << format(*normal, 6) << " | " << format(*without, 6) << " | "
                 << fixed(100.0 * instruction_difference, 3) << " % |\n";
    } else {
      instructions_counted = false;
      effect_off << "not counted (valgrind missing or failed) | | |\n";
    }
  }

  // ---- Whole steps of the default scene under a held pull, 1 ms intervals, each integrator.
  std::ostringstream stepping;
  stepping << "| tets | threads | integrator | steps/s | mean step (ms) | real-time factor |\n"
              "|---:|---:|---|---:|---:|---:|\n";
  std::optional<double> target_size_factor;  // central difference, 10583 tets, most threads
  for (int tets : o.stepping_tet_counts) {
    const SceneSetup scene = default_scene(tets);
    const std::vector<PointLoad> pull =
        seed_pull_loads(scene.mesh, build_model(scene.mesh, scene.model_options));
    for (std::size_t t = 0; t < thread_counts.size(); ++t)
      for (IntegratorKind kind : kAllIntegrators) {
        ModelOptions options = scene.model_options;
        options.integrator.kind = kind;
        options.integrator.step_s = 1e-3;
        const SimModel model = build_model(scene.mesh, options);
        SimState state = make_rest_state(model, pools[t]);
        advance(model, state, {pull, {}}, 1e-3);  // warm-up: first factorisation, caches
        // Best of three runs from the same state, as for the force figures.
        SteppingTiming timing;
        for (int run = 0; run < kSteppingRepetitions; ++run) {
          SimState copy = state;
          const SteppingTiming attempt = time_stepping(model, copy, {pull, {}}, 1e-3, o.min_time_s);
          if (run == 0 || attempt.real_time_factor() > timing.real_time_factor()) timing = attempt;
        }
        std::cout << model.tet_count << " tets, " << thread_label(thread_counts[t]) << ", "
                  << integrator_name(kind) << ": " << format(timing.steps_per_s())
                  << " steps/s, real-time factor " << format(timing.real_time_factor())
                  << std::endl;
        stepping << "| " << model.tet_count << " | " << thread_counts[t] << " | "
                 << integrator_name(kind) << " | " << format(timing.steps_per_s()) << " | "
                 << format(1e3 * timing.simulated_s / std::max(1, timing.steps.substeps)) << " | "
                 << format(timing.real_time_factor()) << " |\n";
        if (tets == 10583 && kind == IntegratorKind::central_difference &&
            t + 1 == thread_counts.size())
          target_size_factor = timing.real_time_factor();
      }
  }

  // The seed's Table 1 beside ours, then the workstation (on its own: nothing else running).
  const std::vector<Table1Row> table1 =
      run_table1(o.tet_counts, o.table1_simulated_s, pools.back());
  const std::filesystem::path workstation = o.workstation.value_or(default_workstation());
  const WorkstationMemory workstation_memory =
      measure_workstation(workstation, o.workstation_tets, o.workstation_seconds);
  if (workstation_memory.peak_mb)
    std::cout << "workstation peak resident memory: " << fixed(*workstation_memory.peak_mb)
              << " MB (" << o.workstation_tets << " tets, " << number(o.workstation_seconds)
              << " s; target <= " << number(kWorkstationTargetMb) << " MB)" << std::endl;
  else
    std::cout << "workstation peak resident memory: " << workstation_memory.outcome << std::endl;

  std::ostringstream line;
  line << "liversim-cli bench --tets ";
  for (std::size_t i = 0; i < o.tet_counts.size(); ++i) line << (i ? "," : "") << o.tet_counts[i];
  line << " --stepping-tets ";
  for (std::size_t i = 0; i < o.stepping_tet_counts.size(); ++i)
    line << (i ? "," : "") << o.stepping_tet_counts[i];
  line << " --threads " << threads << " --min-time " << o.min_time_s << " --table1-seconds "
       << number(o.table1_simulated_s) << " --workstation-tets " << o.workstation_tets
       << " --workstation-seconds " << number(o.workstation_seconds);
  if (o.workstation) line << " --workstation " << o.workstation->string();
  TimingSettings table1_settings;
  table1_settings.simulated_s = o.table1_simulated_s;

  // The targets, each against what was measured above.
  const ForceRow& full = force_rows.back();
  const double full_one_thread = full.ns_per_tet.back().front();
  const double full_speedup =
      thread_counts.size() > 1 ? full_one_thread / full.ns_per_tet.back().back() : 1.0;
  auto verdict = [](bool met) { return met ? "met" : "**not met**"; };
  std::ostringstream targets;
  targets << "| target (issue 6) | measured | verdict |\n|---|---:|---|\n"
          << "| full model ≤ 50 ns per tet per force evaluation, one thread ("
          << o.tet_counts.back() << " tets) | " << format(full_one_thread) << " ns | "
          << verdict(full_one_thread <= 50.0) << " |\n"
          << "| ≥ 1.8× on two threads (full model, " << o.tet_counts.back() << " tets) | "
          << format(full_speedup, 3)
          << "× (this machine's own ceiling: " << format(ceiling.speedup(), 3) << "×) | "
          << (thread_counts.size() > 1 ? verdict(full_speedup >= 1.8) : "not measured") << " |\n"
          << "| 10583-tet liver at real-time factor ≥ 1, 1 ms steps, central difference, "
          << thread_label(thread_counts.back()) << " | "
          << (target_size_factor ? format(*target_size_factor) : std::string("not measured"))
          << " | " << (target_size_factor ? verdict(*target_size_factor >= 1.0) : "not measured")
          << " |\n"
          << "| full model ≤ 1 KiB per tet (model + state) | " << format(full_total_bytes, 4)
          << " B | " << verdict(full_total_bytes <= 1024.0) << " |\n"
          << "| an effect left off costs ≤ 3 % over a build without it | "
          << (instructions_counted ? "instructions executed (callgrind): largest " +
                                         fixed(100.0 * worst_instruction_difference, 3) + " %; "
                                   : std::string("instructions not counted (no valgrind); "))
          << "wall time, difference of the bests: largest " << fixed(100.0 * worst_difference)
          << " % (positive: the normal build was slower), the normal build against itself "
          << fixed(100.0 * control_difference) << " % | "
          << (instructions_counted
                  ? std::string(verdict(worst_instruction_difference <= 0.03)) + " (instructions)" +
                        (worst_difference <= 0.03 ? ", met (wall time)"
                                                  : ", not met in wall time (see below)")
              : worst_difference <= 0.03 ? std::string(verdict(true))
              : worst_difference <= std::abs(control_difference)
                  ? std::string("**not resolved** (within the measurement's own spread)")
                  : std::string(verdict(false)))
          << " |\n"
          << "| workstation ≤ 600 MB resident with the 10583-tet liver | "
          << (workstation_memory.peak_mb ? fixed(*workstation_memory.peak_mb) + " MB"
                                         : std::string("not measured"))
          << " | "
          << (workstation_memory.peak_mb ? verdict(*workstation_memory.peak_mb <= 600.0)
                                         : "not measured")
          << " |\n";

  std::ostringstream md;
  md << "# Performance\n\n"
     << written_by(line.str()) << "\n\nElement loops built for " << element_kernel_instruction_set()
     << ". Wall-clock time on this machine (the same build has run 2 to 3 times slower on "
        "other virtual machines of this kind: compare figures only within one run); each force "
        "figure is the best of "
     << kRepetitions << " runs of at least " << o.min_time_s
     << " s (this virtual machine's run-to-run spread is up to 30 %, so the least disturbed run "
        "is the figure).\n\n"
     << "## Targets\n\n"
     << targets.str() << "\n## Internal-force evaluation (ns per tetrahedron)\n\n"
     << "One `compute_internal_forces` of the built-in liver at rest (viscous regions advance "
        "their history by 1 ms each time), per column size (the seed's five meshes). Effect laws "
        "as in the accuracy study (docs/accuracy-study.md). All run vectorised element loops "
        "(four elements per instruction with AVX2); viscous ones in blocks of 64 elements, "
        "stage by stage, leaving yielding or collapsed elements to the general update.\n\n"
     << "### " << thread_label(1) << "\n\n"
     << force_table([](const std::vector<double>& v) { return format(v.front()); });
  if (thread_counts.size() > 1)
    md << "\n### " << thread_label(thread_counts.back()) << "\n\n"
       << force_table([](const std::vector<double>& v) { return format(v.back()); })
       << "\n### Speed-up of " << thread_label(thread_counts.back()) << " over one\n\n"
       << force_table(
              [](const std::vector<double>& v) { return format(v.front() / v.back(), 3) + "×"; })
       << "\nWhat this machine itself allows: independent multiply-add chains in the element "
          "loops' instruction set (no memory traffic, nothing shared; `measure_parallel_ceiling`) "
          "run "
       << format(ceiling.speedup(), 3) << "× faster on " << ceiling.threads
       << " threads than on one (" << fixed(ceiling.one_thread_s * 1e3) << " ms against "
       << fixed(ceiling.all_threads_s * 1e3)
       << " ms, best of 3). Both figures vary from run to run on this virtual machine; where the "
          "element loops fall short of the ceiling, memory (the vectorised loops gather node "
          "positions and stream some 200 bytes per element) and a worker descheduled on the last "
          "chunk are the suspects, not yet measured apart.\n";
  md << "\n## What an effect that is off costs\n\n"
     << "The force loops are also compiled without one effect each (`forces_variants.h`: the "
        "effect's branches and kernels are not in that build at all; gravity's are its weight and "
        "its support's push, added once per evaluation outside the element loops). Each row times "
        "one evaluation of the tissue's forces (`compute_tissue_forces`: the internal forces and, "
        "with gravity, the weight and the support's push) on the same "
        "scene, with that effect off, on the normal build and on the build without it, back to "
        "back, "
     << kEffectOffRounds << " rounds of runs of at least " << number(effect_off_run_s * 1e3)
     << " ms (alternating which goes first); the times are each build's best. The difference "
        "judged is that of the two bests: other work on this machine only ever adds time, so a "
        "build's fastest run is the best estimate of its own cost. The median over the rounds of "
        "each back-to-back pair's difference is shown beside it: it would cancel a slow drift of "
        "the machine's speed, but any stall inside one run of a pair moves it by percents. The "
        "first row is the control: the normal build timed against itself the same way, the "
        "measurement's own spread. One thread, "
     << default_size.description
     << ".\n\nTime on this shared virtual machine moves by more than the 3 % judged, so each "
        "row also counts the instructions the force loops execute on each build: "
     << kCountedEvaluations
     << " evaluations under callgrind, which counts instructions rather than seconds and gives "
        "the same count on every run whatever else the machine is doing. Equal counts mean the "
        "effect that is off costs no work; a wall-time difference left beside equal counts is "
        "code placement or the machine. Command of each count (here the last row's, build without "
        "the effect): `"
     << (counting_command.empty() ? std::string("not run: valgrind missing") : counting_command)
     << "`.\n\n"
     << effect_off.str()
     << "\nLesions, cutting and haptics are not effects of the force loops: a lesion is only "
        "other per-element moduli (the same arrays, no branch); a cut changes the mesh and "
        "rebuilds the model (its cost: "
        "cutting-performance.md), "
        "and the haptic force path runs on the servo thread, outside the force loops.\n"
     << "\n## Memory (bytes per tetrahedron, " << o.tet_counts.back()
     << "-tet target size)\n\nHeap arrays of the model and of a central-difference state "
        "(`model_bytes`, `state_bytes`).\n\n"
     << memory.str() << "\n## Whole steps\n\nThe default scene ("
     << "built-in liver, 0.5 N pull over the surface within 20 mm of the marked point) advanced "
        "in 1 ms intervals after one warm-up interval, best of "
     << kSteppingRepetitions << " runs of at least " << o.min_time_s
     << " s from the same state (two threads vary much more from run to run than one here); "
        "explicit schemes split a 1 ms step that is above their stability limit (mean step below "
        "1 ms). Threads run the force loops; "
        "the implicit schemes' assembly and factorisation run on one thread.\n\n"
     << stepping.str() << "\n## The seed's Table 1 side by side\n\n"
     << "Deformation time at the seed's mesh sizes: the seed's pull, "
     << number(table1_settings.force_n) << " N along +z (anterior) spread over the surface within "
     << number(table1_settings.load_radius_m * 1e3)
     << " mm of the marked point, from rest, with the default integrator (central difference) "
        "and with RK4 (the seed's scheme), each requesting the seed's step Δt = "
     << number(table1_settings.frame_s * 1e3) << " ms.\n\n"
     << table1_markdown(table1, o.table1_simulated_s)
     << "\nOur deformation time: the wall time of simulating " << number(o.table1_simulated_s)
     << " s of the pull in frames of " << number(table1_settings.frame_s * 1e3)
     << " ms (one `advance()` per frame; the model build is excluded; "
     << thread_label(thread_counts.back())
     << "), in ms. "
        "\"steps\" counts the integrator's steps: an explicit step above the stability "
        "limit is split by the engine, so there can be more steps than frames. The real-time "
        "factor is "
        "simulated time over wall time (≥ 1: faster than real time). Seed columns: the seed's "
        "Table 1 (its unit is not stated and is read as ms; its \"deformation time\" is not "
        "defined; i7-10700); [3] conical-spring model, [14] FEM with optimised implicit Euler. "
        "Our cutting column: the cost of a cut update is measured by `liversim-cli bench-cut` "
        "(docs/cutting-performance.md). Sizes that are not the seed's "
        "have no seed figures (-). The same measurement with more detail: `liversim-cli "
        "experiment timing` (docs/seed-experiments.md).\n"
     << "\n## Workstation peak resident memory\n\n"
     << "The workstation (`liversim`) run as a child process with the built-in liver, closed by "
        "its own timer; the figure is the child's peak resident set size (`wait4` `ru_maxrss`), "
        "in MB (1 MB = 10^6 bytes). Command: `"
     << workstation_memory.command << "` (" << o.workstation_tets << " tets, "
     << number(o.workstation_seconds) << " s after the window is shown). Target: ≤ "
     << number(kWorkstationTargetMb) << " MB with the 10583-tet liver.\n\n";
  if (workstation_memory.peak_mb)
    md << "Peak resident memory: " << fixed(*workstation_memory.peak_mb) << " MB against the "
       << "target ≤ " << number(kWorkstationTargetMb)
       << " MB: " << (*workstation_memory.peak_mb <= kWorkstationTargetMb ? "met" : "NOT met")
       << (o.workstation_tets != 10583 ? " (measured at another size than the target's)" : "")
       << ".\n";
  else
    md << "Peak resident memory: " << workstation_memory.outcome << ".\n";
  return write_report(o.output_dir / "performance.md", md.str());
}

}  // namespace

std::function<std::optional<int>()> add_bench_command(CLI::App& app) {
  auto options = std::make_shared<BenchOptions>();
  auto* bench =
      app.add_subcommand("bench",
                         "Measure force-evaluation cost per effect set and mesh size, memory per "
                         "tetrahedron and whole-step rates; write docs/performance.md");
  BenchOptions& o = *options;
  bench->add_option("--tets", o.tet_counts, "Built-in liver sizes of the force benchmark")
      ->delimiter(',')
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  bench->add_option("--stepping-tets", o.stepping_tet_counts, "Liver sizes of the step benchmark")
      ->delimiter(',')
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  bench
      ->add_option("--threads", o.threads,
                   "Threads of the multithreaded runs, besides one (default: the engine's, "
                   "LIVERSIM_THREADS or the hardware's)")
      ->check(CLI::Range(1, 256));
  bench->add_option("--min-time", o.min_time_s, "Least wall time of each measurement (s)")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  bench->add_option("--output-dir", o.output_dir, "Where performance.md goes")
      ->capture_default_str();
  bench
      ->add_option("--table1-seconds", o.table1_simulated_s,
                   "Simulated time of each case of the seed's Table 1 beside ours (s)")
      ->check(CLI::Range(TimingSettings{}.frame_s, 3600.0))
      ->capture_default_str();
  bench->add_option("--workstation", o.workstation,
                    "The workstation executable whose peak memory is measured (default: "
                    "liversim beside liversim-cli)");
  bench
      ->add_option("--workstation-tets", o.workstation_tets,
                   "Liver size of the workstation memory run")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  bench
      ->add_option("--workstation-seconds", o.workstation_seconds,
                   "How long the workstation runs after its window is shown (s)")
      ->check(CLI::Range(0.001, 86'400.0))
      ->capture_default_str();
  // Internal, for the instruction counts of the effect-off table (count_instructions).
  bench->add_option("--effect-off-case", o.effect_off_case)->group("");
  bench->add_flag("--without-effect", o.without_effect)->group("");
  bench->add_option("--evaluations", o.evaluations)->check(CLI::Range(1, 100000))->group("");
  return [options, bench]() -> std::optional<int> {
    if (!bench->parsed()) return std::nullopt;
    if (options->effect_off_case)
      return guarded([&] { return evaluate_effect_off_case(*options); });
    return guarded([&] { return run_bench(*options); });
  };
}

}  // namespace liversim::cli
