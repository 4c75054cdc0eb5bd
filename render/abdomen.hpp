#pragma once
// What an endoscope sees around the organ: the abdominal cavity's wall (the peritoneum), a
// sphere about the organ's box that reaches out to the ports, so that the scope's own shaft
// and the instruments' shafts behind their ports are outside it. Its triangles face inward.
#include <vector>

#include <Eigen/Core>

#include "render/camera.hpp"
#include "render/render_scene.hpp"

namespace render {

struct Abdomen {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 1;  // m
};

// The cavity about the box [lo, hi]: centred on it, its radius the farther of 1.35 times the
// box's half diagonal and the nearest port (every port is then on or outside the wall).
Abdomen abdomen_around(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const std::vector<Eigen::Vector3d>& ports);

// The wall as a triangle mesh (a UV sphere of `rings` x 2 `rings` quads), normals inward.
SkinMesh abdomen_wall(const Abdomen& a, int rings);

// A look-at camera with the pose of an endoscope (world from camera, OpenCV axes) and its
// vertical field of view: the same picture as the pose, for the renderer's matrices.
Camera endoscope_camera(const Eigen::Isometry3d& pose, double vertical_fov_deg);

}  // namespace render
