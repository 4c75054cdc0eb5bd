#pragma once
// A scratch folder for one test file in one test process, under the system's temporary
// folder: named for the file and the process, so that concurrent runs (ctest -j, several
// checkouts, CI next to a developer) never write into each other's files. Made on first use;
// removed, with what is in it, when the process ends normally.
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>
#include <system_error>

namespace vdmsim::test {

inline std::filesystem::path scratch_dir(const std::string& name) {
  struct Made {
    std::set<std::filesystem::path> paths;
    ~Made() {
      for (const std::filesystem::path& p : paths) {
        std::error_code ec;
        std::filesystem::remove_all(p, ec);
      }
    }
  };
  static Made made;
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("vdmsim_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  made.paths.insert(d);
  return d;
}

}  // namespace vdmsim::test
