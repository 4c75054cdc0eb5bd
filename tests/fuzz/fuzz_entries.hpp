#pragma once
// Entry points shared by the libFuzzer targets (fuzz_scene, fuzz_mesh; clang only) and the
// corpus replay test that every build runs: the same code sees the same inputs.
#include <cstddef>
#include <cstdint>

namespace vdmsim::fuzz {

// The bytes as a scene file, through load_scene (YAML parsing and every schema check).
void scene_input(const std::uint8_t* data, std::size_t size);

// The first byte chooses the format (OBJ, STL, PLY; by its value mod 3), the rest is the file,
// through load_surface_mesh (reader, welding, validation).
void mesh_input(const std::uint8_t* data, std::size_t size);

}  // namespace vdmsim::fuzz
