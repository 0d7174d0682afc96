#pragma once
// Reading tetrahedral meshes from disk: Abaqus .inp (C3D4, C3D4T read as C3D4) and Gmsh .msh v2/v4.

#include "liversim/engine/tet_mesh.h"

#include <filesystem>
#include <stdexcept>
#include <string>

namespace liversim {

// A malformed or unsupported mesh file. what() reads "FILE:LINE: message" (LINE omitted when the
// problem is not tied to one line, e.g. an empty file or a missing section).
class MeshReadError : public std::runtime_error {
 public:
  MeshReadError(std::filesystem::path file, int line, const std::string& message);
  const std::filesystem::path& file() const { return file_; }
  int line() const { return line_; }  // 1-based; 0 when not tied to a line
  const std::string& message() const { return message_; }

 private:
  std::filesystem::path file_;
  int line_;
  std::string message_;
};

// Abaqus input file. Coordinates are taken as metres. Node and element ids may be sparse; they are
// renumbered densely in file order. *Nset/*Elset (with or without "generate") become named sets.
TetMesh read_abaqus_inp(const std::filesystem::path& file);

// Gmsh mesh file, format 2.2 or 4.x (ASCII or binary). Only 4-node tetrahedra (type 4) are kept;
// lower-dimensional elements are skipped. The physical tag becomes the element region.
TetMesh read_gmsh_msh(const std::filesystem::path& file);

// Chooses the reader by extension (.inp or .msh); anything else is a MeshReadError.
TetMesh read_tet_mesh(const std::filesystem::path& file);

}  // namespace liversim
