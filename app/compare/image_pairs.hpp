#pragma once
// The images `vdmsim compare` compares: two PNG files, or two folders (run outputs) whose PNG
// images, found in the folders and their subfolders (frames/, stress/, the contact sheet), are
// paired by their path relative to the folder.
#include <string>
#include <vector>

namespace vdmsim {

struct ImagePair {
  std::string name;  // the relative path (folders) or ACTUAL's path (two files)
  std::string expected, actual;
};

struct ImagePairing {
  bool folders = false;
  std::vector<ImagePair> pairs;                  // sorted by name
  std::vector<std::string> missing_in_actual;    // relative paths found in EXPECTED only
  std::vector<std::string> missing_in_expected;  // relative paths found in ACTUAL only
  std::string error;                             // bad input (a missing path, a file beside a folder, no images)
  bool ok() const { return error.empty(); }
};

// Pairs EXPECTED with ACTUAL.
ImagePairing pair_images(const std::string& expected, const std::string& actual);

}  // namespace vdmsim
