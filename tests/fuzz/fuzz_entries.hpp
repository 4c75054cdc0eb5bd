#pragma once
// Entry points shared by the libFuzzer targets (fuzz_scene, fuzz_mesh, fuzz_sweep; clang only) and the
// corpus replay test that every build runs: the same code sees the same inputs.
#include <cstddef>
#include <cstdint>

namespace vdmsim::fuzz {

// The bytes as a scene file, through load_scene (YAML parsing and every schema check).
void scene_input(const std::uint8_t* data, std::size_t size);

// The first byte chooses the format (OBJ, STL, PLY; by its value mod 3), the rest is the file,
// through load_surface_mesh (reader, welding, validation).
void mesh_input(const std::uint8_t* data, std::size_t size);

// The bytes as a sweep file (tests/fuzz/sweep_entry.cpp) beside a small valid base scene
// (base.yaml) and organ, through read_sweep_file and, when it is valid, plan_sweep: every run's
// scene must read back as YAML with no top-level key the base scene or the sweep's keys do not
// name (a value that became YAML structure aborts).
void sweep_input(const std::uint8_t* data, std::size_t size);

}  // namespace vdmsim::fuzz
