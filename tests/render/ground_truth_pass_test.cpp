// The ground-truth views against a ray cast of the same geometry (engine-independent: an
// icosphere organ and a capsule probe in front of it): each pixel's ray, from the camera
// model's intrinsics and pose, meets the object the segmentation names, at the depth the
// depth view gives, with the normal the normals view gives; the views do not depend on the
// pictures' anti-aliasing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/shapes.hpp"
#include "render/renderer.hpp"
#include "support/ray_triangle.hpp"

namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// The segment of a capsule probe (tools::probe_shape): from z = -r to z = -(L - r) in its frame.
struct GtCapsule {
  Eigen::Vector3d a, b;
  double r;
  Eigen::Vector3d closest(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d ab = b - a;
    return a + std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) * ab;
  }
};

// Sphere tracing of the capsule's distance function: the ray's parameter, or kNoHit.
double gt_ray_capsule(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const GtCapsule& c) {
  double t = 0;
  for (int k = 0; k < 400 && t < 10; ++k) {
    const Eigen::Vector3d p = o + t * d;
    const double dist = (p - c.closest(p)).norm() - c.r;
    if (dist < 1e-10) return t;
    t += dist;
  }
  return kNoHit;
}

struct GtScene {
  vdm::SurfaceMesh sphere = vdm::make_icosphere(0.05, 3);
  render::InstrumentView probe;
  GtCapsule capsule;
  render::RenderScene scene;
  GtScene() {
    tools::InstrumentDef def;
    def.radius = 0.01;
    def.length = 0.2;
    tools::InstrumentPose pose;
    pose.tip = Eigen::Vector3d(0.08, -0.11, 0.01);
    pose.axis = Eigen::Vector3d(1, 0, 0.1).normalized();
    probe = render::instrument_view(def, pose);
    capsule = {probe.frame * Eigen::Vector3d(0, 0, -def.radius), probe.frame * Eigen::Vector3d(0, 0, -(def.length - def.radius)),
               def.radius};
    scene.positions = &sphere.positions;
    scene.instruments.push_back(probe);
  }
};

render::RenderSettings gt_settings(render::Antialias aa) {
  render::RenderSettings s;
  s.width = 160;
  s.height = 120;
  s.antialias = aa;
  s.auto_camera = false;
  s.camera.eye = {0.06, -0.3, 0.09};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.up = {0, 0, 1};
  s.camera.fov_deg = 40;
  return s;
}

struct GtImages {
  render::FloatImage depth;
  render::Image ids, normals;
};

GtImages gt_draw(render::Renderer& r, const render::RenderScene& scene) {
  GtImages out;
  const std::vector<render::View> views = {render::View::shaded, render::View::depth, render::View::segmentation,
                                           render::View::normals};
  render::ViewOptions options;
  options.hud = false;
  int taken = 0;
  const bool ok = r.draw_views(scene, views, options, [&](render::View v, render::ViewImage& im) {
    EXPECT_EQ(v, views[size_t(taken)]);
    EXPECT_EQ(im.file, render::view_row(v).file);
    ++taken;
    if (v == render::View::depth) out.depth = im.floats;
    if (v == render::View::segmentation) out.ids = im.image;
    if (v == render::View::normals) out.normals = im.image;
    return true;
  });
  EXPECT_TRUE(ok) << r.error();
  EXPECT_EQ(taken, 4);
  return out;
}

}  // namespace

TEST(GroundTruthPass, DepthIdsAndNormalsAgreeWithARayCastThroughEachPixel) {
  GtScene g;
  std::string error;
  auto r = render::Renderer::create(gt_settings(render::Antialias::edge), g.sphere, error);
  ASSERT_TRUE(r) << error;
  const GtImages im = gt_draw(*r, g.scene);
  const render::CameraModel cam = r->camera_model();
  ASSERT_EQ(im.depth.width, 160);
  ASSERT_EQ(im.depth.height, 120);
  ASSERT_EQ(im.ids.width, 160);
  EXPECT_GT(cam.near, 0.0);
  EXPECT_GT(cam.far, cam.near);

  const int w = cam.width, h = cam.height;
  std::vector<int> want_id(size_t(w * h), 0);
  std::vector<double> want_z(size_t(w * h), 0.0);
  std::vector<Eigen::Vector3d> want_normal(size_t(w * h), Eigen::Vector3d::Zero());
  const Eigen::Matrix3d R = cam.pose.linear();
  const Eigen::Vector3d C = cam.pose.translation();
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d ray_cam((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d d = (R * ray_cam).normalized();
      double t_organ = kNoHit;
      for (Eigen::Index k = 0; k < g.sphere.triangles.rows(); ++k)
        t_organ = std::min(t_organ, test::ray_triangle(C, d, g.sphere.positions.row(g.sphere.triangles(k, 0)).transpose(),
                                                    g.sphere.positions.row(g.sphere.triangles(k, 1)).transpose(),
                                                    g.sphere.positions.row(g.sphere.triangles(k, 2)).transpose()));
      const double t_probe = gt_ray_capsule(C, d, g.capsule);
      const size_t i = size_t(v * w + u);
      if (t_organ == kNoHit && t_probe == kNoHit) continue;
      const bool organ = t_organ < t_probe;
      const Eigen::Vector3d p = C + std::min(t_organ, t_probe) * d;
      want_id[i] = organ ? render::kOrganId : render::kFirstInstrumentId;
      want_z[i] = (R.transpose() * (p - C)).z();
      const Eigen::Vector3d n_world = organ ? p.normalized() : (p - g.capsule.closest(p)).normalized();
      want_normal[i] = R.transpose() * n_world;
    }

  // Ids: every pixel agrees except where the ray cast's id changes between neighbours (a
  // silhouette crossing the pixel, or the probe's facets against the ray cast's round capsule).
  int organ_pixels = 0, probe_pixels = 0, background_pixels = 0, disagreeing = 0;
  std::vector<double> depth_errors;
  double worst_normal_deg = 0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const size_t i = size_t(v * w + u);
      const int got = im.ids.rgba[i * 4];
      bool edge = false;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int uu = std::clamp(u + du, 0, w - 1), vv = std::clamp(v + dv, 0, h - 1);
          edge = edge || want_id[size_t(vv * w + uu)] != want_id[i];
        }
      if (got != want_id[i]) {
        ++disagreeing;
        EXPECT_TRUE(edge) << "pixel (" << u << ", " << v << "): id " << got << ", the ray cast's " << want_id[i];
        continue;
      }
      (got == 0 ? background_pixels : got == 1 ? organ_pixels : probe_pixels)++;
      const float z = im.depth.values[i];
      if (got == 0) {
        EXPECT_EQ(z, 0.0f) << "pixel (" << u << ", " << v << ")";
        const std::uint8_t* n = &im.normals.rgba[i * 4];
        EXPECT_EQ(n[0] + n[1] + n[2], 0) << "pixel (" << u << ", " << v << ")";
        continue;
      }
      if (got == 1) {
        depth_errors.push_back(std::abs(double(z) - want_z[i]));
      } else if (!edge) {  // the probe's facets against the ray cast's round capsule
        EXPECT_NEAR(z, want_z[i], 2e-4) << "probe pixel (" << u << ", " << v << ")";
      }
      const std::uint8_t* n = &im.normals.rgba[i * 4];
      const Eigen::Vector3d normal(n[0] / 127.5 - 1, n[1] / 127.5 - 1, n[2] / 127.5 - 1);
      if (!edge)
        worst_normal_deg = std::max(worst_normal_deg, std::acos(std::clamp(normal.normalized().dot(want_normal[i]), -1.0, 1.0)) * 180 / M_PI);
    }
  EXPECT_GT(organ_pixels, 1200);
  EXPECT_GT(probe_pixels, 300);
  EXPECT_GT(background_pixels, 5000);
  EXPECT_LT(disagreeing, (organ_pixels + probe_pixels) / 50) << "ids disagreeing with the ray cast";
  // The organ's depth is that of the same triangles: float rounding only.
  ASSERT_FALSE(depth_errors.empty());
  std::sort(depth_errors.begin(), depth_errors.end());
  EXPECT_LT(depth_errors.back(), 1e-5) << "worst organ depth error (m)";
  EXPECT_LT(depth_errors[depth_errors.size() / 2], 1e-6) << "median organ depth error (m)";
  // Interpolated vertex normals against the round shapes' normals, within 8-bit steps.
  EXPECT_LT(worst_normal_deg, 3.0);
}

// The ground-truth views come from their own single-sample pass: the same bytes whatever the
// pictures' anti-aliasing, and again on a second draw.
TEST(GroundTruthPass, TheViewsAreExactWhateverThePicturesAntiAliasing) {
  GtScene g;
  std::string error;
  auto edge = render::Renderer::create(gt_settings(render::Antialias::edge), g.sphere, error);
  ASSERT_TRUE(edge) << error;
  auto msaa = render::Renderer::create(gt_settings(render::Antialias::msaa), g.sphere, error);
  ASSERT_TRUE(msaa) << error;
  const GtImages a = gt_draw(*edge, g.scene), b = gt_draw(*msaa, g.scene), again = gt_draw(*edge, g.scene);
  EXPECT_EQ(a.depth.values, b.depth.values);
  EXPECT_EQ(a.ids.rgba, b.ids.rgba);
  EXPECT_EQ(a.normals.rgba, b.normals.rgba);
  EXPECT_EQ(a.depth.values, again.depth.values);
  EXPECT_EQ(a.ids.rgba, again.ids.rgba);
  // Only the ids 0, 1 and 2: no blended edge values.
  for (size_t i = 0; i < a.ids.rgba.size(); i += 4) ASSERT_LE(a.ids.rgba[i], 2) << "pixel " << i / 4;
}

// A taker that stops the drawing: no further view is drawn, and it is not a failure.
TEST(GroundTruthPass, DrawingStopsWhenTheTakerSaysSo) {
  GtScene g;
  std::string error;
  auto r = render::Renderer::create(gt_settings(render::Antialias::edge), g.sphere, error);
  ASSERT_TRUE(r) << error;
  int taken = 0;
  render::ViewOptions options;
  EXPECT_TRUE(r->draw_views(g.scene, {render::View::depth, render::View::segmentation}, options,
                            [&](render::View, render::ViewImage&) { return ++taken < 1; }));
  EXPECT_EQ(taken, 1);
  EXPECT_TRUE(r->error().empty());
}
