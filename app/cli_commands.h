#pragma once
// The headless commands of liversim-cli. Each returns the process exit code and reports problems
// on stderr as "liversim-cli: error: ...".

#include "liversim/engine/model.h"
#include "liversim/meshing/default_scene.h"

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace liversim::cli {

struct MeshSource {
  int tet_count = 5406;  // built-in liver at this element count (the target count of `surface`)
  std::optional<std::filesystem::path> file;      // or a .inp / .msh file
  std::optional<std::string> fixed_set;           // node set of `file` held fixed
  std::optional<std::filesystem::path> scenario;  // or a scenario file (organ, tissue, lesions)
  std::optional<std::filesystem::path> surface;   // or a surface model, meshed at `tet_count`
  std::optional<std::string> length_unit;         // of `surface` (mm, cm or m): required with it
};

struct MeshReportOptions {
  MeshSource mesh;
  std::optional<std::filesystem::path> surface_output;  // the mesh's boundary as OBJ, in mm
  // A row of the report appended to this markdown table (docs/mesh-quality.md's tables), its
  // header written first when the file is new.
  std::optional<std::filesystem::path> table_output;
};

struct SimulateOptions {
  MeshSource mesh;
  // A name of integrator_from_name; unset: the scenario's, else central difference.
  std::optional<std::string> integrator;
  double dt_s = 0.0;  // requested integrator step; 0: the stable step (explicit schemes only)
  double duration_s = 1.0;
  std::optional<int> node;  // default: a point on the anterior surface of the right lobe
  Eigen::Vector3d force_n{0.0, 0.1, 0.0};
  double load_radius_m = 0.01;  // the load is spread over surface nodes within this radius
  std::optional<std::filesystem::path> csv_output;
  double sample_interval_s = 0.01;
};

// A homogeneous material point of the viscous tissue law (core/viscous_tissue.h) under uniaxial
// stress, compared with the seed's 1-D closed forms (docs/viscous-tissue.md, Eq. 2–4).
enum class MaterialTest {
  relaxation,   // axial strain held from t = 0; nominal stress vs Eq. 2
  creep,        // nominal stress held from t = 0; axial strain vs Eq. 3
  yield_creep,  // creep above the yield limit; axial strain vs Eq. 4
};

// The defaults are ASSUMPTIONS, not data: the seed quotes only E = 3500 Pa, taken as the
// instantaneous modulus E1 + E2, and gives no split nor viscosities, yield limit or creep index.
struct MaterialTestOptions {
  MaterialTest test = MaterialTest::relaxation;
  double e1_pa = 2000.0;
  double e2_pa = 1500.0;
  double eta1_pa_s = 2000.0;  // τ = η1/E1 = 1 s
  double poisson_ratio = 0.49;
  double yield_limit_pa = 0.5;
  double eta2_pa_s_pow_n = 500.0;
  double creep_index_n = 0.5;
  double strain = 1e-3;    // held axial strain (relaxation)
  double stress_pa = 1.0;  // held nominal axial stress (creep, yield-creep)
  double duration_s = 10.0;
  double dt_s = 0.01;
  std::optional<std::filesystem::path> csv_output;
  std::optional<std::filesystem::path> plot_output;
  // A row (test, equation, load, step, largest error) appended to this markdown table
  // (docs/material-verification.md), its header written first when the file is new.
  std::optional<std::filesystem::path> table_output;
};

struct ScreenshotOptions {
  MeshSource mesh;
  std::filesystem::path output;
  int width = 1024;
  int height = 768;
};

// Prints the mesh's quality report (and, for a surface model, its meshing attempts and time).
int mesh_report(const MeshReportOptions& options);
int simulate(const SimulateOptions& options);
// Reads and checks scenario files; prints each error as "FILE: field.path: message". Exit status 0
// when every file is valid, 1 otherwise. No files: the shipped scenarios (data_paths.h).
int validate_scenarios(std::vector<std::filesystem::path> files);
int screenshot(const ScreenshotOptions& options);
int material_test(const MaterialTestOptions& options);
// Reports a problem on stderr as "liversim-cli: error: <message>" and returns exit code 2.
int fail(const std::string& message);

// Runs `body` and turns the exceptions of bad input into an error message and exit code 2.
template <typename Body>
int guarded(Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

// A number as the user would type it (shortest round trip is not needed: 6 digits).
std::string number(double value);
// A number for a report table, to `precision` significant digits.
std::string format(double value, int precision = 3);
// Today's date (UTC) as YYYY-MM-DD, for the header of a written report.
std::string today_utc();
// The value below which a fraction `p` (0 to 1) of `values` lie, the nearest of them; 0 for none.
double percentile(std::vector<double> values, double p);
// The processor as /proc/cpuinfo names it ("unknown processor" elsewhere), for a report's header.
std::string processor_name();
// Writes a report file and says so on stdout; 0, or fail()'s exit code naming the file.
int write_report(const std::filesystem::path& file, const std::string& text);
// The line under a written report's title: "Written by `COMMAND` on DATE (PROCESSOR, N hardware
// threads)." on a line of its own, which packaging/regenerate-docs.sh replaces with its own line
// (the commit, the machine and the command) when it reruns the command.
std::string written_by(const std::string& command);
// Appends `row` (one markdown table line, without its newline) to the table in `file`, writing
// `header` (the table's two first lines, without their last newline) first when the file is new or
// empty; says so on stdout. Throws std::runtime_error naming the file when it cannot be written.
void append_table_row(const std::filesystem::path& file, const std::string& header,
                      const std::string& row);

// The integrator of --integrator NAME; throws std::invalid_argument naming it and listing the
// valid names.
IntegratorKind integrator_kind(const std::string& name);
// The integrator settings of --integrator and --dt, checked before the (slow) model build.
IntegratorSettings integrator_settings(const std::string& name, double dt_s);
// The built-in liver with the given integrator (and material-test's assumed viscoelastic split of
// the seed's E = 3500 Pa when asked), and the wall time of the model build.
struct ExperimentScene {
  SceneSetup scene;
  SimModel model;
  double build_wall_s = 0.0;
};
ExperimentScene build_scene(int tet_count, const IntegratorSettings& integrator,
                            bool viscoelastic = false);
// A short pull on the liver, released, with a screenshot of the deformed organ while pulled.
int demo(const ScreenshotOptions& options);

}  // namespace liversim::cli
