#pragma once
// Rigid models that are only drawn, never simulated: the tools' (resources/tools), read through
// assimp with their materials. The physics of a tool stays its capsules (tools.h); a model is
// made to match them, in the tool's frame (see resources/tools/README.md).

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace liversim {

// One material's triangles, with a normal per vertex for smooth shading (creases carry their
// own vertices).
struct VisualMesh {
  std::vector<Eigen::Vector3f> position_m;
  std::vector<Eigen::Vector3f> normal;  // unit
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::array<float, 3> diffuse_colour{0.7f, 0.7f, 0.7f};  // 0..1
  float specular = 0.0f;                                  // 0..1, of the specular colour
  float shininess = 1.0f;                                 // specular exponent
};

using VisualModel = std::vector<VisualMesh>;

// Reads a model file (OBJ with its MTL, glTF, PLY, ...), its lengths scaled to metres. Throws
// SurfaceImportError (surface_import.h) naming the file and what is wrong: missing, unreadable,
// no triangles, a coordinate that is not a number.
VisualModel read_visual_model(const std::filesystem::path& file, double metres_per_unit);

}  // namespace liversim
