// Scenario files: every field survives a save and a load, the shipped scenarios build, and each
// file of the malformed corpus is refused with its own error naming the field.
#include "liversim/engine/model.h"
#include "liversim/engine/model_building.h"
#include "liversim/scenario/scenario.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string_view>

namespace liversim {
namespace {

namespace fs = std::filesystem;
const fs::path kShippedDir = fs::path(LIVERSIM_TEST_DATA_DIR) / ".." / ".." / "scenarios";
const fs::path kCorpusDir = fs::path(LIVERSIM_TEST_DATA_DIR) / "scenarios";

// A valid scenario whose every field differs from its default.
Scenario every_field_set() {
  Scenario s;
  s.title = "All fields";
  s.description = "Every field away from its default";
  s.organ.target_tet_count = 3841;
  s.organ.fix_ligament = false;
  s.organ.fixed_balls = {{{-60.0, 20.0, -30.0}, 15.0}, {{10.0, 0.0, -35.0}, 8.5}};
  s.parenchyma.elastic = TissueMaterial{4000.0, 0.48, 1055.0, 0.0};
  s.parenchyma.viscoelastic = ViscoelasticParameters{2500.0, 1500.0, 3000.0};
  s.parenchyma.viscoplastic = ViscoplasticParameters{60.0, 5000.0, 0.6};
  s.parenchyma.fibres = FibreSpec{1200.0, 3.0, {0.0, 0.6, 0.8}};
  s.parenchyma.fracture_toughness_j_per_m2 = 180.0;
  s.parenchyma.blade_friction_n_per_m = 55.0;
  LesionSpec lesion;
  lesion.name = "tumour";
  lesion.centre_mm = {-45.0, 5.0, 30.0};
  lesion.radii_mm = {10.0, 12.5, 9.0};
  lesion.youngs_modulus_pa = 20000.0;
  lesion.yield_limit_pa = 400.0;
  lesion.viscosity_pa_s = 9000.0;
  lesion.fracture_toughness_j_per_m2 = 450.0;
  lesion.blade_friction_n_per_m = 160.0;
  lesion.hidden = true;
  s.lesions = {lesion};
  s.effects = {false, true, true, true};
  s.effects.gravity = true;
  s.effects.gravity_direction = {0.0, -1.0, 0.0};
  s.effects.gravity_m_per_s2 = 4.9;
  s.integrator.kind = IntegratorKind::backward_euler;
  s.integrator.step_s = 0.002;
  s.integrator.tolerance_m = 2e-6;
  s.tools = {ToolKind::scalpel, ToolKind::forceps};
  s.task.kind = TaskKind::resect_lesion;
  s.task.instructions = "Cut it out";
  s.task.time_limit_s = 450.0;
  s.task.lesion = "tumour";
  s.task.margin_mm = 12.0;
  s.task.planned_plane = PlaneSpec{{-45.0, 5.0, 5.0}, {0.0, 0.0, 1.0}};
  s.task.safe_force_n = 2.0;
  s.task.damage_tension_strain = 0.4;
  s.task.damage_compression_strain = 0.6;
  s.rubric = {{"lesion_breached", 3.0, PassRule::at_most, 0.0},
              {"lesion_margin_mm", 2.0, PassRule::at_least, 10.0}};
  return s;
}

Scenario round_trip(const Scenario& s) {
  const ScenarioReading reading = read_scenario(write_scenario(s));
  for (const ScenarioError& e : reading.errors) ADD_FAILURE() << e.text();
  return reading.scenario.value_or(Scenario{});
}

TEST(ScenarioFile, EveryFieldSurvivesASaveAndALoad) {
  const Scenario full = every_field_set();
  EXPECT_TRUE(validate(full).empty());
  EXPECT_EQ(round_trip(full), full);

  // Each field changed alone is written and read back: it is not lost in either direction.
  const std::vector<std::pair<const char*, std::function<void(Scenario&)>>> changes = {
      {"title", [](Scenario& s) { s.title = "Other"; }},
      {"description", [](Scenario& s) { s.description = "Other text, with \"quotes\" and é"; }},
      {"organ.target_tet_count", [](Scenario& s) { s.organ.target_tet_count = 7312; }},
      {"organ.fix_ligament", [](Scenario& s) { s.organ.fix_ligament = true; }},
      {"organ.fixed_balls", [](Scenario& s) { s.organ.fixed_balls[1].radius_mm = 9.25; }},
      {"parenchyma.youngs_modulus_pa",
       [](Scenario& s) {
         s.parenchyma.elastic.youngs_modulus_pa = 4500.0;
         s.parenchyma.viscoelastic->e1_pa = 3000.0;
       }},
      {"parenchyma.poisson_ratio", [](Scenario& s) { s.parenchyma.elastic.poisson_ratio = 0.45; }},
      {"parenchyma.density", [](Scenario& s) { s.parenchyma.elastic.density_kg_per_m3 = 1070.0; }},
      {"parenchyma.viscoelastic.eta1",
       [](Scenario& s) { s.parenchyma.viscoelastic->eta1_pa_s = 10.5e3; }},
      {"parenchyma.viscoplastic.yield",
       [](Scenario& s) { s.parenchyma.viscoplastic->yield_limit_pa = 33.3; }},
      {"parenchyma.viscoplastic.eta2",
       [](Scenario& s) { s.parenchyma.viscoplastic->eta2_pa_s_pow_n = 7e4; }},
      {"parenchyma.viscoplastic.n",
       [](Scenario& s) { s.parenchyma.viscoplastic->creep_index_n = 1.0; }},
      {"parenchyma.fibres.k1", [](Scenario& s) { s.parenchyma.fibres->k1_pa = 800.0; }},
      {"parenchyma.fracture_toughness_j_per_m2",
       [](Scenario& s) { s.parenchyma.fracture_toughness_j_per_m2 = 225.0; }},
      {"parenchyma.blade_friction_n_per_m",
       [](Scenario& s) { s.parenchyma.blade_friction_n_per_m = 70.0; }},
      {"parenchyma.fibres.k2", [](Scenario& s) { s.parenchyma.fibres->k2 = 0.7; }},
      {"parenchyma.fibres.direction",
       [](Scenario& s) {
         s.parenchyma.fibres->direction = {1.0, 0.0, 0.0};
       }},
      {"lesions[0].centre_mm", [](Scenario& s) { s.lesions[0].centre_mm[2] = 25.0; }},
      {"lesions[0].radii_mm", [](Scenario& s) { s.lesions[0].radii_mm[1] = 7.0; }},
      {"lesions[0].youngs_modulus_pa",
       [](Scenario& s) { s.lesions[0].youngs_modulus_pa = 8000.0; }},
      {"lesions[0].yield_limit_pa", [](Scenario& s) { s.lesions[0].yield_limit_pa.reset(); }},
      {"lesions[0].viscosity_pa_s", [](Scenario& s) { s.lesions[0].viscosity_pa_s.reset(); }},
      {"lesions[0].fracture_toughness_j_per_m2",
       [](Scenario& s) { s.lesions[0].fracture_toughness_j_per_m2.reset(); }},
      {"lesions[0].blade_friction_n_per_m",
       [](Scenario& s) { s.lesions[0].blade_friction_n_per_m.reset(); }},
      {"lesions[0].hidden", [](Scenario& s) { s.lesions[0].hidden = false; }},
      {"effects.near_incompressibility",
       [](Scenario& s) { s.effects.near_incompressibility = true; }},
      {"effects.fibres", [](Scenario& s) { s.effects.fibres = false; }},
      {"effects.viscoplastic", [](Scenario& s) { s.effects.viscoplastic = false; }},
      {"effects.gravity", [](Scenario& s) { s.effects.gravity = false; }},
      {"effects.gravity_direction",
       [](Scenario& s) {
         s.effects.gravity_direction = {0.0, 0.0, -1.0};
       }},
      {"effects.gravity_m_per_s2", [](Scenario& s) { s.effects.gravity_m_per_s2 = 9.81; }},
      {"integrator.kind", [](Scenario& s) { s.integrator.kind = IntegratorKind::bdf2; }},
      {"integrator.step_s", [](Scenario& s) { s.integrator.step_s = 0.001; }},
      {"integrator.tolerance_m", [](Scenario& s) { s.integrator.tolerance_m = 1e-7; }},
      {"tools", [](Scenario& s) { s.tools.push_back(ToolKind::probe); }},
      {"task.instructions", [](Scenario& s) { s.task.instructions.clear(); }},
      {"task.time_limit_s", [](Scenario& s) { s.task.time_limit_s = 60.0; }},
      {"task.safe_force_n", [](Scenario& s) { s.task.safe_force_n = 0.8; }},
      {"task.damage_tension_strain", [](Scenario& s) { s.task.damage_tension_strain = 0.25; }},
      {"task.damage_compression_strain",
       [](Scenario& s) { s.task.damage_compression_strain = 0.45; }},
      {"task.margin_mm", [](Scenario& s) { s.task.margin_mm = 0.0; }},
      {"task.planned_plane", [](Scenario& s) { s.task.planned_plane.reset(); }},
      {"rubric[1].threshold", [](Scenario& s) { s.rubric[1].threshold = 5.5; }},
      {"rubric[0].rule", [](Scenario& s) { s.rubric[0].rule = PassRule::at_least; }},
      {"rubric[0].weight", [](Scenario& s) { s.rubric[0].weight = 0.25; }},
      {"rubric[0].metric", [](Scenario& s) { s.rubric[0].metric = "task_success"; }},
  };
  for (const auto& [field, change] : changes) {
    Scenario changed = full;
    change(changed);
    ASSERT_FALSE(changed == full) << field << ": the change changed nothing";
    EXPECT_EQ(round_trip(changed), changed) << field;
  }

  // The other task kinds keep their own fields.
  Scenario retract = full;
  retract.task = TaskSpec{};
  retract.task.kind = TaskKind::retract_lobe;
  retract.task.grasp_point_mm = {100.0, 0.0, 20.0};
  retract.task.lift_mm = 42.0;
  retract.tools = {ToolKind::forceps};
  EXPECT_EQ(round_trip(retract), retract);
  Scenario mesh_file = full;
  mesh_file.organ = OrganSpec{};
  mesh_file.organ.geometry = OrganGeometry::tet_mesh_file;
  mesh_file.organ.file = "meshes/liver.inp";
  mesh_file.organ.fixed_node_set = "FixT&P";
  mesh_file.lesions.clear();
  mesh_file.task = retract.task;
  mesh_file.tools = {ToolKind::forceps};
  EXPECT_EQ(round_trip(mesh_file), mesh_file);
}

TEST(ScenarioFile, WritingReplacesTheFileWholeAndNamesAFolderThatIsMissing) {
  const fs::path file = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "written-scenario.json";
  const Scenario full = every_field_set();
  write_scenario_file(full, file);
  const ScenarioReading reading = read_scenario_file(file);
  ASSERT_TRUE(reading.scenario.has_value());
  EXPECT_EQ(*reading.scenario, full);
  EXPECT_FALSE(fs::exists(fs::path(file) += ".saving"));

  const fs::path nowhere = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "no-such-folder" / "s.json";
  try {
    write_scenario_file(full, nowhere);
    FAIL() << "writing into a missing folder succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-folder"), std::string::npos) << e.what();
  }
  const ScenarioReading missing = read_scenario_file(nowhere);
  ASSERT_EQ(missing.errors.size(), 1u);
  EXPECT_NE(missing.errors[0].message.find("no such file"), std::string::npos);
}

TEST(ScenarioFile, VersionsNewerThanThisBuildAreRefusedAndTheCurrentOneIsRead) {
  std::string text = write_scenario(every_field_set());
  const ScenarioReading current = read_scenario(text);
  EXPECT_TRUE(current.scenario.has_value());
  EXPECT_EQ(current.file_version, kScenarioFormatVersion);

  const std::string version = "\"version\": " + std::to_string(kScenarioFormatVersion);
  const auto at = text.find(version);
  ASSERT_NE(at, std::string::npos);
  std::string newer = text;
  newer.replace(at, version.size(), "\"version\": " + std::to_string(kScenarioFormatVersion + 1));
  const ScenarioReading refused = read_scenario(newer);
  EXPECT_FALSE(refused.scenario.has_value());
  ASSERT_EQ(refused.errors.size(), 1u);
  EXPECT_EQ(refused.errors[0].path, "version");
  EXPECT_NE(refused.errors[0].message.find("newer than this LiverSim reads"), std::string::npos);

  std::string zero = text;
  zero.replace(at, version.size(), "\"version\": 0");
  EXPECT_FALSE(read_scenario(zero).scenario.has_value());
}

// Each malformed file and the error it must produce (its field path and a part of its message).
// Every file of the corpus is listed: a new file without an expectation fails the test.
TEST(ScenarioFile, EachMalformedFileGetsItsOwnErrorAndNothingIsHalfLoaded) {
  const std::map<std::string, std::pair<std::string, std::string>> expected = {
      {"schema-not-json.json", {"", "not valid JSON at line 46, column 3"}},
      {"schema-not-an-object.json", {"", "expected an object"}},
      {"schema-wrong-format.json", {"format", "\"liversim-session\" is invalid"}},
      {"schema-newer-version.json", {"version", "99 is newer than this LiverSim reads"}},
      {"schema-missing-title.json", {"title", "missing"}},
      {"schema-unknown-field.json", {"lesion", "unknown field: expected one of"}},
      {"schema-negative-radius.json",
       {"lesions[0].radii_mm[0]", "-3 is invalid: expected a number, 2 to 50 mm"}},
      {"schema-poisson-half.json",
       {"parenchyma.poisson_ratio", "0.5 is invalid: expected Poisson's ratio ν, 0.3 to 0.499"}},
      {"schema-modulus-as-text.json",
       {"parenchyma.youngs_modulus_pa", "\"3500\" is invalid: expected a number"}},
      {"schema-unknown-tool.json", {"tools[1]", "\"laser\" is invalid"}},
      {"schema-surface-file-without-unit.json", {"organ.length_unit", "missing"}},
      {"schema-surface-file-with-node-set.json",
       {"organ.fixed_node_set", "is for geometry tet-mesh-file only"}},
      {"schema-rubric-both-rules.json", {"rubric[0]", "exactly one of at_most and at_least"}},
      {"schema-unknown-metric.json", {"rubric[0].metric", "\"speed\" is invalid"}},
      {"schema-unknown-integrator.json", {"integrator.kind", "\"euler\" is invalid"}},
      {"schema-tet-count-out-of-range.json",
       {"organ.target_tet_count", "10 is invalid: expected a whole number from 1000 to 50000"}},
      {"schema-missing-task.json", {"task", "missing"}},
      {"schema-implicit-without-step.json",
       {"integrator.step_s", "0 is invalid with bdf2: expected a step above 0"}},
      {"semantic-lesion-outside-liver.json",
       {"lesions[0].centre_mm",
        "(500, 0, 0) mm is invalid: expected a point inside the built-in liver"}},
      {"semantic-unknown-task-lesion.json",
       {"task.lesion", "\"nope\" is invalid: expected the name of a lesion"}},
      {"semantic-viscoplastic-without-viscoelastic.json",
       {"effects.viscoplastic", "without effects.viscoelastic"}},
      {"semantic-viscoelastic-law-missing.json", {"parenchyma.viscoelastic", "missing"}},
      {"semantic-instantaneous-modulus-mismatch.json",
       {"parenchyma.viscoelastic", "e1_pa + e2_pa = 4000 Pa is invalid"}},
      {"semantic-task-needs-probe.json", {"tools", "needs the probe"}},
      {"semantic-lesion-softer-than-parenchyma.json",
       {"lesions[0].youngs_modulus_pa",
        "2000 Pa is invalid: expected 1 to 100 times the parenchyma's 3500 Pa"}},
      {"semantic-duplicate-lesion-names.json", {"lesions[1].name", "another lesion has this name"}},
      {"semantic-zero-fibre-direction.json", {"parenchyma.fibres.direction", "not all 0"}},
      {"semantic-zero-gravity-direction.json", {"effects.gravity_direction", "not all 0"}},
      {"schema-gravity-too-strong.json",
       {"effects.gravity_m_per_s2", "100 is invalid: expected gravity's strength, 0.981 to 29.43"}},
      {"semantic-surface-file-not-a-model.json",
       {"organ.file", "expected a surface model (.obj, .stl, .ply, .gltf, .glb, .fbx, .3ds)"}},
      {"semantic-rubric-weights-zero.json", {"rubric", "the weights sum to 0"}},
  };
  std::set<std::string> seen;
  for (const auto& entry : fs::directory_iterator(kCorpusDir)) {
    const std::string name = entry.path().filename().string();
    seen.insert(name);
    const auto it = expected.find(name);
    ASSERT_NE(it, expected.end()) << name << " has no expected error in this test";
    const ScenarioReading reading = read_scenario_file(entry.path());
    EXPECT_FALSE(reading.scenario.has_value()) << name;
    ASSERT_EQ(reading.errors.size(), 1u)
        << name << ": one fault, one error; got "
        << (reading.errors.empty() ? "none" : reading.errors[1].text());
    EXPECT_EQ(reading.errors[0].path, it->second.first) << name;
    EXPECT_NE(reading.errors[0].message.find(it->second.second), std::string::npos)
        << name << ": " << reading.errors[0].text();
  }
  EXPECT_EQ(seen.size(), expected.size()) << "a listed file is missing from " << kCorpusDir;
}

TEST(ScenarioFile, SeveralFaultsAreAllReported) {
  Scenario s = every_field_set();
  std::string text = write_scenario(s);
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("\"poisson_ratio\": 0.48", "\"poisson_ratio\": 0.7");
  replace("\"time_limit_s\": 450.0", "\"time_limit_s\": -1");
  replace("\"safe_force_n\": 2.0", "\"safe_force_n\": 0");
  const ScenarioReading reading = read_scenario(text);
  EXPECT_FALSE(reading.scenario.has_value());
  std::set<std::string> paths;
  for (const ScenarioError& e : reading.errors) paths.insert(e.path);
  EXPECT_EQ(paths, (std::set<std::string>{"parenchyma.poisson_ratio", "task.time_limit_s",
                                          "task.safe_force_n"}));
}

// Found by fuzzing (docs/fuzzing.md): a number beyond a double's range escaped the reader as the
// JSON library's out_of_range exception and ended the program. It is an error of the text, at its
// line and column, like any other.
TEST(ScenarioFile, ANumberBeyondADoublesRangeIsAnErrorOfTheTextNotACrash) {
  for (const std::string number : {"1e506", "-2.5E+400"}) {
    const ScenarioReading reading = read_scenario(
        "{\n  \"format\": \"liversim-scenario\",\n  \"version\": " + number + "\n}\n");
    EXPECT_FALSE(reading.scenario);
    ASSERT_EQ(reading.errors.size(), 1u);
    EXPECT_EQ(reading.errors[0].text(), "not valid JSON at line 3, column 14: the number " +
                                            number +
                                            " is out of range: expected at most about 1.8e308 "
                                            "in size");
  }
}

// A palpation scenario as an older format version wrote it, with that version's `effects`.
std::string older_palpation_scenario(int version, std::string_view effects) {
  return R"({
  "format": "liversim-scenario", "version": )" +
         std::to_string(version) + R"(, "title": "Written by an older version",
  "organ": {"geometry": "built-in-liver", "target_tet_count": 1500, "fix_ligament": true},
  "parenchyma": {"youngs_modulus_pa": 3500, "poisson_ratio": 0.49, "density_kg_per_m3": 1060},
  "effects": )" +
         std::string(effects) +
         R"(,
  "tools": ["probe"],
  "task": {"kind": "palpate-lesion", "lesion": "t", "time_limit_s": 180},
  "lesions": [{"name": "t", "centre_mm": [-50, 10, 40], "radii_mm": [12, 12, 12],
               "youngs_modulus_pa": 17500}]
})";
}

// Version 2 added gravity; a version-1 file (every shipped scenario before it) reads as before,
// with gravity off and its direction and strength at their defaults, and says it was migrated.
TEST(ScenarioFile, AVersionOneFileReadsWithGravityOff) {
  const std::string text = older_palpation_scenario(
      1, R"({"near_incompressibility": true, "viscoelastic": false, "viscoplastic": false,
              "fibres": false})");
  const ScenarioReading reading = read_scenario(text);
  ASSERT_TRUE(reading.scenario) << (reading.errors.empty() ? "" : reading.errors[0].text());
  EXPECT_EQ(reading.file_version, 1);
  EXPECT_FALSE(reading.scenario->effects.gravity);
  EXPECT_EQ(reading.scenario->effects, EffectsSpec{});
  // Saved again, it is the current version with gravity written out (and still off).
  const std::string saved = write_scenario(*reading.scenario);
  EXPECT_NE(saved.find("\"version\": " + std::to_string(kScenarioFormatVersion)),
            std::string::npos);
  EXPECT_NE(saved.find("\"gravity\": false"), std::string::npos) << saved;
  EXPECT_EQ(round_trip(*reading.scenario), *reading.scenario);
}

// Version 3 added the fracture toughness; a version-2 file reads with the liver's, for the
// parenchyma and for each lesion, and the scene's regions have it.
TEST(ScenarioFile, AVersionTwoFileReadsWithTheLiversFractureToughness) {
  const std::string text = older_palpation_scenario(
      2, R"({"near_incompressibility": true, "viscoelastic": false, "viscoplastic": false,
              "fibres": false, "gravity": false, "gravity_direction": [0, 0, -1],
              "gravity_m_per_s2": 9.81})");
  const ScenarioReading reading = read_scenario(text);
  ASSERT_TRUE(reading.scenario) << (reading.errors.empty() ? "" : reading.errors[0].text());
  EXPECT_EQ(reading.file_version, 2);
  const Scenario& s = *reading.scenario;
  EXPECT_EQ(s.parenchyma.fracture_toughness_j_per_m2, 200.0);
  EXPECT_FALSE(s.lesions[0].fracture_toughness_j_per_m2);
  const auto regions = region_materials(s);
  ASSERT_EQ(regions.size(), 2u);
  EXPECT_EQ(regions[0].fracture_toughness_j_per_m2, 200.0);
  EXPECT_EQ(regions[1].fracture_toughness_j_per_m2, 200.0) << "a lesion takes the parenchyma's";

  // Set, each region has its own; saved, the parenchyma's is written out.
  Scenario tough = s;
  tough.parenchyma.fracture_toughness_j_per_m2 = 150.0;
  tough.lesions[0].fracture_toughness_j_per_m2 = 600.0;
  const auto tough_regions = region_materials(tough);
  EXPECT_EQ(tough_regions[0].fracture_toughness_j_per_m2, 150.0);
  EXPECT_EQ(tough_regions[1].fracture_toughness_j_per_m2, 600.0);
  const SceneSetup scene = build_scene(tough, ".");
  EXPECT_EQ(build_model(scene.mesh, scene.model_options).regions[1].fracture_toughness_j_per_m2,
            600.0);
  const std::string saved = write_scenario(s);
  EXPECT_NE(saved.find("\"fracture_toughness_j_per_m2\": 200"), std::string::npos) << saved;

  // Out of the documented range, or not a number, it is refused, naming the field.
  tough.lesions[0].fracture_toughness_j_per_m2 = 1e5;
  tough.parenchyma.fracture_toughness_j_per_m2 = std::nan("");
  const auto errors = validate(tough);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].path, "parenchyma.fracture_toughness_j_per_m2");
  EXPECT_EQ(errors[1].path, "lesions[0].fracture_toughness_j_per_m2");
  EXPECT_NE(errors[1].message.find("expected fracture toughness J, 20 to 5000 J/m²"),
            std::string::npos)
      << errors[1].message;
  std::string text_too_tough = text;
  text_too_tough.replace(text_too_tough.find("\"density_kg_per_m3\": 1060"), 25,
                         "\"density_kg_per_m3\": 1060, \"fracture_toughness_j_per_m2\": 0");
  const ScenarioReading refused = read_scenario(text_too_tough);
  EXPECT_FALSE(refused.scenario);
  ASSERT_EQ(refused.errors.size(), 1u);
  EXPECT_EQ(refused.errors[0].path, "parenchyma.fracture_toughness_j_per_m2");
}

// Version 4 added the blade friction; a version-3 file reads with the default (70 N/m) for the
// parenchyma, each lesion takes the parenchyma's, and the scene's regions have them.
TEST(ScenarioFile, AVersionThreeFileReadsWithTheDefaultBladeFriction) {
  std::string text = older_palpation_scenario(
      3, R"({"near_incompressibility": true, "viscoelastic": false, "viscoplastic": false,
              "fibres": false, "gravity": false, "gravity_direction": [0, 0, -1],
              "gravity_m_per_s2": 9.81})");
  const ScenarioReading reading = read_scenario(text);
  ASSERT_TRUE(reading.scenario) << (reading.errors.empty() ? "" : reading.errors[0].text());
  EXPECT_EQ(reading.file_version, 3);
  const Scenario& s = *reading.scenario;
  EXPECT_EQ(s.parenchyma.blade_friction_n_per_m, 70.0);
  EXPECT_FALSE(s.lesions[0].blade_friction_n_per_m);
  const auto regions = region_materials(s);
  ASSERT_EQ(regions.size(), 2u);
  EXPECT_EQ(regions[0].blade_friction_n_per_m, 70.0);
  EXPECT_EQ(regions[1].blade_friction_n_per_m, 70.0) << "a lesion takes the parenchyma's";

  // Set, each region has its own, into the model; saved, the parenchyma's is written out.
  Scenario rough = s;
  rough.parenchyma.blade_friction_n_per_m = 0.0;
  rough.lesions[0].blade_friction_n_per_m = 250.0;
  const SceneSetup scene = build_scene(rough, ".");
  const SimModel model = build_model(scene.mesh, scene.model_options);
  EXPECT_EQ(model.regions[0].blade_friction_n_per_m, 0.0);
  EXPECT_EQ(model.regions[1].blade_friction_n_per_m, 250.0);
  const std::string saved = write_scenario(rough);
  EXPECT_NE(saved.find("\"blade_friction_n_per_m\": 0"), std::string::npos) << saved;
  EXPECT_NE(saved.find("\"blade_friction_n_per_m\": 250"), std::string::npos) << saved;
  EXPECT_EQ(round_trip(rough), rough);

  // Out of the documented range, or not a number, it is refused, naming the field and the range.
  rough.lesions[0].blade_friction_n_per_m = -1.0;
  rough.parenchyma.blade_friction_n_per_m = std::nan("");
  const auto errors = validate(rough);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].path, "parenchyma.blade_friction_n_per_m");
  EXPECT_EQ(errors[1].path, "lesions[0].blade_friction_n_per_m");
  EXPECT_NE(errors[1].message.find("expected blade friction, 0 to 2000 N/m"), std::string::npos)
      << errors[1].message;
  text.replace(text.find("\"density_kg_per_m3\": 1060"), 25,
               "\"density_kg_per_m3\": 1060, \"blade_friction_n_per_m\": 5000");
  const ScenarioReading refused = read_scenario(text);
  EXPECT_FALSE(refused.scenario);
  ASSERT_EQ(refused.errors.size(), 1u);
  EXPECT_EQ(refused.errors[0].path, "parenchyma.blade_friction_n_per_m");
}

// Gravity in the scene: its acceleration is g times the normalised direction when on, and the
// model has no gravity at all when off (the direction and strength are kept for switching it on).
TEST(ScenarioScene, GravityIsTheModelsAccelerationWhenOnAndAbsentWhenOff) {
  Scenario s = every_field_set();
  s.organ.fixed_balls.clear();
  s.organ.fix_ligament = true;
  s.effects.gravity = true;
  s.effects.gravity_direction = {0.0, 0.6, -0.8};
  s.effects.gravity_m_per_s2 = 9.81;
  const SceneSetup on_scene = build_scene(s, ".");
  const SimModel on = build_model(on_scene.mesh, on_scene.model_options);
  EXPECT_TRUE(on.effects.gravity);
  EXPECT_NEAR(on.gravity_m_per_s2.y(), 0.6 * 9.81, 1e-12);
  EXPECT_NEAR(on.gravity_m_per_s2.z(), -0.8 * 9.81, 1e-12);
  EXPECT_EQ(on.gravity_m_per_s2.x(), 0.0);

  s.effects.gravity = false;
  const SceneSetup off_scene = build_scene(s, ".");
  const SimModel off = build_model(off_scene.mesh, off_scene.model_options);
  EXPECT_FALSE(off.effects.gravity);
  EXPECT_TRUE(off.gravity_m_per_s2.isZero(0.0));
  EXPECT_EQ(round_trip(s).effects.gravity_direction, s.effects.gravity_direction);

  // A strength out of range is refused by validate() too (the editor builds scenarios in code).
  s.effects.gravity_m_per_s2 = 0.0;
  const auto errors = validate(s);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "effects.gravity_m_per_s2");
}

// Found by fuzzing (docs/fuzzing.md): a direction written not of unit length is normalised on
// reading, and normalising the saved unit vector again moved it by an ulp, so a saved scenario did
// not read back equal to the one saved. Once read, it is a fixed point of saving and reading.
TEST(ScenarioFile, ANormalisedDirectionIsSavedAndReadBackExactly) {
  Scenario s = every_field_set();
  s.task.planned_plane->normal = {1.0, 2.0, 0.0};
  s.parenchyma.fibres->direction = {0.0, 3.0, 7.0};
  const ScenarioReading first = read_scenario(write_scenario(s));
  ASSERT_TRUE(first.scenario) << (first.errors.empty() ? "" : first.errors[0].text());
  EXPECT_NEAR(first.scenario->task.planned_plane->normal[0], 1.0 / std::sqrt(5.0), 1e-15);
  EXPECT_EQ(round_trip(*first.scenario), *first.scenario);
  EXPECT_EQ(round_trip(round_trip(*first.scenario)), *first.scenario);
}

// The shipped scenarios read cleanly and build a model with the effects and lesions they ask for.
TEST(ShippedScenario, EachBuildsTheModelItDescribes) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kShippedDir)) {
    if (entry.path().extension() != ".json") continue;
    ++count;
    const std::string name = entry.path().filename().string();
    const ScenarioReading reading = read_scenario_file(entry.path());
    for (const ScenarioError& e : reading.errors) ADD_FAILURE() << name << ": " << e.text();
    ASSERT_TRUE(reading.scenario.has_value()) << name;
    const Scenario& s = *reading.scenario;
    SceneSetup scene = build_scene(s, entry.path().parent_path());
    const SimModel model = build_model(scene.mesh, scene.model_options);
    EXPECT_EQ(model.effects.viscous, s.effects.viscoelastic) << name;
    EXPECT_EQ(model.effects.fibres, s.effects.fibres) << name;
    EXPECT_EQ(model.effects.average_nodal_pressure, s.effects.near_incompressibility) << name;
    EXPECT_EQ(model.regions.size(), 1 + s.lesions.size()) << name;
    EXPECT_FALSE(scene.model_options.fixed_nodes.empty()) << name;
    // Each lesion's elements are those whose centroid is in its ellipsoid, with its stiffness.
    for (std::size_t i = 0; i < s.lesions.size(); ++i) {
      const auto region = static_cast<std::int32_t>(i + 1);
      const double volume_expected_m3 = 4.0 / 3.0 * 3.14159265358979 * s.lesions[i].radii_mm[0] *
                                        s.lesions[i].radii_mm[1] * s.lesions[i].radii_mm[2] * 1e-9;
      double volume_m3 = 0.0;
      for (std::size_t e = 0; e < model.tet_count; ++e)
        if (model.region[e] == region) volume_m3 += model.rest_volume_m3[e];
      // Centroid sampling on ~1 cm elements: within half of the ellipsoid's volume either way.
      EXPECT_GT(volume_m3, 0.5 * volume_expected_m3) << name;
      EXPECT_LT(volume_m3, 1.5 * volume_expected_m3) << name;
      EXPECT_EQ(model.regions[region].tissue.youngs_modulus_pa, s.lesions[i].youngs_modulus_pa);
      const double toughness = model.regions[region].fracture_toughness_j_per_m2;
      EXPECT_EQ(toughness, s.lesions[i].fracture_toughness_j_per_m2.value_or(
                               s.parenchyma.fracture_toughness_j_per_m2));
      // A tumour to resect is harder to cut than the liver around it (issue 42).
      if (s.task.kind == TaskKind::resect_lesion && s.task.lesion == s.lesions[i].name) {
        EXPECT_GT(toughness, model.regions[0].fracture_toughness_j_per_m2) << name;
      }
    }
  }
  EXPECT_GE(count, 4);
}

TEST(ScenarioScene, ALesionRelaxesLikeTheParenchymaUnlessGivenItsOwnViscosity) {
  Scenario s = every_field_set();
  s.effects = {true, true, true, false};
  s.lesions[0].viscosity_pa_s.reset();
  s.lesions[0].yield_limit_pa.reset();
  s.organ.fixed_balls.clear();
  s.organ.fix_ligament = true;
  SceneSetup scene = build_scene(s, ".");
  ASSERT_EQ(scene.model_options.regions.size(), 2u);
  const RegionMaterial& parenchyma = scene.model_options.regions[0];
  const RegionMaterial& lesion = scene.model_options.regions[1];
  ASSERT_TRUE(lesion.viscoelastic && parenchyma.viscoelastic);
  EXPECT_DOUBLE_EQ(lesion.viscoelastic->instantaneous_modulus_pa(), s.lesions[0].youngs_modulus_pa);
  EXPECT_DOUBLE_EQ(lesion.viscoelastic->eta1_pa_s / lesion.viscoelastic->e1_pa,
                   parenchyma.viscoelastic->eta1_pa_s / parenchyma.viscoelastic->e1_pa);
  EXPECT_EQ(lesion.viscoplastic->yield_limit_pa, parenchyma.viscoplastic->yield_limit_pa);
  EXPECT_FALSE(lesion.fibres.has_value());

  s.lesions[0].viscosity_pa_s = 9000.0;
  s.lesions[0].yield_limit_pa = 400.0;
  scene = build_scene(s, ".");
  EXPECT_EQ(scene.model_options.regions[1].viscoelastic->eta1_pa_s, 9000.0);
  EXPECT_EQ(scene.model_options.regions[1].viscoplastic->yield_limit_pa, 400.0);
}

TEST(ScenarioScene, AnEffectThatIsOffIsNotInTheModelButItsParametersAreKept) {
  Scenario s = every_field_set();
  s.effects = {true, false, false, false};
  s.organ.fixed_balls.clear();
  s.organ.fix_ligament = true;
  const SceneSetup scene = build_scene(s, ".");
  const SimModel model = build_model(scene.mesh, scene.model_options);
  EXPECT_FALSE(model.effects.viscous);
  EXPECT_FALSE(model.effects.fibres);
  EXPECT_TRUE(model.viscous_parameters.empty());
  EXPECT_TRUE(model.fibre_parameters.empty());
  EXPECT_TRUE(round_trip(s).parenchyma.viscoelastic.has_value());
}

TEST(ScenarioScene, ALiveTissueChangeGivesTheModelABuildWouldGive) {
  const Scenario before = every_field_set();
  const SceneSetup scene = build_scene(before, ".");
  Scenario after = before;
  TissueSpec& t = after.parenchyma;
  t.elastic = TissueMaterial{8000.0, 0.45, 1100.0, 0.0};
  t.viscoelastic = ViscoelasticParameters{5000.0, 3000.0, 4000.0};
  t.viscoplastic = ViscoplasticParameters{90.0, 4000.0, 0.8};
  t.fibres->k1_pa = 2000.0;
  ASSERT_TRUE(validate(after).empty());
  ModelOptions options = scene.model_options;
  options.regions = region_materials(after);
  const SimModel built = build_model(scene.mesh, options);

  SimModel changed = build_model(scene.mesh, scene.model_options);
  set_region_materials(changed, region_materials(after));
  // The same arithmetic in the same order: equal to the last bit.
  EXPECT_EQ(changed.shear_modulus_pa, built.shear_modulus_pa);
  EXPECT_EQ(changed.lame_lambda_pa, built.lame_lambda_pa);
  EXPECT_EQ(changed.lumped_mass_kg, built.lumped_mass_kg);
  EXPECT_EQ(changed.inverse_mass_per_kg, built.inverse_mass_per_kg);
  ASSERT_EQ(changed.fibre_parameters.size(), built.fibre_parameters.size());
  for (std::size_t e = 0; e < built.tet_count; ++e)
    ASSERT_EQ(changed.fibre_parameters[e].k1_pa, built.fibre_parameters[e].k1_pa) << e;
  ASSERT_EQ(changed.viscous_parameters.size(), 2u);  // the parenchyma and the lesion
  for (std::size_t r = 0; r < 2; ++r) {
    const auto& a = *changed.viscous_parameters[r];
    const auto& b = *built.viscous_parameters[r];
    EXPECT_EQ(a.viscoelastic.e1_pa, b.viscoelastic.e1_pa);
    EXPECT_EQ(a.viscoelastic.eta1_pa_s, b.viscoelastic.eta1_pa_s);
    EXPECT_EQ(a.viscoplastic->yield_limit_pa, b.viscoplastic->yield_limit_pa);
    EXPECT_EQ(a.poisson_ratio, 0.45);
  }
  EXPECT_EQ(changed.stable_time_step_s, built.stable_time_step_s);

  // Every modulus doubled (exactly, in binary): K doubles, so the highest frequency of M⁻¹K
  // rises by √2 and the stable step shrinks.
  const SimModel original = build_model(scene.mesh, scene.model_options);
  Scenario stiffer = before;
  stiffer.parenchyma.elastic.youngs_modulus_pa *= 2.0;
  stiffer.parenchyma.viscoelastic->e1_pa *= 2.0;
  stiffer.parenchyma.viscoelastic->e2_pa *= 2.0;
  stiffer.parenchyma.fibres->k1_pa *= 2.0;
  stiffer.lesions[0].youngs_modulus_pa *= 2.0;
  SimModel doubled = original;
  set_region_materials(doubled, region_materials(stiffer));
  EXPECT_NEAR(doubled.max_frequency_rad_per_s, std::sqrt(2.0) * original.max_frequency_rad_per_s,
              1e-9 * original.max_frequency_rad_per_s);
  EXPECT_LT(doubled.stable_time_step_s, original.stable_time_step_s);
}

TEST(ScenarioScene, ALiveTissueChangeIsRefusedWholeWhenAParameterIsBad) {
  const Scenario s = every_field_set();
  const SceneSetup scene = build_scene(s, ".");
  SimModel model = build_model(scene.mesh, scene.model_options);
  Scenario bad = s;
  bad.parenchyma.elastic.poisson_ratio = std::numeric_limits<double>::quiet_NaN();
  const double step = model.stable_time_step_s;
  try {
    set_region_materials(model, region_materials(bad));
    FAIL() << "a NaN Poisson's ratio was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("region 0 (parenchyma)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Poisson"), std::string::npos) << e.what();
  }
  EXPECT_EQ(model.stable_time_step_s, step);
  // A toughness that is no number is refused by the model too, not only by the scenario's reader.
  std::vector<RegionMaterial> regions = region_materials(s);
  regions[1].fracture_toughness_j_per_m2 = std::numeric_limits<double>::quiet_NaN();
  try {
    set_region_materials(model, regions);
    FAIL() << "a NaN fracture toughness was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("region 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fracture toughness"), std::string::npos) << e.what();
  }
  // The lesion's region needs a material too.
  EXPECT_THROW(set_region_materials(model, {region_materials(s)[0]}), std::invalid_argument);
}

TEST(ScenarioScene, PaintedBallsHoldTheSurfaceInsideThem) {
  Scenario s = every_field_set();
  s.effects = {true, false, false, false};
  s.organ.fix_ligament = false;
  s.organ.fixed_balls = {{{-60.0, 20.0, -30.0}, 20.0}};
  const SceneSetup scene = build_scene(s, ".");
  ASSERT_FALSE(scene.model_options.fixed_nodes.empty());
  for (NodeIndex n : scene.model_options.fixed_nodes)
    EXPECT_LE((scene.mesh.rest_position_m.at(n) - Eigen::Vector3d(-0.060, 0.020, -0.030)).norm(),
              0.020 + 1e-12);
}

TEST(ScenarioScene, AMeshFileWithoutTheNamedNodeSetIsAClearError) {
  Scenario s = every_field_set();
  s.organ = OrganSpec{};
  s.organ.geometry = OrganGeometry::tet_mesh_file;
  s.organ.file = "cube_sparse.inp";
  s.organ.fixed_node_set = "NoSuchSet";
  s.lesions.clear();
  s.task = TaskSpec{};
  s.task.kind = TaskKind::retract_lobe;
  s.tools = {ToolKind::forceps};
  s.effects = {true, false, false, false};
  try {
    build_scene(s, LIVERSIM_TEST_DATA_DIR);
    FAIL() << "a missing node set was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("NoSuchSet"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace liversim
