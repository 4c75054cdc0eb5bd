#pragma once
// Golden-image comparison (in the manner of Filament's render-diff): two images match when
// the share of pixels whose largest channel difference exceeds `max_channel_diff` is at most
// `max_differing_share`. The diff image shows matching pixels as a faded grey copy of the
// expected image and differing ones in red, brighter for larger differences.
#include <string>

#include "render/image.hpp"

namespace render {

struct CompareTolerance {
  int max_channel_diff = 2;           // 0-255: a pixel differs when any channel differs by more
  double max_differing_share = 0.0;   // 0-1: share of differing pixels allowed
};

struct CompareResult {
  bool same_size = false;
  bool match = false;
  int largest_diff = 0;       // largest channel difference over all pixels
  long differing_pixels = 0;  // pixels beyond max_channel_diff
  double differing_share = 0;
  std::string summary() const;
};

CompareResult compare_images(const Image& expected, const Image& actual, const CompareTolerance& tol, Image* diff);

}  // namespace render
