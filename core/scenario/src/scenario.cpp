#include "liversim/scenario/scenario.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/parameter_ranges.h"
#include "liversim/engine/support.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/liver_geometry.h"
#include "liversim/meshing/surface_import.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace liversim {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;
namespace p = parameter;

// ---- Names of the enumerations, as written in files.

constexpr std::pair<OrganGeometry, std::string_view> kGeometryNameList[] = {
    {OrganGeometry::built_in_liver, "built-in-liver"},
    {OrganGeometry::tet_mesh_file, "tet-mesh-file"},
    {OrganGeometry::surface_file, "surface-file"},
};
constexpr std::pair<TaskKind, std::string_view> kTaskNameList[] = {
    {TaskKind::palpate_lesion, "palpate-lesion"},
    {TaskKind::retract_lobe, "retract-lobe"},
    {TaskKind::resect_lesion, "resect-lesion"},
};
template <class Enum>
using NameTable = std::span<const std::pair<Enum, std::string_view>>;

// Tools and integrators are named where they are defined (tool_name, integrator_name).
NameTable<ToolKind> tool_names() {
  static const std::vector<std::pair<ToolKind, std::string_view>> table = [] {
    std::vector<std::pair<ToolKind, std::string_view>> t;
    for (ToolKind kind : kToolKinds) t.emplace_back(kind, tool_name(kind));
    return t;
  }();
  return table;
}
NameTable<IntegratorKind> integrator_names() {
  static const std::vector<std::pair<IntegratorKind, std::string_view>> table = [] {
    std::vector<std::pair<IntegratorKind, std::string_view>> t;
    for (IntegratorKind kind : kAllIntegrators) t.emplace_back(kind, integrator_name(kind));
    return t;
  }();
  return table;
}

constexpr NameTable<OrganGeometry> kGeometryNames = kGeometryNameList;
constexpr NameTable<TaskKind> kTaskNames = kTaskNameList;

template <class Enum>
std::string_view name_of(NameTable<Enum> names, Enum value) {
  for (const auto& [v, name] : names)
    if (v == value) return name;
  return "?";
}

template <class Enum>
std::optional<Enum> named(NameTable<Enum> names, const Json& value) {
  if (value.is_string())
    for (const auto& [v, name] : names)
      if (value.get<std::string>() == name) return v;
  return std::nullopt;
}

template <class Enum>
std::string names_list(NameTable<Enum> names) {
  std::string list;
  for (const auto& [v, name] : names) list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

constexpr MetricInfo kMetrics[] = {
    {"task_time_s", "s", "time from the first tool contact to the end of the task"},
    {"path_length_mm", "mm", "distance the tool tip travelled"},
    {"movements", "", "separate tool movements (motion between pauses)"},
    {"economy_of_motion", "",
     "path of the movements over their straight-line distance (1: straight)"},
    {"idle_time_s", "s", "time the tool was still for at least the pause time"},
    {"peak_force_n", "N", "largest force on the tissue"},
    {"mean_force_n", "N", "mean force while in contact"},
    {"rms_force_n", "N", "root mean square force while in contact"},
    {"time_above_safe_force_s", "s", "time the force exceeded the safe threshold"},
    {"force_integral_n_s", "N·s", "force on the tissue integrated over the session"},
    {"peak_force_rate_n_per_s", "N/s", "fastest change of the force between servo frames"},
    {"tissue_damage_mm3", "mm³", "volume of tissue strained beyond the damage strain"},
    {"resected_volume_mm3", "mm³", "volume of the pieces cut free"},
    {"lesion_margin_mm", "mm", "least distance from the cut surface to the lesion"},
    {"lesion_breached", "", "1 when the cut entered the lesion, else 0"},
    {"plane_deviation_mm", "mm", "mean distance of the cut from the planned plane"},
    {"task_success", "", "1 when the task's goal was reached, else 0"},
    {"specimen_volume_mm3", "mm³", "volume of the specimens (pieces cut free, kept as bodies)"},
    {"specimen_contains_lesion", "", "1 when the lesion is whole in one specimen, else 0"},
    {"specimen_margin_mm", "mm", "least distance from the specimen's cut faces to the lesion"},
    {"specimen_r0", "",
     "1 when the specimen holds the whole lesion with the task's margin, else 0"},
    // The left hand's device, in a session with one in each hand (issue 43).
    {"left_path_length_mm", "mm", "distance the left hand's tool tip travelled"},
    {"left_movements", "", "separate movements of the left hand's tool"},
    {"left_economy_of_motion", "", "the left hand's economy of motion"},
    {"left_idle_time_s", "s", "time the left hand's tool was still for at least the pause time"},
    {"left_peak_force_n", "N", "largest force of the left hand's tool on the tissue"},
    {"left_mean_force_n", "N", "mean force of the left hand's tool while in contact"},
    {"left_rms_force_n", "N", "root mean square force of the left hand's tool while in contact"},
    {"left_time_above_safe_force_s", "s", "time the left hand's force exceeded the safe threshold"},
    {"left_force_integral_n_s", "N·s", "the left hand's force integrated over the session"},
    {"left_peak_force_rate_n_per_s", "N/s", "fastest change of the left hand's force"},
    {"both_hands_working_fraction", "",
     "share of the time either hand worked (moved or touched) when both did"},
};

// ---- Reading: a cursor over one JSON object that knows its path and collects errors.

std::string shown(const Json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string range_text(double min, double max, std::string_view unit) {
  const std::string u = unit.empty() ? "" : " " + std::string(unit);
  return format_number(min) + " to " + format_number(max) + u;
}

class Fields {
 public:
  // `known`: every key the object may have; any other is an error (a misspelt key would
  // otherwise be silently ignored).
  Fields(const Json& value, std::string path, std::vector<ScenarioError>& errors,
         std::initializer_list<std::string_view> known)
      : value_(value), path_(std::move(path)), errors_(errors) {
    if (!value_.is_object()) {
      fail_here(shown(value_) + " is invalid: expected an object");
      return;
    }
    for (const auto& [key, item] : value_.items())
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        std::string list;
        for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        errors_.push_back({at(key), "unknown field: expected one of " + list});
      }
  }

  bool is_object() const { return value_.is_object(); }
  bool has(std::string_view key) const { return value_.is_object() && value_.contains(key); }
  const Json* get(std::string_view key) const {
    if (!has(key)) return nullptr;
    return &value_.at(std::string(key));
  }
  std::string at(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }
  void fail(std::string_view key, std::string message) {
    errors_.push_back({at(key), std::move(message)});
  }
  void fail_here(std::string message) { errors_.push_back({path_, std::move(message)}); }

  void missing(std::string_view key, std::string_view expected) {
    fail(key, "missing: expected " + std::string(expected));
  }

  // A number in [min, max] (NaN and infinities are not JSON numbers; null is refused too).
  std::optional<double> number(std::string_view key, double min, double max, std::string_view unit,
                               bool required, std::string_view what = {}) {
    const Json* v = get(key);
    const std::string expected =
        (what.empty() ? std::string() : std::string(what) + ", ") + range_text(min, max, unit);
    if (!v) {
      if (required) missing(key, expected);
      return std::nullopt;
    }
    if (!v->is_number()) {
      fail(key, shown(*v) + " is invalid: expected a number, " + expected);
      return std::nullopt;
    }
    const double x = v->get<double>();
    if (!(x >= min && x <= max)) {
      fail(key, format_number(x) + " is invalid: expected " + expected);
      return std::nullopt;
    }
    return x;
  }
  std::optional<double> parameter(std::string_view key, std::string_view range_name,
                                  bool required) {
    const ParameterRange& r = parameter_range(range_name);
    return number(key, r.min, r.max, r.unit, required, r.label);
  }
  std::optional<int> integer(std::string_view key, int min, int max, bool required) {
    const Json* v = get(key);
    const std::string expected =
        "a whole number from " + std::to_string(min) + " to " + std::to_string(max);
    if (!v) {
      if (required) missing(key, expected);
      return std::nullopt;
    }
    const double x = v->is_number() ? v->get<double>() : std::nan("");
    if (!(std::floor(x) == x && x >= min && x <= max)) {
      fail(key, shown(*v) + " is invalid: expected " + expected);
      return std::nullopt;
    }
    return static_cast<int>(x);
  }
  std::optional<bool> boolean(std::string_view key, bool required) {
    const Json* v = get(key);
    if (!v) {
      if (required) missing(key, "true or false");
      return std::nullopt;
    }
    if (!v->is_boolean()) {
      fail(key, shown(*v) + " is invalid: expected true or false");
      return std::nullopt;
    }
    return v->get<bool>();
  }
  std::optional<std::string> text(std::string_view key, bool required, bool non_empty = false) {
    const Json* v = get(key);
    if (!v) {
      if (required) missing(key, non_empty ? "a non-empty text" : "a text");
      return std::nullopt;
    }
    if (!v->is_string() || (non_empty && v->get<std::string>().empty())) {
      fail(key, shown(*v) + " is invalid: expected " + (non_empty ? "a non-empty text" : "a text"));
      return std::nullopt;
    }
    return v->get<std::string>();
  }
  template <class Enum>
  std::optional<Enum> choice(std::string_view key, NameTable<Enum> names, bool required) {
    const Json* v = get(key);
    const std::string expected = "one of " + names_list(names);
    if (!v) {
      if (required) missing(key, expected);
      return std::nullopt;
    }
    const std::optional<Enum> value = named(names, *v);
    if (!value) fail(key, shown(*v) + " is invalid: expected " + expected);
    return value;
  }
  // Three numbers, each in [min, max].
  std::optional<std::array<double, 3>> triple(std::string_view key, double min, double max,
                                              std::string_view unit, bool required) {
    const Json* v = get(key);
    const std::string expected = "three numbers, each " + range_text(min, max, unit);
    if (!v) {
      if (required) missing(key, expected);
      return std::nullopt;
    }
    if (!v->is_array() || v->size() != 3) {
      fail(key, shown(*v) + " is invalid: expected " + expected);
      return std::nullopt;
    }
    std::array<double, 3> out{};
    bool ok = true;
    for (std::size_t i = 0; i < 3; ++i) {
      const Json& x = (*v)[i];
      const std::string where = at(key) + "[" + std::to_string(i) + "]";
      if (!x.is_number() || !(x.get<double>() >= min && x.get<double>() <= max)) {
        errors_.push_back(
            {where, shown(x) + " is invalid: expected a number, " + range_text(min, max, unit)});
        ok = false;
      } else {
        out[i] = x.get<double>();
      }
    }
    if (!ok) return std::nullopt;
    return out;
  }
  // A direction: three numbers, not all zero; returned normalised.
  std::optional<std::array<double, 3>> direction(std::string_view key, bool required) {
    auto d = triple(key, -1e6, 1e6, "", required);
    if (!d) return std::nullopt;
    const double length = std::sqrt((*d)[0] * (*d)[0] + (*d)[1] * (*d)[1] + (*d)[2] * (*d)[2]);
    if (!(length > 1e-12)) {
      fail(key, shown(*get(key)) + " is invalid: expected a direction (three numbers, not all 0)");
      return std::nullopt;
    }
    // One of unit length to rounding (as write_scenario writes them) is kept as written: dividing
    // again moved it by an ulp, so a saved scenario did not read back equal (found by fuzzing).
    if (std::abs(length - 1.0) > 1e-14)
      for (double& x : *d) x /= length;
    return d;
  }
  const Json* array(std::string_view key, bool required, std::string_view of) {
    const Json* v = get(key);
    if (!v) {
      if (required) missing(key, "a list of " + std::string(of));
      return nullptr;
    }
    if (!v->is_array()) {
      fail(key, shown(*v) + " is invalid: expected a list of " + std::string(of));
      return nullptr;
    }
    return v;
  }

 private:
  const Json& value_;
  std::string path_;
  std::vector<ScenarioError>& errors_;
};

// Scene extents in mm: generous bounds on any position (the built-in liver spans ±140 mm).
constexpr double kPositionLimitMm = 1000.0;

OrganSpec read_organ(const Json& value, std::vector<ScenarioError>& errors) {
  OrganSpec organ;
  Fields f(value, "organ", errors,
           {"geometry", "file", "length_unit", "target_tet_count", "fix_ligament", "fixed_node_set",
            "fixed_balls"});
  if (!f.is_object()) return organ;
  organ.geometry = f.choice("geometry", kGeometryNames, true).value_or(organ.geometry);
  const bool built_in = organ.geometry == OrganGeometry::built_in_liver;
  const bool mesh_file = organ.geometry == OrganGeometry::tet_mesh_file;
  const bool surface_file = organ.geometry == OrganGeometry::surface_file;
  if (!built_in) organ.file = f.text("file", true, true).value_or("");
  if (mesh_file) organ.fixed_node_set = f.text("fixed_node_set", false).value_or("");
  if (!mesh_file)
    organ.target_tet_count =
        f.integer("target_tet_count", 1000, 50000, false).value_or(organ.target_tet_count);
  if (built_in) organ.fix_ligament = f.boolean("fix_ligament", false).value_or(true);
  if (surface_file) {
    const std::optional<std::string> unit = f.text("length_unit", true);
    bool known = false;
    for (const auto& [name, metres] : kLengthUnits)
      if (unit && *unit == name) {
        organ.metres_per_unit = metres;
        known = true;
      }
    if (unit && !known) f.fail("length_unit", "is \"" + *unit + "\"; expected mm, cm or m");
  }
  // A field of another geometry is an error.
  const std::pair<std::string_view, std::string_view> only_for[] = {
      {"file", built_in ? "tet-mesh-file and surface-file" : ""},
      {"fixed_node_set", mesh_file ? "" : "tet-mesh-file"},
      {"target_tet_count", mesh_file ? "built-in-liver and surface-file" : ""},
      {"fix_ligament", built_in ? "" : "built-in-liver"},
      {"length_unit", surface_file ? "" : "surface-file"}};
  for (const auto& [key, geometries] : only_for)
    if (!geometries.empty() && f.has(key))
      f.fail(key, "is for geometry " + std::string(geometries) + " only");
  if (const Json* balls = f.array("fixed_balls", false, "balls {centre_mm, radius_mm}")) {
    for (std::size_t i = 0; i < balls->size(); ++i) {
      Fields b((*balls)[i], f.at("fixed_balls") + "[" + std::to_string(i) + "]", errors,
               {"centre_mm", "radius_mm"});
      if (!b.is_object()) continue;
      FixedBall ball;
      const auto centre = b.triple("centre_mm", -kPositionLimitMm, kPositionLimitMm, "mm", true);
      const auto radius = b.number("radius_mm", 1.0, 100.0, "mm", true);
      if (centre) ball.centre_mm = *centre;
      if (radius) ball.radius_mm = *radius;
      organ.fixed_balls.push_back(ball);
    }
  }
  return organ;
}

TissueSpec read_tissue(const Json& value, std::vector<ScenarioError>& errors) {
  TissueSpec tissue;
  Fields f(value, "parenchyma", errors,
           {"youngs_modulus_pa", "poisson_ratio", "density_kg_per_m3", "mooney_rivlin_fraction",
            "fracture_toughness_j_per_m2", "blade_friction_n_per_m", "viscoelastic", "viscoplastic",
            "fibres"});
  if (!f.is_object()) return tissue;
  TissueMaterial& m = tissue.elastic;
  m.youngs_modulus_pa = f.parameter("youngs_modulus_pa", p::youngs_modulus, true).value_or(0.0);
  m.poisson_ratio = f.parameter("poisson_ratio", p::poisson_ratio, true).value_or(0.0);
  m.density_kg_per_m3 = f.parameter("density_kg_per_m3", p::density, true).value_or(0.0);
  m.mooney_rivlin_fraction =
      f.parameter("mooney_rivlin_fraction", p::mooney_rivlin_fraction, false).value_or(0.0);
  tissue.fracture_toughness_j_per_m2 =
      f.parameter("fracture_toughness_j_per_m2", p::fracture_toughness, false)
          .value_or(tissue.fracture_toughness_j_per_m2);
  tissue.blade_friction_n_per_m = f.parameter("blade_friction_n_per_m", p::blade_friction, false)
                                      .value_or(tissue.blade_friction_n_per_m);
  if (const Json* v = f.get("viscoelastic")) {
    Fields g(*v, f.at("viscoelastic"), errors, {"e1_pa", "e2_pa", "eta1_pa_s"});
    if (g.is_object())
      tissue.viscoelastic =
          ViscoelasticParameters{g.parameter("e1_pa", p::e1, true).value_or(0.0),
                                 g.parameter("e2_pa", p::e2, true).value_or(0.0),
                                 g.parameter("eta1_pa_s", p::eta1, true).value_or(0.0)};
  }
  if (const Json* v = f.get("viscoplastic")) {
    Fields g(*v, f.at("viscoplastic"), errors,
             {"yield_limit_pa", "eta2_pa_s_pow_n", "creep_index_n"});
    if (g.is_object())
      tissue.viscoplastic =
          ViscoplasticParameters{g.parameter("yield_limit_pa", p::yield_limit, true).value_or(0.0),
                                 g.parameter("eta2_pa_s_pow_n", p::eta2, true).value_or(0.0),
                                 g.parameter("creep_index_n", p::creep_index, true).value_or(0.0)};
  }
  if (const Json* v = f.get("fibres")) {
    Fields g(*v, f.at("fibres"), errors, {"k1_pa", "k2", "direction"});
    if (g.is_object()) {
      FibreSpec fibres;
      fibres.k1_pa = g.parameter("k1_pa", p::fibre_k1, true).value_or(0.0);
      fibres.k2 = g.parameter("k2", p::fibre_k2, true).value_or(0.0);
      fibres.direction = g.direction("direction", true).value_or(fibres.direction);
      tissue.fibres = fibres;
    }
  }
  return tissue;
}

// The list at `path`: each element an object of the `known` keys, read by read_item(fields); a
// value that is not a list is one error.
template <class Item, class ReadItem>
std::vector<Item> read_object_list(const Json& value, const std::string& path,
                                   std::string_view what,
                                   std::initializer_list<std::string_view> known,
                                   std::vector<ScenarioError>& errors, ReadItem read_item) {
  std::vector<Item> items;
  if (!value.is_array()) {
    errors.push_back({path, shown(value) + " is invalid: expected a list of " + std::string(what)});
    return items;
  }
  for (std::size_t i = 0; i < value.size(); ++i) {
    Fields f(value[i], path + "[" + std::to_string(i) + "]", errors, known);
    if (f.is_object()) items.push_back(read_item(f));
  }
  return items;
}

std::vector<LesionSpec> read_lesions(const Json& value, std::vector<ScenarioError>& errors) {
  return read_object_list<LesionSpec>(
      value, "lesions", "lesions",
      {"name", "centre_mm", "radii_mm", "youngs_modulus_pa", "yield_limit_pa", "viscosity_pa_s",
       "fracture_toughness_j_per_m2", "blade_friction_n_per_m", "hidden"},
      errors, [](Fields& f) {
        LesionSpec lesion;
        lesion.name = f.text("name", true, true).value_or("");
        lesion.centre_mm = f.triple("centre_mm", -kPositionLimitMm, kPositionLimitMm, "mm", true)
                               .value_or(Millimetres3{});
        lesion.radii_mm = f.triple("radii_mm", 2.0, 50.0, "mm", true).value_or(lesion.radii_mm);
        lesion.youngs_modulus_pa =
            f.number("youngs_modulus_pa", 1000.0, 2e6, "Pa", true, "lesion's Young's modulus")
                .value_or(lesion.youngs_modulus_pa);
        lesion.yield_limit_pa = f.parameter("yield_limit_pa", p::yield_limit, false);
        lesion.viscosity_pa_s = f.parameter("viscosity_pa_s", p::eta1, false);
        lesion.fracture_toughness_j_per_m2 =
            f.parameter("fracture_toughness_j_per_m2", p::fracture_toughness, false);
        lesion.blade_friction_n_per_m =
            f.parameter("blade_friction_n_per_m", p::blade_friction, false);
        lesion.hidden = f.boolean("hidden", false).value_or(false);
        return lesion;
      });
}

EffectsSpec read_effects(const Json& value, std::vector<ScenarioError>& errors) {
  EffectsSpec effects;
  Fields f(value, "effects", errors,
           {"near_incompressibility", "viscoelastic", "viscoplastic", "fibres", "gravity",
            "gravity_direction", "gravity_m_per_s2"});
  if (!f.is_object()) return effects;
  effects.near_incompressibility =
      f.boolean("near_incompressibility", false).value_or(effects.near_incompressibility);
  effects.viscoelastic = f.boolean("viscoelastic", false).value_or(false);
  effects.viscoplastic = f.boolean("viscoplastic", false).value_or(false);
  effects.fibres = f.boolean("fibres", false).value_or(false);
  effects.gravity = f.boolean("gravity", false).value_or(false);
  effects.gravity_direction =
      f.direction("gravity_direction", false).value_or(effects.gravity_direction);
  effects.gravity_m_per_s2 = f.number("gravity_m_per_s2", kMinGravityMPerS2, kMaxGravityMPerS2,
                                      "m/s²", false, "gravity's strength")
                                 .value_or(effects.gravity_m_per_s2);
  return effects;
}

IntegratorSettings read_integrator(const Json& value, std::vector<ScenarioError>& errors) {
  IntegratorSettings integrator;
  Fields f(value, "integrator", errors, {"kind", "step_s", "tolerance_m"});
  if (!f.is_object()) return integrator;
  integrator.kind = f.choice("kind", integrator_names(), true).value_or(integrator.kind);
  integrator.step_s =
      f.number("step_s", 0.0, 0.01, "s", false, "0 (the stable step, explicit schemes) or a step")
          .value_or(0.0);
  integrator.tolerance_m = f.number("tolerance_m", 1e-9, 1e-3, "m", false, "dopri5's local error")
                               .value_or(integrator.tolerance_m);
  return integrator;
}

std::vector<ToolKind> read_tools(const Json& value, std::vector<ScenarioError>& errors) {
  std::vector<ToolKind> tools;
  const std::string expected = "a list of tools, each one of " + names_list(tool_names());
  if (!value.is_array() || value.empty()) {
    errors.push_back({"tools", shown(value) + " is invalid: expected " + expected});
    return tools;
  }
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string where = "tools[" + std::to_string(i) + "]";
    const std::optional<ToolKind> tool = named(tool_names(), value[i]);
    if (!tool)
      errors.push_back(
          {where, shown(value[i]) + " is invalid: expected one of " + names_list(tool_names())});
    else if (std::find(tools.begin(), tools.end(), *tool) != tools.end())
      errors.push_back({where, shown(value[i]) + " is listed twice"});
    else
      tools.push_back(*tool);
  }
  return tools;
}

TaskSpec read_task(const Json& value, std::vector<ScenarioError>& errors) {
  TaskSpec task;
  Fields f(value, "task", errors,
           {"kind", "instructions", "time_limit_s", "lesion", "margin_mm", "planned_plane",
            "grasp_point_mm", "lift_mm", "safe_force_n", "damage_tension_strain",
            "damage_compression_strain"});
  if (!f.is_object()) return task;
  task.kind = f.choice("kind", kTaskNames, true).value_or(task.kind);
  task.instructions = f.text("instructions", false).value_or("");
  task.time_limit_s = f.number("time_limit_s", 10.0, 7200.0, "s", true).value_or(task.time_limit_s);
  task.safe_force_n = f.number("safe_force_n", 0.1, 10.0, "N", false).value_or(task.safe_force_n);
  task.damage_tension_strain =
      f.number("damage_tension_strain", 0.05, 2.0, "", false).value_or(task.damage_tension_strain);
  task.damage_compression_strain = f.number("damage_compression_strain", 0.05, 0.95, "", false)
                                       .value_or(task.damage_compression_strain);
  const bool about_lesion = task.kind != TaskKind::retract_lobe;
  auto only_for = [&](std::string_view key, std::string_view kinds) {
    if (f.has(key)) f.fail(key, "is for task kind " + std::string(kinds) + " only");
  };
  if (about_lesion) {
    task.lesion = f.text("lesion", true, true).value_or("");
    only_for("grasp_point_mm", "retract-lobe");
    only_for("lift_mm", "retract-lobe");
  } else {
    task.grasp_point_mm =
        f.triple("grasp_point_mm", -kPositionLimitMm, kPositionLimitMm, "mm", true)
            .value_or(Millimetres3{});
    task.lift_mm = f.number("lift_mm", 5.0, 100.0, "mm", true).value_or(task.lift_mm);
    only_for("lesion", "palpate-lesion or resect-lesion");
  }
  if (task.kind == TaskKind::resect_lesion) {
    task.margin_mm = f.number("margin_mm", 0.0, 50.0, "mm", true).value_or(task.margin_mm);
    if (const Json* plane = f.get("planned_plane")) {
      Fields g(*plane, f.at("planned_plane"), errors, {"point_mm", "normal"});
      if (g.is_object()) {
        PlaneSpec spec;
        spec.point_mm = g.triple("point_mm", -kPositionLimitMm, kPositionLimitMm, "mm", true)
                            .value_or(Millimetres3{});
        spec.normal = g.direction("normal", true).value_or(spec.normal);
        task.planned_plane = spec;
      }
    }
  } else {
    only_for("margin_mm", "resect-lesion");
    only_for("planned_plane", "resect-lesion");
  }
  return task;
}

std::vector<RubricCriterion> read_rubric(const Json& value, std::vector<ScenarioError>& errors) {
  return read_object_list<RubricCriterion>(
      value, "rubric", "criteria", {"metric", "weight", "at_most", "at_least"}, errors,
      [](Fields& f) {
        RubricCriterion criterion;
        if (const auto metric = f.text("metric", true)) {
          if (find_metric(*metric))
            criterion.metric = *metric;
          else {
            std::string list;
            for (const MetricInfo& m : gradable_metrics())
              list += (list.empty() ? "" : ", ") + std::string(m.name);
            f.fail("metric", shown(*f.get("metric")) + " is invalid: expected one of " + list);
          }
        }
        criterion.weight = f.number("weight", 0.0, 100.0, "", true).value_or(0.0);
        const bool most = f.has("at_most"), least = f.has("at_least");
        if (most == least) {
          f.fail_here("needs exactly one of at_most and at_least (the pass threshold)");
        } else {
          criterion.rule = most ? PassRule::at_most : PassRule::at_least;
          criterion.threshold =
              f.number(most ? "at_most" : "at_least", -1e9, 1e9, "", true, "the pass threshold")
                  .value_or(0.0);
        }
        return criterion;
      });
}

// Older format versions, step by step up to the current one. Version 2 added effects.gravity and
// its direction and strength; a version-1 file has none, which reads as gravity off. Version 3
// added the fracture toughness of the parenchyma and of each lesion; an older file has none,
// which reads as the default (liver's) toughness. Version 4 added the blade friction of the
// parenchyma and of each lesion; an older file has none, which reads as the default (70 N/m) for
// every region. So there is nothing to rewrite. A later version
// adds its step here (and a test with a file of the one before).
void migrate(Json& /*document*/, int /*from_version*/) {}

// Thresholds of relative agreement.
bool nearly_equal(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
}

// Where a point sits relative to a lesion's ellipsoid: < 1 inside.
double ellipsoid_measure(const LesionSpec& lesion, const Eigen::Vector3d& point_m) {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = (point_m[k] - lesion.centre_mm[k] * 1e-3) / (lesion.radii_mm[k] * 1e-3);
    sum += d * d;
  }
  return sum;
}

}  // namespace

std::span<const MetricInfo> gradable_metrics() {
  return kMetrics;
}

const MetricInfo* find_metric(std::string_view name) {
  for (const MetricInfo& m : kMetrics)
    if (m.name == name) return &m;
  return nullptr;
}

Eigen::Vector3d gravity_acceleration_m_per_s2(const EffectsSpec& effects) {
  if (!effects.gravity) return Eigen::Vector3d::Zero();
  const auto& d = effects.gravity_direction;
  return effects.gravity_m_per_s2 * Eigen::Vector3d(d[0], d[1], d[2]).normalized();
}

std::string_view task_name(TaskKind kind) {
  return name_of(kTaskNames, kind);
}

bool TissueSpec::operator==(const TissueSpec& o) const {
  auto same_elastic = [](const TissueMaterial& a, const TissueMaterial& b) {
    return a.youngs_modulus_pa == b.youngs_modulus_pa && a.poisson_ratio == b.poisson_ratio &&
           a.density_kg_per_m3 == b.density_kg_per_m3 &&
           a.mooney_rivlin_fraction == b.mooney_rivlin_fraction;
  };
  auto same_viscoelastic = [](const auto& a, const auto& b) {
    return a.has_value() == b.has_value() &&
           (!a || (a->e1_pa == b->e1_pa && a->e2_pa == b->e2_pa && a->eta1_pa_s == b->eta1_pa_s));
  };
  auto same_viscoplastic = [](const auto& a, const auto& b) {
    return a.has_value() == b.has_value() && (!a || (a->yield_limit_pa == b->yield_limit_pa &&
                                                     a->eta2_pa_s_pow_n == b->eta2_pa_s_pow_n &&
                                                     a->creep_index_n == b->creep_index_n));
  };
  return same_elastic(elastic, o.elastic) && same_viscoelastic(viscoelastic, o.viscoelastic) &&
         same_viscoplastic(viscoplastic, o.viscoplastic) && fibres == o.fibres &&
         fracture_toughness_j_per_m2 == o.fracture_toughness_j_per_m2 &&
         blade_friction_n_per_m == o.blade_friction_n_per_m;
}

bool Scenario::operator==(const Scenario& o) const {
  const IntegratorSettings &a = integrator, &b = o.integrator;
  return title == o.title && description == o.description && organ == o.organ &&
         parenchyma == o.parenchyma && lesions == o.lesions && effects == o.effects &&
         a.kind == b.kind && a.step_s == b.step_s && a.tolerance_m == b.tolerance_m &&
         tools == o.tools && task == o.task && rubric == o.rubric;
}

std::vector<ScenarioError> validate(const Scenario& s) {
  std::vector<ScenarioError> errors;
  auto fail = [&](std::string path, std::string message) {
    errors.push_back({std::move(path), std::move(message)});
  };
  if (s.title.empty()) fail("title", "missing: expected a non-empty text");
  const TissueSpec& t = s.parenchyma;
  if (const auto message = validate(t.elastic)) fail("parenchyma", *message);
  const ParameterRange& toughness = parameter_range(p::fracture_toughness);
  auto check_toughness = [&](const std::string& path, double value) {
    if (!toughness.contains(value))
      fail(path, format_number(value) + " J/m² is invalid: expected " +
                     std::string(toughness.label) + ", " + format_number(toughness.min) + " to " +
                     format_number(toughness.max) + " J/m²");
  };
  check_toughness("parenchyma.fracture_toughness_j_per_m2", t.fracture_toughness_j_per_m2);
  const ParameterRange& friction = parameter_range(p::blade_friction);
  auto check_friction = [&](const std::string& path, double value) {
    if (!friction.contains(value))
      fail(path, format_number(value) + " N/m is invalid: expected " + std::string(friction.label) +
                     ", " + format_number(friction.min) + " to " + format_number(friction.max) +
                     " N/m");
  };
  check_friction("parenchyma.blade_friction_n_per_m", t.blade_friction_n_per_m);

  // Each effect that is on needs its law; viscoplasticity sits in series with viscoelasticity.
  if (s.effects.viscoelastic && !t.viscoelastic)
    fail("parenchyma.viscoelastic",
         "missing: expected {e1_pa, e2_pa, eta1_pa_s} since effects.viscoelastic is true");
  if (s.effects.viscoplastic && !s.effects.viscoelastic)
    fail("effects.viscoplastic",
         "true is invalid without effects.viscoelastic: the viscoplastic law acts in series with "
         "the viscoelastic one (seed Eq. 4)");
  if (s.effects.viscoplastic && !t.viscoplastic)
    fail("parenchyma.viscoplastic",
         "missing: expected {yield_limit_pa, eta2_pa_s_pow_n, creep_index_n} since "
         "effects.viscoplastic is true");
  if (s.effects.fibres && !t.fibres)
    fail("parenchyma.fibres",
         "missing: expected {k1_pa, k2, direction} since effects.fibres is true");
  // Checked whether gravity is on or not: the editor keeps them for when it is switched on.
  if (!(s.effects.gravity_m_per_s2 >= kMinGravityMPerS2 &&
        s.effects.gravity_m_per_s2 <= kMaxGravityMPerS2))
    fail("effects.gravity_m_per_s2", format_number(s.effects.gravity_m_per_s2) +
                                         " is invalid: expected gravity's strength, " +
                                         format_number(kMinGravityMPerS2) + " to " +
                                         format_number(kMaxGravityMPerS2) + " m/s²");
  {
    const auto& d = s.effects.gravity_direction;
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(length > 1e-12) || !std::isfinite(length))
      fail("effects.gravity_direction",
           "is invalid: expected a direction (three finite numbers, not all 0)");
  }
  if (s.effects.viscoelastic && t.viscoelastic) {
    const double sum = t.viscoelastic->instantaneous_modulus_pa();
    if (!nearly_equal(sum, t.elastic.youngs_modulus_pa))
      fail("parenchyma.viscoelastic", "e1_pa + e2_pa = " + format_number(sum) +
                                          " Pa is invalid: expected the instantaneous modulus, "
                                          "parenchyma.youngs_modulus_pa = " +
                                          format_number(t.elastic.youngs_modulus_pa) + " Pa");
    if (t.elastic.mooney_rivlin_fraction != 0.0)
      fail("parenchyma.mooney_rivlin_fraction",
           format_number(t.elastic.mooney_rivlin_fraction) +
               " is invalid with effects.viscoelastic: expected 0 (the viscous law's elastic base "
               "is Neo-Hookean)");
  }

  if (!is_explicit(s.integrator.kind) && !(s.integrator.step_s > 0.0))
    fail("integrator.step_s",
         format_number(s.integrator.step_s) + " is invalid with " +
             std::string(integrator_name(s.integrator.kind)) +
             ": expected a step above 0, up to 0.01 s (an implicit scheme has no stable step of "
             "its own to take)");

  const bool built_in = s.organ.geometry == OrganGeometry::built_in_liver;
  if (!built_in && s.organ.file.empty()) fail("organ.file", "missing: expected a mesh file");
  if (s.organ.geometry == OrganGeometry::surface_file) {
    if (!s.organ.file.empty() && !is_surface_file(s.organ.file)) {
      std::string formats;
      for (const std::string& extension : surface_file_extensions())
        formats += (formats.empty() ? "" : ", ") + extension;
      fail("organ.file",
           "\"" + s.organ.file + "\" is invalid: expected a surface model (" + formats + ")");
    }
    if (std::none_of(std::begin(kLengthUnits), std::end(kLengthUnits), [&](const LengthUnit& unit) {
          return unit.metres == s.organ.metres_per_unit;
        }))
      fail("organ.length_unit",
           format_number(s.organ.metres_per_unit) + " m is invalid: expected mm, cm or m");
  }
  const LiverShape liver;
  std::set<std::string> names;
  for (std::size_t i = 0; i < s.lesions.size(); ++i) {
    const LesionSpec& lesion = s.lesions[i];
    const std::string at = "lesions[" + std::to_string(i) + "]";
    if (lesion.name.empty()) fail(at + ".name", "missing: expected a non-empty text");
    if (!lesion.name.empty() && !names.insert(lesion.name).second)
      fail(at + ".name", "\"" + lesion.name + "\" is invalid: another lesion has this name");
    const ParameterRange& ratio = parameter_range(p::lesion_stiffness_ratio);
    const double r = lesion.youngs_modulus_pa / t.elastic.youngs_modulus_pa;
    if (t.elastic.youngs_modulus_pa > 0.0 && !ratio.contains(r))
      fail(at + ".youngs_modulus_pa",
           format_number(lesion.youngs_modulus_pa) + " Pa is invalid: expected " +
               format_number(ratio.min) + " to " + format_number(ratio.max) +
               " times the parenchyma's " + format_number(t.elastic.youngs_modulus_pa) + " Pa (" +
               std::string(ratio.why) + ")");
    if (lesion.fracture_toughness_j_per_m2)
      check_toughness(at + ".fracture_toughness_j_per_m2", *lesion.fracture_toughness_j_per_m2);
    if (lesion.blade_friction_n_per_m)
      check_friction(at + ".blade_friction_n_per_m", *lesion.blade_friction_n_per_m);
    if (built_in && !(liver.value(to_metres(lesion.centre_mm)) < 0.0))
      fail(at + ".centre_mm", "(" + format_number(lesion.centre_mm[0]) + ", " +
                                  format_number(lesion.centre_mm[1]) + ", " +
                                  format_number(lesion.centre_mm[2]) +
                                  ") mm is invalid: expected a point inside the built-in liver");
  }

  const auto has_tool = [&](ToolKind kind) {
    return std::find(s.tools.begin(), s.tools.end(), kind) != s.tools.end();
  };
  if (s.tools.empty()) fail("tools", "[] is invalid: expected at least one tool");
  const TaskSpec& task = s.task;
  if (task.kind != TaskKind::retract_lobe) {
    const bool known = std::any_of(s.lesions.begin(), s.lesions.end(),
                                   [&](const LesionSpec& l) { return l.name == task.lesion; });
    if (!known)
      fail("task.lesion", "\"" + task.lesion + "\" is invalid: expected the name of a lesion");
  }
  const std::pair<TaskKind, ToolKind> needs[] = {{TaskKind::palpate_lesion, ToolKind::probe},
                                                 {TaskKind::retract_lobe, ToolKind::forceps},
                                                 {TaskKind::resect_lesion, ToolKind::scalpel}};
  for (const auto& [kind, tool] : needs)
    if (task.kind == kind && !has_tool(tool))
      fail("tools", "task " + std::string(task_name(kind)) + " needs the " +
                        std::string(tool_name(tool)) + ": expected it among the tools");
  if (built_in && task.kind == TaskKind::retract_lobe &&
      !(liver.value(to_metres(task.grasp_point_mm)) < 0.01))
    fail("task.grasp_point_mm",
         "is invalid: expected a point on or inside the built-in liver "
         "(within 10 mm of its surface)");

  double weights = 0.0;
  for (const RubricCriterion& c : s.rubric) weights += c.weight;
  if (!s.rubric.empty() && !(weights > 0.0))
    fail("rubric", "the weights sum to 0: expected at least one criterion with weight > 0");
  return errors;
}

ScenarioReading read_scenario(std::string_view json_text) {
  ScenarioReading reading;
  std::vector<ScenarioError>& errors = reading.errors;
  Json document;
  // Where a problem of the text is, from the offset of the character after it.
  const auto not_valid_at = [&](std::size_t offset, const std::string& what) {
    offset = std::min(offset, json_text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i + 1 < offset; ++i) {
      if (json_text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    errors.push_back({"", "not valid JSON at line " + std::to_string(line) + ", column " +
                              std::to_string(column) + ": " + what});
  };
  try {
    document = Json::parse(json_text.begin(), json_text.end());
  } catch (const Json::parse_error& e) {
    std::string what = e.what();
    if (const auto colon = what.rfind(": "); colon != std::string::npos)
      what = what.substr(colon + 2);
    not_valid_at(e.byte, what);
    return reading;
  } catch (const Json::out_of_range& e) {
    // A number beyond a double's range (found by fuzzing: docs/fuzzing.md). The parser names the
    // number, not where it is: its first place in the text.
    const std::string what = e.what();
    const auto open = what.find('\''), close = what.rfind('\'');
    const std::string number =
        open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
    const auto at = number.empty() ? std::string_view::npos : json_text.find(number);
    const std::string message = "the number " + (number.empty() ? std::string("") : number + " ") +
                                "is out of range: expected at most about 1.8e308 in size";
    if (at == std::string_view::npos)
      errors.push_back({"", "not valid JSON: " + message});
    else
      not_valid_at(at + 1, message);
    return reading;
  }
  Fields top(document, "", errors,
             {"format", "version", "title", "description", "organ", "parenchyma", "lesions",
              "effects", "integrator", "tools", "task", "rubric"});
  if (!top.is_object()) return reading;
  const auto format = top.text("format", true);
  if (format && *format != kScenarioFormatName) {
    top.fail("format", shown(*top.get("format")) + " is invalid: expected \"" +
                           std::string(kScenarioFormatName) + "\"");
    return reading;  // not a scenario: the other fields would only add noise
  }
  const auto version = top.integer("version", 1, 1000000, true);
  if (!version) return reading;
  reading.file_version = *version;
  if (*version > kScenarioFormatVersion) {
    top.fail("version", std::to_string(*version) + " is newer than this LiverSim reads (up to " +
                            std::to_string(kScenarioFormatVersion) +
                            "): open the file with a newer LiverSim");
    return reading;
  }
  migrate(document, *version);

  Scenario s;
  s.title = top.text("title", true, true).value_or("");
  s.description = top.text("description", false).value_or("");
  if (const Json* v = top.get("organ"))
    s.organ = read_organ(*v, errors);
  else
    top.missing("organ", "an object {geometry, ...}");
  if (const Json* v = top.get("parenchyma"))
    s.parenchyma = read_tissue(*v, errors);
  else
    top.missing("parenchyma", "an object {youngs_modulus_pa, poisson_ratio, density_kg_per_m3}");
  if (const Json* v = top.get("lesions")) s.lesions = read_lesions(*v, errors);
  if (const Json* v = top.get("effects")) s.effects = read_effects(*v, errors);
  if (const Json* v = top.get("integrator")) s.integrator = read_integrator(*v, errors);
  if (const Json* v = top.get("tools")) s.tools = read_tools(*v, errors);
  if (const Json* v = top.get("task"))
    s.task = read_task(*v, errors);
  else
    top.missing("task", "an object {kind, time_limit_s, ...}");
  if (const Json* v = top.get("rubric")) s.rubric = read_rubric(*v, errors);
  // The cross-field checks only on fields that read cleanly: a bad field is reported once.
  if (!errors.empty()) return reading;
  errors = validate(s);
  if (errors.empty()) reading.scenario = std::move(s);
  return reading;
}

ScenarioReading read_scenario_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    ScenarioReading reading;
    std::error_code ec;
    const std::string why = !std::filesystem::exists(file, ec) ? "no such file" : "cannot be read";
    reading.errors.push_back({"", file.string() + ": " + why});
    return reading;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return read_scenario(text.str());
}

std::string write_scenario(const Scenario& s) {
  auto triple = [](const std::array<double, 3>& v) {
    return OrderedJson::array({v[0], v[1], v[2]});
  };
  OrderedJson doc;
  doc["format"] = kScenarioFormatName;
  doc["version"] = kScenarioFormatVersion;
  doc["title"] = s.title;
  if (!s.description.empty()) doc["description"] = s.description;

  OrderedJson organ;
  organ["geometry"] = name_of(kGeometryNames, s.organ.geometry);
  if (s.organ.geometry == OrganGeometry::built_in_liver) {
    organ["target_tet_count"] = s.organ.target_tet_count;
    organ["fix_ligament"] = s.organ.fix_ligament;
  } else if (s.organ.geometry == OrganGeometry::tet_mesh_file) {
    organ["file"] = s.organ.file;
    if (!s.organ.fixed_node_set.empty()) organ["fixed_node_set"] = s.organ.fixed_node_set;
  } else {
    organ["file"] = s.organ.file;
    for (const auto& [name, metres] : kLengthUnits)
      if (metres == s.organ.metres_per_unit) organ["length_unit"] = name;
    organ["target_tet_count"] = s.organ.target_tet_count;
  }
  if (!s.organ.fixed_balls.empty()) {
    OrderedJson balls = OrderedJson::array();
    for (const FixedBall& b : s.organ.fixed_balls)
      balls.push_back({{"centre_mm", triple(b.centre_mm)}, {"radius_mm", b.radius_mm}});
    organ["fixed_balls"] = balls;
  }
  doc["organ"] = organ;

  const TissueSpec& t = s.parenchyma;
  OrderedJson tissue;
  tissue["youngs_modulus_pa"] = t.elastic.youngs_modulus_pa;
  tissue["poisson_ratio"] = t.elastic.poisson_ratio;
  tissue["density_kg_per_m3"] = t.elastic.density_kg_per_m3;
  if (t.elastic.mooney_rivlin_fraction != 0.0)
    tissue["mooney_rivlin_fraction"] = t.elastic.mooney_rivlin_fraction;
  tissue["fracture_toughness_j_per_m2"] = t.fracture_toughness_j_per_m2;
  tissue["blade_friction_n_per_m"] = t.blade_friction_n_per_m;
  if (t.viscoelastic)
    tissue["viscoelastic"] = {{"e1_pa", t.viscoelastic->e1_pa},
                              {"e2_pa", t.viscoelastic->e2_pa},
                              {"eta1_pa_s", t.viscoelastic->eta1_pa_s}};
  if (t.viscoplastic)
    tissue["viscoplastic"] = {{"yield_limit_pa", t.viscoplastic->yield_limit_pa},
                              {"eta2_pa_s_pow_n", t.viscoplastic->eta2_pa_s_pow_n},
                              {"creep_index_n", t.viscoplastic->creep_index_n}};
  if (t.fibres)
    tissue["fibres"] = {{"k1_pa", t.fibres->k1_pa},
                        {"k2", t.fibres->k2},
                        {"direction", triple(t.fibres->direction)}};
  doc["parenchyma"] = tissue;

  OrderedJson lesions = OrderedJson::array();
  for (const LesionSpec& l : s.lesions) {
    OrderedJson lesion;
    lesion["name"] = l.name;
    lesion["centre_mm"] = triple(l.centre_mm);
    lesion["radii_mm"] = triple(l.radii_mm);
    lesion["youngs_modulus_pa"] = l.youngs_modulus_pa;
    if (l.yield_limit_pa) lesion["yield_limit_pa"] = *l.yield_limit_pa;
    if (l.viscosity_pa_s) lesion["viscosity_pa_s"] = *l.viscosity_pa_s;
    if (l.fracture_toughness_j_per_m2)
      lesion["fracture_toughness_j_per_m2"] = *l.fracture_toughness_j_per_m2;
    if (l.blade_friction_n_per_m) lesion["blade_friction_n_per_m"] = *l.blade_friction_n_per_m;
    lesion["hidden"] = l.hidden;
    lesions.push_back(lesion);
  }
  doc["lesions"] = lesions;

  doc["effects"] = {{"near_incompressibility", s.effects.near_incompressibility},
                    {"viscoelastic", s.effects.viscoelastic},
                    {"viscoplastic", s.effects.viscoplastic},
                    {"fibres", s.effects.fibres},
                    {"gravity", s.effects.gravity},
                    {"gravity_direction", triple(s.effects.gravity_direction)},
                    {"gravity_m_per_s2", s.effects.gravity_m_per_s2}};
  doc["integrator"] = {{"kind", integrator_name(s.integrator.kind)},
                       {"step_s", s.integrator.step_s},
                       {"tolerance_m", s.integrator.tolerance_m}};
  OrderedJson tools = OrderedJson::array();
  for (ToolKind tool : s.tools) tools.push_back(tool_name(tool));
  doc["tools"] = tools;

  const TaskSpec& k = s.task;
  OrderedJson task;
  task["kind"] = task_name(k.kind);
  if (!k.instructions.empty()) task["instructions"] = k.instructions;
  task["time_limit_s"] = k.time_limit_s;
  task["safe_force_n"] = k.safe_force_n;
  task["damage_tension_strain"] = k.damage_tension_strain;
  task["damage_compression_strain"] = k.damage_compression_strain;
  if (k.kind == TaskKind::retract_lobe) {
    task["grasp_point_mm"] = triple(k.grasp_point_mm);
    task["lift_mm"] = k.lift_mm;
  } else {
    task["lesion"] = k.lesion;
  }
  if (k.kind == TaskKind::resect_lesion) {
    task["margin_mm"] = k.margin_mm;
    if (k.planned_plane)
      task["planned_plane"] = {{"point_mm", triple(k.planned_plane->point_mm)},
                               {"normal", triple(k.planned_plane->normal)}};
  }
  doc["task"] = task;

  OrderedJson rubric = OrderedJson::array();
  for (const RubricCriterion& c : s.rubric) {
    OrderedJson criterion;
    criterion["metric"] = c.metric;
    criterion["weight"] = c.weight;
    criterion[c.rule == PassRule::at_most ? "at_most" : "at_least"] = c.threshold;
    rubric.push_back(criterion);
  }
  doc["rubric"] = rubric;
  return doc.dump(2) + "\n";
}

void write_scenario_file(const Scenario& scenario, const std::filesystem::path& file) {
  const std::string text = write_scenario(scenario);
  std::filesystem::path temporary = file;
  temporary += ".saving";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out)
      throw std::runtime_error("cannot write " + temporary.string() + ": " +
                               std::generic_category().message(errno));
    out << text;
    out.flush();
    if (!out) {
      const std::string why = std::generic_category().message(errno);
      out.close();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw std::runtime_error("cannot write " + file.string() + " (" + why +
                               "); the file on disk is unchanged");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw std::runtime_error("cannot replace " + file.string() + ": " + ec.message());
  }
}

std::vector<RegionMaterial> region_materials(const Scenario& s) {
  // Region 0: the parenchyma, with the laws of the effects that are on.
  const TissueSpec& t = s.parenchyma;
  RegionMaterial parenchyma;
  parenchyma.tissue = t.elastic;
  parenchyma.fracture_toughness_j_per_m2 = t.fracture_toughness_j_per_m2;
  parenchyma.blade_friction_n_per_m = t.blade_friction_n_per_m;
  if (s.effects.viscoelastic) parenchyma.viscoelastic = t.viscoelastic;
  if (s.effects.viscoplastic) parenchyma.viscoplastic = t.viscoplastic;
  if (s.effects.fibres) parenchyma.fibres = FibreParameters{t.fibres->k1_pa, t.fibres->k2};
  std::vector<RegionMaterial> regions{parenchyma};
  // Lesions: isotropic (a tumour has no fibre architecture), the parenchyma's laws scaled to the
  // lesion's stiffness.
  for (const LesionSpec& lesion : s.lesions) {
    RegionMaterial material;
    material.tissue = t.elastic;
    material.tissue.youngs_modulus_pa = lesion.youngs_modulus_pa;
    material.fracture_toughness_j_per_m2 =
        lesion.fracture_toughness_j_per_m2.value_or(t.fracture_toughness_j_per_m2);
    material.blade_friction_n_per_m =
        lesion.blade_friction_n_per_m.value_or(t.blade_friction_n_per_m);
    const double ratio = lesion.youngs_modulus_pa / t.elastic.youngs_modulus_pa;
    if (parenchyma.viscoelastic) {
      ViscoelasticParameters law = *parenchyma.viscoelastic;
      law.e1_pa *= ratio;
      law.e2_pa *= ratio;
      // Without a viscosity of its own the lesion relaxes with the parenchyma's time τ = η1/E1.
      law.eta1_pa_s = lesion.viscosity_pa_s.value_or(law.eta1_pa_s * ratio);
      material.viscoelastic = law;
    }
    if (parenchyma.viscoplastic) {
      ViscoplasticParameters law = *parenchyma.viscoplastic;
      law.yield_limit_pa = lesion.yield_limit_pa.value_or(law.yield_limit_pa);
      material.viscoplastic = law;
    }
    regions.push_back(material);
  }
  return regions;
}

SceneSetup build_scene(const Scenario& s, const std::filesystem::path& scenario_folder,
                       const MeshingProgressCallback& meshing_progress) {
  if (const auto errors = validate(s); !errors.empty())
    throw std::invalid_argument(errors.front().text());
  SceneSetup scene;
  if (s.organ.geometry == OrganGeometry::built_in_liver) {
    scene = default_scene(s.organ.target_tet_count);
    if (!s.organ.fix_ligament) scene.model_options.fixed_nodes.clear();
  } else {
    std::filesystem::path file = s.organ.file;
    if (file.is_relative()) file = scenario_folder / file;
    if (s.organ.geometry == OrganGeometry::surface_file)
      scene = scene_from_surface(file, s.organ.metres_per_unit, s.organ.target_tet_count,
                                 meshing_progress);
    else
      scene = scene_from_file(file, s.organ.fixed_node_set.empty()
                                        ? std::nullopt
                                        : std::optional<std::string>(s.organ.fixed_node_set));
  }
  TetMesh& mesh = scene.mesh;
  ModelOptions& options = scene.model_options;

  // Painted balls: the surface nodes inside them are held too.
  if (!s.organ.fixed_balls.empty()) {
    const BoundarySurface surface = extract_surface(mesh);
    std::vector<std::uint8_t> fixed(mesh.node_count(), 0);
    for (NodeIndex n : options.fixed_nodes) fixed[n] = 1;
    for (NodeIndex n : surface.nodes)
      for (const FixedBall& ball : s.organ.fixed_balls)
        if ((mesh.rest_position_m.at(n) - to_metres(ball.centre_mm)).norm() <=
            ball.radius_mm * 1e-3)
          fixed[n] = 1;
    options.fixed_nodes.clear();
    for (std::size_t n = 0; n < fixed.size(); ++n)
      if (fixed[n]) options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
  }

  options.regions = region_materials(s);
  if (s.effects.fibres) {
    const auto& d = s.parenchyma.fibres->direction;
    options.fibre_field.first_family = {Eigen::Vector3d(d[0], d[1], d[2])};
  }
  options.average_nodal_pressure = s.effects.near_incompressibility;
  options.gravity_m_per_s2 = gravity_acceleration_m_per_s2(s.effects);
  // Gravity pulls the organ onto its bed, and a freed piece onto the tray beside it (support.h).
  if (s.effects.gravity)
    options.support =
        std::make_shared<const SupportSurface>(support_under(mesh, options.gravity_m_per_s2));
  options.integrator = s.integrator;

  // Lesions: regions 1, 2, ... over the elements whose centroid lies in the ellipsoid.
  if (mesh.region.size() < mesh.tet_count()) mesh.region.resize(mesh.tet_count(), 0);
  for (std::size_t i = 0; i < s.lesions.size(); ++i) {
    const LesionSpec& lesion = s.lesions[i];
    const auto region = static_cast<std::int32_t>(i + 1);
    std::size_t taken = 0;
    for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int c = 0; c < 4; ++c) centroid += 0.25 * mesh.rest_position_m.at(mesh.corner[c][e]);
      if (ellipsoid_measure(lesion, centroid) < 1.0) {
        mesh.region[e] = region;
        ++taken;
      }
    }
    if (taken == 0)
      throw std::invalid_argument("lesions[" + std::to_string(i) + "] (\"" + lesion.name +
                                  "\"): no element of the mesh has its centre inside the lesion; "
                                  "move it inside the organ or make it larger");
  }
  scene.description = s.title + " (" + scene.description + ")";
  return scene;
}

}  // namespace liversim
