#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>

#include "render/contact_sheet.hpp"
#include "render/number_format.hpp"
#include "render/png_io.hpp"
#include "render/image_queue.hpp"

namespace fs = std::filesystem;

namespace {
render::Image pattern(int w, int h) {
  render::Image im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = im.pixel(x, y);
      p[0] = std::uint8_t(x * 7 + y);
      p[1] = std::uint8_t(y * 13);
      p[2] = std::uint8_t((x ^ y) * 3);
      p[3] = 255;
    }
  return im;
}
fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "image_io" / name;
  fs::create_directories(p.parent_path());
  return p;
}
}  // namespace

TEST(PngIo, RoundTripIsLosslessAtEveryLevel) {
  const render::Image im = pattern(37, 23);
  for (int level : {0, 1, 6, 9}) {
    const fs::path p = scratch("round_" + std::to_string(level) + ".png");
    std::string error;
    ASSERT_TRUE(render::write_png(p.string(), im, level, false, error)) << error;
    render::Image back;
    ASSERT_TRUE(render::read_png(p.string(), back, error)) << error;
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.rgba, im.rgba);
    EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
  }
}

TEST(PngIo, RoundTripKeepsTheAlphaChannelAtFastAndSlowLevels) {
  render::Image im = pattern(29, 17);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) im.pixel(x, y)[3] = std::uint8_t(x * 9 + y * 5);
  for (int level : {1, 3, 6}) {  // the fast levels go through libdeflate when the build has it
    const fs::path p = scratch("alpha_" + std::to_string(level) + ".png");
    std::string error;
    ASSERT_TRUE(render::write_png(p.string(), im, level, true, error)) << error;
    render::Image back;
    ASSERT_TRUE(render::read_png(p.string(), back, error)) << error;
    EXPECT_EQ(back.rgba, im.rgba) << "level " << level;
  }
}

TEST(PngIo, NoiseThatDoesNotCompressRoundTripsAtTheFastLevel) {
  render::Image im(64, 48);
  std::uint32_t state = 12345;
  for (std::uint8_t& v : im.rgba) {
    state = state * 1664525u + 1013904223u;
    v = std::uint8_t(state >> 24);
  }
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) im.pixel(x, y)[3] = 255;
  const fs::path p = scratch("noise_1.png");
  std::string error;
  ASSERT_TRUE(render::write_png(p.string(), im, 1, false, error)) << error;
  EXPECT_GT(fs::file_size(p), im.rgba.size() * 3 / 4 / 4) << "noise does not compress below a quarter";
  render::Image back;
  ASSERT_TRUE(render::read_png(p.string(), back, error)) << error;
  EXPECT_EQ(back.rgba, im.rgba);
}

// write_png_spending packs the rows over the image's own buffer: byte for byte the file
// write_png makes, for narrow, odd and one-row images, at the fast and the libpng levels.
TEST(PngIo, SpendingTheImageWritesTheSameFile) {
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const auto& [w, h] : {std::pair{1, 1}, {1, 9}, {2, 3}, {37, 23}, {64, 1}, {33, 40}})
    for (int level : {1, 3, 6}) {
      const render::Image im = pattern(w, h);
      const std::string tag = std::to_string(w) + "x" + std::to_string(h) + "_" + std::to_string(level);
      const fs::path a = scratch("kept_" + tag + ".png"), b = scratch("spent_" + tag + ".png");
      std::string error;
      ASSERT_TRUE(render::write_png(a.string(), im, level, false, error)) << error;
      render::Image spent = im;
      ASSERT_TRUE(render::write_png_spending(b.string(), spent, level, error)) << error;
      EXPECT_EQ(bytes(a), bytes(b)) << tag;
      render::Image back;
      ASSERT_TRUE(render::read_png(b.string(), back, error)) << error;
      EXPECT_EQ(back.rgba, im.rgba) << tag;
    }
}

TEST(PngIo, ReadingGarbageOrAMissingFileFailsWithTheFileName) {
  const fs::path p = scratch("garbage.png");
  { std::ofstream(p) << "not a png at all"; }
  render::Image im;
  std::string error;
  EXPECT_FALSE(render::read_png(p.string(), im, error));
  EXPECT_NE(error.find("garbage.png"), std::string::npos) << error;
  EXPECT_FALSE(render::read_png(scratch("missing.png").string(), im, error));
  EXPECT_NE(error.find("missing.png"), std::string::npos) << error;
}

// A write into a folder that does not exist fails; the queue reports the file, stops taking
// images, and the images before the failure are complete.
TEST(ImageQueue, AWriteFailureIsReportedAndEarlierImagesStayComplete) {
  const fs::path ok1 = scratch("queue_ok1.png"), ok2 = scratch("queue_ok2.png");
  const fs::path bad = scratch("no_such_folder") / "x.png";
  render::ImageQueue q(1, 2);
  EXPECT_TRUE(q.push(pattern(64, 48), ok1.string()));
  EXPECT_TRUE(q.push(pattern(64, 48), ok2.string()));
  q.push(pattern(64, 48), bad.string());
  EXPECT_FALSE(q.finish());
  EXPECT_NE(q.error().find("x.png"), std::string::npos) << q.error();
  EXPECT_FALSE(q.push(pattern(8, 8), scratch("after.png").string()));
  render::Image back;
  std::string error;
  EXPECT_TRUE(render::read_png(ok1.string(), back, error)) << error;
  EXPECT_TRUE(render::read_png(ok2.string(), back, error)) << error;
  EXPECT_EQ(q.written(), 2);
}

TEST(ContactSheet, EvenlySpacedFramesIncludeFirstAndLast) {
  EXPECT_EQ(render::contact_sheet_frames(5, 12), (std::vector<int>{0, 1, 2, 3, 4}));
  const auto f = render::contact_sheet_frames(90, 12);
  ASSERT_EQ(f.size(), 12u);
  EXPECT_EQ(f.front(), 0);
  EXPECT_EQ(f.back(), 89);
  for (size_t i = 1; i < f.size(); ++i) EXPECT_NEAR(f[i] - f[i - 1], 89.0 / 11, 1.0);
}

TEST(Hud, NiceTicksAndUnits) {
  EXPECT_EQ(render::nice_ticks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  const auto t = render::nice_ticks(-0.013, 0.027, 4);
  ASSERT_FALSE(t.empty());
  EXPECT_GE(t.front(), -0.013);
  EXPECT_LE(t.back(), 0.027 + 1e-12);
  EXPECT_EQ(render::display_unit("Pa", 4000).second, "kPa");
  EXPECT_EQ(render::display_unit("Pa", 4e6).second, "MPa");
  EXPECT_EQ(render::display_unit("m", 0.02).second, "mm");
  EXPECT_DOUBLE_EQ(render::display_unit("m", 0.02).first, 1e3);
  EXPECT_EQ(render::format_number(0.000123456, 3), "0.000123");
}
