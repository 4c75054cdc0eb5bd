#pragma once
// DIR/camera.json, written with the ground-truth views: the camera's intrinsics in pixels
// (width, height, fx, fy, cx, cy, OpenCV's convention: render::CameraModel) and its near and
// far clip planes (m, along the optical axis). Its pose, frame by frame, is in poses.csv.
#include <string>

#include "render/camera.hpp"

namespace vdmsim {

std::string camera_json(const render::CameraModel& camera);

}  // namespace vdmsim
