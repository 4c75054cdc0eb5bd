// Edge anti-aliasing (render/edge_aa): against the exact coverage of straight edges drawn
// without anti-aliasing, against 16x multisampling of a rendered sphere; flat areas, soft
// gradients and axis-aligned edges untouched; the HUD layer's compositing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "engine/shapes.hpp"
#include "render/edge_aa.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"

namespace {

using render::Image;

struct Rgb {
  int r, g, b;
};

void fill(Image& im, int x, int y, Rgb c, double share_of_b = 0, Rgb b = {0, 0, 0}) {
  std::uint8_t* p = im.pixel(x, y);
  p[0] = static_cast<std::uint8_t>(std::lround(c.r + share_of_b * (b.r - c.r)));
  p[1] = static_cast<std::uint8_t>(std::lround(c.g + share_of_b * (b.g - c.g)));
  p[2] = static_cast<std::uint8_t>(std::lround(c.b + share_of_b * (b.b - c.b)));
  p[3] = 255;
}

// A half-plane edge through (cx, cy) at angle `deg` (degrees from the x axis): `a` on one side,
// `b` on the other. `aliased` takes each pixel's centre; `exact` the share of the pixel's area
// on b's side (24 x 24 sub-samples per pixel).
void half_plane(int w, int h, double deg, Rgb a, Rgb b, Image& aliased, Image& exact) {
  aliased = Image(w, h);
  exact = Image(w, h);
  const double cx = w * 0.5 + 0.37, cy = h * 0.5 + 0.21;  // off the pixel grid
  const double nx = -std::sin(deg * M_PI / 180), ny = std::cos(deg * M_PI / 180);
  auto on_b = [&](double x, double y) { return (x - cx) * nx + (y - cy) * ny > 0; };
  const int n = 24;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      fill(aliased, x, y, on_b(x + 0.5, y + 0.5) ? b : a);
      int inside = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) inside += on_b(x + (i + 0.5) / n, y + (j + 0.5) / n);
      fill(exact, x, y, a, double(inside) / (n * n), b);
    }
}

// Mean absolute difference of the RGB channels over the image, levels.
double mean_difference(const Image& p, const Image& q) {
  double sum = 0;
  for (size_t i = 0; i < p.rgba.size(); ++i)
    if (i % 4 != 3) sum += std::abs(int(p.rgba[i]) - int(q.rgba[i]));
  return sum / (double(p.width) * p.height * 3);
}

int intermediate_pixels(const Image& im, Rgb a, Rgb b) {
  int count = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      const bool is_a = p[0] == a.r && p[1] == a.g && p[2] == a.b, is_b = p[0] == b.r && p[1] == b.g && p[2] == b.b;
      count += !is_a && !is_b;
    }
  return count;
}

TEST(EdgeAa, StaircasesOfStraightEdgesMoveTowardTheirExactCoverage) {
  const Rgb dark{150, 50, 40}, light{190, 195, 200};
  // Shallow, diagonal and steep edges, both ways: runs along rows and along columns.
  for (double deg : {4.0, 11.0, 25.0, 45.0, 63.0, 80.0, 95.0, 120.0, 152.0, 173.0}) {
    Image aliased, exact;
    half_plane(96, 64, deg, dark, light, aliased, exact);
    ASSERT_EQ(intermediate_pixels(aliased, dark, light), 0);
    Image smoothed = aliased;
    render::EdgeSmoother smoother;
    const render::EdgeAaStats stats = smoother.apply(smoothed);
    EXPECT_GT(stats.blended, 0) << deg;
    EXPECT_GT(intermediate_pixels(smoothed, dark, light), 20) << deg;
    const double before = mean_difference(aliased, exact), after = mean_difference(smoothed, exact);
    // The aliased edge is wrong by a quarter of the colour step on average along it; the
    // smoothed one by a fraction of that. At 45 degrees the staircase is the same whatever
    // the edge's offset across it (steps of one pixel both ways): the smoothing assumes the
    // edge through the steps' midpoints and gains little there.
    const bool diagonal = std::abs(std::fmod(deg, 90.0) - 45.0) < 5.0;
    EXPECT_LT(after, (diagonal ? 0.97 : 0.5) * before) << deg << " degrees: " << before << " -> " << after;
  }
}

TEST(EdgeAa, AnEdgeOfTwoColoursOfEqualBrightnessIsSmoothedToo) {
  // Yellow on grey of about the same luminance (a colour-map's high end on the background).
  const Rgb yellow{230, 215, 40}, grey{200, 200, 205};
  Image aliased, exact;
  half_plane(80, 60, 17.0, yellow, grey, aliased, exact);
  Image smoothed = aliased;
  render::EdgeSmoother().apply(smoothed);
  EXPECT_LT(mean_difference(smoothed, exact), 0.5 * mean_difference(aliased, exact));
}

TEST(EdgeAa, LeavesFlatAreasSoftGradientsAndAxisAlignedEdgesUnchanged) {
  render::EdgeSmoother smoother;
  Image flat(50, 40);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 50; ++x) fill(flat, x, y, {120, 60, 50});
  Image copy = flat;
  EXPECT_EQ(smoother.apply(copy).candidates, 0);
  EXPECT_EQ(copy.rgba, flat.rgba);

  // Shading: 3 levels per pixel across, 2 down (under the threshold of 20).
  Image ramp(64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) fill(ramp, x, y, {20 + 3 * x, 10 + 2 * y, 100});
  copy = ramp;
  smoother.apply(copy);
  EXPECT_EQ(copy.rgba, ramp.rgba);

  // A vertical and a horizontal edge on pixel boundaries: the aliased picture is exact there.
  Image cross(64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) fill(cross, x, y, (x < 23) != (y < 31) ? Rgb{200, 200, 200} : Rgb{40, 40, 40});
  copy = cross;
  const render::EdgeAaStats stats = smoother.apply(copy);
  EXPECT_GT(stats.candidates, 0);  // the edges are seen...
  EXPECT_EQ(copy.rgba, cross.rgba);  // ...and left as they are
}

TEST(EdgeAa, SameImageSameResult) {
  Image aliased, exact;
  half_plane(70, 50, 33.0, {10, 20, 30}, {240, 230, 220}, aliased, exact);
  Image a = aliased, b = aliased;
  render::EdgeSmoother first, second;
  first.apply(a);
  first.apply(aliased);  // buffers reused
  second.apply(b);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(aliased.rgba, b.rgba);
}

TEST(EdgeAa, CompositeOverIsPremultipliedOver) {
  Image image(4, 2), layer(2, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) fill(image, x, y, {100, 150, 200});
  // Transparent, opaque white, half-transparent black panel (premultiplied: rgb 0), and
  // half-transparent white (premultiplied: 128).
  const std::uint8_t px[4][4] = {{0, 0, 0, 0}, {255, 255, 255, 255}, {0, 0, 0, 128}, {128, 128, 128, 128}};
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 4; ++c) layer.rgba[size_t(4 * k + c)] = px[k][c];
  render::composite_over(image, layer, 1, 0);
  EXPECT_EQ(image.pixel(0, 0)[0], 100);  // outside the layer
  EXPECT_EQ(image.pixel(1, 0)[0], 100);  // transparent
  EXPECT_EQ(image.pixel(2, 0)[2], 255);  // opaque white
  EXPECT_NEAR(image.pixel(1, 1)[1], 150 * 127 / 255.0, 1.0);
  EXPECT_NEAR(image.pixel(2, 1)[2], 128 + 200 * 127 / 255.0, 1.0);
  EXPECT_EQ(image.pixel(3, 1)[0], 100);
}

// A rendered sphere against 16 samples per pixel (drawn at 4 x 4 the size, box-filtered
// down): on its silhouette, edge smoothing comes much closer than one sample, and not as
// close as llvmpipe's 4x multisampling (its only multisampled mode: 2, 8 and 16 samples
// give 4).
TEST(EdgeAa, RenderedSphereComesCloseToSupersampling) {
  const vdm::SurfaceMesh sphere = vdm::make_icosphere(0.05, 4);
  auto draw = [&](render::Antialias aa, int samples, int scale) {
    render::RenderSettings s;
    s.width = 240 * scale;
    s.height = 180 * scale;
    s.antialias = aa;
    s.samples = samples;
    std::string error;
    auto r = render::Renderer::create(s, sphere, error);
    EXPECT_TRUE(r) << error;
    render::RenderScene scene;
    scene.positions = &sphere.positions;
    Image im;
    if (r) r->draw_shaded(scene, false, im);
    return scale > 1 ? render::downscale(im, scale) : im;
  };
  const Image reference = draw(render::Antialias::none, 1, 4), none = draw(render::Antialias::none, 1, 1),
              edge = draw(render::Antialias::edge, 1, 1), msaa = draw(render::Antialias::msaa, 4, 1);
  ASSERT_EQ(reference.width, 240);
  const std::filesystem::path out = std::filesystem::path(VDMSIM_BUILD_DIR) / "test-output" / "edge_aa";
  std::filesystem::create_directories(out);
  std::string error;
  for (auto [im, name] : {std::pair{&reference, "ssaa16"}, std::pair{&msaa, "msaa4"}, std::pair{&none, "none"},
                          std::pair{&edge, "edge"}})
    EXPECT_TRUE(render::write_png((out / (std::string("sphere_") + name + ".png")).string(), *im, 1, false, error)) << error;
  // Summed over the pixels where the single-sample picture is off by more than 8 levels (the
  // silhouette; elsewhere the pictures differ by a level or two of shading).
  std::vector<std::pair<int, int>> silhouette;
  auto off = [&](const Image& im, int x, int y) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(im.pixel(x, y)[c]) - int(reference.pixel(x, y)[c])));
    return d;
  };
  for (int y = 0; y < none.height; ++y)
    for (int x = 0; x < none.width; ++x)
      if (off(none, x, y) > 8) silhouette.emplace_back(x, y);
  auto error_of = [&](const Image& im) {
    double sum = 0;
    for (auto [x, y] : silhouette) sum += off(im, x, y);
    return sum / double(std::max<size_t>(1, silhouette.size()));
  };
  const double e_none = error_of(none), e_edge = error_of(edge), e_msaa = error_of(msaa);
  std::printf("against 16 samples, on %zu silhouette pixels: one sample %.1f, edge %.1f, 4x MSAA %.1f levels\n",
              silhouette.size(), e_none, e_edge, e_msaa);
  EXPECT_GT(silhouette.size(), 100u);
  EXPECT_LT(e_edge, 0.5 * e_none);
  EXPECT_LT(e_msaa, e_edge);        // multisampling measures what the smoothing estimates...
  EXPECT_LT(e_edge, 1.5 * e_msaa);  // ...but not by much (34, 12 and 10 levels when written)
}

}  // namespace
