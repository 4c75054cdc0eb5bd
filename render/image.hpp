#pragma once
// An 8-bit RGBA image, rows top to bottom (the order PNG files use).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace render {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes, row-major, top row first

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0) {}
  bool empty() const { return width <= 0 || height <= 0; }
  std::uint8_t* pixel(int x, int y) { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
  const std::uint8_t* pixel(int x, int y) const { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
};

// Reverses the row order in place (OpenGL reads bottom-up).
void flip_rows(Image& image);

// Box-filtered downscale by an integer factor (>= 1); sizes round down.
Image downscale(const Image& image, int factor);

}  // namespace render
