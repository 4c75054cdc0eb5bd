#pragma once
// The camera: look-at and perspective matrices (OpenGL conventions, column vectors), and the
// automatic framing used when a scene gives no camera.
#include <Eigen/Core>

namespace render {

struct Camera {
  Eigen::Vector3d eye{0.0, -1.0, 0.5};
  Eigen::Vector3d target{0.0, 0.0, 0.0};
  Eigen::Vector3d up{0.0, 0.0, 1.0};
  double fov_deg = 40;  // vertical field of view
};

// A camera that frames the box [lo, hi] from the front, to the right and above (looking
// along +y with z up), as close as the box's corners allow with a small margin.
Camera auto_frame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double fov_deg, double aspect);

Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up);
Eigen::Matrix4f perspective(double fov_deg, double aspect, double z_near, double z_far);
Eigen::Matrix4f orthographic(double left, double right, double bottom, double top, double z_near, double z_far);

}  // namespace render
