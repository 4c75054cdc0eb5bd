#include "app/run/output_dir.hpp"

#include <filesystem>
#include <fstream>

namespace vdmsim {

bool prepare_output_dir(const std::string& dir, std::string& error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    error = dir + ": cannot create the output folder (" + (ec ? ec.message() : "not a folder") + ")";
    return false;
  }
  const fs::path probe = fs::path(dir) / ".vdmsim-write-test";
  {
    std::ofstream f(probe);
    if (!f || !(f << "ok") || !(f.flush())) {
      error = dir + ": the output folder is not writable";
      return false;
    }
  }
  fs::remove(probe, ec);
  return true;
}

bool write_file_atomically(const std::filesystem::path& path, const std::string& body, std::string& error) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << body;
    f.flush();
    if (!f) {
      error = tmp.string() + ": write failed";
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    error = path.string() + ": " + ec.message();
    return false;
  }
  return true;
}

}  // namespace vdmsim
