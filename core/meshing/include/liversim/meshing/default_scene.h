#pragma once
// The scene the workstation and the CLI start with when nothing else is asked for: the built-in
// liver with the seed's tissue, held at its ligament attachment. Scenario files (issue 9) will
// replace these defaults; until then this is the one place they are defined.

#include "liversim/engine/model.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/liver_geometry.h"
#include "liversim/meshing/surface_import.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace liversim {

struct SceneSetup {
  TetMesh mesh;
  ModelOptions model_options;
  VisualSurface visual;     // what is rendered: on the smooth organ surface when it is known
  std::string description;  // e.g. "built-in liver, 5450 tetrahedra"
  // default_scene's: the element count asked for, which builds the same liver again.
  std::optional<int> built_in_liver_tets;
};

// Built-in liver at the requested element count, ligament nodes fixed.
SceneSetup default_scene(int tet_count = kDefaultLiverTetCount);

// A mesh read from disk, with the nodes of the named node set fixed. Throws MeshReadError for a bad
// file and std::invalid_argument when the set does not exist.
SceneSetup scene_from_file(const std::filesystem::path& file,
                           const std::optional<std::string>& fixed_node_set);

// Meshing's progress; returning false cancels (SurfaceMeshingCancelled).
using MeshingProgressCallback = std::function<bool(const MeshingProgress&)>;

// A surface model (surface_import.h) in `metres_per_unit`, checked and tetrahedralised at about
// `target_tet_count` elements; nothing is fixed. The rendered surface is the mesh's boundary,
// which is the model's own triangles. Throws SurfaceImportError naming the file and the problem.
SceneSetup scene_from_surface(const std::filesystem::path& file, double metres_per_unit,
                              int target_tet_count, const MeshingProgressCallback& progress = {});

// The surface node nearest to the centre of the anterior (+z) face of the mesh's bounding box: a
// reproducible "marked point" for loads when none is given.
NodeIndex anterior_marked_node(const TetMesh& mesh);

}  // namespace liversim
