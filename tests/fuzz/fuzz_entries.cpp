#include "fuzz/fuzz_entries.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "app/scene/mesh_io.hpp"
#include "app/scene/scene.hpp"

namespace vdmsim::fuzz {
namespace {

// Writes the bytes to a per-process temporary file with the given extension.
std::string to_file(const std::uint8_t* data, std::size_t size, const char* ext) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("vdmsim_fuzz_" + std::to_string(::getpid()) + "." + ext)).string();
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  return path;
}

}  // namespace

void scene_input(const std::uint8_t* data, std::size_t size) {
  const std::string path = to_file(data, size, "yaml");
  const SceneLoadResult r = load_scene(path);
  for (const SceneProblem& p : r.problems) (void)p.text();
  std::remove(path.c_str());
}

void mesh_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  static const char* const kExt[] = {"obj", "stl", "ply"};
  const std::string path = to_file(data + 1, size - 1, kExt[data[0] % 3]);
  MeshLoadOptions opt;
  opt.max_file_bytes = 1 << 20;
  const MeshLoadResult r = load_surface_mesh(path, opt);
  if (r.ok && !(r.mesh.positions.allFinite())) std::abort();  // a valid organ is finite
  std::remove(path.c_str());
}

}  // namespace vdmsim::fuzz
