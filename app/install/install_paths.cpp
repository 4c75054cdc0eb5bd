#include "app/install/install_paths.hpp"

#include <filesystem>
#include <system_error>

// Set for this file alone by app/CMakeLists.txt:
//   VDMSIM_ASSIMP_MODULE             the module's path in the build tree
//   VDMSIM_ASSIMP_MODULE_NAME        its file name
//   VDMSIM_MODULE_DIR_FROM_BINDIR    the installed module's folder, relative to the installed executable's
//   VDMSIM_DATA_DIR_FROM_BINDIR      the installed scenes' and meshes' folder, relative to the same
//   VDMSIM_SOURCE_DIR_STR            the source tree

namespace vdmsim {

namespace fs = std::filesystem;

std::string executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

namespace {

// `relative` (to the executable's folder) when `probe` exists under it, else "".
std::string installed(const char* relative, const char* probe) {
  const std::string bin = executable_dir();
  if (bin.empty()) return "";
  const fs::path dir = (fs::path(bin) / relative).lexically_normal();
  std::error_code ec;
  return fs::exists(dir / probe, ec) ? dir.string() : "";
}

}  // namespace

std::string assimp_module_path() {
  const std::string dir = installed(VDMSIM_MODULE_DIR_FROM_BINDIR, VDMSIM_ASSIMP_MODULE_NAME);
  return dir.empty() ? std::string(VDMSIM_ASSIMP_MODULE) : (fs::path(dir) / VDMSIM_ASSIMP_MODULE_NAME).string();
}

std::string data_dir() {
  const std::string dir = installed(VDMSIM_DATA_DIR_FROM_BINDIR, "scenes");
  return dir.empty() ? (fs::path(VDMSIM_SOURCE_DIR_STR) / "assets").string() : dir;
}

}  // namespace vdmsim
