#pragma once
// Reading a model file through assimp, for surface_import.cpp and visual_model.cpp: the checks
// before it and the error that names the file.

#include "liversim/meshing/surface_import_error.h"

#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace liversim::detail {

// The file's triangles (points and lines dropped), post-processed with `steps`. Throws
// SurfaceImportError naming the file when the unit is not a positive number, the file is
// missing, assimp cannot read it as `what`, it is a damaged PLY file (ply_problem) or binary glTF
// file (glb_problem), or a face has no corners, too many, or a corner that is no vertex.
const aiScene* read_assimp_scene(Assimp::Importer& importer, const std::filesystem::path& file,
                                 double metres_per_unit, unsigned steps, const std::string& what);

// What is wrong with a PLY file (a file starting with "ply", in any case, which is how assimp
// knows one), in its header or its data against the header, and where; none for a sound PLY file
// or another format.
std::optional<std::string> ply_problem(const std::filesystem::path& file);

// What is wrong with the lengths of a binary glTF file (a .glb, or a file starting with "glTF");
// none for sound lengths or another format.
std::optional<std::string> glb_problem(const std::filesystem::path& file);

}  // namespace liversim::detail
