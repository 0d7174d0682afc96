#pragma once
// Reading a model file through assimp, for surface_import.cpp and visual_model.cpp: the checks
// before it and the error that names the file.

#include "liversim/core/surface_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <cmath>
#include <filesystem>
#include <string>

namespace liversim::detail {

// The file's triangles (points and lines dropped), post-processed with `steps`. Throws
// SurfaceImportError naming the file when the unit is not a positive number, the file is
// missing, or assimp cannot read it as `what`.
inline const aiScene* read_assimp_scene(Assimp::Importer& importer,
                                        const std::filesystem::path& file, double metres_per_unit,
                                        unsigned steps, const std::string& what) {
  const std::string name = file.string();
  if (!(metres_per_unit > 0.0) || !std::isfinite(metres_per_unit))
    throw SurfaceImportError(name + ": the length unit must be a positive number of metres");
  if (!std::filesystem::exists(file)) throw SurfaceImportError(name + ": no such file");
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(name, steps);
  if (scene == nullptr)
    throw SurfaceImportError(name + ": cannot read it as " + what + ": " +
                             importer.GetErrorString());
  return scene;
}

}  // namespace liversim::detail
