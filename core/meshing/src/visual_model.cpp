#include "liversim/meshing/visual_model.h"

#include "assimp_reading.h"
#include "liversim/meshing/surface_import.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cmath>

namespace liversim {

VisualModel read_visual_model(const std::filesystem::path& file, double metres_per_unit) {
  const std::string name = file.string();
  Assimp::Importer importer;
  // Normals the file gives are kept (its creases); missing ones are made smooth.
  const aiScene* scene = detail::read_assimp_scene(
      importer, file, metres_per_unit,
      aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType |
          aiProcess_GenSmoothNormals | aiProcess_FindDegenerates,
      "a model");
  VisualModel model;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* source = scene->mMeshes[m];
    if (source->mNormals == nullptr) continue;  // no triangles in it
    VisualMesh mesh;
    mesh.position_m.reserve(source->mNumVertices);
    mesh.normal.reserve(source->mNumVertices);
    for (unsigned v = 0; v < source->mNumVertices; ++v) {
      const aiVector3D& p = source->mVertices[v];
      const aiVector3D& n = source->mNormals[v];
      mesh.position_m.emplace_back(static_cast<float>(p.x * metres_per_unit),
                                   static_cast<float>(p.y * metres_per_unit),
                                   static_cast<float>(p.z * metres_per_unit));
      Eigen::Vector3f normal(n.x, n.y, n.z);
      if (!mesh.position_m.back().allFinite() || !normal.allFinite())
        throw SurfaceImportError(name + ": a vertex of mesh " + std::to_string(m) +
                                 " is not a number");
      mesh.normal.push_back(normal.norm() > 0.0f ? normal.normalized() : normal);
    }
    for (unsigned f = 0; f < source->mNumFaces; ++f) {
      const aiFace& face = source->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({static_cast<std::int32_t>(face.mIndices[0]),
                                static_cast<std::int32_t>(face.mIndices[1]),
                                static_cast<std::int32_t>(face.mIndices[2])});
    }
    if (mesh.triangles.empty()) continue;
    if (source->mMaterialIndex < scene->mNumMaterials) {
      const aiMaterial* material = scene->mMaterials[source->mMaterialIndex];
      aiColor3D colour;
      if (material->Get(AI_MATKEY_COLOR_DIFFUSE, colour) == aiReturn_SUCCESS)
        mesh.diffuse_colour = {colour.r, colour.g, colour.b};
      if (material->Get(AI_MATKEY_COLOR_SPECULAR, colour) == aiReturn_SUCCESS)
        mesh.specular = std::clamp(std::max({colour.r, colour.g, colour.b}), 0.0f, 1.0f);
      float shininess = 0.0f;
      if (material->Get(AI_MATKEY_SHININESS, shininess) == aiReturn_SUCCESS && shininess > 0.0f)
        mesh.shininess = shininess;
    }
    model.push_back(std::move(mesh));
  }
  if (model.empty()) throw SurfaceImportError(name + ": the file holds no triangles");
  return model;
}

}  // namespace liversim
