#include "app/compare/image_pairs.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>
#include <system_error>

namespace vdmsim {

namespace fs = std::filesystem;

namespace {

bool is_png(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".png";
}

// The PNG files under `dir`, as paths relative to it ("" in `error` unless the folder cannot be read).
std::set<std::string> pngs_under(const fs::path& dir, std::string& error) {
  std::set<std::string> out;
  std::error_code ec;
  fs::recursive_directory_iterator it(dir, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const fs::path& p = it->path();
    std::error_code probe;  // a file that vanishes or cannot be inspected is not a PNG of the folder
    if (it->is_regular_file(probe) && is_png(p)) out.insert(p.lexically_relative(dir).generic_string());
  }
  if (ec) error = dir.string() + ": cannot read the folder (" + ec.message() + ")";
  return out;
}

}  // namespace

ImagePairing pair_images(const std::string& expected, const std::string& actual) {
  ImagePairing r;
  std::error_code ec;
  for (const std::string& p : {expected, actual})
    if (!fs::exists(p, ec)) {
      r.error = p + ": no such file or folder";
      return r;
    }
  const bool dir_e = fs::is_directory(expected, ec), dir_a = fs::is_directory(actual, ec);
  if (dir_e != dir_a) {
    r.error = (dir_e ? actual : expected) + ": a file, but " + (dir_e ? expected : actual) +
              " is a folder (compare two PNG files or two folders)";
    return r;
  }
  if (!dir_e) {
    r.pairs.push_back({actual, expected, actual});
    return r;
  }
  r.folders = true;
  const std::set<std::string> e = pngs_under(expected, r.error);
  if (!r.ok()) return r;
  const std::set<std::string> a = pngs_under(actual, r.error);
  if (!r.ok()) return r;
  if (e.empty()) {
    r.error = expected + ": no PNG images in the folder or its subfolders";
    return r;
  }
  for (const std::string& name : e) {
    if (a.count(name))
      r.pairs.push_back({name, (fs::path(expected) / name).string(), (fs::path(actual) / name).string()});
    else
      r.missing_in_actual.push_back(name);
  }
  for (const std::string& name : a)
    if (!e.count(name)) r.missing_in_expected.push_back(name);
  return r;
}

}  // namespace vdmsim
