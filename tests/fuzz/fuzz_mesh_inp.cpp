// Fuzz target: the Abaqus .inp reader (mesh_io.h). It promises a valid mesh or a
// MeshReadError naming the file and, where there is one, the line; nothing else.

#include "fuzz_mesh_check.h"
#include "fuzz_support.h"
#include "liversim/engine/mesh_io.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace liversim;
  const auto file = fuzz::write_scratch_file("input.inp", data, size);
  try {
    fuzz::check_mesh(read_abaqus_inp(file));
  } catch (const MeshReadError& error) {
    LIVERSIM_FUZZ_CHECK(error.file() == file && !error.message().empty() && error.line() >= 0);
  }
  return 0;
}
