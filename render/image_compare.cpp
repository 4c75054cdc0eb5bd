#include "render/image_compare.hpp"

#include <algorithm>
#include <cstdlib>
#include <sstream>

namespace render {

std::string CompareResult::summary() const {
  std::ostringstream s;
  if (!same_size) return "image sizes differ";
  s << differing_pixels << " pixels differ (" << differing_share * 100 << " %), largest channel difference "
    << largest_diff;
  return s.str();
}

CompareResult compare_images(const Image& expected, const Image& actual, const CompareTolerance& tol, Image* diff) {
  CompareResult r;
  r.same_size = expected.width == actual.width && expected.height == actual.height && !expected.empty();
  if (!r.same_size) return r;
  if (diff) *diff = Image(expected.width, expected.height);
  for (int y = 0; y < expected.height; ++y)
    for (int x = 0; x < expected.width; ++x) {
      const std::uint8_t* a = expected.pixel(x, y);
      const std::uint8_t* b = actual.pixel(x, y);
      int d = 0;
      for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
      r.largest_diff = std::max(r.largest_diff, d);
      const bool differs = d > tol.max_channel_diff;
      if (differs) ++r.differing_pixels;
      if (diff) {
        std::uint8_t* q = diff->pixel(x, y);
        if (differs) {
          q[0] = static_cast<std::uint8_t>(std::min(255, 128 + d));
          q[1] = q[2] = 0;
        } else {
          const int grey = (a[0] + a[1] + a[2]) / 3;
          q[0] = q[1] = q[2] = static_cast<std::uint8_t>(160 + grey / 4);
        }
        q[3] = 255;
      }
    }
  r.differing_share = double(r.differing_pixels) / (double(expected.width) * expected.height);
  r.match = r.differing_share <= tol.max_differing_share;
  return r;
}

}  // namespace render
