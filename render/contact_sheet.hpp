#pragma once
// A contact sheet for quick review: evenly spaced frames of a sequence in a grid, each
// labelled with its frame number (or a label of its own, lines split by '\n'), under a
// title line. `vdmsim sweep` lays out one frame of each run the same way.
#include <string>
#include <vector>

#include "render/image.hpp"

namespace render {

struct Thumbnail {
  int frame = 0;
  Image image;
  std::string label;  // "" : "frame N"
};

// The frames to show out of `frames` (at most `count`, evenly spaced, first and last included).
std::vector<int> contact_sheet_frames(int frames, int count);

bool write_contact_sheet(const std::vector<Thumbnail>& thumbnails, const std::string& title, const std::string& path,
                         int compression_level, std::string& error);

}  // namespace render
