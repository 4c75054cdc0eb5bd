// The pinhole camera model (OpenCV's convention) reproduces the renderer's OpenGL projection:
// a world point lands at the same pixel, and the pose's axes are the camera's.
#include <gtest/gtest.h>

#include <cmath>

#include "render/camera.hpp"

namespace {

// Where OpenGL's look_at and perspective put `p`: (u, v) with the centre of the top-left pixel
// at (0, 0) (window coordinates have the pixel centres at i + 1/2, rows from the bottom).
Eigen::Vector2d opengl_pixel(const render::Camera& c, int w, int h, double near, double far, const Eigen::Vector3d& p) {
  const Eigen::Matrix4f m = render::perspective(c.fov_deg, double(w) / h, near, far) * render::look_at(c.eye, c.target, c.up);
  const Eigen::Vector4d clip = m.cast<double>() * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  const double x_ndc = clip.x() / clip.w(), y_ndc = clip.y() / clip.w();
  return {(x_ndc + 1) * 0.5 * w - 0.5, h - (y_ndc + 1) * 0.5 * h - 0.5};
}

Eigen::Vector2d pinhole_pixel(const render::CameraModel& m, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = m.pose.inverse() * p;
  return {m.fx * q.x() / q.z() + m.cx, m.fy * q.y() / q.z() + m.cy};
}

}  // namespace

TEST(CameraModel, ProjectsWorldPointsToThePixelsOpenGLDrawsThemAt) {
  struct Case {
    render::Camera camera;
    int w, h;
  };
  render::Camera tilted;
  tilted.eye = {0.16, -0.24, 0.19};
  tilted.target = {0.025, 0.0, 0.025};
  tilted.up = {0, 0, 1};
  tilted.fov_deg = 35;
  render::Camera from_above;  // up parallel to the view direction: look_at picks another up
  from_above.eye = {0.01, 0.02, 0.5};
  from_above.target = {0.01, 0.02, 0.0};
  from_above.up = {0, 0, 1};
  from_above.fov_deg = 60;
  render::Camera odd_up;
  odd_up.eye = {-0.3, 0.1, 0.05};
  odd_up.target = {0.0, 0.0, 0.0};
  odd_up.up = {0.2, 1.0, 0.3};
  odd_up.fov_deg = 20;
  for (const Case& k : {Case{tilted, 1280, 720}, Case{from_above, 321, 240}, Case{odd_up, 64, 97}}) {
    const double dist = (k.camera.eye - k.camera.target).norm();
    const render::CameraModel m = render::camera_model(k.camera, k.w, k.h, 0.1 * dist, 3 * dist);
    EXPECT_EQ(m.width, k.w);
    EXPECT_EQ(m.height, k.h);
    EXPECT_DOUBLE_EQ(m.cx, 0.5 * (k.w - 1));
    EXPECT_DOUBLE_EQ(m.cy, 0.5 * (k.h - 1));
    // The pose: a rotation, z along the view direction, y down against the up vector.
    const Eigen::Matrix3d r = m.pose.linear();
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    EXPECT_LT((r.col(2) - (k.camera.target - k.camera.eye).normalized()).norm(), 1e-12);
    EXPECT_LT((m.pose.translation() - k.camera.eye).norm(), 1e-15);
    const Eigen::Vector3d right = r.col(0), down = r.col(1);
    if (r.col(2).cross(k.camera.up).norm() > 1e-6) {
      EXPECT_LT(down.dot(k.camera.up), 0.0);
      EXPECT_NEAR(right.dot(k.camera.up), 0.0, 1e-12);
    }
    // Points across the view, near and far.
    for (double s : {-0.35, 0.0, 0.2})
      for (double t : {-0.3, 0.1, 0.25})
        for (double depth : {0.5, 1.0, 1.7}) {
          const Eigen::Vector3d p = m.pose * Eigen::Vector3d(s * depth, t * depth, depth * dist);
          const Eigen::Vector2d gl = opengl_pixel(k.camera, k.w, k.h, 0.1 * dist, 3 * dist, p);
          const Eigen::Vector2d pin = pinhole_pixel(m, p);
          EXPECT_LT((gl - pin).norm(), 2e-3) << "image " << k.w << "x" << k.h << " at " << p.transpose() << ": OpenGL "
                                             << gl.transpose() << ", pinhole " << pin.transpose();
        }
  }
}
