// The renderer says when it could not draw a frame (engine-independent: a sphere).
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "engine/shapes.hpp"
#include "render/renderer.hpp"

namespace {

using render::Image;

// OpenGL refusing to map the organ's buffer (made to happen once): that frame is reported
// with the reason, and the next frame is drawn as if nothing had happened.
TEST(Renderer, AFrameOpenGLCannotDrawIsReportedAndTheNextIsDrawn) {
  const vdm::SurfaceMesh sphere = vdm::make_icosphere(0.05, 3);
  render::RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  std::string error;
  auto r = render::Renderer::create(settings, sphere, error);
  ASSERT_TRUE(r) << error;
  render::RenderScene scene;
  scene.positions = &sphere.positions;
  scene.scalar.assign(size_t(sphere.node_count()), 0.5f);
  const render::StressView view;
  Image first, failed, next, stress;
  ASSERT_TRUE(r->draw_shaded(scene, false, first)) << r->error();
  EXPECT_TRUE(r->error().empty());
  r->fail_next_map_for_testing();
  EXPECT_FALSE(r->draw_shaded(scene, false, failed));
  EXPECT_NE(r->error().find("could not map the organ's vertex buffer"), std::string::npos) << r->error();
  ASSERT_TRUE(r->draw_shaded(scene, false, next)) << r->error();
  EXPECT_TRUE(r->error().empty());
  EXPECT_EQ(next.rgba, first.rgba);
  r->fail_next_map_for_testing();
  EXPECT_FALSE(r->draw_stress(scene, view, true, stress));
  EXPECT_FALSE(r->error().empty());
  EXPECT_TRUE(r->draw_stress(scene, view, true, stress)) << r->error();
}

}  // namespace

namespace {

// Pixels of `a` and `b` that differ, counted in the image's four quadrants (top-left,
// top-right, bottom-left, bottom-right; rows from the top).
std::array<int, 4> differences(const Image& a, const Image& b) {
  std::array<int, 4> n{0, 0, 0, 0};
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const size_t i = 4 * (size_t(y) * size_t(a.width) + size_t(x));
      if (a.rgba[i] != b.rgba[i] || a.rgba[i + 1] != b.rgba[i + 1] || a.rgba[i + 2] != b.rgba[i + 2])
        ++n[size_t((y >= a.height / 2 ? 2 : 0) + (x >= a.width / 2 ? 1 : 0))];
    }
  return n;
}

// Pixels of the gizmo's z axis colour (a saturated blue: nothing else in the picture is blue)
// in the bottom-left quadrant.
int blue_pixels_bottom_left(const Image& im) {
  int n = 0;
  for (int y = im.height / 2; y < im.height; ++y)
    for (int x = 0; x < im.width / 2; ++x) {
      const size_t i = 4 * (size_t(y) * size_t(im.width) + size_t(x));
      if (im.rgba[i + 2] > 180 && im.rgba[i] < 130 && im.rgba[i + 2] > im.rgba[i + 1] + 50) ++n;
    }
  return n;
}

TEST(Renderer, TheGizmoIsDrawnInTheBottomLeftCornerOnlyWhenAsked) {
  const vdm::SurfaceMesh sphere = vdm::make_icosphere(0.05, 3);
  render::RenderSettings settings;
  settings.width = 320;
  settings.height = 240;
  std::string error;
  auto plain = render::Renderer::create(settings, sphere, error);
  ASSERT_TRUE(plain) << error;
  settings.gizmo = true;
  auto with = render::Renderer::create(settings, sphere, error);
  ASSERT_TRUE(with) << error;
  render::RenderScene scene;
  scene.positions = &sphere.positions;
  Image a, b;
  ASSERT_TRUE(plain->draw_shaded(scene, false, a)) << plain->error();
  ASSERT_TRUE(with->draw_shaded(scene, false, b)) << with->error();
  const std::array<int, 4> d = differences(a, b);
  EXPECT_GT(d[2], 400);  // the disc and its axes
  EXPECT_EQ(d[0] + d[1] + d[3], 0) << d[0] << " " << d[1] << " " << d[3];
  EXPECT_EQ(blue_pixels_bottom_left(a), 0);  // a tissue-red sphere on a grey floor
  EXPECT_GT(blue_pixels_bottom_left(b), 10);
}

TEST(Renderer, AFocusBoxIsFramedInsteadOfTheOrgan) {
  const vdm::SurfaceMesh sphere = vdm::make_icosphere(0.05, 3);
  render::RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  settings.has_focus_box = true;
  settings.focus_lo = Eigen::Vector3d(0.03, -0.01, 0.03);
  settings.focus_hi = Eigen::Vector3d(0.05, 0.01, 0.06);
  std::string error;
  auto r = render::Renderer::create(settings, sphere, error);
  ASSERT_TRUE(r) << error;
  const render::Camera want = render::auto_frame(settings.focus_lo, settings.focus_hi, settings.camera.fov_deg, 96.0 / 64.0);
  EXPECT_EQ(r->camera().eye, want.eye);
  EXPECT_EQ(r->camera().target, want.target);
  // An explicit camera wins over the box.
  settings.auto_camera = false;
  settings.camera.eye = Eigen::Vector3d(0, -1, 0.5);
  auto fixed = render::Renderer::create(settings, sphere, error);
  ASSERT_TRUE(fixed) << error;
  EXPECT_EQ(fixed->camera().eye, settings.camera.eye);
}

}  // namespace

namespace {

// Two balls in one surface, the second 12 cm to the right of the first.
vdm::SurfaceMesh two_balls() {
  const vdm::SurfaceMesh ball = vdm::make_icosphere(0.05, 3);
  vdm::SurfaceMesh both;
  const Eigen::Index n = ball.positions.rows(), t = ball.triangles.rows();
  both.positions.resize(2 * n, 3);
  both.triangles.resize(2 * t, 3);
  both.positions.topRows(n) = ball.positions;
  both.positions.bottomRows(n) = ball.positions;
  both.positions.bottomRows(n).col(0).array() += 0.12;
  both.triangles.topRows(t) = ball.triangles;
  both.triangles.bottomRows(t) = ball.triangles.array() + static_cast<int>(n);
  return both;
}

// Reddish (tissue of the liver's look) and greenish pixels in the left and right halves.
struct Tints {
  int red[2] = {0, 0}, green[2] = {0, 0};
};
Tints tints(const Image& im) {
  Tints t;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const size_t i = 4 * (size_t(y) * size_t(im.width) + size_t(x));
      const int r = im.rgba[i], g = im.rgba[i + 1], half = x >= im.width / 2;
      if (r > g + 40) ++t.red[half];
      if (g > r + 10) ++t.green[half];
    }
  return t;
}

// Each organ of the surface is drawn in its own look: the second ball, a gallbladder, green,
// the first red; without parts both are the liver's red. Each has its own segmentation id.
TEST(Renderer, EachOrganIsDrawnInItsOwnLookWithItsOwnId) {
  const vdm::SurfaceMesh both = two_balls();
  render::RenderSettings settings;
  settings.width = 160;
  settings.height = 80;
  settings.floor = false;
  std::string error;
  auto plain = render::Renderer::create(settings, both, error);
  ASSERT_TRUE(plain) << error;
  const long t = both.triangles.rows() / 2;
  settings.organ_parts = {{t, render::TissueLook::liver}, {t, render::TissueLook::gallbladder}};
  auto looks = render::Renderer::create(settings, both, error);
  ASSERT_TRUE(looks) << error;
  render::RenderScene scene;
  scene.positions = &both.positions;
  Image a, b;
  ASSERT_TRUE(plain->draw_shaded(scene, false, a)) << plain->error();
  ASSERT_TRUE(looks->draw_shaded(scene, false, b)) << looks->error();
  const Tints ta = tints(a), tb = tints(b);
  EXPECT_GT(ta.red[0], 500);
  EXPECT_GT(ta.red[1], 500);
  EXPECT_EQ(ta.green[0] + ta.green[1], 0);
  EXPECT_EQ(tb.red[0], ta.red[0]);
  EXPECT_GT(tb.green[1], 500);
  EXPECT_LT(tb.red[1], tb.green[1] / 20);
  // And each its own segmentation id: 1 the first (left), 2 the second (right); one organ: 1.
  const auto ids = [&](render::Renderer& r) {
    std::array<int, 3> left{0, 0, 0}, right{0, 0, 0};
    render::ViewOptions options;
    options.hud = false;
    EXPECT_TRUE(r.draw_views(scene, {render::View::segmentation}, options, [&](render::View, render::ViewImage& im) {
      for (int y = 0; y < im.image.height; ++y)
        for (int x = 0; x < im.image.width; ++x) {
          const int id = im.image.rgba[4 * (size_t(y) * size_t(im.image.width) + size_t(x))];
          if (id <= 2) ++(x < im.image.width / 2 ? left : right)[size_t(id)];
        }
      return true;
    })) << r.error();
    return std::array<std::array<int, 3>, 2>{left, right};
  };
  const auto one = ids(*plain), two = ids(*looks);
  EXPECT_GT(one[0][1], 500);
  EXPECT_GT(one[1][1], 500);
  EXPECT_EQ(one[0][2] + one[1][2], 0);
  EXPECT_EQ(two[0][1], one[0][1]);
  EXPECT_EQ(two[1][2], one[1][1]);
  EXPECT_EQ(two[1][1] + two[0][2], 0);
}

}  // namespace
