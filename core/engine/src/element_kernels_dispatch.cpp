#include "element_kernels.h"

namespace liversim::detail {

const ElasticKernels& elastic_kernels() {
  static const ElasticKernels& chosen = []() -> const ElasticKernels& {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
      return avx2::elastic_kernels();
#endif
    return generic::elastic_kernels();
  }();
  return chosen;
}

}  // namespace liversim::detail
