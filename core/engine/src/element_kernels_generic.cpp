// The element kernels for any x86-64 (or other) processor.
#define LIVERSIM_KERNEL_ISA generic
#define LIVERSIM_KERNEL_ISA_NAME "generic"
#include "element_kernels_body.h"
