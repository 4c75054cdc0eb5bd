#include "render/colormap.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {
// CIE L* of an sRGB colour (perceived lightness, 0-100).
double lightness(const render::Rgb8& c) {
  auto lin = [](double v) { v /= 255; return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); };
  const double y = 0.2126 * lin(c.r) + 0.7152 * lin(c.g) + 0.0722 * lin(c.b);
  return y > 216.0 / 24389 ? 116 * std::cbrt(y) - 16 : 24389.0 / 27 * y;
}
}  // namespace

// Sequential maps must get lighter monotonically and evenly (perceptual uniformity's first
// property): L* rises at every step of the 256-entry table, by steps within a factor 3.
TEST(ColorMap, SequentialMapsRiseInLightnessMonotonically) {
  for (auto name : {render::ColorMapName::viridis, render::ColorMapName::magma, render::ColorMapName::inferno,
                    render::ColorMapName::plasma, render::ColorMapName::grey}) {
    const auto& t = render::colormap_table(name);
    double min_step = 1e9, max_step = 0;
    for (int i = 1; i < 256; ++i) {
      const double step = lightness(t[i]) - lightness(t[i - 1]);
      min_step = std::min(min_step, step);
      max_step = std::max(max_step, step);
    }
    EXPECT_GT(min_step, -0.05) << render::to_string(name);  // rounding to 8 bits only
    EXPECT_LT(max_step, 3 * (lightness(t[255]) - lightness(t[0])) / 255 + 0.5) << render::to_string(name);
    EXPECT_GT(lightness(t[255]) - lightness(t[0]), 50) << render::to_string(name);
  }
}

TEST(ColorMap, EndsAreThePublishedColoursAndDivergingMapIsSymmetric) {
  const auto& v = render::colormap_table(render::ColorMapName::viridis);
  EXPECT_NEAR(v[0].r, 0x44, 1);
  EXPECT_NEAR(v[0].g, 0x01, 1);
  EXPECT_NEAR(v[0].b, 0x54, 1);
  EXPECT_NEAR(v[255].r, 0xFD, 1);
  EXPECT_NEAR(v[255].g, 0xE7, 1);
  EXPECT_NEAR(v[255].b, 0x25, 1);
  const auto& d = render::colormap_table(render::ColorMapName::coolwarm);
  for (int i = 0; i < 128; ++i) EXPECT_NEAR(lightness(d[i]), lightness(d[255 - i]), 6.0) << i;
  EXPECT_GT(lightness(d[128]), lightness(d[0]) + 20);  // light in the middle, dark at both ends
}

TEST(ColorMap, ParsesNamesAndClampsInput) {
  render::ColorMapName n;
  EXPECT_TRUE(render::parse_colormap("magma", n));
  EXPECT_EQ(n, render::ColorMapName::magma);
  EXPECT_FALSE(render::parse_colormap("jet", n));
  const auto lo = render::colormap(render::ColorMapName::viridis, -3), hi = render::colormap(render::ColorMapName::viridis, 7);
  const auto nan = render::colormap(render::ColorMapName::viridis, std::nan(""));
  EXPECT_EQ(lo.r, render::colormap_table(render::ColorMapName::viridis)[0].r);
  EXPECT_EQ(hi.g, render::colormap_table(render::ColorMapName::viridis)[255].g);
  EXPECT_EQ(nan.b, lo.b);
}
