#include "render/views.hpp"

#include <cstdio>

namespace render {

const std::vector<ViewRow>& view_table() {
  // What each view is: docs/rendering.md, "The views"; the scene reference's render.views.
  static const std::vector<ViewRow> table = {
      {View::shaded, "shaded", "frames", "frame", ViewFile::png_rgb, ViewPass::picture},
      {View::stress, "stress", "stress", "stress", ViewFile::png_rgb, ViewPass::picture},
      {View::depth, "depth", "depth", "depth", ViewFile::npy_float32, ViewPass::ground_truth},
      {View::segmentation, "segmentation", "segmentation", "segmentation", ViewFile::png_grey, ViewPass::ground_truth},
      {View::normals, "normals", "normals", "normals", ViewFile::png_rgb, ViewPass::ground_truth},
  };
  return table;
}

const ViewRow& view_row(View v) { return view_table()[static_cast<size_t>(v)]; }

bool parse_view(const std::string& name, View& out) {
  for (const ViewRow& row : view_table())
    if (name == row.name) {
      out = row.view;
      return true;
    }
  return false;
}

std::vector<std::string> view_names() {
  std::vector<std::string> names;
  for (const ViewRow& row : view_table()) names.emplace_back(row.name);
  return names;
}

const char* file_extension(ViewFile f) { return f == ViewFile::npy_float32 ? ".npy" : ".png"; }

std::string view_file_name(const ViewRow& row, int f) {
  char number[16];
  std::snprintf(number, sizeof number, "_%05d", f);
  return row.prefix + std::string(number) + file_extension(row.file);
}

std::string video_file_name(const std::vector<View>& views, View v) {
  if (view_row(v).pass != ViewPass::picture) return "";
  for (View first : views)
    if (view_row(first).pass == ViewPass::picture) return first == v ? "video.mp4" : std::string(view_row(v).name) + ".mp4";
  return "";
}

}  // namespace render
