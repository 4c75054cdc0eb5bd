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

// -1 until the first question, then 0 (the SSE2 kernels) or 1 (AVX2). Constant-initialised,
// so a kernel run from another translation unit's static initialiser finds it set up.
std::atomic<signed char> state{-1};

}  // namespace

bool avx2_supported() {
  static const bool supported = detect();
  return supported;
}

bool avx2_enabled() {
  signed char v = state.load(std::memory_order_relaxed);
  if (v < 0) {  // first use (threads racing here all store the same value)
    v = from_environment() ? 1 : 0;
    state.store(v, std::memory_order_relaxed);
  }
  return v != 0;
}

bool set_avx2(bool on) {
  state.store(on && avx2_supported() ? 1 : 0, std::memory_order_relaxed);
  return avx2_enabled();
}

}  // namespace vdm::simd
