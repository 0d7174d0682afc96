// Fuzz target: the trace-blob decoders of the session log (session_log.h), frame chunks ("LSF1")
// and the simulation's input chunks ("LSI1"). Each promises its items or a StorageError saying
// what is wrong; what decodes encodes back to the same bytes (frames: exact, every bit) or to a
// fixed point (inputs: a flag byte other than 0 or 1 reads as 1).

#include "fuzz_support.h"
#include "liversim/sessions/session_store.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace liversim;
  const std::span<const std::uint8_t> bytes(data, size);
  try {
    const std::vector<ServoFrame> frames = decode_frame_chunk(bytes);
    const std::vector<std::uint8_t> encoded = encode_frame_chunk(frames);
    LIVERSIM_FUZZ_CHECK(std::equal(encoded.begin(), encoded.end(), bytes.begin(), bytes.end()));
  } catch (const StorageError& error) {
    LIVERSIM_FUZZ_CHECK(!std::string_view(error.what()).empty());
  }
  try {
    const std::vector<SimulationInput> inputs = decode_input_chunk(bytes);
    const std::vector<std::uint8_t> encoded = encode_input_chunk(inputs);
    LIVERSIM_FUZZ_CHECK(encoded.size() == bytes.size());
    LIVERSIM_FUZZ_CHECK(encode_input_chunk(decode_input_chunk(encoded)) == encoded);
  } catch (const StorageError& error) {
    LIVERSIM_FUZZ_CHECK(!std::string_view(error.what()).empty());
  }
  return 0;
}
