// The default scene, rendered offscreen, against a baseline picture (tests/baselines): catches
// changes to the liver's look (mesh, colours, lights, camera). The comparison is VTK's own
// regression-test metric (vtkImageDifference), which forgives shifts of up to two pixels and the
// small differences between graphics drivers; a deformed liver shows that it can fail.
//
// Needs an X display (Debian's VTK has no EGL or OSMesa): run it under
//   xvfb-run -a -s "-screen 0 1280x1024x24" ctest -L render
//
// Updating the baseline after an intended change of the picture: run the test, look at the
// output it names, and copy that over tests/baselines/default_scene.png.
#include <gtest/gtest.h>

#include <vtkCamera.h>
#include <vtkImageData.h>
#include <vtkImageDifference.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/interaction/cutting.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/scenario/data_paths.h"
#include "liversim/scenario/scenario.h"
#include "render/liver_scene.h"

namespace liversim {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 800;
constexpr int kHeight = 600;
const fs::path kBaseline = fs::path(LIVERSIM_BASELINE_DIR) / "default_scene.png";
const fs::path kOutputDir = LIVERSIM_TEST_OUTPUT_DIR;

// The comparison is vtkImageDifference's: per pixel, the smallest colour error against the other
// picture's pixels up to 2 pixels away (also 3x3-averaged), less kPixelThreshold per channel; the
// thresholded error sums that over the picture, each pixel's error as a fraction of 255.
//
// Two renders of the same scene here (Xvfb, llvmpipe) are identical, pixel for pixel, within a
// process and between processes. The tolerance is for other drivers and Mesa versions: their
// shading and anti-aliasing differ by a few levels, their edges by a pixel.
//
// kPixelThreshold: VTK's default of 105 (of 255) is meant for comparing different graphics
// systems and is blind here: a 10 mm bump in the liver or its colour 20 % darker still give 0.
// 16 (6 %) catches a 3 mm bump (0.58) and a 10 % darker colour (18) while forgiving a camera
// turned by 1 degree (0.001), measured against the flat-coloured liver's baseline; against the
// mottled liver's: the 3 mm bump 0.39, the organ's pixels made 10 % darker 2.4, the camera turned
// by 1 degree 0.
constexpr int kPixelThreshold = 16;
// Largest accepted thresholded error: vtkRegressionTestImage's default.
constexpr double kMaxThresholdedError = 0.15;

struct ImageComparison {
  // vtkImageDifference::GetError() is left out: past a pixel's first neighbour within the
  // threshold it stops looking, so it is not 0 even for identical pictures.
  double thresholded_error = 0.0;
  vtkSmartPointer<vtkImageData> difference;  // per-pixel thresholded error (RGB)
};

vtkSmartPointer<vtkImageData> readPng(const fs::path& file) {
  vtkNew<vtkPNGReader> reader;
  if (!fs::exists(file) || !reader->CanReadFile(file.string().c_str())) return nullptr;
  reader->SetFileName(file.string().c_str());
  reader->Update();
  return reader->GetOutput();
}

// Compares two RGB pictures of the same size. Returns nothing, and records why, when they cannot
// be compared.
std::optional<ImageComparison> compare(const fs::path& test, const fs::path& baseline) {
  const auto a = readPng(test);
  const auto b = readPng(baseline);
  if (!a || !b) {
    ADD_FAILURE() << "cannot read " << (a ? baseline : test) << " as a PNG";
    return std::nullopt;
  }
  int da[3], db[3];
  a->GetDimensions(da);
  b->GetDimensions(db);
  if (da[0] != db[0] || da[1] != db[1] || a->GetNumberOfScalarComponents() != 3 ||
      b->GetNumberOfScalarComponents() != 3) {
    ADD_FAILURE() << test << " is " << da[0] << "x" << da[1] << " with "
                  << a->GetNumberOfScalarComponents() << " components, " << baseline << " is "
                  << db[0] << "x" << db[1] << " with " << b->GetNumberOfScalarComponents()
                  << "; both must be RGB pictures of the same size";
    return std::nullopt;
  }
  vtkNew<vtkImageDifference> difference;
  difference->SetInputData(a);
  difference->SetImageData(b);
  difference->SetThreshold(kPixelThreshold);
  difference->AllowShiftOn();
  difference->AveragingOn();
  difference->Update();
  ImageComparison result;
  result.thresholded_error = difference->GetThresholdedError();
  result.difference = difference->GetOutput();
  return result;
}

struct PixelDifference {
  long count = 0;   // pixels that differ in any channel
  int largest = 0;  // largest difference of a channel, of 255
};

// Exact comparison of two pictures of the same size and type.
PixelDifference differingPixels(vtkImageData* a, vtkImageData* b) {
  PixelDifference result;
  const auto* pa = static_cast<const unsigned char*>(a->GetScalarPointer());
  const auto* pb = static_cast<const unsigned char*>(b->GetScalarPointer());
  const int components = a->GetNumberOfScalarComponents();
  const vtkIdType pixels = a->GetNumberOfPoints();
  for (vtkIdType i = 0; i < pixels; ++i) {
    bool differs = false;
    for (int c = 0; c < components; ++c) {
      const int d = std::abs(pa[i * components + c] - pb[i * components + c]);
      result.largest = std::max(result.largest, d);
      differs |= d != 0;
    }
    result.count += differs ? 1 : 0;
  }
  return result;
}

void writePng(vtkImageData* image, const fs::path& file) {
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(file.string().c_str());
  writer->SetInputData(image);
  writer->Write();
}

// A smooth bump: nodes near `centre` move by up to `amplitude_m`, falling off as a Gaussian of
// width `sigma_m`.
NodeArray bumped(const NodeArray& rest, const Eigen::Vector3d& centre,
                 const Eigen::Vector3d& amplitude_m, double sigma_m) {
  NodeArray moved = rest;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const double r2 = (rest.at(i) - centre).squaredNorm();
    moved.set(i, rest.at(i) + std::exp(-r2 / (2 * sigma_m * sigma_m)) * amplitude_m);
  }
  return moved;
}

class RenderBaselineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* display = std::getenv("DISPLAY");
    ASSERT_TRUE(display != nullptr && *display != '\0')
        << "DISPLAY is not set. This rendering test needs an X server (Debian's VTK has no EGL "
           "or OSMesa); run it under\n  xvfb-run -a -s \"-screen 0 1280x1024x24\" ctest -L render";
    fs::create_directories(kOutputDir);
  }

  // Renders the default scene, with the nodes at `position` (all mesh nodes) when given.
  static fs::path render(const std::string& name,
                         const std::optional<NodeArray>& position = std::nullopt) {
    const SceneSetup setup = default_scene();
    LiverScene scene(setup.mesh, setup.visual);
    if (position) scene.update_positions(*position);
    return screenshot(scene, name);
  }

  static fs::path screenshot(LiverScene& scene, const std::string& name) {
    const fs::path file = kOutputDir / (name + ".png");
    write_screenshot_png(scene, file, kWidth, kHeight);
    return file;
  }

  // Where `point_m` falls in the screenshots' pixels (from the bottom-left). The scene's renderer
  // converts only while in a window of their size: screenshot() gives it back without one.
  static Eigen::Vector2d screenshotPixel(LiverScene& scene, const Eigen::Vector3d& point_m) {
    vtkNew<vtkRenderWindow> window;  // never drawn, so never opened
    window->SetSize(kWidth, kHeight);
    window->AddRenderer(scene.renderer());
    const Eigen::Vector2d pixel = scene.world_to_display(point_m);
    window->RemoveRenderer(scene.renderer());
    return pixel;
  }

  // The picture `output` against tests/baselines/NAME.png; on failure the rendered picture and
  // the difference stay in the output folder, named in the message. On success `output` is
  // removed.
  void expectMatchesBaseline(const fs::path& output, const std::string& name) {
    const fs::path baseline = fs::path(LIVERSIM_BASELINE_DIR) / (name + ".png");
    ASSERT_TRUE(fs::exists(baseline))
        << "the baseline " << baseline << " is missing. The picture rendered now is\n  " << output
        << "\nlook at it and, if it is right, copy it there:\n  cp " << output << ' ' << baseline;
    const auto comparison = compare(output, baseline);
    ASSERT_TRUE(comparison);
    const PixelDifference pixels = differingPixels(readPng(output), readPng(baseline));
    std::cout << name << " against the baseline: " << report(*comparison) << "; " << pixels.count
              << " pixels differ, by at most " << pixels.largest << " of 255\n";
    if (comparison->thresholded_error > kMaxThresholdedError) {
      const fs::path diff = kOutputDir / (name + "_diff.png");
      writePng(comparison->difference, diff);
      ADD_FAILURE() << name << " no longer looks like the baseline: " << report(*comparison)
                    << "\n  rendered now: " << output << "\n  baseline:     " << baseline
                    << "\n  difference:   " << diff
                    << "\nif the change is intended, copy the rendered picture over the baseline.";
      return;
    }
    fs::remove(output);  // passed: nothing to inspect
  }

  static std::string report(const ImageComparison& c) {
    return "thresholded error " + std::to_string(c.thresholded_error) + " (limit " +
           std::to_string(kMaxThresholdedError) + ", pixel threshold " +
           std::to_string(kPixelThreshold) + ")";
  }
};

TEST_F(RenderBaselineTest, DefaultSceneMatchesTheBaseline) {
  expectMatchesBaseline(render("default_scene"), "default_scene");
}

TEST_F(RenderBaselineTest, RenderingIsRepeatable) {
  // The threshold rests on this: two renders of the same scene are identical, pixel for pixel.
  const fs::path first = render("repeat_first");
  const fs::path second = render("repeat_second");
  const auto a = readPng(first);
  const auto b = readPng(second);
  ASSERT_TRUE(a && b);
  const PixelDifference pixels = differingPixels(a, b);
  std::cout << "two renders of the default scene: " << pixels.count << " pixels differ, by at most "
            << pixels.largest << " of 255\n";
  EXPECT_EQ(pixels.count, 0) << "the renderer is not deterministic; see " << first << " and "
                             << second;
  const auto comparison = compare(first, second);
  ASSERT_TRUE(comparison);
  EXPECT_EQ(comparison->thresholded_error, 0.0);
  if (!HasFailure()) {
    fs::remove(first);
    fs::remove(second);
  }
}

TEST_F(RenderBaselineTest, DeformedLiverDiffersFromTheBaseline) {
  ASSERT_TRUE(fs::exists(kBaseline)) << "the baseline " << kBaseline << " is missing";
  // The anterior face pulled 5 mm down and toward the viewer over a few centimetres: less than a
  // gentle grab does.
  const SceneSetup setup = default_scene();
  const Eigen::Vector3d centre = setup.mesh.rest_position_m.at(anterior_marked_node(setup.mesh));
  const fs::path output =
      render("deformed_scene", bumped(setup.mesh.rest_position_m, centre,
                                      0.005 * Eigen::Vector3d(0.0, -3.0, 2.0).normalized(), 0.025));

  const auto comparison = compare(output, kBaseline);
  ASSERT_TRUE(comparison);
  std::cout << "deformed scene against the baseline: " << report(*comparison) << '\n';
  EXPECT_GT(comparison->thresholded_error, kMaxThresholdedError)
      << "the comparison does not notice a deformed liver; see " << output;
  if (!HasFailure()) fs::remove(output);
}

// Pixels that differ between two pictures of the same scene.
long changedPixels(const fs::path& a, const fs::path& b) {
  return differingPixels(readPng(a), readPng(b)).count;
}

// The shipped wedge resection: a peripheral tumour in the left lobe, visible to the trainee.
SceneSetup wedgeResectionScene(Scenario& scenario) {
  const fs::path file = shipped_scenarios_folder() / "wedge-resection-peripheral-tumour.json";
  ScenarioReading reading = read_scenario_file(file);
  if (!reading.scenario) throw std::runtime_error("cannot read " + file.string());
  scenario = *reading.scenario;
  return build_scene(scenario, file.parent_path());
}

// A lesion shows through in its own colour: pale yellow, which neither the liver (red) nor the
// background (grey-blue) has.
long yellowPixels(const fs::path& file) {
  const auto image = readPng(file);
  const auto* p = static_cast<const unsigned char*>(image->GetScalarPointer());
  long count = 0;
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i, p += 3)
    count += p[0] > 120 && p[1] > 90 && p[2] < 0.8 * p[1] && p[1] > 0.6 * p[0];
  return count;
}

TEST_F(RenderBaselineTest, SeeThroughShowsTheLesionInsideTheLiver) {
  Scenario scenario;
  const SceneSetup setup = wedgeResectionScene(scenario);
  const std::vector<LesionShape> lesions = visible_lesions(scenario);
  ASSERT_EQ(lesions.size(), 1u);
  LiverScene scene(setup.mesh, setup.visual);
  scene.set_opacity(kSeeThroughOpacity);
  const fs::path without = screenshot(scene, "see_through_without_lesion");
  scene.show_lesions(lesions);
  // Every triangle of the lesion's sphere (24 × 16 facets) lies inside the liver: all held.
  EXPECT_EQ(scene.shown_lesion_triangle_count(), 2u * 24u * 15u);
  const fs::path with = screenshot(scene, "see_through_lesion");
  // The lesion (radius 8 mm) in its own colour.
  EXPECT_EQ(yellowPixels(without), 0);
  // Its disc seen through the liver: the liver, ~280 mm across, spans about 480 px, so the
  // lesion's 16 mm are about 27 px across; at least half its disc's area.
  EXPECT_GT(yellowPixels(with), 250);
  EXPECT_GT(changedPixels(without, with), 200);
  fs::remove(without);
  expectMatchesBaseline(with, "see_through_lesion");
}

// A cut through a lesion and back (a replay seeking to its start): each model moves the lesion
// by its own embedding, never by the other's (whose nodes the other mesh may not have).
TEST_F(RenderBaselineTest, ALesionFollowsTheCutModelAndTheUncutOneAgain) {
  Scenario scenario;
  const SceneSetup setup = wedgeResectionScene(scenario);
  const std::vector<LesionShape> lesions = visible_lesions(scenario);
  ASSERT_EQ(lesions.size(), 1u);
  const SimModel model = build_model(setup.mesh, setup.model_options);
  // An upright blade drawn from the front to the lesion's centre: a slit, nothing cut off.
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < model.node_count; ++i) box.extend(model.rest_position_m.at(i));
  const Eigen::Vector3d centre_m = lesions[0].centre_m;
  BladeStroke stroke;
  for (double z = box.max().z() + 0.01; z >= centre_m.z(); z -= 0.002)
    stroke.add({Eigen::Vector3d(centre_m.x(), box.max().y() + 0.01, z),
                Eigen::Vector3d(centre_m.x(), box.min().y() - 0.01, z)});
  CuttingSettings anything;
  anything.cutting_stress_pa = 0.0;
  const CutResult cut = cut_tissue(model, make_rest_state(model), stroke, anything);
  ASSERT_TRUE(cut.cut());
  ASSERT_GT(cut.model->node_count, model.node_count) << "the cut split no node";

  LiverScene scene(setup.mesh, setup.visual);
  scene.set_opacity(kSeeThroughOpacity);
  scene.show_lesions(lesions);
  const std::size_t whole_lesion = scene.shown_lesion_triangle_count();
  const fs::path before = screenshot(scene, "lesion_before_cut");
  scene.show_cut_model(*cut.model, cut.state.position_m);
  EXPECT_GT(scene.shown_lesion_triangle_count(), 0u);
  const fs::path cut_picture = screenshot(scene, "lesion_cut");
  EXPECT_GT(changedPixels(before, cut_picture), 100) << "the cut does not show";
  scene.show_uncut(make_rest_state(model).position_m);
  EXPECT_EQ(scene.shown_lesion_triangle_count(), whole_lesion);
  const fs::path back = screenshot(scene, "lesion_uncut_again");
  // The same scene drawn again by the same renderer.
  EXPECT_EQ(changedPixels(before, back), 0);
  for (const fs::path& file : {before, cut_picture, back}) fs::remove(file);
}

TEST_F(RenderBaselineTest, ACutShowsItsFacesAndTheScalpel) {
  const SceneSetup setup = default_scene();
  const SimModel model = build_model(setup.mesh, setup.model_options);
  // The left lobe's tip cut off by an oblique plane: the blade, upright across the liver's
  // depth and leaning toward the tip at the back, is drawn from below the liver to above it.
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < model.node_count; ++i) box.extend(model.rest_position_m.at(i));
  BladeStroke stroke;
  for (double y = box.min().y() - 0.01; y <= box.max().y() + 0.01; y += 0.002)
    stroke.add({Eigen::Vector3d(0.085, y, box.max().z() + 0.01),
                Eigen::Vector3d(0.115, y, box.min().z() - 0.01)});
  CuttingSettings anything;
  anything.cutting_stress_pa = 0.0;
  // The freed tip taken out at once (not kept as a body, where it would hide the cut faces).
  anything.min_free_body_volume_m3 = std::numeric_limits<double>::infinity();
  const CutResult cut = cut_tissue(model, make_rest_state(model), stroke, anything);
  ASSERT_TRUE(cut.cut());
  EXPECT_GT(cut.report.removed_elements, 0u) << "the tip did not come free";

  LiverScene scene(setup.mesh, setup.visual);
  const fs::path uncut = screenshot(scene, "before_cut");
  scene.set_tool_models(load_tool_models());
  scene.show_cut_model(*cut.model, cut.state.position_m);
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.pose.origin_m = Eigen::Vector3d(0.10, box.max().y() + 0.012, box.center().z());
  scalpel.pose.orientation = Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitX());
  scene.show_tool(scalpel);
  const fs::path after = screenshot(scene, "after_cut");
  EXPECT_GT(changedPixels(uncut, after), 2000) << "the cut changed little of the picture";
  fs::remove(uncut);
  expectMatchesBaseline(after, "after_cut");
}

TEST(ToolModelsLoading, AMissingFolderNamesEachFileAndLeavesTheCapsules) {
  const ToolModels models = load_tool_models("/nonexistent/tools");
  EXPECT_FALSE(models.probe || models.forceps_body || models.forceps_jaw || models.scalpel);
  for (const char* file : {"probe.obj", "forceps-body.obj", "forceps-jaw.obj", "scalpel.obj"})
    EXPECT_NE(models.problem.find(std::string("/nonexistent/tools/") + file + ": no such file"),
              std::string::npos)
        << models.problem;
}

TEST_F(RenderBaselineTest, ToolModelsAreReadAndDrawnWhereTheirCapsulesAre) {
  const ToolModels models = load_tool_models();
  ASSERT_TRUE(models.problem.empty()) << models.problem;
  const SceneSetup setup = default_scene();
  LiverScene scene(setup.mesh, setup.visual);
  scene.set_tool_models(models);
  // The forceps half open in front of the liver, the shaft toward the viewer and up.
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 0.6;
  forceps.pose.origin_m = Eigen::Vector3d(-0.02, 0.0, 0.08);
  forceps.pose.orientation = Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX());
  scene.show_tool(forceps);
  const fs::path modelled = screenshot(scene, "forceps_model");
  // The jaws' tips (tools.cpp) must fall on the model's steel, not on the liver behind.
  std::array<Capsule, 3> parts;
  ASSERT_EQ(tool_capsules(forceps, parts), 3);
  scene.set_tool_models({});  // no models: the capsules
  scene.show_tool(forceps);
  const fs::path capsules = screenshot(scene, "forceps_capsules");
  const auto a = readPng(modelled);
  const auto b = readPng(capsules);
  for (int jaw = 1; jaw <= 2; ++jaw) {
    // Two thirds along each jaw, where both drawings have steel.
    const Eigen::Vector3d point = parts[jaw].a_m + (2.0 / 3.0) * (parts[jaw].b_m - parts[jaw].a_m);
    const Eigen::Vector2d pixel = screenshotPixel(scene, point);
    for (const auto& image : {a, b}) {
      const auto* p =
          static_cast<unsigned char*>(image->GetScalarPointer(int(pixel.x()), int(pixel.y()), 0));
      // Steel is grey (red ≈ green ≈ blue); the liver is red.
      EXPECT_LT(std::abs(p[0] - p[2]), 40) << "jaw " << jaw << " is not drawn at its capsule";
    }
  }
  EXPECT_GT(changedPixels(modelled, capsules), 100) << "the model looks like the capsules";
  fs::remove(capsules);
  // The model follows the tool when it moves again.
  scene.set_tool_models(models);
  forceps.pose.origin_m.x() += 0.03;
  scene.show_tool(forceps);
  const fs::path moved = screenshot(scene, "forceps_moved");
  EXPECT_GT(changedPixels(modelled, moved), 100) << "the model did not follow the tool";
  fs::remove(moved);
  expectMatchesBaseline(modelled, "forceps_model");
}

// Two hands (issue 43): the left hand's forceps and the right hand's scalpel are drawn at once,
// each where its capsules are, and the same kind in both hands is drawn twice.
TEST_F(RenderBaselineTest, EachHandsToolIsDrawnAtOnce) {
  const SceneSetup setup = default_scene();
  LiverScene scene(setup.mesh, setup.visual);
  scene.set_tool_models(load_tool_models());
  const fs::path empty = screenshot(scene, "no_tools");
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 0.4;
  forceps.pose.origin_m = Eigen::Vector3d(-0.03, 0.0, 0.08);
  forceps.pose.orientation = Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX());
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.pose.origin_m = Eigen::Vector3d(0.05, 0.0, 0.08);
  scalpel.pose.orientation = Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX());
  scene.show_tool(Hand::left, forceps);
  scene.show_tool(Hand::right, scalpel);
  const fs::path both = screenshot(scene, "two_hands");
  const auto image = readPng(both);
  // Steel (grey: red ≈ blue) halfway along each tool's shaft.
  for (const Tool& tool : {forceps, scalpel}) {
    std::array<Capsule, 3> parts;
    tool_capsules(tool, parts);
    const Eigen::Vector2d pixel = screenshotPixel(scene, 0.5 * (parts[0].a_m + parts[0].b_m));
    const auto* p =
        static_cast<unsigned char*>(image->GetScalarPointer(int(pixel.x()), int(pixel.y()), 0));
    EXPECT_LT(std::abs(p[0] - p[2]), 40) << tool_name(tool.kind) << "'s shaft is not drawn";
  }
  // The left hand's put down: only the right's is drawn; a scalpel in each hand: two scalpels.
  scene.show_tool(Hand::left, std::nullopt);
  const fs::path right_only = screenshot(scene, "right_hand_only");
  EXPECT_GT(changedPixels(both, right_only), 500) << "the left hand's forceps stayed";
  Tool other = scalpel;
  other.pose.origin_m.x() = -0.03;
  scene.show_tool(Hand::left, other);
  const fs::path two_scalpels = screenshot(scene, "two_scalpels");
  EXPECT_GT(changedPixels(right_only, two_scalpels), 500) << "the left hand's scalpel is not drawn";
  // Put down, neither is drawn.
  scene.show_tool(Hand::left, std::nullopt);
  scene.show_tool(Hand::right, std::nullopt);
  const fs::path none = screenshot(scene, "tools_put_down");
  EXPECT_EQ(changedPixels(empty, none), 0) << "a tool put down is still drawn";
  for (const fs::path& file : {empty, right_only, two_scalpels, none}) fs::remove(file);
  expectMatchesBaseline(both, "two_hands");
}

// The organ's pixels: red well above blue, which neither the grey-blue background nor the steel
// has.
bool organPixel(const unsigned char* p) {
  return p[0] >= 64 && p[0] > 2 * p[2];
}

// A pixel's hue along the liver's palette: green over red, each less blue, in levels of 255. White
// light scales red, green and blue alike, and a white highlight adds the same to each: neither
// changes it (until red saturates). What changes it is the surface's own colour.
double paletteHue(const unsigned char* p) {
  return 255.0 * (p[1] - p[2]) / (p[0] - p[2]);
}

double paletteHue(const double* colour) {
  return 255.0 * (colour[1] - colour[2]) / (colour[0] - colour[2]);
}

// Rounding each channel to a level moves the difference above and the one below by a level each at
// most, hence paletteHue by at most 255 * (1 + 0.3) / (red - blue) levels (the ratio stays below
// 0.3): 5.2 levels on the pixels it is measured on, whose red exceeds their blue by 64 or more.
constexpr int kHueMinRedOverBlue = 64;
constexpr double kHueRounding = 255.0 * 1.3 / kHueMinRedOverBlue;

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

TEST_F(RenderBaselineTest, TheLiverIsMottledAndHasHighlights) {
  const fs::path file = render("mottled");
  const auto image = readPng(file);
  ASSERT_TRUE(image);
  std::vector<double> hue;
  long organ = 0, highlight = 0;
  const auto* p = static_cast<const unsigned char*>(image->GetScalarPointer());
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i, p += 3) {
    if (!organPixel(p)) continue;
    ++organ;
    // Highlights: white added to the red-brown brings green nearer red than the palette's
    // lightest colour has it, by more than the rounding (2.8 levels at red >= 64).
    highlight += 255.0 * p[1] / p[0] > 255.0 * kTissueLightColour[1] / kTissueLightColour[0] + 10.0;
    if (p[0] - p[2] >= kHueMinRedOverBlue && p[0] < 250) hue.push_back(paletteHue(p));
  }
  std::sort(hue.begin(), hue.end());
  // The organ, ~480 px across, covers well over 50 000 of the 800 x 600 pixels; most of it is
  // bright enough to measure.
  ASSERT_GT(organ, 50'000);
  ASSERT_GT(hue.size(), static_cast<std::size_t>(organ / 2));
  const double low = quantile(hue, 0.1), high = quantile(hue, 0.9);
  std::cout << "organ pixels: " << organ << ", " << hue.size() << " measured; hue 10th to 90th "
            << "percentile: " << low << " to " << high << " (palette "
            << paletteHue(kTissueDarkColour) << " to " << paletteHue(kTissueLightColour)
            << "); highlight pixels: " << highlight << '\n';
  // One flat colour would spread the hue by the rounding alone, 2 x 5.2 levels at the most. The
  // palette spans 39 levels: the mottle's middle 80 % must spread over more than one flat colour
  // can...
  EXPECT_GT(high - low, 2.0 * kHueRounding) << "the organ shows one flat colour; see " << file;
  // ...within the palette (and the rounding).
  EXPECT_GE(low, paletteHue(kTissueDarkColour) - kHueRounding);
  EXPECT_LE(high, paletteHue(kTissueLightColour) + kHueRounding);
  // A moist organ under a headlight and a lamp shows highlights: at least 200 pixels, a patch
  // ~16 px across.
  EXPECT_GT(highlight, 200) << "no specular highlights; see " << file;
  if (!HasFailure()) fs::remove(file);
}

// The pattern belongs to the tissue: the organ and the camera moved by the same 37 mm (the
// mottle's patches are 25 to 50 mm) give the same picture, which a pattern fixed in space would
// not. Only the rasterisation of the organ's outline may change with the rounding.
TEST_F(RenderBaselineTest, TheMottlingMovesWithTheTissue) {
  const SceneSetup setup = default_scene();
  LiverScene scene(setup.mesh, setup.visual);
  const fs::path before = screenshot(scene, "mottle_before");
  const Eigen::Vector3d shift(0.03, -0.02, 0.01);
  NodeArray moved = setup.mesh.rest_position_m;
  for (std::size_t i = 0; i < moved.size(); ++i) moved.set(i, moved.at(i) + shift);
  scene.update_positions(moved);
  vtkCamera* camera = scene.renderer()->GetActiveCamera();
  double position[3], focal[3];
  camera->GetPosition(position);
  camera->GetFocalPoint(focal);
  camera->SetPosition(position[0] + shift.x(), position[1] + shift.y(), position[2] + shift.z());
  camera->SetFocalPoint(focal[0] + shift.x(), focal[1] + shift.y(), focal[2] + shift.z());
  const fs::path after = screenshot(scene, "mottle_after");
  const auto a = readPng(before);
  const auto b = readPng(after);
  ASSERT_TRUE(a && b);
  // Pixels that differ by more than the rounding of a level or two, against the outline's length
  // (organ pixels beside a non-organ pixel).
  const int width = a->GetDimensions()[0], height = a->GetDimensions()[1];
  const auto* pa = static_cast<const unsigned char*>(a->GetScalarPointer());
  const auto* pb = static_cast<const unsigned char*>(b->GetScalarPointer());
  long differing = 0, outline = 0;
  for (int y = 1; y + 1 < height; ++y)
    for (int x = 1; x + 1 < width; ++x) {
      const auto* p = pa + 3 * (y * width + x);
      const auto* q = pb + 3 * (y * width + x);
      bool differs = false;
      for (int c = 0; c < 3; ++c) differs |= std::abs(p[c] - q[c]) > 2;
      differing += differs;
      if (organPixel(p) && !(organPixel(p - 3) && organPixel(p + 3) && organPixel(p - 3 * width) &&
                             organPixel(p + 3 * width)))
        ++outline;
    }
  std::cout << "moved with the camera: " << differing << " pixels differ by more than 2 levels; "
            << "outline " << outline << " pixels\n";
  EXPECT_GT(outline, 1000);
  EXPECT_LT(differing, outline) << "the pattern did not move with the tissue; see " << before
                                << " and " << after;
  if (!HasFailure()) {
    fs::remove(before);
    fs::remove(after);
  }
}

// Luminance of an 8-bit RGB pixel (Rec. 601 weights), in levels.
double luminance(const unsigned char* p) {
  return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
}

// A crease made on purpose: the middle of the anterior face pressed 15 mm in over about a
// centimetre (a Gaussian pit of width 6 mm), as a probe's tip pressing the liver leaves it. (A
// shallow dimple, whose walls rise gently, leaves most of the sky open: little occlusion.)
TEST_F(RenderBaselineTest, AmbientOcclusionDarkensCreases) {
  const SceneSetup setup = default_scene();
  const Eigen::Vector3d centre = setup.mesh.rest_position_m.at(anterior_marked_node(setup.mesh));
  constexpr double kDepth_m = 0.015, kWidth_m = 0.006;
  const NodeArray dented =
      bumped(setup.mesh.rest_position_m, centre, Eigen::Vector3d(0.0, 0.0, -kDepth_m), kWidth_m);
  LiverScene scene(setup.mesh, setup.visual);
  scene.update_positions(dented);
  EXPECT_FALSE(scene.ambient_occlusion());
  const fs::path plain = screenshot(scene, "occlusion_off");
  scene.set_ambient_occlusion(true);
  EXPECT_TRUE(scene.ambient_occlusion());
  const fs::path occluded = screenshot(scene, "occlusion_on");
  const fs::path again = screenshot(scene, "occlusion_on_again");
  const auto a = readPng(plain);
  const auto b = readPng(occluded);
  ASSERT_TRUE(a && b);
  // The same picture twice: the pass's sample kernel and noise are fixed, not drawn anew.
  EXPECT_EQ(differingPixels(b, readPng(again)).count, 0) << "see " << occluded << " and " << again;

  // The dimple's floor on the screen: within one width of its centre, pressed in.
  const Eigen::Vector2d floor_px = screenshotPixel(scene, centre - Eigen::Vector3d(0, 0, kDepth_m));
  const double floor_radius_px = (screenshotPixel(scene, centre + Eigen::Vector3d(kWidth_m, 0, 0)) -
                                  screenshotPixel(scene, centre))
                                     .norm();
  const int width = a->GetDimensions()[0];
  const auto* pa = static_cast<const unsigned char*>(a->GetScalarPointer());
  const auto* pb = static_cast<const unsigned char*>(b->GetScalarPointer());
  long organ = 0, brighter = 0, floor = 0;
  double drop_floor = 0.0, drop_elsewhere = 0.0;
  for (vtkIdType i = 0; i < a->GetNumberOfPoints(); ++i, pa += 3, pb += 3) {
    if (!organPixel(pa)) continue;
    ++organ;
    const double drop = luminance(pa) - luminance(pb);
    // Occlusion only ever takes light away; 1 level for rounding.
    brighter += drop < -1.0;
    const Eigen::Vector2d pixel(static_cast<double>(i % width), static_cast<double>(i / width));
    if ((pixel - floor_px).norm() < floor_radius_px) {
      ++floor;
      drop_floor += drop;
    } else {
      drop_elsewhere += drop;
    }
  }
  ASSERT_GT(organ, 50'000);
  ASSERT_GT(floor, 100) << "the dimple is not in the picture";
  drop_floor /= floor;
  drop_elsewhere /= organ - floor;
  std::cout << "ambient occlusion: the dimple's floor (" << floor << " px) darker by " << drop_floor
            << " levels, the rest of the organ by " << drop_elsewhere << "; " << brighter
            << " pixels brighter\n";
  EXPECT_EQ(brighter, 0);
  // Visibly darker in the crease: by more than the baselines' pixel threshold, 16 levels...
  EXPECT_GT(drop_floor, 16.0) << "see " << plain << " and " << occluded;
  // ...and more than 4 times as much as the organ's open, mostly convex surface: occlusion, not
  // a darker picture.
  EXPECT_GT(drop_floor, 4.0 * drop_elsewhere);
  scene.set_ambient_occlusion(false);
  EXPECT_FALSE(scene.ambient_occlusion());
  const fs::path off_again = screenshot(scene, "occlusion_off_again");
  EXPECT_EQ(changedPixels(plain, off_again), 0) << "turning it off leaves the picture changed";
  if (!HasFailure())
    for (const fs::path& file : {plain, occluded, again, off_again}) fs::remove(file);
}

TEST_F(RenderBaselineTest, AmbientOcclusionKeepsTheSeeThroughView) {
  Scenario scenario;
  const SceneSetup setup = wedgeResectionScene(scenario);
  LiverScene scene(setup.mesh, setup.visual);
  scene.show_lesions(visible_lesions(scenario));
  scene.set_opacity(kSeeThroughOpacity);
  const fs::path plain = screenshot(scene, "see_through_occlusion_off");
  scene.set_ambient_occlusion(true);
  const fs::path occluded = screenshot(scene, "see_through_occlusion_on");
  const long lesion_plain = yellowPixels(plain), lesion_occluded = yellowPixels(occluded);
  std::cout << "lesion pixels seen through: " << lesion_plain << " without occlusion, "
            << lesion_occluded << " with\n";
  // The lesion still shows through, as in SeeThroughShowsTheLesionInsideTheLiver (at least half
  // its disc, 250 px), and the liver around it is still seen through: its picture is not the
  // solid organ's.
  EXPECT_GT(lesion_occluded, 250) << "see " << occluded;
  scene.set_opacity(1.0);
  const fs::path solid = screenshot(scene, "solid_occlusion_on");
  EXPECT_GT(changedPixels(solid, occluded), 50'000) << "see " << solid << " and " << occluded;
  if (!HasFailure())
    for (const fs::path& file : {plain, occluded, solid}) fs::remove(file);
}

}  // namespace
}  // namespace liversim
