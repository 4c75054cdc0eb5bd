#pragma once
// The camera: look-at and perspective matrices (OpenGL conventions, column vectors), and the
// automatic framing used when a scene gives no camera.
#include <Eigen/Core>
#include <Eigen/Geometry>

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

// A pinhole camera as measurements need it (camera.json, poses.csv), in OpenCV's convention:
// camera axes x right, y down, z forward (along the optical axis); pixel (u, v) = (column, row)
// with the centre of the top-left pixel at (0, 0), so that a point (X, Y, Z) in camera axes is
// seen at u = fx X / Z + cx, v = fy Y / Z + cy.
struct CameraModel {
  int width = 0, height = 0;        // pixels
  double fx = 0, fy = 0;            // focal lengths (pixels)
  double cx = 0, cy = 0;            // principal point (pixels)
  double near = 0, far = 0;         // the clip planes: distances along the optical axis (m)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world from camera: origin the optical centre
};

// The camera a look-at `camera` and perspective(fov_deg, width / height, near, far) make:
// the same picture, as a pinhole model.
CameraModel camera_model(const Camera& camera, int width, int height, double near, double far);
// World from camera (OpenCV axes) of a look-at camera, with look_at's choice of up.
Eigen::Isometry3d camera_pose(const Camera& camera);

Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up);
Eigen::Matrix4f perspective(double fov_deg, double aspect, double z_near, double z_far);
Eigen::Matrix4f orthographic(double left, double right, double bottom, double top, double z_near, double z_far);

}  // namespace render
