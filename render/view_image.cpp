#include "render/view_image.hpp"

#include "render/npy_io.hpp"
#include "render/png_io.hpp"

namespace render {

bool write_view_image(const std::string& path, ViewImage& image, int png_compression, std::string& error) {
  switch (image.file) {
    case ViewFile::png_rgb: return write_png_spending(path, image.image, png_compression, error);
    case ViewFile::png_grey: return write_grey_png_spending(path, image.image, png_compression, error);
    case ViewFile::npy_float32:
      return write_npy(path, image.floats.values, image.floats.width, image.floats.height, error);
  }
  error = path + ": unknown file format";
  return false;
}

}  // namespace render
