// libFuzzer target: mesh files, OBJ / STL / PLY (build with -DVDMSIM_FUZZ=ON and clang).
#include "fuzz/fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vdmsim::fuzz::mesh_input(data, size);
  return 0;
}
