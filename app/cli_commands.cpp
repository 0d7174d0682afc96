#include "cli_commands.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/engine/viscous_tissue.h"
#include "liversim/interaction/grab.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/data_paths.h"
#include "liversim/scenario/scenario.h"

#ifdef LIVERSIM_HAVE_RENDER
#include "render/curve_plot.h"
#include "render/liver_scene.h"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

namespace liversim::cli {

int fail(const std::string& message) {
  std::cerr << "liversim-cli: error: " << message << "\n";
  return 2;
}

std::string number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

std::string format(double value, int precision) {
  std::ostringstream text;
  text << std::setprecision(precision) << value;
  return text.str();
}

std::string today_utc() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
  return text;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto at = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(at, values.size() - 1)];
}

std::string processor_name() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos)
      return line.substr(line.find(':') + 2);
  return "unknown processor";
}

int write_report(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  if (!out) return fail("cannot write " + file.string());
  std::cout << "wrote " << file.string() << "\n";
  return 0;
}

std::string written_by(const std::string& command) {
  return "Written by `" + command + "` on " + today_utc() + " (" + processor_name() + ", " +
         std::to_string(std::thread::hardware_concurrency()) + " hardware threads).";
}

void append_table_row(const std::filesystem::path& file, const std::string& header,
                      const std::string& row) {
  std::error_code error;
  const bool has_header =
      std::filesystem::exists(file, error) && std::filesystem::file_size(file, error) > 0 && !error;
  std::ofstream out(file, std::ios::app);
  if (!has_header) out << header << "\n";
  out << row << "\n";
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
  std::cout << "wrote a row of " << file.string() << "\n";
}

IntegratorKind integrator_kind(const std::string& name) {
  if (auto kind = integrator_from_name(name)) return *kind;
  std::string valid;
  for (IntegratorKind kind : kAllIntegrators)
    valid += (valid.empty() ? "" : ", ") + std::string(integrator_name(kind));
  throw std::invalid_argument("unknown integrator '" + name + "': expected one of " + valid);
}

IntegratorSettings integrator_settings(const std::string& name, double dt_s) {
  IntegratorSettings settings;
  settings.kind = integrator_kind(name);
  if (!std::isfinite(dt_s) || dt_s < 0.0)
    throw std::invalid_argument("--dt " + number(dt_s) +
                                " s is invalid: expected a finite value >= 0 (0: the stable step)");
  if (dt_s == 0.0 && !is_explicit(settings.kind))
    throw std::invalid_argument("--integrator " + name +
                                " is implicit and needs a step: give --dt S (e.g. --dt 0.002)");
  settings.step_s = dt_s;
  return settings;
}

ExperimentScene build_scene(int tet_count, const IntegratorSettings& integrator,
                            bool viscoelastic) {
  ExperimentScene built{default_scene(tet_count), {}, 0.0};
  ModelOptions options = built.scene.model_options;
  options.integrator = integrator;
  if (viscoelastic) {
    // material-test's assumed split of the seed's E = 3500 Pa (docs/viscous-tissue.md).
    options.regions[0].viscoelastic = kSeedViscoelastic;
  }
  const auto start = std::chrono::steady_clock::now();
  built.model = build_model(built.scene.mesh, options);
  built.build_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return built;
}

namespace {

// A surface model's file does not say its unit reliably: it is never guessed.
double metres_per_unit(const std::filesystem::path& surface,
                       const std::optional<std::string>& unit) {
  if (!unit)
    throw std::invalid_argument("--surface " + surface.string() +
                                " needs --length-unit mm, cm or m (the unit of its lengths)");
  for (const auto& [name, metres] : kLengthUnits)
    if (*unit == name) return metres;
  throw std::invalid_argument(surface.string() + ": --length-unit '" + *unit +
                              "' is unknown: expected mm, cm or m");
}

// How a surface model was meshed: Gmsh's wall time and each attempt's element count.
struct SurfaceMeshingRecord {
  double meshing_s = 0.0;
  std::vector<int> attempt_tets;
};

// Reads, checks and meshes a surface model, printing each finished meshing attempt and the
// wall time of reading and checking the surface and of meshing it (also into `record`).
SceneSetup mesh_surface(const std::filesystem::path& file, const std::optional<std::string>& unit,
                        int target_tet_count, SurfaceMeshingRecord* record) {
  const double metres = metres_per_unit(file, unit);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  std::optional<Clock::time_point> meshing_start;  // when Gmsh's first attempt begins
  int attempts = 0;
  auto progress = [&](const MeshingProgress& attempt) {
    if (attempt.tet_count == 0) {  // about to mesh
      if (!meshing_start) meshing_start = Clock::now();
      return true;
    }
    ++attempts;
    if (record) record->attempt_tets.push_back(attempt.tet_count);
    std::ostringstream line;
    line << std::fixed << std::setprecision(2) << "meshing attempt " << attempt.attempt << "/"
         << attempt.max_attempts << ": element size " << attempt.element_size_mm << " mm, "
         << attempt.tet_count << " tetrahedra\n";
    std::cout << line.str() << std::flush;
    return true;
  };
  SceneSetup scene = scene_from_surface(file, metres, target_tet_count, progress);
  const Clock::time_point end = Clock::now();
  const Clock::time_point meshed_from = meshing_start.value_or(end);
  if (record) record->meshing_s = std::chrono::duration<double>(end - meshed_from).count();
  std::ostringstream summary;
  summary << std::fixed << std::setprecision(3) << "surface read and checked in "
          << std::chrono::duration<double>(meshed_from - start).count() << " s; meshed in "
          << std::chrono::duration<double>(end - meshed_from).count() << " s wall time, "
          << attempts << (attempts == 1 ? " attempt" : " attempts") << " (target "
          << target_tet_count << " tetrahedra)\n";
  const int tets = static_cast<int>(scene.mesh.tet_count());
  if (std::abs(tets - target_tet_count) >
      SurfaceMeshingOptions{}.count_tolerance * target_tet_count)
    summary << "note: " << tets << " tetrahedra are off the target by more than the mesher's "
            << number(SurfaceMeshingOptions{}.count_tolerance * 100.0)
            << " %: the model's own triangles bound the mesh, so their size limits the count\n";
  std::cout << summary.str();
  return scene;
}

SceneSetup load_scene(const MeshSource& source, SurfaceMeshingRecord* meshing = nullptr) {
  if (source.length_unit && !source.surface)
    throw std::invalid_argument("--length-unit applies to --surface only");
  if (source.scenario) {
    if (source.file || source.fixed_set || source.surface)
      throw std::invalid_argument(
          "--scenario names its own organ: leave out --mesh, --surface and --fixed-set");
    const ScenarioReading reading = read_scenario_file(*source.scenario);
    if (!reading.scenario) {
      std::string message = source.scenario->string() + " is not a valid scenario:";
      for (const ScenarioError& error : reading.errors) message += "\n  " + error.text();
      throw std::invalid_argument(message);
    }
    return build_scene(*reading.scenario, source.scenario->parent_path());
  }
  if (source.file && source.surface)
    throw std::invalid_argument("--mesh and --surface are two organs: give one of them");
  if (source.file) return scene_from_file(*source.file, source.fixed_set);
  if (source.fixed_set) throw std::invalid_argument("--fixed-set needs --mesh");
  if (source.surface)
    return mesh_surface(*source.surface, source.length_unit, source.tet_count, meshing);
  return default_scene(source.tet_count);
}

// The mesh's boundary as a Wavefront OBJ in millimetres, triangles counter-clockwise from outside
// (what --surface reads back with --length-unit mm).
std::string boundary_obj(const SceneSetup& scene) {
  const BoundarySurface boundary = extract_surface(scene.mesh);
  std::ostringstream obj;
  obj << "# Boundary of " << scene.description << ": " << boundary.nodes.size() << " vertices, "
      << boundary.triangles.size()
      << " triangles, counter-clockwise from outside; lengths in millimetres.\n"
      << std::setprecision(10);
  for (NodeIndex n : boundary.nodes) {
    const Eigen::Vector3d p = scene.mesh.rest_position_m.at(n) * 1e3;
    obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  for (const auto& t : boundary.triangles)
    obj << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return obj.str();
}

// What mesh-report measured, for a row of its table.
struct MeshReportFigures {
  const MeshQualityReport& quality;
  double surface_gap_mean_m, surface_gap_max_m;  // rendered surface off the boundary nodes
  const SimModel& model;
  const std::optional<SimModel>& element_pressure;  // the model without averaged pressure
  const SurfaceMeshingRecord& meshing;
};

// One row of docs/mesh-quality.md's tables, appended to `table`: a surface model's with its
// meshing, any other organ's with the rendered surface's distance and the step without averaging.
void append_mesh_report_row(const std::filesystem::path& table, const MeshSource& source,
                            const MeshReportFigures& f) {
  const bool surface = source.surface.has_value();
  std::ostringstream header, row;
  header << "| organ | requested | tets | nodes | volume (L) | min / max dihedral (°) | max "
            "aspect R/3r | min / median height (mm) | inverted / degenerate | ";
  header << (surface ? "ω_max (rad/s) | explicit step (ms) | meshing time (s) | attempts |"
                     : "rendered surface off the boundary nodes, mean / max (mm) | ω_max (rad/s) | "
                       "explicit step (ms) | without averaged pressure: ω_max / step |");
  header << "\n|---|---:|---:|---:|---:|---|---:|---|---|"
         << (surface ? "---:|---:|---:|---|" : "---|---:|---:|---|");
  const std::string organ = source.surface    ? source.surface->filename().string()
                            : source.file     ? source.file->filename().string()
                            : source.scenario ? source.scenario->filename().string()
                                              : std::string("built-in liver");
  const bool requested = surface || (!source.file && !source.scenario);
  const MeshQualityReport& q = f.quality;
  row << std::fixed << "| " << organ << " | "
      << (requested ? std::to_string(source.tet_count) : std::string("–")) << " | " << q.tet_count
      << " | " << q.node_count << " | " << std::setprecision(4) << q.volume_m3 * 1e3 << " | "
      << std::setprecision(2) << q.min_dihedral_deg << " / " << q.max_dihedral_deg << " | "
      << q.max_aspect_ratio << " | " << q.min_height_m * 1e3 << " / " << q.median_height_m * 1e3
      << " | " << q.inverted_count << " / " << q.degenerate_count << " | ";
  if (!surface) row << 1e3 * f.surface_gap_mean_m << " / " << 1e3 * f.surface_gap_max_m << " | ";
  row << std::setprecision(0) << f.model.max_frequency_rad_per_s << " | " << std::setprecision(3)
      << f.model.stable_time_step_s * 1e3 << " | ";
  if (surface) {
    row << f.meshing.meshing_s << " | " << f.meshing.attempt_tets.size() << " (";
    for (std::size_t i = 0; i < f.meshing.attempt_tets.size(); ++i)
      row << (i ? ", " : "") << f.meshing.attempt_tets[i];
    row << ") |";
  } else if (f.element_pressure) {
    row << std::setprecision(0) << f.element_pressure->max_frequency_rad_per_s << " / "
        << std::setprecision(3) << f.element_pressure->stable_time_step_s * 1e3 << " |";
  } else {
    row << "the same (this organ is not averaged) |";
  }
  append_table_row(table, header.str(), row.str());
}

// What a material test records and the closed form it is compared with.
struct MaterialQuantity {
  const char* name;      // in the summary and on the plot's y axis
  const char* unit;      // "" for a strain
  const char* column;    // CSV column of the simulated value; "analytic_" + column beside it
  const char* equation;  // of the seed, in docs/viscous-tissue.md
};

MaterialQuantity material_quantity(MaterialTest test) {
  switch (test) {
    case MaterialTest::relaxation:
      return {"nominal axial stress", "Pa", "stress_pa", "Eq. 2"};
    case MaterialTest::creep:
      return {"axial strain", "", "strain", "Eq. 3"};
    case MaterialTest::yield_creep:
      return {"axial strain", "", "strain", "Eq. 4"};
  }
  throw std::logic_error("unknown material test");
}

// The curve of a held load: samples at t = 0 (the instantaneous jump) and after every step.
struct MaterialCurve {
  std::vector<double> time_s, simulated, analytic;
  double largest_relative_error = 0.0;
  double time_of_largest_error_s = 0.0;
};

// Bounds the run time and memory (three doubles per step) of a mistyped --dt.
constexpr double kMaxMaterialSteps = 1e7;

}  // namespace

int mesh_report(const MeshReportOptions& options) {
  return guarded([&] {
    SurfaceMeshingRecord meshing;
    const SceneSetup scene = load_scene(options.mesh, &meshing);
    const MeshQualityReport quality = assess_quality(scene.mesh);
    std::cout << scene.description << "\n" << quality;
    std::cout << "fixed nodes " << scene.model_options.fixed_nodes.size() << "\n";
    std::vector<double> visual_xyz;
    map_visual_positions(scene.visual, scene.mesh.rest_position_m, visual_xyz);
    double gap_sum = 0.0, gap_max = 0.0;
    for (std::size_t v = 0; v < scene.visual.vertex_count(); ++v) {
      const Eigen::Vector3d vertex(visual_xyz[3 * v], visual_xyz[3 * v + 1], visual_xyz[3 * v + 2]);
      const double gap =
          (vertex - scene.mesh.rest_position_m.at(scene.visual.surface.nodes[v])).norm();
      gap_sum += gap;
      gap_max = std::max(gap_max, gap);
    }
    const double gap_mean = gap_sum / std::max<std::size_t>(scene.visual.vertex_count(), 1);
    std::cout << std::fixed << std::setprecision(2)
              << "rendered surface off the physics boundary nodes: mean " << 1e3 * gap_mean
              << " mm, max " << 1e3 * gap_max << " mm\n";
    const SimModel model = build_model(scene.mesh, scene.model_options);
    std::cout << std::fixed << std::setprecision(0) << "highest frequency at rest "
              << model.max_frequency_rad_per_s << " rad/s; explicit central-difference step "
              << std::setprecision(3) << model.stable_time_step_s * 1e3 << " ms ("
              << std::setprecision(2) << model.stable_step_safety
              << " x 2/omega, E = " << std::setprecision(0)
              << model.regions[0].tissue.youngs_modulus_pa << " Pa, nu = " << std::setprecision(3)
              << model.regions[0].tissue.poisson_ratio << ")\n";
    // What the averaging of the pressure over the nodes does to the step (docs/mesh-quality.md).
    std::optional<SimModel> element_pressure;
    if (scene.model_options.average_nodal_pressure) {
      ModelOptions without = scene.model_options;
      without.average_nodal_pressure = false;
      element_pressure = build_model(scene.mesh, without);
      std::cout << std::setprecision(0) << "without averaged pressure: highest frequency "
                << element_pressure->max_frequency_rad_per_s << " rad/s; step "
                << std::setprecision(3) << element_pressure->stable_time_step_s * 1e3 << " ms\n";
    }
    std::cout << std::defaultfloat;
    if (options.table_output)
      append_mesh_report_row(*options.table_output, options.mesh,
                             {quality, gap_mean, gap_max, model, element_pressure, meshing});
    if (options.surface_output) return write_report(*options.surface_output, boundary_obj(scene));
    return 0;
  });
}

int validate_scenarios(std::vector<std::filesystem::path> files) {
  if (files.empty()) {
    const std::filesystem::path folder = shipped_scenarios_folder();
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error))
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    if (error || files.empty())
      return fail("no shipped scenarios in " + folder.string() +
                  (error ? ": " + error.message() : std::string()));
    std::sort(files.begin(), files.end());
    std::cout << "shipped scenarios in " << folder.string() << ":\n";
  }
  int invalid = 0;
  for (const auto& file : files) {
    const ScenarioReading reading = read_scenario_file(file);
    if (reading.scenario) {
      std::cout << file.string() << ": valid: \"" << reading.scenario->title
                << "\" (format version " << reading.file_version
                << (reading.file_version < kScenarioFormatVersion ? ", migrated" : "") << ")\n";
      continue;
    }
    ++invalid;
    for (const ScenarioError& error : reading.errors)
      std::cout << file.string() << ": " << error.text() << "\n";
  }
  return invalid == 0 ? 0 : 1;
}

int simulate(const SimulateOptions& options) {
  return guarded([&]() -> int {
    if (!options.force_n.allFinite()) return fail("--force must be three finite numbers");
    SceneSetup scene = load_scene(options.mesh);
    // --integrator and --dt override the scene's scheme (a scenario's own, else central
    // difference) and its step; a scenario's other integrator settings stay.
    IntegratorSettings& integrator = scene.model_options.integrator;
    if (options.integrator || options.dt_s != 0.0) {
      const IntegratorSettings chosen = integrator_settings(
          options.integrator.value_or(std::string(integrator_name(integrator.kind))), options.dt_s);
      integrator.kind = chosen.kind;
      integrator.step_s = chosen.step_s;
    }
    const SimModel model = build_model(scene.mesh, scene.model_options);
    const NodeIndex node = options.node.value_or(anterior_marked_node(scene.mesh));
    if (node < 0 || static_cast<std::size_t>(node) >= model.node_count)
      return fail("--node " + std::to_string(node) + " is outside the mesh (" +
                  std::to_string(model.node_count) + " nodes, numbered from 0)");
    if (model.is_fixed[node]) return fail("--node " + std::to_string(node) + " is a fixed node");

    // Spread the load with the same bump weights a grab uses (weights sum to 1).
    const Grab patch =
        grab_surface(extract_surface(scene.mesh), scene.mesh.rest_position_m, model.lumped_mass_kg,
                     scene.mesh.rest_position_m.at(node), options.load_radius_m, 1.0);
    std::vector<PointLoad> loads;
    for (std::size_t i = 0; i < patch.nodes.size(); ++i)
      loads.push_back({patch.nodes[i], options.force_n * patch.stiffness_n_per_m[i]});
    const StepInputs inputs{loads, {}};

    std::ofstream csv;
    if (options.csv_output) {
      csv.open(*options.csv_output);
      if (!csv) return fail("cannot write " + options.csv_output->string());
      csv << "time_s,ux_m,uy_m,uz_m\n";
    }
    SimState state = make_rest_state(model, shared_worker_pool());
    const Eigen::Vector3d rest = model.rest_position_m.at(node);
    auto write_sample = [&] {
      const Eigen::Vector3d u = state.position_m.at(node) - rest;
      if (csv) csv << state.time_s << "," << u.x() << "," << u.y() << "," << u.z() << "\n";
    };
    write_sample();
    const auto wall_start = std::chrono::steady_clock::now();
    const int samples =
        std::max(1, static_cast<int>(std::ceil(options.duration_s / options.sample_interval_s)));
    StepReport steps;
    for (int i = 0; i < samples; ++i) {
      accumulate(steps, advance(model, state, inputs, options.duration_s / samples));
      write_sample();
    }
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const Eigen::Vector3d u = state.position_m.at(node) - rest;
    if (!u.allFinite()) return fail("the simulation diverged (non-finite displacement)");

    std::cout << std::setprecision(6) << scene.description << "; load "
              << options.force_n.transpose() << " N on node " << node << " spread over "
              << patch.nodes.size() << " surface nodes\n"
              << integrator_name(model.integrator.kind) << ": " << steps.substeps << " steps of "
              << steps.smallest_substep_s * 1e3 << " to " << steps.largest_substep_s * 1e3
              << " ms, " << steps.force_evaluations << " force evaluations";
    if (!is_explicit(model.integrator.kind))
      std::cout << ", " << steps.newton_iterations << " Newton iterations, " << steps.factorizations
                << " factorisations"
                << (steps.unconverged_steps > 0
                        ? " (" + std::to_string(steps.unconverged_steps) + " steps unconverged)"
                        : std::string());
    std::cout << "; " << wall_s << " s wall time\n";
    if (is_explicit(model.integrator.kind)) {
      // What the engine had to do to stay stable (the seed's RK4 at 2 ms needs this).
      std::cout << "stable explicit step at rest " << model.stable_time_step_s * 1e3
                << " ms (central difference); compression and fibres stiffened it up to "
                << steps.max_stiffening << "x";
      if (steps.stability_limited_steps > 0)
        std::cout << "; " << steps.stability_limited_steps << " steps shortened below the "
                  << "requested " << model.integrator.step_s * 1e3
                  << " ms by the stability limit (smallest " << steps.smallest_stable_step_s * 1e3
                  << " ms)";
      std::cout << "\n";
    }
    std::cout << "displacement of node " << node << " after " << state.time_s
              << " s (mm): " << (u * 1e3).transpose() << "  |u| = " << u.norm() * 1e3 << "\n";
    if (csv) std::cout << "wrote " << options.csv_output->string() << "\n";
    return 0;
  });
}

int material_test(const MaterialTestOptions& o) {
  return guarded([&]() -> int {
    if (!std::isfinite(o.dt_s) || o.dt_s <= 0.0)
      return fail("--dt " + number(o.dt_s) + " s is invalid: expected a finite value > 0");
    if (!std::isfinite(o.duration_s) || o.duration_s < o.dt_s)
      return fail("--duration " + number(o.duration_s) +
                  " s is invalid: expected a finite value of at least --dt (" + number(o.dt_s) +
                  " s)");
    if (o.duration_s / o.dt_s > kMaxMaterialSteps)
      return fail("--duration / --dt gives " + number(o.duration_s / o.dt_s) + " steps; at most " +
                  number(kMaxMaterialSteps) + " are allowed");
    const bool holds_strain = o.test == MaterialTest::relaxation;
    if (holds_strain && (!std::isfinite(o.strain) || o.strain <= 0.0))
      return fail("--strain " + number(o.strain) + " is invalid: expected a finite value > 0");
    if (!holds_strain && (!std::isfinite(o.stress_pa) || o.stress_pa <= 0.0))
      return fail("--stress " + number(o.stress_pa) +
                  " Pa is invalid: expected a finite value > 0");

    ViscousTissueParameters parameters{{o.e1_pa, o.e2_pa, o.eta1_pa_s}, o.poisson_ratio, {}};
    if (o.test == MaterialTest::yield_creep)
      parameters.viscoplastic =
          ViscoplasticParameters{o.yield_limit_pa, o.eta2_pa_s_pow_n, o.creep_index_n};
    if (auto message = validate(parameters)) return fail(*message);
    if (o.test == MaterialTest::yield_creep && o.stress_pa <= o.yield_limit_pa)
      return fail("--stress " + number(o.stress_pa) + " Pa must exceed the yield limit --yield " +
                  number(o.yield_limit_pa) + " Pa: below it yield-creep is plain creep");

    const ViscoelasticParameters& ve = parameters.viscoelastic;
    const double tau_s = ve.relaxation_time_s();
    const double tau_c_s = ve.retardation_time_s();
    const double e_instant_pa = ve.instantaneous_modulus_pa();
    auto analytic = [&](double t_s) {
      switch (o.test) {
        case MaterialTest::relaxation:  // Eq. 2
          return ve.e2_pa * o.strain +
                 (e_instant_pa * o.strain - ve.e2_pa * o.strain) * std::exp(-t_s / tau_s);
        case MaterialTest::creep:  // Eq. 3
          return o.stress_pa / ve.e2_pa +
                 o.stress_pa * (1.0 / e_instant_pa - 1.0 / ve.e2_pa) * std::exp(-t_s / tau_c_s);
        case MaterialTest::yield_creep:  // Eq. 4 = Eq. 3 + the viscoplastic creep
          return o.stress_pa / ve.e2_pa +
                 o.stress_pa * (1.0 / e_instant_pa - 1.0 / ve.e2_pa) * std::exp(-t_s / tau_c_s) +
                 (o.stress_pa - o.yield_limit_pa) * std::pow(t_s, o.creep_index_n) /
                     o.eta2_pa_s_pow_n;
      }
      throw std::logic_error("unknown material test");
    };

    UniaxialDriver driver(parameters);
    auto simulate_step = [&](double dt_s) {
      return holds_strain ? driver.step_to_stretch(1.0 + o.strain, dt_s)
                          : driver.step_to_nominal_stress(o.stress_pa, dt_s) - 1.0;
    };
    MaterialCurve curve;
    auto record = [&](double t_s, double simulated) {
      const double exact = analytic(t_s);
      const double relative_error = std::abs(simulated - exact) / std::abs(exact);
      curve.time_s.push_back(t_s);
      curve.simulated.push_back(simulated);
      curve.analytic.push_back(exact);
      if (relative_error > curve.largest_relative_error) {
        curve.largest_relative_error = relative_error;
        curve.time_of_largest_error_s = t_s;
      }
    };
    record(0.0, simulate_step(0.0));  // the load is applied as a step at t = 0
    // The tolerance keeps round-off in duration/dt from adding a last step of ~1e-13 s; a
    // duration that is not a multiple of dt ends with one shorter step.
    const auto steps = static_cast<long>(std::ceil(o.duration_s / o.dt_s * (1.0 - 1e-12)));
    double t_s = 0.0;
    for (long k = 1; k <= steps; ++k) {
      const double t_next_s = std::min(static_cast<double>(k) * o.dt_s, o.duration_s);
      const double simulated = simulate_step(t_next_s - t_s);
      t_s = t_next_s;
      record(t_s, simulated);
    }

    const MaterialQuantity quantity = material_quantity(o.test);
    const std::string unit = *quantity.unit ? std::string(" ") + quantity.unit : "";
    const char* test_names[] = {"relaxation", "creep", "yield-creep"};
    std::cout << std::setprecision(6) << "material-test " << test_names[static_cast<int>(o.test)]
              << ": E1 = " << ve.e1_pa << " Pa, E2 = " << ve.e2_pa << " Pa, eta1 = " << ve.eta1_pa_s
              << " Pa s (tau = " << tau_s << " s, tau_c = " << tau_c_s
              << " s), nu = " << o.poisson_ratio;
    if (parameters.viscoplastic)
      std::cout << ", yield limit = " << o.yield_limit_pa << " Pa, eta2 = " << o.eta2_pa_s_pow_n
                << " Pa s^n, n = " << o.creep_index_n;
    if (holds_strain)
      std::cout << "; axial strain " << o.strain << " held from t = 0\n";
    else
      std::cout << "; nominal axial stress " << o.stress_pa << " Pa held from t = 0\n";
    std::cout << "time step " << o.dt_s << " s: " << steps << " steps to " << t_s << " s\n"
              << quantity.name << " at t = " << t_s << " s: simulated " << curve.simulated.back()
              << unit << ", analytic (seed " << quantity.equation << ") " << curve.analytic.back()
              << unit << "\n"
              << std::scientific << std::setprecision(3)
              << "largest relative error over the curve: " << curve.largest_relative_error
              << std::defaultfloat << std::setprecision(6)
              << " (at t = " << curve.time_of_largest_error_s << " s)\n";

    if (o.table_output) {
      std::ostringstream row;
      row << "| " << test_names[static_cast<int>(o.test)] << " | " << quantity.equation << " | "
          << (holds_strain ? "strain " + number(o.strain) : "stress " + number(o.stress_pa) + " Pa")
          << " | " << number(o.dt_s) << " | " << number(t_s) << " | " << std::scientific
          << std::setprecision(1) << curve.largest_relative_error << std::defaultfloat << " | "
          << number(curve.time_of_largest_error_s) << " |";
      append_table_row(*o.table_output,
                       "| test | equation | held | step (s) | simulated (s) | largest relative "
                       "error over the curve | at t (s) |\n|---|---|---|---:|---:|---:|---:|",
                       row.str());
    }
    // The CSV first: a plot that cannot be drawn (no display) must not lose the computed curve.
    if (o.csv_output) {
      std::ofstream csv(*o.csv_output);
      if (!csv) return fail("cannot write " + o.csv_output->string());
      csv << "time_s," << quantity.column << ",analytic_" << quantity.column << ",relative_error\n"
          << std::setprecision(10);
      for (std::size_t i = 0; i < curve.time_s.size(); ++i)
        csv << curve.time_s[i] << "," << curve.simulated[i] << "," << curve.analytic[i] << ","
            << std::abs(curve.simulated[i] - curve.analytic[i]) / std::abs(curve.analytic[i])
            << "\n";
      if (!csv) return fail("writing " + o.csv_output->string() + " failed");
      std::cout << "wrote " << o.csv_output->string() << "\n";
    }
    if (o.plot_output) {
#ifdef LIVERSIM_HAVE_RENDER
      std::string title = holds_strain
                              ? "Relaxation under axial strain " + number(o.strain)
                              : "Creep under nominal stress " + number(o.stress_pa) + " Pa";
      if (parameters.viscoplastic) title += " (yield limit " + number(o.yield_limit_pa) + " Pa)";
      title += std::string(": simulated vs seed ") + quantity.equation;
      write_curve_plot_png(
          *o.plot_output, title, "time (s)",
          std::string(quantity.name) +
              (*quantity.unit ? std::string(" (") + quantity.unit + ")" : std::string()),
          curve.time_s,
          {{"simulated (dt = " + number(o.dt_s) + " s)", curve.simulated, false},
           {std::string("analytic, ") + quantity.equation, curve.analytic, true}},
          800, 500);
      std::cout << "wrote " << o.plot_output->string() << "\n";
#else
      return fail("cannot write " + o.plot_output->string() +
                  ": this liversim-cli was built without the renderer (LIVERSIM_BUILD_UI=OFF)");
#endif
    }
    return 0;
  });
}

#ifdef LIVERSIM_HAVE_RENDER
int screenshot(const ScreenshotOptions& options) {
  return guarded([&] {
    const SceneSetup scene = load_scene(options.mesh);
    LiverScene view(scene.mesh, scene.visual);
    write_screenshot_png(view, options.output, options.width, options.height);
    std::cout << "wrote " << options.output.string() << " (" << scene.description << ")\n";
    return 0;
  });
}

int demo(const ScreenshotOptions& options) {
  return guarded([&] {
    const SceneSetup scene = load_scene(options.mesh);
    const SimModel model = build_model(scene.mesh, scene.model_options);
    const NodeIndex node = anterior_marked_node(scene.mesh);
    const BoundarySurface& surface = scene.visual.surface;
    // Grab the anterior point and pull it 3 cm forward and down over 0.3 s, then hold.
    const Eigen::Vector3d grabbed = scene.mesh.rest_position_m.at(node);
    const Grab grab = grab_surface(surface, scene.mesh.rest_position_m, model.lumped_mass_kg,
                                   grabbed, 0.02, 300.0);
    SimState state = make_rest_state(model, shared_worker_pool());
    std::vector<NodeSpring> springs;
    const Eigen::Vector3d pull(0.0, -0.02, 0.03);
    constexpr int kFrames = 30;
    for (int frame = 1; frame <= kFrames; ++frame) {
      const double ramp = std::min(1.0, frame / 18.0);
      grab_springs(grab, grabbed + ramp * pull, springs);
      advance(model, state, StepInputs{{}, springs}, 1.0 / 60.0);
    }
    const Eigen::Vector3d handle = grabbed + pull;
    const Eigen::Vector3d force = grab_reaction_force_n(grab, handle, state.position_m);
    LiverScene view(scene.mesh, scene.visual);
    view.update_positions(state.position_m);
    view.show_grab_marker(handle);
    write_screenshot_png(view, options.output, options.width, options.height);
    std::cout << "demo: pulled " << scene.description << " by " << pull.norm() * 1e3 << " mm for "
              << state.time_s << " s; grabbed point moved "
              << (state.position_m.at(node) - grabbed).norm() * 1e3 << " mm; tool force "
              << force.norm() << " N\nwrote " << options.output.string() << "\n";
    return 0;
  });
}
#else
int screenshot(const ScreenshotOptions&) {
  return fail("this liversim-cli was built without the renderer (LIVERSIM_BUILD_UI=OFF)");
}
int demo(const ScreenshotOptions& options) {
  return screenshot(options);
}
#endif

}  // namespace liversim::cli
