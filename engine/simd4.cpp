#include "engine/simd4.hpp"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace vdm::simd {

namespace {

bool detect() {
  __builtin_cpu_init();  // may run before libgcc's own initialiser: a static initialiser
  return __builtin_cpu_supports("avx2") != 0;
}

bool from_environment() {
  if (!avx2_supported()) return false;
  const char* v = std::getenv("VDMSIM_SIMD");
  return !(v && std::strcmp(v, "sse2") == 0);
}

// Zero (the SSE2 kernels) until initialised: a kernel run from another static initialiser
// before this one still gives the same bits.
std::atomic<bool> enabled{from_environment()};

}  // namespace

bool avx2_supported() {
  static const bool supported = detect();
  return supported;
}

bool avx2_enabled() { return enabled.load(std::memory_order_relaxed); }

bool set_avx2(bool on) {
  enabled.store(on && avx2_supported(), std::memory_order_relaxed);
  return avx2_enabled();
}

}  // namespace vdm::simd
