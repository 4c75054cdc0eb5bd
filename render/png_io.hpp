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

// Reads any 8-bit or 16-bit PNG into RGBA8. On failure returns false with a message naming
// the file.
bool read_png(const std::string& path, Image& image, std::string& error);

}  // namespace render
