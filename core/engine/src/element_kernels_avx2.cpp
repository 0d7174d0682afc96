// The element kernels built with AVX2 and FMA (core/CMakeLists.txt sets the flags for this file
// alone); used only when the processor has both (element_kernels_dispatch.cpp).
#if defined(__x86_64__) && defined(__AVX2__) && defined(__FMA__)
#define LIVERSIM_KERNEL_ISA avx2
#define LIVERSIM_KERNEL_ISA_NAME "avx2+fma"
#include "element_kernels_body.h"
#else
#include "element_kernels.h"
namespace liversim::detail::avx2 {
// Not built for AVX2 (another architecture or compiler): the generic build stands in.
const ElasticKernels& elastic_kernels() {
  return generic::elastic_kernels();
}
}  // namespace liversim::detail::avx2
#endif
