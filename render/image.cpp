#include "render/image.hpp"

#include <algorithm>
#include <cstring>

namespace render {

void flip_rows(Image& image) {
  const size_t row = static_cast<size_t>(image.width) * 4;
  std::vector<std::uint8_t> tmp(row);
  for (int y = 0; y < image.height / 2; ++y) {
    std::uint8_t* a = &image.rgba[y * row];
    std::uint8_t* b = &image.rgba[(image.height - 1 - y) * row];
    std::memcpy(tmp.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, tmp.data(), row);
  }
}

Image downscale(const Image& image, int factor) {
  factor = std::max(1, factor);
  Image out(image.width / factor, image.height / factor);
  const int n = factor * factor;
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      int sum[4] = {0, 0, 0, 0};
      for (int dy = 0; dy < factor; ++dy)
        for (int dx = 0; dx < factor; ++dx) {
          const std::uint8_t* p = image.pixel(x * factor + dx, y * factor + dy);
          for (int c = 0; c < 4; ++c) sum[c] += p[c];
        }
      std::uint8_t* q = out.pixel(x, y);
      for (int c = 0; c < 4; ++c) q[c] = static_cast<std::uint8_t>((sum[c] + n / 2) / n);
    }
  return out;
}

}  // namespace render
