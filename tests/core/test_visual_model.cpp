// Tool models read through assimp (visual_model.h), and points carried by the deforming mesh
// (surface.h, embed_points): what the see-through view draws lesions with.
#include "block_mesh.h"

#include "liversim/engine/surface.h"
#include "liversim/meshing/surface_import.h"
#include "liversim/meshing/visual_model.h"
#include "liversim/scenario/data_paths.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace liversim {
namespace {

namespace fs = std::filesystem;

const fs::path kTools = shipped_resources_folder() / "tools";

TEST(VisualModel, TheShippedToolModelsReadInMetresWithUnitNormalsAndTheirMaterials) {
  for (const char* file : {"probe.obj", "forceps-body.obj", "forceps-jaw.obj", "scalpel.obj"}) {
    SCOPED_TRACE(file);
    const VisualModel model = read_visual_model(kTools / file, 1e-3);
    ASSERT_FALSE(model.empty());
    Eigen::AlignedBox3f box;
    bool steel = false;
    for (const VisualMesh& mesh : model) {
      ASSERT_EQ(mesh.position_m.size(), mesh.normal.size());
      ASSERT_FALSE(mesh.triangles.empty());
      for (const auto& p : mesh.position_m) box.extend(p);
      for (const auto& n : mesh.normal) EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
      for (const auto& t : mesh.triangles)
        for (auto v : t) ASSERT_LT(static_cast<std::size_t>(v), mesh.position_m.size());
      // tools.mtl's steel: Kd 0.72 0.74 0.78, shiny.
      steel |= std::abs(mesh.diffuse_colour[0] - 0.72f) < 1e-3f && mesh.specular > 0.5f;
    }
    EXPECT_TRUE(steel) << "no mesh has the steel material of tools.mtl";
    // Millimetres read as metres: the tools are at most 13 cm long, the jaw and blade 2 cm.
    EXPECT_LE(box.max().z(), 0.1301f);
    EXPECT_GE(box.min().z(), -0.0201f);
  }
  // The jaw sits on the +x side of the hinge, within its capsule (radius 1.5 mm).
  Eigen::AlignedBox3f jaw;
  for (const VisualMesh& mesh : read_visual_model(kTools / "forceps-jaw.obj", 1e-3))
    for (const auto& p : mesh.position_m) jaw.extend(p);
  EXPECT_GE(jaw.min().x(), -1e-6f);
  EXPECT_LE(jaw.max().x(), 0.0015f + 1e-6f);
}

TEST(VisualModel, ABadModelFileIsRefusedNamingIt) {
  const auto refused = [](const fs::path& file, double unit, const std::string& why) {
    try {
      read_visual_model(file, unit);
      ADD_FAILURE() << file << " was read";
    } catch (const SurfaceImportError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      EXPECT_NE(message.find(why), std::string::npos) << message;
    }
  };
  refused("/nonexistent/probe.obj", 1e-3, "no such file");
  refused(kTools / "probe.obj", 0.0, "length unit");
  const fs::path garbage = fs::temp_directory_path() / "liversim-garbage-model.obj";
  std::ofstream(garbage) << "this is not a model\n\x01\x02\x03";
  refused(garbage, 1e-3, garbage.filename().string());
  fs::remove(garbage);
}

TEST(EmbeddedPoints, PointsInsideAreHeldAndFollowTheMesh) {
  const TetMesh mesh = testing::block_mesh(4, 3, 3, {0.04, 0.03, 0.03}, 0.15);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i)
    points.emplace_back(0.04 * unit(random), 0.03 * unit(random), 0.03 * unit(random));
  points.emplace_back(0.5, 0.5, 0.5);  // far outside: not held
  const EmbeddedPoints embedded = embed_points(mesh, points);
  ASSERT_EQ(embedded.held.size(), points.size());
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    ASSERT_TRUE(embedded.held[i]) << "point " << i << " inside the block is not held";
    for (double w : embedded.weights[i]) EXPECT_GE(w, -1e-12) << "point " << i;
  }
  EXPECT_FALSE(embedded.held.back());

  // At rest the weights give the points back; moved rigidly, the points move with the mesh.
  std::vector<double> xyz;
  map_embedded_positions(embedded.host_nodes, embedded.weights, mesh.rest_position_m, xyz);
  for (std::size_t i = 0; i + 1 < points.size(); ++i)
    EXPECT_LT((Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) - points[i]).norm(),
              1e-14);
  const Eigen::Affine3d motion =
      Eigen::Translation3d(0.01, -0.02, 0.005) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  NodeArray moved = mesh.rest_position_m;
  for (std::size_t n = 0; n < moved.size(); ++n) moved.set(n, motion * mesh.rest_position_m.at(n));
  map_embedded_positions(embedded.host_nodes, embedded.weights, moved, xyz);
  for (std::size_t i = 0; i + 1 < points.size(); ++i)
    EXPECT_LT(
        (Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) - motion * points[i]).norm(),
        1e-14);
}

}  // namespace
}  // namespace liversim
