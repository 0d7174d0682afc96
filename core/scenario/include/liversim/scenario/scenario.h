#pragma once
// A training scenario: the organ, its tissue and lesions, the effects simulated, the integrator,
// the tools allowed, the task and how it is graded. Read from and written to a versioned JSON file
// (docs/scenario-format.md; the JSON Schema in scenarios/schema/). Reading validates everything
// before anything is built: a file with any error yields no scenario and a list of errors, each
// naming the field's path, its value and what is expected.

#include "liversim/engine/model.h"
#include "liversim/interaction/tools.h"
#include "liversim/meshing/default_scene.h"

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

// The version this build writes and the newest it reads; older files are migrated on reading.
inline constexpr int kScenarioFormatVersion = 4;
inline constexpr std::string_view kScenarioFormatName = "liversim-scenario";

using Millimetres3 =
    std::array<double, 3>;  // a point or a size, in mm, scene axes (liver_geometry.h)
inline Eigen::Vector3d to_metres(const Millimetres3& mm) {
  return Eigen::Vector3d(mm[0], mm[1], mm[2]) * 1e-3;
}
inline Millimetres3 to_millimetres(const Eigen::Vector3d& m) {
  return {m.x() * 1e3, m.y() * 1e3, m.z() * 1e3};
}

enum class OrganGeometry {
  built_in_liver,  // the generated liver (liver_geometry.h) at target_tet_count
  tet_mesh_file,   // a tetrahedral mesh (.inp, .msh; mesh_io.h), in metres
  surface_file,    // a surface model (surface_import.h), tetrahedralised at target_tet_count
};

// A ball of the organ's surface held fixed (e.g. painted in the editor): surface nodes within
// radius_mm of centre_mm.
struct FixedBall {
  Millimetres3 centre_mm{};
  double radius_mm = 0.0;
  bool operator==(const FixedBall&) const = default;
};

struct OrganSpec {
  OrganGeometry geometry = OrganGeometry::built_in_liver;
  std::string file;  // the files': relative to the scenario file's folder, or absolute
  int target_tet_count = kDefaultLiverTetCount;  // built_in_liver, surface_file
  double metres_per_unit = 1e-3;                 // surface_file: its length unit (length_unit)
  bool fix_ligament = true;    // built_in_liver: the coronary ligament's bare area
  std::string fixed_node_set;  // tet_mesh_file: a node set of the file ("" none)
  std::vector<FixedBall> fixed_balls;
  bool operator==(const OrganSpec&) const = default;
};

struct FibreSpec {
  double k1_pa = 0.0;
  double k2 = 0.0;
  std::array<double, 3> direction{1.0, 0.0, 0.0};  // uniform reference direction (normalised)
  bool operator==(const FibreSpec&) const = default;
};

// The parenchyma (region 0). Each law's parameters are kept even when its effect is off, so
// switching an effect back on restores them.
struct TissueSpec {
  TissueMaterial elastic;
  std::optional<ViscoelasticParameters> viscoelastic;  // E = E1 + E2 must equal elastic's E
  std::optional<ViscoplasticParameters> viscoplastic;
  std::optional<FibreSpec> fibres;
  // The energy to make new cut surface (J/m²): what holds a scalpel back as it cuts and what it
  // takes to break in (RegionMaterial; docs/cutting.md). Porcine liver: 187–225 J/m².
  double fracture_toughness_j_per_m2 = RegionMaterial{}.fracture_toughness_j_per_m2;
  // The friction on a cutting blade's sides per metre of its edge in the tissue (N/m): assumed,
  // 70 N/m (RegionMaterial; docs/cutting.md).
  double blade_friction_n_per_m = RegionMaterial{}.blade_friction_n_per_m;
  bool operator==(const TissueSpec&) const;
};

// A lesion: an ellipsoid of other tissue (a tumour), axis-aligned, inside the organ.
struct LesionSpec {
  std::string name;
  Millimetres3 centre_mm{};
  Millimetres3 radii_mm{10.0, 10.0, 10.0};
  double youngs_modulus_pa = 17500.0;    // instantaneous, with viscoelasticity
  std::optional<double> yield_limit_pa;  // with viscoplasticity (default: the parenchyma's)
  std::optional<double> viscosity_pa_s;  // η1 with viscoelasticity (default: the parenchyma's)
  std::optional<double> fracture_toughness_j_per_m2;  // J/m² (default: the parenchyma's)
  std::optional<double> blade_friction_n_per_m;       // N/m (default: the parenchyma's)
  bool hidden = false;                                // not drawn for the trainee (palpation tasks)
  bool operator==(const LesionSpec&) const = default;
};

// Gravity's strength a scenario may set (m/s²): from a tenth of Earth's, to see the effect
// slowly, to three times it, beyond which no trainer has a use for it.
inline constexpr double kMinGravityMPerS2 = 0.981;
inline constexpr double kMaxGravityMPerS2 = 29.43;
inline constexpr double kEarthGravityMPerS2 = 9.81;

// The effects simulated: an effect that is off is not computed (and costs nothing).
struct EffectsSpec {
  bool near_incompressibility = true;  // average nodal pressure
  bool viscoelastic = false;
  bool viscoplastic = false;  // needs viscoelastic
  bool fibres = false;
  // The organ's weight. Its direction and strength are kept when it is off, as the tissue's laws
  // are. The default direction is posterior (−z): the patient lies supine on the table.
  bool gravity = false;
  std::array<double, 3> gravity_direction{0.0, 0.0, -1.0};  // scene axes, normalised on reading
  double gravity_m_per_s2 = kEarthGravityMPerS2;
  bool operator==(const EffectsSpec&) const = default;
};

// The gravitational acceleration the effects ask for (m/s², scene axes): zero when gravity is off.
Eigen::Vector3d gravity_acceleration_m_per_s2(const EffectsSpec& effects);

enum class TaskKind { palpate_lesion, retract_lobe, resect_lesion };

struct PlaneSpec {
  Millimetres3 point_mm{};
  std::array<double, 3> normal{0.0, 0.0, 1.0};  // normalised on reading
  bool operator==(const PlaneSpec&) const = default;
};

struct TaskSpec {
  TaskKind kind = TaskKind::palpate_lesion;
  std::string instructions;  // shown to the trainee
  double time_limit_s = 300.0;
  std::string lesion;       // palpate_lesion, resect_lesion: the lesion's name
  double margin_mm = 10.0;  // resect_lesion: least distance from the cut to the lesion
  std::optional<PlaneSpec> planned_plane;  // resect_lesion
  Millimetres3 grasp_point_mm{};           // retract_lobe: where the lobe is to be grasped
  double lift_mm = 30.0;                   // retract_lobe: how far it is to be lifted
  // Grading thresholds (docs/session-metrics.md): a force on the tissue above safe_force_n is
  // excessive; tissue stretched past 1 + tension strain or squeezed below 1 − compression strain
  // is damaged.
  double safe_force_n = 1.5;
  double damage_tension_strain = 0.3;
  double damage_compression_strain = 0.5;
  bool operator==(const TaskSpec&) const = default;
};

// The metrics a rubric can grade (computed from a session: issue 10), with their units.
struct MetricInfo {
  std::string_view name;
  std::string_view unit;  // "" for counts and yes/no (1/0)
  std::string_view meaning;
};
std::span<const MetricInfo> gradable_metrics();
const MetricInfo* find_metric(std::string_view name);

enum class PassRule { at_most, at_least };

struct RubricCriterion {
  std::string metric;  // a name of gradable_metrics()
  double weight = 1.0;
  PassRule rule = PassRule::at_most;
  double threshold = 0.0;  // in the metric's unit
  bool operator==(const RubricCriterion&) const = default;
};

struct Scenario {
  std::string title;
  std::string description;
  OrganSpec organ;
  TissueSpec parenchyma;
  std::vector<LesionSpec> lesions;
  EffectsSpec effects;
  IntegratorSettings integrator;
  std::vector<ToolKind> tools = std::vector<ToolKind>(kToolKinds.begin(), kToolKinds.end());
  TaskSpec task;
  std::vector<RubricCriterion> rubric;
  bool operator==(const Scenario&) const;
};

// One thing wrong with a scenario file: the field's path (e.g. "lesions[0].radii_mm[1]"; "" for
// the file as a whole) and what is wrong, naming the value and what is expected.
struct ScenarioError {
  std::string path;
  std::string message;
  std::string text() const { return path.empty() ? message : path + ": " + message; }
};

struct ScenarioReading {
  std::optional<Scenario> scenario;  // set only when there are no errors
  std::vector<ScenarioError> errors;
  int file_version = 0;  // as written (0: unknown)
};

// Reads and validates a scenario from JSON text; older format versions are migrated.
ScenarioReading read_scenario(std::string_view json_text);
// The same from a file; an unreadable file is one error naming it.
ScenarioReading read_scenario_file(const std::filesystem::path& file);

// The checks read_scenario makes after parsing, on a scenario built in code (e.g. the editor's):
// ranges, references between fields, lesions inside the built-in liver.
std::vector<ScenarioError> validate(const Scenario& scenario);

// JSON text of the current format version (two-space indent, fields in a fixed order).
std::string write_scenario(const Scenario& scenario);
// Writes it to `file` through a temporary file renamed over it, so a failed write (a full disk)
// leaves any earlier file whole. Throws std::runtime_error naming the file and the cause.
void write_scenario_file(const Scenario& scenario, const std::filesystem::path& file);

// The scene a scenario describes: the mesh (lesions as regions 1, 2, ...), the model options (the
// integrator, the effects' laws, fixed nodes) and what is rendered. `scenario_folder` resolves a
// relative mesh file. Throws std::invalid_argument naming the field at fault (e.g. a node set
// missing from the mesh, a lesion outside the mesh) and MeshReadError for a bad mesh file.
SceneSetup build_scene(const Scenario& scenario, const std::filesystem::path& scenario_folder,
                       const MeshingProgressCallback& meshing_progress = {});

// The materials of its scene's regions (ModelOptions::regions): the parenchyma (region 0) with the
// laws of the effects that are on, then each lesion's, the parenchyma's laws scaled to its
// stiffness. build_scene uses them; a live change of the tissue recomputes them.
std::vector<RegionMaterial> region_materials(const Scenario& scenario);

std::string_view task_name(TaskKind kind);

}  // namespace liversim
