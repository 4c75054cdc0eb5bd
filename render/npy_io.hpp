#pragma once
// NumPy .npy files of a float32 image (format 1.0: the magic string, a header naming the dtype
// '<f4' and the shape (height, width), then the values little-endian, row-major, top row
// first), readable by numpy.load. Written to "<path>.tmp" and renamed into place when
// complete, as the PNG files are.
#include <string>
#include <vector>

namespace render {

// `values`: width x height, row-major, top row first.
bool write_npy(const std::string& path, const std::vector<float>& values, int width, int height, std::string& error);

// Reads a 2-D little-endian float32 .npy (C order) as write_npy writes it. False with a message
// naming the file otherwise.
bool read_npy(const std::string& path, std::vector<float>& values, int& width, int& height, std::string& error);

}  // namespace render
