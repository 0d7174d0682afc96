#pragma once
// The effects a build may leave out, as bits of LIVERSIM_FORCES_WITHOUT (the studies' public
// kWithout* constants are these).
namespace liversim::force_loop_bits {
inline constexpr unsigned fibres = 1;
inline constexpr unsigned viscous = 2;
inline constexpr unsigned average_nodal_pressure = 4;
inline constexpr unsigned mooney_rivlin = 8;
inline constexpr unsigned gravity = 16;  // the weight and the support's push
}  // namespace liversim::force_loop_bits
