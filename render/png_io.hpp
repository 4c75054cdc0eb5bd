#pragma once
// PNG files through libpng. Writing goes to "<path>.tmp" and is renamed into place only when
// complete, so a PNG that exists is never half written (a crash, Ctrl-C or a full disk leaves
// the frames before it intact).
#include <string>

#include "render/image.hpp"

namespace render {

// compression_level: zlib level 0-9 (1 is fast and close in size to 6 for renders).
// `alpha`: keep the alpha channel (otherwise RGB, smaller and faster).
bool write_png(const std::string& path, const Image& image, int compression_level, bool alpha, std::string& error);
// The same for an image that is not needed afterwards: at the fast levels (1-3, RGB) its
// buffer holds the PNG's rows while they are compressed (no 2.8 MB copy for a 720p frame),
// so its pixels are overwritten. The file is the same as write_png's.
bool write_png_spending(const std::string& path, Image& image, int compression_level, std::string& error);
// An 8-bit greyscale PNG of the image's red channel (exact values: ids, masks), written as
// write_png_spending writes (the image's pixels overwritten at the fast levels).
bool write_grey_png_spending(const std::string& path, Image& image, int compression_level, std::string& error);

// Reads any 8-bit or 16-bit PNG into RGBA8. On failure returns false with a message naming
// the file.
bool read_png(const std::string& path, Image& image, std::string& error);

}  // namespace render
