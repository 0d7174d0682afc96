// Fuzz target: the surface-model importer (surface_import.h) over assimp, in every format it
// reads. The first byte of the input picks the format (its extension: assimp chooses the reader
// by it), the rest is the file. read_surface_file promises triangles over its vertices, all
// finite, or a SurfaceImportError; the checks a scenario's organ then gets (surface_problems,
// orient_outward) must not fail on what it returns. Gmsh's meshing is not fuzzed (docs/fuzzing.md).

#include "fuzz_support.h"
#include "liversim/meshing/surface_import.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace liversim;
  if (size < 1) return 0;
  const auto& extensions = surface_file_extensions();
  const std::string& extension = extensions[data[0] % extensions.size()];
  const auto file = fuzz::write_scratch_file("input" + extension, data + 1, size - 1);
  try {
    TriangleSurface surface = read_surface_file(file, 1e-3);
    const auto vertices = static_cast<std::int64_t>(surface.vertices_m.size());
    LIVERSIM_FUZZ_CHECK(!surface.triangles.empty());
    for (const auto& v : surface.vertices_m) LIVERSIM_FUZZ_CHECK(v.allFinite());
    for (const auto& t : surface.triangles)
      for (int k = 0; k < 3; ++k) {
        LIVERSIM_FUZZ_CHECK(t[k] >= 0 && t[k] < vertices);
        LIVERSIM_FUZZ_CHECK(t[k] != t[(k + 1) % 3]);
      }
    surface_problems(surface);
    orient_outward(surface);
  } catch (const SurfaceImportError& error) {
    LIVERSIM_FUZZ_CHECK(std::string(error.what()).starts_with(file.string() + ": "));
  }
  return 0;
}
