/* Compatibility layer for headers compiled both by OpenCL C 1.2 and by C++17.
 *
 * Shared headers (everything under kernels/shared/) declare plain-old-data structs that cross the
 * host/device boundary. They use only the vector types float4/int4/uint4 (16-byte aligned in both
 * languages, never float3) and 32-bit scalars, and pad explicitly, so the layout is identical on
 * both sides. The host checks sizes and offsets with static_assert (host/device/device_types.cpp).
 *
 * In C++ the declarations live in namespace wp::dev, opened and closed by WP_DEV_BEGIN/WP_DEV_END.
 */
#ifndef WP_SHARED_COMPAT_H
#define WP_SHARED_COMPAT_H

#ifdef __OPENCL_VERSION__

#define WP_DEV_BEGIN
#define WP_DEV_END

#else /* C++ host */

#include <cstdint>

#define WP_DEV_BEGIN \
  namespace wp {     \
  namespace dev {
#define WP_DEV_END \
  }                \
  }

WP_DEV_BEGIN
using uint = std::uint32_t;
struct alignas(16) float4 {
  float x, y, z, w;
};
struct alignas(16) int4 {
  std::int32_t x, y, z, w;
};
struct alignas(16) uint4 {
  std::uint32_t x, y, z, w;
};
struct alignas(32) float8 {
  float s[8];
};
struct alignas(32) int8 {
  std::int32_t s[8];
};
WP_DEV_END

#endif

#endif /* WP_SHARED_COMPAT_H */
