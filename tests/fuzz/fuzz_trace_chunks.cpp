// Fuzz target: the trace-blob decoders of the session log (session_log.h), frame chunks ("LSF1",
// "LSF2") and the simulation's input chunks ("LSI1"). Each promises its items or a StorageError
// saying what is wrong; what decodes encodes to a fixed point that decodes to the same items
// (frames: every bit; a chunk is written in layout 2, and an orientation whose w is NaN reads as
// none) and, for a layout-2 chunk with no orientation column NaN, to the same bytes; inputs: a
// flag byte other than 0 or 1 reads as 1.

#include "fuzz_support.h"
#include "liversim/sessions/session_store.h"

#include <cstddef>
#include <cstring>
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
    LIVERSIM_FUZZ_CHECK(encode_frame_chunk(decode_frame_chunk(encoded)) == encoded);
    const std::vector<ServoFrame> again = decode_frame_chunk(encoded);
    LIVERSIM_FUZZ_CHECK(again.size() == frames.size());
    bool every_orientation = bytes.size() > 3 && bytes[3] == '2';
    for (std::size_t i = 0; i < frames.size(); ++i) {
      LIVERSIM_FUZZ_CHECK(std::memcmp(&again[i].time_s, &frames[i].time_s, 8) == 0);
      LIVERSIM_FUZZ_CHECK(again[i].sample.buttons == frames[i].sample.buttons);
      LIVERSIM_FUZZ_CHECK(again[i].sample.orientation.has_value() ==
                          frames[i].sample.orientation.has_value());
      every_orientation = every_orientation && frames[i].sample.orientation &&
                          !frames[i].sample.orientation->coeffs().hasNaN();
    }
    if (every_orientation)
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
