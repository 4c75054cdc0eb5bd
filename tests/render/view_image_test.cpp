// The views' files: NumPy .npy float32 images (the layout numpy.load reads) and greyscale PNGs
// of ids, written whole; and the view table's names, folders and videos.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include "render/npy_io.hpp"
#include "render/png_io.hpp"
#include "render/view_image.hpp"
#include "render/views.hpp"

namespace fs = std::filesystem;

namespace {

fs::path view_image_scratch(const std::string& name) {
  const fs::path p = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "view_image" / name;
  fs::create_directories(p.parent_path());
  return p;
}

std::string view_image_file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

render::FloatImage float_ramp(int w, int h) {
  render::FloatImage im;
  im.width = w;
  im.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.values.push_back(y == 0 && x == 0 ? 0.0f : 0.25f + 0.001f * float(x) - 1e-5f * float(y));
  return im;
}

}  // namespace

// The file numpy.load reads: the magic, version 1.0, a header naming '<f4', C order and the
// shape (height, width), padded so that the data starts at a multiple of 64 bytes, then the
// values little-endian, top row first.
TEST(NpyIo, TheFileIsNumPysFormatWithTheValuesLittleEndianRowByRow) {
  const render::FloatImage im = float_ramp(7, 3);
  const fs::path p = view_image_scratch("ramp.npy");
  std::string error;
  ASSERT_TRUE(render::write_npy(p.string(), im.values, im.width, im.height, error)) << error;
  EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
  const std::string bytes = view_image_file_bytes(p);
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const size_t header_length = size_t(static_cast<unsigned char>(bytes[8])) | size_t(static_cast<unsigned char>(bytes[9])) << 8;
  EXPECT_EQ((10 + header_length) % 64, 0u);
  const std::string header = bytes.substr(10, header_length);
  EXPECT_EQ(header.rfind("{'descr': '<f4', 'fortran_order': False, 'shape': (3, 7), }", 0), 0u) << header;
  EXPECT_EQ(header.back(), '\n');
  ASSERT_EQ(bytes.size(), 10 + header_length + 7 * 3 * 4);
  // Row 2, column 5, little-endian.
  const size_t at = 10 + header_length + (2 * 7 + 5) * 4;
  std::uint32_t bits = 0;
  for (int b = 0; b < 4; ++b) bits |= std::uint32_t(static_cast<unsigned char>(bytes[at + size_t(b)])) << (8 * b);
  float value;
  std::memcpy(&value, &bits, 4);
  EXPECT_EQ(value, im.values[2 * 7 + 5]);

  std::vector<float> back;
  int w = 0, h = 0;
  ASSERT_TRUE(render::read_npy(p.string(), back, w, h, error)) << error;
  EXPECT_EQ(w, 7);
  EXPECT_EQ(h, 3);
  EXPECT_EQ(back, im.values);
}

TEST(NpyIo, AWrongSizeOrAnUnwritableFolderIsAnErrorNamingTheFile) {
  std::string error;
  EXPECT_FALSE(render::write_npy(view_image_scratch("short.npy").string(), {1.0f, 2.0f}, 2, 2, error));
  EXPECT_NE(error.find("short.npy"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(view_image_scratch("short.npy")));
  const fs::path missing = view_image_scratch("no_such_folder") / "x.npy";
  EXPECT_FALSE(render::write_npy(missing.string(), {1.0f}, 1, 1, error));
  EXPECT_NE(error.find("x.npy"), std::string::npos) << error;
  std::ofstream(view_image_scratch("garbage.npy")) << "not numpy";
  std::vector<float> v;
  int w = 0, h = 0;
  EXPECT_FALSE(render::read_npy(view_image_scratch("garbage.npy").string(), v, w, h, error));
  EXPECT_NE(error.find("garbage.npy"), std::string::npos) << error;
}

// Ids go to an 8-bit greyscale PNG exactly (the red channel), at the fast and the slow levels.
TEST(ViewImage, SegmentationIdsAreAGreyscalePngOfTheExactValues) {
  for (int level : {1, 6}) {
    render::ViewImage v;
    v.file = render::ViewFile::png_grey;
    v.image = render::Image(33, 9);
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 33; ++x) {
        std::uint8_t* p = v.image.pixel(x, y);
        p[0] = p[1] = p[2] = std::uint8_t((x * 8 + y) % 256);
        p[3] = 255;
      }
    const render::Image want = v.image;
    const fs::path path = view_image_scratch("ids_" + std::to_string(level) + ".png");
    std::string error;
    ASSERT_TRUE(render::write_view_image(path.string(), v, level, error)) << error;
    const std::string bytes = view_image_file_bytes(path);
    ASSERT_GT(bytes.size(), 26u);
    EXPECT_EQ(bytes[25], 0) << "PNG colour type: greyscale";
    EXPECT_EQ(bytes[24], 8) << "8 bits";
    render::Image back;
    ASSERT_TRUE(render::read_png(path.string(), back, error)) << error;
    EXPECT_EQ(back.rgba, want.rgba) << "level " << level;  // grey read back as R = G = B, alpha 255
  }
}

TEST(ViewImage, AFloatViewIsWrittenAsNpy) {
  render::ViewImage v;
  v.file = render::ViewFile::npy_float32;
  v.floats = float_ramp(5, 4);
  const fs::path path = view_image_scratch("depth.npy");
  std::string error;
  ASSERT_TRUE(render::write_view_image(path.string(), v, 1, error)) << error;
  std::vector<float> back;
  int w = 0, h = 0;
  ASSERT_TRUE(render::read_npy(path.string(), back, w, h, error)) << error;
  EXPECT_EQ(back, v.floats.values);
}

// One row per view, in the order of render::View, with its own name and folder; a picture
// view's video is video.mp4 when it is the scene's first picture view.
TEST(ViewTable, EachViewHasItsOwnNameFolderAndFile) {
  const auto& table = render::view_table();
  ASSERT_EQ(table.size(), 5u);
  std::set<std::string> names, folders;
  for (size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(size_t(table[i].view), i);
    names.insert(table[i].name);
    folders.insert(table[i].folder);
    render::View parsed;
    ASSERT_TRUE(render::parse_view(table[i].name, parsed));
    EXPECT_EQ(parsed, table[i].view);
  }
  EXPECT_EQ(names.size(), table.size());
  EXPECT_EQ(folders.size(), table.size());
  render::View unused;
  EXPECT_FALSE(render::parse_view("dept", unused));
  using render::View;
  EXPECT_EQ(render::view_file_name(render::view_row(View::shaded), 12), "frame_00012.png");
  EXPECT_EQ(render::view_file_name(render::view_row(View::depth), 3), "depth_00003.npy");
  EXPECT_EQ(render::view_file_name(render::view_row(View::segmentation), 0), "segmentation_00000.png");
  EXPECT_EQ(render::view_row(View::segmentation).file, render::ViewFile::png_grey);
  EXPECT_EQ(render::view_row(View::depth).pass, render::ViewPass::ground_truth);
  const std::vector<View> both = {View::shaded, View::stress, View::depth};
  EXPECT_EQ(render::video_file_name(both, View::shaded), "video.mp4");
  EXPECT_EQ(render::video_file_name(both, View::stress), "stress.mp4");
  EXPECT_EQ(render::video_file_name(both, View::depth), "");
  EXPECT_EQ(render::video_file_name({View::stress, View::segmentation}, View::stress), "video.mp4");
}
