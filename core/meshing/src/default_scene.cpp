#include "liversim/meshing/default_scene.h"

#include "liversim/engine/mesh_io.h"
#include "liversim/engine/surface.h"

#include <Eigen/Geometry>

#include <limits>
#include <stdexcept>

namespace liversim {

SceneSetup default_scene(int tet_count) {
  SceneSetup setup;
  setup.mesh = generate_liver_mesh(tet_count).mesh;
  setup.model_options.fixed_nodes = setup.mesh.node_sets.at("ligament");
  // ν = 0.49 locks linear tetrahedra; average nodal pressure removes it (docs/tissue-model.md).
  setup.model_options.average_nodal_pressure = true;
  // The mesher's quality guards stop some boundary nodes short of the surface; the rendered
  // surface sits on the smooth shape and follows the elements that hold it.
  const LiverShape shape;
  const BoundarySurface surface = extract_surface(setup.mesh);
  std::vector<Eigen::Vector3d> on_shape;
  on_shape.reserve(surface.nodes.size());
  for (NodeIndex n : surface.nodes)
    on_shape.push_back(shape.closest_surface_point(setup.mesh.rest_position_m.at(n)));
  setup.visual = embed_visual_surface(setup.mesh, surface, on_shape);
  setup.description = "built-in liver, " + std::to_string(setup.mesh.tet_count()) + " tetrahedra";
  setup.built_in_liver_tets = tet_count;
  return setup;
}

SceneSetup scene_from_file(const std::filesystem::path& file,
                           const std::optional<std::string>& fixed_node_set) {
  SceneSetup setup;
  setup.mesh = read_tet_mesh(file);
  if (fixed_node_set) {
    const auto set = setup.mesh.node_sets.find(*fixed_node_set);
    if (set == setup.mesh.node_sets.end())
      throw std::invalid_argument("node set '" + *fixed_node_set + "' is not defined in " +
                                  file.string());
    setup.model_options.fixed_nodes = set->second;
  }
  setup.visual = visual_surface_on_nodes(setup.mesh);
  setup.description =
      file.filename().string() + ", " + std::to_string(setup.mesh.tet_count()) + " tetrahedra";
  return setup;
}

SceneSetup scene_from_surface(const std::filesystem::path& file, double metres_per_unit,
                              int target_tet_count, const MeshingProgressCallback& progress) {
  TriangleSurface surface = read_surface_file(file, metres_per_unit);
  orient_outward(surface);
  SurfaceMeshingOptions options;
  options.target_tet_count = target_tet_count;
  options.progress = progress;
  SceneSetup setup;
  try {
    setup.mesh = tetrahedralise_surface(surface, options);
  } catch (const SurfaceMeshingCancelled&) {
    throw;
  } catch (const SurfaceImportError& e) {
    throw SurfaceImportError(file.string() + ": " + e.what());
  }
  setup.visual = visual_surface_on_nodes(setup.mesh);
  setup.description =
      file.filename().string() + ", " + std::to_string(setup.mesh.tet_count()) + " tetrahedra";
  return setup;
}

NodeIndex anterior_marked_node(const TetMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) box.extend(mesh.rest_position_m.at(n));
  const Eigen::Vector3d target(box.center().x(), box.center().y(), box.max().z());
  NodeIndex best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (NodeIndex n : extract_surface(mesh).nodes) {
    const double d = (mesh.rest_position_m.at(n) - target).squaredNorm();
    if (d < best_distance) {
      best_distance = d;
      best = n;
    }
  }
  return best;
}

}  // namespace liversim
