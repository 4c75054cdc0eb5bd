#pragma once
// One view's image of one frame in the form its file stores (render/views.hpp: ViewFile), and
// the writing of that file: PNG (RGB, or greyscale from the red channel) or NumPy .npy
// (float32). Each file is written to "<path>.tmp" and renamed into place when complete.
#include <string>
#include <vector>

#include "render/image.hpp"
#include "render/views.hpp"

namespace render {

// A float image, rows top to bottom.
struct FloatImage {
  int width = 0, height = 0;
  std::vector<float> values;  // width * height, row-major, top row first
};

struct ViewImage {
  ViewFile file = ViewFile::png_rgb;
  Image image;       // png_rgb: RGB (alpha dropped); png_grey: the red channel
  FloatImage floats; // npy_float32
};

// Writes `image` to `path` in its file's format. At the fast PNG levels its pixels may be
// overwritten (write_png_spending). False with a message naming the file.
bool write_view_image(const std::string& path, ViewImage& image, int png_compression, std::string& error);

}  // namespace render
