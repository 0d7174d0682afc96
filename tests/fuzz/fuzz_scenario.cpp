// Fuzz target: the scenario reader and its validator (scenario.h). read_scenario promises a
// scenario or a list of errors, never an exception; a scenario it accepts passes validate() and
// reads back the same after write_scenario (what the editor saves is what it opens).

#include "fuzz_support.h"
#include "liversim/scenario/scenario.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace liversim;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ScenarioReading reading = read_scenario(text);
  LIVERSIM_FUZZ_CHECK(reading.scenario.has_value() == reading.errors.empty());
  for (const ScenarioError& error : reading.errors) LIVERSIM_FUZZ_CHECK(!error.message.empty());
  if (!reading.scenario) return 0;

  const Scenario& scenario = *reading.scenario;
  LIVERSIM_FUZZ_CHECK(validate(scenario).empty());
  const ScenarioReading again = read_scenario(write_scenario(scenario));
  LIVERSIM_FUZZ_CHECK(again.errors.empty());
  LIVERSIM_FUZZ_CHECK(again.scenario && *again.scenario == scenario);
  return 0;
}
