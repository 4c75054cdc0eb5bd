#pragma once
// vdmsim compare EXPECTED ACTUAL: golden-image tests of the user's own runs. Compares two PNG
// files, or two folders of them paired by relative path (app/compare/image_pairs.hpp), through
// the renderer's image comparison (render/image_compare.hpp). Exit codes: 0 within tolerance,
// 1 beyond it (an image beyond tolerance, or one found in one folder only), 2 bad input (a
// missing path, an unreadable PNG, sizes that differ, a diff image that cannot be written).
#include <ostream>
#include <string>

namespace vdmsim {

struct CompareOptions {
  int max_diff = 0;        // 0-255: a pixel differs when one of its channels differs by more
  double max_share = 0.0;  // 0-1: the share of differing pixels allowed per image
  // "" for none; the diff image to write (two files), or the folder to write one diff image per
  // pair into, at the pair's relative path (two folders).
  std::string diff;
};

int cmd_compare(const std::string& expected, const std::string& actual, const CompareOptions& options,
                std::ostream& out, std::ostream& err);

}  // namespace vdmsim
