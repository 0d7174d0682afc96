#pragma once
// The one wording of a setting that is out of range, for every validator in the engine:
// "<name> = <value> is invalid: expected <expected>".

#include <sstream>
#include <string>
#include <string_view>

namespace liversim {

inline std::string out_of_range_message(std::string_view name, double value,
                                        std::string_view expected) {
  std::ostringstream message;
  message << name << " = " << value << " is invalid: expected " << expected;
  return message.str();
}

}  // namespace liversim
