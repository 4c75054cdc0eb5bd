// libFuzzer target: sweep files (build with -DVDMSIM_FUZZ=ON and clang), beside a valid base scene.
#include "fuzz/fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vdmsim::fuzz::sweep_input(data, size);
  return 0;
}
