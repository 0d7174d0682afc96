#pragma once

#include <stdexcept>

namespace liversim {

// What went wrong reading, checking or meshing a surface: names the file (when there is one), and
// what is wrong and where.
class SurfaceImportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace liversim
