#include <dlfcn.h>

#include "app/scene/assimp_import.hpp"

namespace vdmsim {

// VDMSIM_ASSIMP_MODULE (app/CMakeLists.txt): the path of the vdmsim_assimp module built
// with this program.
bool read_with_assimp(const std::string& path, std::vector<vdm::Vec3>& points, std::vector<std::array<int, 3>>& tris,
                      std::string& error) {
  using Read = decltype(&vdmsim_assimp_read);
  static const auto entry = []() -> std::pair<Read, std::string> {
    void* lib = dlopen(VDMSIM_ASSIMP_MODULE, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* why = dlerror();
      return {nullptr, std::string("cannot load the assimp module ") + VDMSIM_ASSIMP_MODULE +
                           (why ? std::string(" (") + why + ")" : std::string())};
    }
    auto read = reinterpret_cast<Read>(dlsym(lib, "vdmsim_assimp_read"));
    if (!read) return {nullptr, std::string(VDMSIM_ASSIMP_MODULE) + " has no vdmsim_assimp_read"};
    return {read, std::string()};
  }();
  if (!entry.first) {
    error = entry.second;
    return false;
  }
  return entry.first(path.c_str(), &points, &tris, &error);
}

}  // namespace vdmsim
