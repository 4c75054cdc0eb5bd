// The renderer says when it could not draw a frame (engine-independent: a sphere).
#include <gtest/gtest.h>

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
