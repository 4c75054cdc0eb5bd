#include <dlfcn.h>

#include "app/install/install_paths.hpp"
#include "app/scene/assimp_import.hpp"

namespace vdmsim {

// The vdmsim_assimp module beside the installed program, or the one built with it
// (app/install/install_paths.hpp).
bool read_with_assimp(const std::string& path, std::vector<vdm::Vec3>& points, std::vector<std::array<int, 3>>& tris,
                      std::string& error) {
  using Read = decltype(&vdmsim_assimp_read);
  static const auto entry = []() -> std::pair<Read, std::string> {
    const std::string module = assimp_module_path();
    void* lib = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* why = dlerror();
      return {nullptr, "cannot load the assimp module " + module + (why ? std::string(" (") + why + ")" : std::string())};
    }
    auto read = reinterpret_cast<Read>(dlsym(lib, "vdmsim_assimp_read"));
    if (!read) return {nullptr, module + " has no vdmsim_assimp_read"};
    return {read, std::string()};
  }();
  if (!entry.first) {
    error = entry.second;
    return false;
  }
  return entry.first(path.c_str(), &points, &tris, &error);
}

}  // namespace vdmsim
